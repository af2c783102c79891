"""Plot PPO learning curves from ``rl_ppo.py --json`` outputs.

Each input is a file whose last line is the JSON object ``rl_ppo.py --json``
prints; the figure shows the training return (mean of the last 100
episodes) against env steps for every run, with the run's random and
sinusoid baselines as dotted lines in the same colour.

    python benchmarks/rl_ppo.py --timesteps 600000 --actuation symmetric --json > sym.log
    python benchmarks/plot_rl.py sym.log seed.log --out docs/figures/ppo_flat.png
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path


def load(path: str) -> dict:
    """The JSON object on the last non-empty line of ``path``."""
    lines = [ln for ln in Path(path).read_text().splitlines() if ln.strip()]
    if not lines:
        raise SystemExit(f"{path}: empty file")
    try:
        return json.loads(lines[-1])
    except json.JSONDecodeError as exc:
        raise SystemExit(f"{path}: the last line is not rl_ppo.py's JSON ({exc})") from None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", help="files ending with rl_ppo.py's JSON line")
    ap.add_argument("--out", required=True, help="output image (png, svg, pdf)")
    args = ap.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.0), constrained_layout=True)
    for k, path in enumerate(args.runs):
        run = load(path)
        color = f"C{k}"
        steps = [c[0] / 1000 for c in run["curve"]]
        ret = [c[1] for c in run["curve"]]
        label = f'PPO, actuation "{run.get("actuation", "seed")}", control_dt {run.get("control_dt", 0.05)} s'
        ax.plot(steps, ret, color=color, label=label)
        ax.axhline(run["sinusoid"], color=color, ls=":", lw=1)
        ax.axhline(run["random"], color=color, ls="--", lw=0.8)
        ax.annotate(
            f"sinusoid {run['sinusoid']:.2f}",
            (steps[-1], run["sinusoid"]),
            color=color,
            fontsize=8,
            ha="right",
            va="bottom",
        )
    ax.set_yscale("log")  # returns are distances (> 0) spanning three decades
    ax.set_xlabel("env steps (thousands)")
    ax.set_ylabel("training return:\nNormFinalDist in 4 s (voxel lengths)")
    ax.set_title("PPO on SoftWalker-Flat-v0 (dashed: random policy)")
    ax.legend(loc="lower right", fontsize=8)
    fig.savefig(args.out, dpi=120, bbox_inches="tight")  # no clipped label
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
