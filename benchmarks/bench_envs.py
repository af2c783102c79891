"""Environment throughput: env steps per second and render time of the SoftWalker ids.

Measures, with the default walker (216 voxels) and the default 0.05 s control
step, random actions:

* a single env (``gym.make``, the engine on one thread);
* ``SyncVectorEnv`` over N single envs (``make_vec(..., vectorization_mode="sync")``);
* the batched vector env (``make_vec(...)``: the ids' ``vector_entry_point``,
  all N robots in one engine call, the engine's default thread count);
* the engine alone for the same simulated time (the floor under any env);
* ``render()`` in ms per 320 x 240 frame on each id.

For scale, issue 6 quotes EvoGym's ``Walker-v0`` at about 400 env steps/s on
this machine kind for a 15-voxel 2-D body. Appends a table to
benchmarks/RESULTS.md.

    python benchmarks/bench_envs.py            # about 1 minute
    python benchmarks/bench_envs.py --quick --json
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import gymnasium as gym
import numpy as np
import results_log

import softgym  # noqa: F401  (registers the ids)
from softgym.design import default_walker
from softgym.engine import Simulation, default_num_threads, openmp_enabled

EVOGYM_WALKER = 400.0  # env steps/s, EvoGym Walker-v0 on this machine kind (issue 6)
ENV_ID = "SoftWalker-Flat-v0"


def env_steps_per_s(env, n_steps: int, num_envs: int = 1, seed: int = 0) -> float:
    """Env steps per second (sub-env steps for vector envs), random actions, autoreset included."""
    env.action_space.seed(seed)
    actions = [env.action_space.sample() for _ in range(min(n_steps, 64))]
    env.reset(seed=seed)
    env.step(actions[0])  # warm-up
    t0 = time.perf_counter()
    for k in range(n_steps):
        _, _, term, trunc, _ = env.step(actions[k % len(actions)])
        if num_envs == 1 and (term or trunc):
            env.reset()
    return n_steps * num_envs / (time.perf_counter() - t0)


def engine_steps_per_s(
    n_robots: int, n_steps: int, threads: int, control_dt: float = 0.05
) -> float:
    """The engine alone: set random temperatures, advance by control_dt (as the env does)."""
    sim = Simulation([default_walker()] * n_robots, n_threads=threads)
    rng = np.random.default_rng(0)
    n_vox = sim.positions(0).shape[0]
    temps = [14.0 * rng.uniform(-1, 1, (n_robots, n_vox)) for _ in range(64)]
    sim.advance(1.0)  # settle, as the env's reset does
    t0 = time.perf_counter()
    for k in range(n_steps):
        for r in range(n_robots):
            sim.set_temperature(r, temps[k % 64][r])
        sim.advance(control_dt)
    return n_steps * n_robots / (time.perf_counter() - t0)


def render_ms(env_id: str, frames: int) -> float:
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    for _ in range(5):
        env.step(env.action_space.sample())
    env.render()
    t0 = time.perf_counter()
    for _ in range(frames):
        env.render()
    ms = (time.perf_counter() - t0) / frames * 1e3
    env.close()
    return ms


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="short runs (< 30 s)")
    ap.add_argument("--json", action="store_true", help="print one JSON object as the last line")
    ap.add_argument("--no-append", action="store_true", help="do not append to RESULTS.md")
    ap.add_argument("--num-envs", type=int, default=16, help="vector env size (16)")
    args = ap.parse_args(argv)
    n = args.num_envs
    single_steps = 100 if args.quick else 400
    vec_steps = 10 if args.quick else 40
    threads = default_num_threads()
    cores = os.cpu_count()
    print(
        f"softgym env benchmark: {ENV_ID}, default walker (216 voxels), control_dt 0.05 s, "
        f"OpenMP {'on' if openmp_enabled() else 'off'}, {threads} engine threads, "
        f"{cores} CPUs",
        file=sys.stderr,
    )

    rows: list[tuple[str, float, str]] = []

    def add(name: str, value: float, note: str = "") -> float:
        rows.append((name, value, note))
        print(f"  {name:<46} {value:10.1f}  {note}", file=sys.stderr)
        return value

    single = add(
        "single env (gym.make), env steps/s",
        env_steps_per_s(gym.make(ENV_ID), single_steps),
        "engine on 1 thread",
    )
    eng1 = add(
        "engine alone, 1 robot, steps/s",
        engine_steps_per_s(1, single_steps, 1),
        "the floor under the single env",
    )
    sync_env = gym.make_vec(ENV_ID, num_envs=n, vectorization_mode="sync")
    sync = add(f"SyncVectorEnv x{n}, env steps/s", env_steps_per_s(sync_env, vec_steps, n))
    sync_env.close()
    vec_env = gym.make_vec(ENV_ID, num_envs=n)
    assert type(vec_env).__name__ == "SoftWalkerVectorEnv"
    vec = add(
        f"batched vector env x{n}, env steps/s",
        env_steps_per_s(vec_env, vec_steps, n),
        f"one engine call, {threads} threads",
    )
    vec_env.close()
    engn = add(
        f"engine alone, {n} robots, steps/s",
        engine_steps_per_s(n, vec_steps, threads),
        f"{threads} threads",
    )
    ratio = vec / sync
    frames = 10 if args.quick else 40
    render = {
        eid: render_ms(eid, frames)
        for eid in ("SoftWalker-Flat-v0", "SoftWalker-Wall-v0", "SoftWalker-Stairs-v0")
    }
    for eid, ms in render.items():
        add(f"render {eid} 320x240, ms/frame", ms)
    print(
        f"batched vector env / SyncVectorEnv (N={n}): {ratio:.2f}x per env step; "
        f"single env at {single / eng1:.0%} of the engine alone, vector env at {vec / engn:.0%}; "
        f"single env {single / EVOGYM_WALKER:.2f}x EvoGym Walker-v0's ~400 steps/s "
        f"(216 3-D voxels vs 15 2-D)",
        file=sys.stderr,
    )

    summary = {
        "single_env_steps_per_s": single,
        "sync_vector_env_steps_per_s": sync,
        "vector_env_steps_per_s": vec,
        "vector_vs_sync": ratio,
        "engine_1_robot_steps_per_s": eng1,
        "engine_n_robots_steps_per_s": engn,
        "render_ms_per_frame": render,
        "num_envs": n,
        "threads": threads,
        "cpus": cores,
        "quick": args.quick,
    }
    if not args.no_append:
        lines = [
            results_log.heading(
                "bench_envs.py", args.quick, [f"{cores} CPUs", f"{threads} engine threads"]
            ),
            f"{ENV_ID}, default walker (216 voxels), control_dt 0.05 s, random actions.\n",
            "| measure | value | note |",
            "|---|---|---|",
        ]
        lines += [f"| {name} | {value:.1f} | {note} |" for name, value, note in rows]
        lines.append(
            f"\nBatched vector env / SyncVectorEnv at N = {n}: {ratio:.2f}x per env step.\n"
        )
        results_log.append("\n".join(lines))
    if args.json:
        print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
