"""The ``softgym`` command line.

Subcommands
-----------
simulate
    Simulate the embedded default walker (or a design JSON) and write its
    centre-of-mass trajectory figure and a summary JSON.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
import time
from pathlib import Path

import numpy as np

__all__ = ["main"]

log = logging.getLogger("softgym")


def _default_body():
    try:
        from softgym.design import default_walker
    except ImportError:  # pragma: no cover - the design layer ships with the package
        default_walker = None
    if default_walker is not None:
        return default_walker()
    from softgym.engine import Body

    grid = np.ones((6, 6, 6), dtype=np.int32)
    grid[3:] = 2
    return Body(
        grid=grid, youngs_modulus=[0, 5e6, 5e6], density=[0, 1e6, 1e6], poisson=[0, 0.35, 0.35],
        cte=[0, 0.01, -0.01], mu_static=[0, 1, 1], mu_kinetic=[0, 0.5, 0.5],
    )


def _cmd_simulate(args: argparse.Namespace) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from softgym.engine import SimConfig, Simulation

    if args.design:
        from softgym.design import RobotDesign

        robot = RobotDesign.load(args.design)
    else:
        robot = _default_body()
    cfg = SimConfig(actuation=args.actuation, trace_interval=0.05)
    sim = Simulation([robot], cfg)
    t0 = time.perf_counter()
    rollout = sim.run(args.seconds)
    wall = time.perf_counter() - t0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    L = rollout.voxel_size
    trace = rollout.trace(0)
    disp = (rollout.cm_final[0, :2] - rollout.cm_init[0, :2]) / L
    summary = {
        "seconds": args.seconds,
        "wall_seconds": wall,
        "steps": int(rollout.steps[0]),
        "dt": float(rollout.dt[0]),
        "n_voxels": int(rollout.voxel_offsets[1]),
        "voxel_steps_per_s": float(rollout.voxel_offsets[1] * rollout.steps[0] / wall),
        "norm_final_dist": float(np.hypot(*disp)),
        "diverged": bool(rollout.diverged[0]),
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    ax1.plot(trace[:, 0] / L, trace[:, 1] / L, "-o", ms=2)
    ax1.plot(trace[0, 0] / L, trace[0, 1] / L, "gs", label="start")
    ax1.plot(trace[-1, 0] / L, trace[-1, 1] / L, "r^", label="end")
    ax1.set(xlabel="x (voxels)", ylabel="y (voxels)", title="centre of mass, top view", aspect="equal")
    ax1.legend()
    ax2.plot(trace[:, 3], trace[:, 2] / L)
    ax2.axvline(rollout.init_time, color="k", ls=":", label="init time")
    ax2.set(xlabel="t (s)", ylabel="z (voxels)", title="centre-of-mass height")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(out / "trajectory.png", dpi=120)
    plt.close(fig)
    print(json.dumps(summary, indent=2))
    print(f"wrote {out / 'trajectory.png'} and {out / 'summary.json'}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``softgym`` command."""
    parser = argparse.ArgumentParser(prog="softgym", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("simulate", help="simulate one robot and plot its trajectory")
    p.add_argument("--design", help="a RobotDesign JSON file (default: the embedded walker)")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--actuation", choices=["seed", "symmetric"], default="seed")
    p.add_argument("--out", default="runs/simulate")
    p.set_defaults(func=_cmd_simulate)
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    return int(args.func(args))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
