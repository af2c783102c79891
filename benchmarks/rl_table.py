"""The PPO baseline table and its learning curves, from the runs ``rl_baselines.sh`` stores.

Reads every ``benchmarks/data/rl/ppo/<task>-s<seed>/run.json`` (written by
``rl_ppo.py --run-dir``, also while a run is unfinished) and prints, per task,
PPO's return (deterministic actions, after the run's budget; an unfinished run
shows its last checkpoint's, marked ``*``), how many seeds beat the seed's
sinusoid sampled by the env, random actions, and the evolved controller of
``bench_tasks.py`` (``benchmarks/data/rl/baselines/evolved_controllers.json``:
3 s episodes, where the Gym envs' are 4 s, so it is a reference, not a
same-window comparison). ``--out`` draws the learning curves (one panel per
task: PPO's deterministic return at each checkpoint per seed, the
baselines as horizontal lines).

    python benchmarks/rl_table.py --out docs/figures/ppo_baselines.png
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "rl"


def load_runs(root: Path = DATA / "ppo") -> dict[str, list[dict]]:
    """Stored runs by task (``"push (sensing)"`` for the sensing observation), seeds in order."""
    runs: dict[str, list[dict]] = {}
    for path in sorted(root.glob("*/run.json")):
        run = json.loads(path.read_text())
        sensing = run["settings"].get("observe", "blind") == "sensing"
        runs.setdefault(run["task"] + (" (sensing)" if sensing else ""), []).append(run)
    for task in runs:
        runs[task].sort(key=lambda r: r["settings"]["seed"])
    return runs


def evolved() -> dict[str, dict]:
    """``bench_tasks.py``'s evolved controllers by task."""
    return json.loads((DATA / "baselines" / "evolved_controllers.json").read_text())["tasks"]


def ppo_value(run: dict) -> tuple[float, bool]:
    """PPO's deterministic return: the final one, or the last checkpoint's (unfinished: False)."""
    if run.get("finished"):
        return float(run["final"]["ppo"]), True
    if run["eval_curve"]:
        return float(run["eval_curve"][-1][1]), False
    return float("nan"), False


def table(runs: dict[str, list[dict]]) -> str:
    """The markdown table."""
    evo = evolved()
    lines = [
        "| task | seeds | env steps (budget) | PPO (per seed) | PPO > sinusoid | sinusoid | random | evolved (3 s) |",
        "|---|---:|---|---|---:|---:|---:|---:|",
    ]
    for task, rs in runs.items():
        vals = [ppo_value(r) for r in rs]
        sin = rs[0]["baselines"]["sinusoid"][0]
        rnd = float(np.mean([np.mean(r["baselines"]["random"]) for r in rs]))
        steps = ", ".join(f"{r['num_timesteps'] // 1000}k" for r in rs)
        ppo = ", ".join(f"{v:.3g}{'' if done else '*'}" for v, done in vals)
        above = sum(v > r["baselines"]["sinusoid"][0] for (v, _), r in zip(vals, rs))
        e = evo.get(rs[0]["task"])
        ev = f"{e['evolved_median']:.3g} [{e['evolved_min']:.3g}, {e['evolved_max']:.3g}]" if e else "-"
        lines.append(
            f"| {task} | {len(rs)} | {steps} ({rs[0]['timesteps'] // 1000}k) | {ppo} | "
            f"{above}/{len(rs)} | {sin:.3g} | {rnd:.3g} | {ev} |"
        )
    return "\n".join(lines)


def plot(runs: dict[str, list[dict]], out: str | Path) -> Path:
    """Learning curves, one panel per task, into the image ``out``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    evo = evolved()
    n = len(runs)
    cols = min(4, n)
    rows = -(-n // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.6 * cols, 2.9 * rows), layout="constrained",
                             squeeze=False)  # fmt: skip
    for ax, (task, rs) in zip(axes.flat, runs.items()):
        for k, run in enumerate(rs):
            if run["eval_curve"]:
                t, v = np.array(run["eval_curve"]).T
                ax.plot(t / 1000, v, color=f"C{k}", label=f"PPO seed {run['settings']['seed']}")
        ax.axhline(rs[0]["baselines"]["sinusoid"][0], color="k", ls=":", label="sinusoid")
        ax.axhline(np.mean(rs[0]["baselines"]["random"]), color="grey", ls="--", label="random")
        if rs[0]["task"] in evo:
            ax.axhline(evo[rs[0]["task"]]["evolved_median"], color="C3", ls="-.", label="evolved (3 s)")
        ax.set_title(f"{task} ({rs[0]['action_mode']} actions)", fontsize=9)
        ax.set_xlabel("env steps (k)", fontsize=8)
        ax.set_ylabel("episode return", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.legend(fontsize=6)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle("PPO (SB3): deterministic return per checkpoint", fontsize=10)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return Path(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=None, help="write the learning curves to this image")
    ap.add_argument("--root", default=str(DATA / "ppo"), help="where the runs are stored")
    args = ap.parse_args(argv)
    runs = load_runs(Path(args.root))
    if not runs:
        raise SystemExit(f"no runs stored under {args.root}")
    print(table(runs))
    print("\n* unfinished: the last checkpoint's return.")
    if args.out:
        print(f"wrote {plot(runs, args.out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
