"""The cost of sensing and of the brains' control step, against the engine's own time.

A batch of robots (the default walker) runs one episode of a task in closed
loop (``drive="brain"``, a distributed and a central brain) and, for the
baseline, blind (``drive="action"``, a constant action each step, no
observation read). Each control step is timed in its parts: the engine
(``EpisodeBatch.advance``) and the control step (``BrainDrive.step``: the
sensors, ``Sensing.read`` (the compiled per-voxel pass, the body's rotation,
the task's senses), the networks and the action map), the sensors also alone.
Prints ms per control step and the ratio control / engine, one row per task,
brain kind and control step; appends the table to benchmarks/RESULTS.md
unless ``--no-append``.

    python benchmarks/bench_sensing.py                      # batch 64, push and flat, ~2 min
    python benchmarks/bench_sensing.py --batch 16 --tasks flat --no-append
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import results_log

from softgym.design import default_walker
from softgym.engine import default_num_threads
from softgym.tasks import EpisodeBatch, get_task
from softgym.tasks.brains import brain_spec


def _batch(task, n, dt, drive, kind=None, threads=None, hidden=8):
    ds = [default_walker()] * n
    if kind is not None:
        spec = brain_spec(kind, task, (6, 6, 6), hidden=hidden, control_dt=dt)
        ds = [default_walker().replace(brain=spec.random(i)) for i in range(n)]
    cfg = task.config(trace_interval=1e9)
    b = EpisodeBatch(ds, task, (6, 6, 6), dt, float(task.seconds) - cfg.init_time, None, cfg,
                     n_threads=threads, drive=drive)  # fmt: skip
    b.reset_all()
    return b


def measure(task_name: str, n: int, dt: float, kind: str | None, threads: int, steps: int) -> dict:
    """Seconds per control step of each part (engine, sensing, network) over ``steps`` steps."""
    task = get_task(task_name)
    drive = "action" if kind is None else "brain"
    b = _batch(task, n, dt, drive, kind, threads)
    every = np.ones(n, dtype=bool)
    t_engine = t_sense = t_net = 0.0
    steps = min(steps, b.max_steps)
    if kind is None:
        act = np.zeros((n, b.n_cells))
    for _ in range(steps):
        if kind is None:
            t0 = time.perf_counter()
            b.apply(act)
            t_net += time.perf_counter() - t0
        else:
            t0 = time.perf_counter()
            b.brains.step()  # the senses, the networks and the action map: the whole overhead
            t1 = time.perf_counter()
            b.sensing.read(b.clock(), b.period)  # the senses alone, timed apart
            t_sense += time.perf_counter() - t1
            t_net += t1 - t0
        t3 = time.perf_counter()
        b.advance()
        t_engine += time.perf_counter() - t3
        b.update(every)
    # "control": the whole control step (senses + networks + action map), "sense" its senses
    return {"engine": t_engine / steps, "sense": t_sense / steps, "control": t_net / steps}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", type=int, default=64, help="robots in the batch (default 64)")
    ap.add_argument("--tasks", nargs="+", default=["push", "flat"])
    ap.add_argument("--control-dt", type=float, nargs="+", default=[0.05, 0.02])
    ap.add_argument("--steps", type=int, default=40, help="control steps timed per case")
    ap.add_argument("--threads", type=int, default=None, help="engine threads (default all)")
    ap.add_argument("--no-append", action="store_true")
    args = ap.parse_args(argv)
    threads = default_num_threads() if args.threads is None else args.threads
    rows = []
    head = ("| task | control step (s) | brain | engine ms/step | control ms/step (of which sensing) "
            "| control / engine |")  # fmt: skip
    print(head)
    print("|---|---|---|---|---|---|")
    for name in args.tasks:
        for dt in args.control_dt:
            for kind in (None, "distributed", "central"):
                r = measure(name, args.batch, dt, kind, threads, args.steps)
                ratio = r["control"] / r["engine"]
                row = (f"| {name} | {dt:g} | {kind or 'blind (action)'} | {1e3 * r['engine']:.1f} | "
                       f"{1e3 * r['control']:.1f} ({1e3 * r['sense']:.1f}) | "
                       f"{'-' if kind is None else f'{100 * ratio:.1f} %'} |")  # fmt: skip
                print(row, flush=True)
                rows.append(row)
    if not args.no_append:
        text = results_log.heading("bench_sensing.py", details=[f"batch {args.batch}", f"{threads} threads"])
        text += (f"\n`python benchmarks/bench_sensing.py --batch {args.batch} --tasks {' '.join(args.tasks)} "
                 f"--control-dt {' '.join(f'{d:g}' for d in args.control_dt)} --steps {args.steps} "
                 f"--threads {threads}`\n\n")  # fmt: skip
        results_log.append(text + head + "\n|---|---|---|---|---|---|\n" + "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
