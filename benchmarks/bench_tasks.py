"""Is each task meaningful? Random actions, the seed's sinusoid and a short evolution, per task.

For every registered task (``softgym.tasks.task_names()``), on the default
6x6x6 walker in its Gym environment (``SoftWalkerVectorEnv``, 0.02 s control
steps, 3 s episodes):

* **random**: uniform random actions in [-1, 1], mean score of 3 seeded episodes;
* **sinusoid**: the design's own controller (``drive="controller"``: the seed's
  open-loop sinusoid, exactly what ``softgym.evaluate`` reports);
* **evolved**: the best score of a short controller evolution, median (and
  range) over 3 seeds: an open-loop policy ``action_c = a_c sin(theta + phi_c)``
  (``theta`` the observed drive phase) with one phase ``phi_c`` and amplitude
  ``a_c`` per cell, started from the seed's sinusoid sampled per step (all
  phases 0) and its mutants, evolved by an elitist (mu + lambda) strategy, the whole
  population stepped as one vector env (one engine call per control step);
* **env steps/s**: robot control steps per second of wall time during evolution.

A task is meaningful when the evolved controller beats random actions (and the
scores differ). The score is the task's ``score`` (its reward metric: voxel
lengths, radians for ``turn``, voxel lengths^2 for ``grow``).

    python benchmarks/bench_tasks.py              # 6 x 5 generations x 3 seeds (~25 min on 2 busy cores)
    python benchmarks/bench_tasks.py --quick      # a few minutes: 4 x 2 generations x 1 seed
    python benchmarks/bench_tasks.py --tasks gap,push --no-append
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import platform
import time
from pathlib import Path

import numpy as np

from softgym.envs import SoftWalkerVectorEnv
from softgym.tasks import get_task, task_names

RESULTS = Path(__file__).with_name("RESULTS.md")


def _run_episode(env: SoftWalkerVectorEnv, policy) -> np.ndarray:
    """One episode of every sub-env; returns the ``score`` each had when its episode ended."""
    obs, _ = env.reset(seed=0)
    score = np.full(env.num_envs, np.nan)
    t = 0
    while np.isnan(score).any():
        obs, _, term, trunc, info = env.step(policy(obs, t))
        t += 1
        ended = (term | trunc) & np.isnan(score)
        score[ended] = np.asarray(info["score"], dtype=np.float64)[ended]
    return score


def _make(task: str, n: int, args: argparse.Namespace, drive: str = "action") -> SoftWalkerVectorEnv:
    steps = int(round(args.episode / args.control_dt))
    return SoftWalkerVectorEnv(num_envs=n, task=task, episode_seconds=args.episode,
                               control_dt=args.control_dt, max_episode_steps=steps,
                               n_threads=args.threads, drive=drive)  # fmt: skip


def random_score(task: str, args: argparse.Namespace) -> float:
    env = _make(task, 3, args)
    rng = np.random.default_rng(0)
    shape = env.single_action_space.shape

    def policy(obs, t):
        return rng.uniform(-1.0, 1.0, (env.num_envs, *shape))

    return float(_run_episode(env, policy).mean())


def sinusoid_score(task: str, args: argparse.Namespace) -> float:
    env = _make(task, 1, args, drive="controller")
    zeros = np.zeros((1, *env.single_action_space.shape))
    return float(_run_episode(env, lambda obs, t: zeros)[0])


def evolve(task: str, seed: int, args: argparse.Namespace) -> tuple[float, int, float]:
    """Best score of a (mu + lambda) evolution of per-cell phases and amplitudes.

    Returns the best score, the robot-steps simulated and the wall time (s).
    """
    pop = args.pop
    env = _make(task, pop, args)
    n = env.single_action_space.shape[0]
    rng = np.random.default_rng(seed)
    mu = max(2, pop // 4)

    def mutate(phase, amp):
        mask = rng.random(phase.shape) < 0.2
        phase = phase + mask * rng.normal(0.0, 0.8, phase.shape)
        return phase, np.clip(amp + mask * rng.normal(0.0, 0.2, amp.shape), 0.0, 1.0)

    # the first individual is the seed's sinusoid sampled per step (every phase 0, full
    # amplitude), the others mutants of it
    phase, amp = np.zeros((pop, n)), np.ones((pop, n))
    phase[1:], amp[1:] = mutate(phase[1:], amp[1:])
    best = -np.inf
    steps = 0
    t0 = time.perf_counter()
    for _ in range(args.generations):
        cos_p, sin_p = np.cos(phase), np.sin(phase)

        def policy(obs, t, cos_p=cos_p, sin_p=sin_p, amp=amp):
            s, c = obs[:, -2:-1], obs[:, -1:]  # sin and cos of the drive phase theta
            return amp * (s * cos_p + c * sin_p)  # a sin(theta + phi)

        score = _run_episode(env, policy)
        steps += pop * int(round(args.episode / args.control_dt))
        best = max(best, float(score.max()))
        elite = np.argsort(-score, kind="stable")[:mu]
        parents = rng.choice(elite, pop - mu)
        new_phase, new_amp = mutate(phase[parents], amp[parents])
        phase = np.concatenate([phase[elite], new_phase])
        amp = np.concatenate([amp[elite], new_amp])
    return best, steps, time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="4 x 2 generations, 1 seed, 3 s episodes")
    p.add_argument("--tasks", help="comma-separated task names (default: all)")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--control-dt", type=float, default=0.02,
                   help="seconds per action (0.02: 12.5 samples of the 0.25 s drive period)")
    p.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    p.add_argument("--json", action="store_true", help="print the rows as JSON at the end")
    args = p.parse_args()
    # (each robot-second costs ~0.3 s of wall time on a busy 2-core machine: the full run
    # simulates 16 tasks x 3 seeds x 5 generations x 6 robots x 3 s, about 25 minutes)
    if args.quick:
        args.pop, args.generations, args.seeds, args.episode = 4, 2, 1, 3.0
    else:
        args.pop, args.generations, args.seeds, args.episode = 6, 5, 3, 3.0
    names = args.tasks.split(",") if args.tasks else task_names()
    rows = []
    t_all = time.perf_counter()
    for name in names:
        task = get_task(name)
        t0 = time.perf_counter()
        rnd = random_score(name, args)
        sin = sinusoid_score(name, args)
        bests, steps, wall = [], 0, 0.0
        for seed in range(args.seeds):
            b, s, w = evolve(name, seed, args)
            bests.append(b)
            steps += s
            wall += w
        row = {
            "task": name, "measure": task.reward, "random": rnd, "sinusoid": sin,
            "evolved": float(np.median(bests)), "evolved_min": float(min(bests)),
            "evolved_max": float(max(bests)), "steps_per_s": steps / wall,
            "seconds": time.perf_counter() - t0,
        }  # fmt: skip
        rows.append(row)
        print(f"{name:12s} {task.reward:16s} random {rnd:8.3f}  sinusoid {sin:8.3f}  evolved "
              f"{row['evolved']:8.3f} [{row['evolved_min']:.3f}, {row['evolved_max']:.3f}]  "
              f"{row['steps_per_s']:7.0f} steps/s  ({row['seconds']:.0f} s)", flush=True)  # fmt: skip
    total = time.perf_counter() - t_all
    lines = [
        "| task | measure | random | seed sinusoid | evolved (median [min, max]) | env steps/s |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for r in rows:
        lines.append(
            f"| {r['task']} | {r['measure']} | {r['random']:.2f} | {r['sinusoid']:.2f} | "
            f"{r['evolved']:.2f} [{r['evolved_min']:.2f}, {r['evolved_max']:.2f}] | "
            f"{r['steps_per_s']:.0f} |"
        )
    table = "\n".join(lines)
    print(table)
    print(f"total {total:.0f} s")
    if not args.no_append:
        mode = "--quick" if args.quick else "full"
        header = (
            f"\n## Task suite ({mode}: population {args.pop}, {args.generations} generations, "
            f"{args.seeds} seed(s), {args.episode:g} s episodes of {args.control_dt:g} s steps), "
            f"{_dt.date.today().isoformat()}, {platform.machine()}, {args.threads} threads, "
            f"{total / 60:.0f} min\n\n"
            "`benchmarks/bench_tasks.py`: the default walker in each task's env; random actions "
            "(mean of 3), the seed's sinusoid (the design's controller), the best of an evolution "
            "of per-cell phases and amplitudes (median over seeds). Scores are each task's "
            "`score` (voxel lengths; rad for turn; voxel lengths^2 for grow).\n\n"
        )
        with RESULTS.open("a") as f:
            f.write(header + table + "\n")
    if args.json:
        print(json.dumps(rows))


if __name__ == "__main__":
    main()
