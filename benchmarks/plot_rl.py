"""Plot the PPO learning curves stored before issue 33 (``benchmarks/data/rl/*.json``).

Each input is either a JSON file (the runs stored in ``benchmarks/data/rl/``)
or a log whose last line is such a JSON object (the format ``rl_ppo.py --json``
printed before issue 33: top-level ``curve``, ``ppo``, ``sinusoid``,
``random``); without inputs the stored runs are drawn. The figure shows the
training return (mean of the last 100 episodes) against env steps for every
run, with the run's sinusoid (dotted) and random-policy (dashed) baselines in
the same colour. Runs of the current ``rl_ppo.py --run-dir`` are drawn by
``rl_table.py``.

    python benchmarks/plot_rl.py --out docs/figures/ppo_flat_600k.png
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

DATA = Path(__file__).resolve().parent / "data" / "rl"


def load(path: str | Path) -> dict:
    """The run in ``path``: the whole file as JSON, or the JSON object on its last non-empty line."""
    text = Path(path).read_text()
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        pass
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise SystemExit(f"{path}: empty file")
    try:
        return json.loads(lines[-1])
    except json.JSONDecodeError as exc:
        raise SystemExit(f"{path}: the last line is not rl_ppo.py's JSON ({exc})") from None


def stored_runs() -> list[Path]:
    """The runs stored in ``benchmarks/data/rl/``, in name order."""
    return sorted(DATA.glob("*.json"))


def plot(runs: list[dict], out: str | Path) -> Path:
    """Draw ``runs`` (``rl_ppo.py --json`` objects) into the image ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 5.0), layout="constrained")
    for k, run in enumerate(runs):
        color = f"C{k}"
        steps = [c[0] / 1000 for c in run["curve"]]
        ret = [c[1] for c in run["curve"]]
        label = (
            f'actuation "{run.get("actuation", "seed")}", control_dt {run.get("control_dt", 0.05)} s'
            f" (trained policy {run['ppo']:.3g})"
        )
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
    presets = sorted({run.get("preset", "corotational") for run in runs})
    ax.set_yscale("log")  # returns are distances (> 0) spanning decades
    ax.set_xlabel("env steps (thousands)")
    ax.set_ylabel("training return: NormFinalDist in 4 s\n(voxel lengths, last 100 episodes)")
    ax.set_title(
        f"PPO on SoftWalker-Flat-v0, {'/'.join(presets)} preset\n"
        "dotted: sinusoid, dashed: random policy"
    )
    fig.legend(loc="outside lower center", fontsize=8, ncols=1)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return Path(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "runs",
        nargs="*",
        help="JSON files or logs ending with rl_ppo.py's JSON line (default: benchmarks/data/rl/*.json)",
    )
    ap.add_argument("--out", required=True, help="output image (png, svg, pdf)")
    args = ap.parse_args(argv)
    paths = args.runs or stored_runs()
    if not paths:
        raise SystemExit(f"no runs given and none stored in {DATA}")
    plot([load(p) for p in paths], args.out)
    print(f"wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
