"""Is each task meaningful? Random actions, the seed's sinusoid and a short evolution, per task.

For every registered task (``softgym.tasks.task_names()``), on the default
6x6x6 walker, 3 s episodes after the 1 s settling:

* **random**: uniform random actions in [-1, 1] in the task's Gym vector env
  (``SoftWalkerVectorEnv``, 0.05 s control steps), mean score of 3 episodes;
* **sinusoid**: the design's own controller (the seed's open-loop sinusoid,
  what ``softgym.evaluate`` reports);
* **evolved**: the best score of a short controller evolution, median (and
  range) over 3 seeds: a drive phase and amplitude per voxel (the engine's own
  sinusoid, shifted and scaled cell by cell: each cell its own material row),
  started from the seed's sinusoid (every phase 0) and its mutants, evolved by
  an elitist (mu + lambda) strategy, each generation one batched Simulation
  restored from the shared settled state;
* **env steps/s**: robot control steps (0.05 s) per second of wall time of the
  task's vector env with 3 robots under random actions.

A task is meaningful when the evolved controller beats random actions (and the
scores differ). The score is the task's ``score`` (its reward metric: voxel
lengths, radians for ``turn``, voxel lengths^2 for ``grow``).

    python benchmarks/bench_tasks.py              # 6 x 15 generations x 3 seeds (~40 min)
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

from softgym.design import default_walker
from softgym.engine import Body, Simulation
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


def _make(task: str, n: int, args: argparse.Namespace) -> SoftWalkerVectorEnv:
    steps = int(round(args.episode / args.control_dt))
    return SoftWalkerVectorEnv(num_envs=n, task=task, episode_seconds=args.episode,
                               control_dt=args.control_dt, max_episode_steps=steps,
                               n_threads=args.threads)  # fmt: skip


def random_score(task: str, args: argparse.Namespace) -> tuple[float, float]:
    """Mean score of 3 random-action episodes and the env's robot steps per second."""
    env = _make(task, 3, args)
    rng = np.random.default_rng(0)
    shape = env.single_action_space.shape

    def policy(obs, t):
        return rng.uniform(-1.0, 1.0, (env.num_envs, *shape))

    env.reset(seed=0)  # the first reset settles: not timed
    t0 = time.perf_counter()
    score = _run_episode(env, policy)
    wall = time.perf_counter() - t0
    return float(score.mean()), 3 * int(round(args.episode / args.control_dt)) / wall


def phase_body(design, phase: np.ndarray, amp: np.ndarray) -> Body:
    """``design``'s body with a drive phase (rad) and amplitude (0-1, on its CTE) per filled cell.

    Each filled cell becomes its own material id (its material's row, CTE times
    ``amp``, phase ``phase``), so the engine's own sinusoid drives it: the seed's
    continuous drive, shifted and scaled cell by cell.
    """
    base = design.to_body()
    flat = design.grid.ravel()
    cells = np.flatnonzero(flat)
    mat = flat[cells].astype(np.intp)
    grid = np.zeros(flat.size, dtype=np.int32)
    grid[cells] = np.arange(1, cells.size + 1)

    def table(values: np.ndarray) -> np.ndarray:
        return np.concatenate([[0.0], np.asarray(values, dtype=np.float64)])

    return Body(
        grid=grid.reshape(design.grid.shape),
        youngs_modulus=table(base.youngs_modulus[mat]),
        density=table(base.density[mat]),
        poisson=table(base.poisson[mat]),
        cte=table(base.cte[mat] * amp[cells]),
        mu_static=table(base.mu_static[mat]),
        mu_kinetic=table(base.mu_kinetic[mat]),
        phase=table(phase[cells]),
        temp_amplitude=base.temp_amplitude,
        period=base.period,
    )


class PhaseRunner:
    """Scores per-cell phase/amplitude controllers of the default walker on a task, batched.

    The settled state (1 s, no actuation: the same for every controller) is
    simulated once and restored; each batch then runs ``episode`` seconds of
    the engine's own drive and reports the task's ``score`` (its
    :meth:`~softgym.tasks.Task.metrics`, as ``softgym.evaluate``).
    """

    def __init__(self, task: str, n: int, args: argparse.Namespace) -> None:
        self.design = default_walker()
        self.task = get_task(task, seconds=1.0 + args.episode)
        self.config = self.task.config()
        self.terrains = [self.task.terrain_for(self.design.shape)] * n
        self.n, self.threads = n, args.threads
        cells = self.design.grid.size
        zero = phase_body(self.design, np.zeros(cells), np.ones(cells))
        sim = Simulation([zero] * n, config=self.config, terrain=self.terrains, n_threads=args.threads)
        sim.advance_to(self.config.init_time)
        self.settled = sim.get_state()

    def scores(self, phase: np.ndarray, amp: np.ndarray) -> np.ndarray:
        bodies = [phase_body(self.design, p, a) for p, a in zip(phase, amp)]
        sim = Simulation(bodies, config=self.config, terrain=self.terrains, n_threads=self.threads)
        sim.set_state(self.settled)
        sim.advance_to(self.task.seconds)
        return self.task.metrics(sim.rollout(), self.terrains)["score"]


def evolve(runner: PhaseRunner, seed: int, args: argparse.Namespace) -> tuple[float, float]:
    """Best score of a (mu + lambda) evolution of per-cell drive phases and amplitudes.

    The first individual is the seed's sinusoid (every phase 0, full amplitude),
    the others its mutants; the best ``mu`` are kept each generation. Returns
    the best score and the seed sinusoid's.
    """
    pop = runner.n
    n = runner.design.grid.size
    rng = np.random.default_rng(seed)
    mu = max(2, pop // 4)

    def mutate(phase, amp):
        # a fifth of the cells' phases and amplitudes, and the amplitude of them all
        mask = rng.random(phase.shape) < 0.2
        phase = phase + mask * rng.normal(0.0, 1.0, phase.shape)
        amp = amp + mask * rng.normal(0.0, 0.3, amp.shape)
        amp *= np.exp(rng.normal(0.0, 0.25, (amp.shape[0], 1)))
        return phase, np.clip(amp, 0.0, 1.0)

    phase, amp = np.zeros((pop, n)), np.ones((pop, n))
    phase[1:], amp[1:] = mutate(phase[1:], amp[1:])
    best, sinusoid = -np.inf, np.nan
    for g in range(args.generations):
        score = runner.scores(phase, amp)
        if g == 0:
            sinusoid = float(score[0])
        best = max(best, float(score.max()))
        elite = np.argsort(-score, kind="stable")[:mu]
        new_phase, new_amp = mutate(phase[rng.choice(elite, pop - mu)], amp[rng.choice(elite, pop - mu)])
        phase = np.concatenate([phase[elite], new_phase])
        amp = np.concatenate([amp[elite], new_amp])
    return best, sinusoid


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true", help="4 x 2 generations, 1 seed")
    p.add_argument("--tasks", help="comma-separated task names (default: all)")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--control-dt", type=float, default=0.05, help="seconds per random action")
    p.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    p.add_argument("--json", action="store_true", help="print the rows as JSON at the end")
    args = p.parse_args()
    # (a robot-second costs ~0.1-0.3 s of wall time on a busy 2-core machine: the full run
    # simulates 16 tasks x 3 seeds x 15 generations x 6 robots x 3 s: ~40 minutes)
    if args.quick:
        args.pop, args.generations, args.seeds, args.episode = 4, 2, 1, 3.0
    else:
        args.pop, args.generations, args.seeds, args.episode = 6, 15, 3, 3.0
    names = args.tasks.split(",") if args.tasks else task_names()
    rows = []
    t_all = time.perf_counter()
    for name in names:
        task = get_task(name)
        t0 = time.perf_counter()
        rnd, steps_per_s = random_score(name, args)
        runner = PhaseRunner(name, args.pop, args)
        runs = [evolve(runner, seed, args) for seed in range(args.seeds)]
        bests, sin = [b for b, _ in runs], runs[0][1]
        row = {
            "task": name, "measure": task.reward, "random": rnd, "sinusoid": sin,
            "evolved": float(np.median(bests)), "evolved_min": float(min(bests)),
            "evolved_max": float(max(bests)), "steps_per_s": steps_per_s,
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
            f"{args.seeds} seed(s), {args.episode:g} s episodes), "
            f"{_dt.date.today().isoformat()}, {platform.machine()}, {args.threads} threads, "
            f"{total / 60:.0f} min\n\n"
            "`benchmarks/bench_tasks.py`: the default walker; random actions in the task's Gym "
            "env (mean of 3), the seed's sinusoid (the design's controller), the best of an "
            "evolution of per-voxel drive phases and amplitudes started from it (median "
            "[min, max] over seeds). Scores are each task's `score` (voxel lengths; rad for "
            "turn; voxel lengths^2 for grow); env steps/s: 0.05 s steps of a 3-robot vector "
            "env under random actions.\n\n"
        )
        with RESULTS.open("a") as f:
            f.write(header + table + "\n")
    if args.json:
        print(json.dumps(rows))


if __name__ == "__main__":
    main()
