"""The PPO baseline table and its learning curves, from the runs ``rl_baselines.sh`` stores.

Reads every ``benchmarks/data/rl/ppo/<task>-s<seed>/run.json`` (written by
``rl_ppo.py --run-dir``, also while a run is unfinished) and prints, per task,
the actions PPO gave (``contraction`` under the seed's law, or ``temperature``
with the actuation law), PPO's return (deterministic actions, after the run's
budget; an unfinished run shows its last checkpoint's, marked ``*``), how many
seeds beat the seed's sinusoid sampled by the env every control step (the
stored baseline the headline compares against) and the engine's continuous
drive of the same sinusoid (``drive="controller"``, what evolution and
``softgym.evaluate`` run; computed here on the installed engine, 4.38 on flat),
random actions, and the evolved controller of ``bench_tasks.py``
(``benchmarks/data/rl/baselines/evolved_controllers.json``: 3 s episodes, where
the Gym envs' are 4 s, so it is a reference, not a same-window comparison).

The notes under the table name the engine each run trained on: ``run.json``
records a ``commit`` where ``rl_ppo.py`` wrote one; the stored runs predate it,
so the notes give the commits that stored each run's checkpoints (``git log``
on its folder: the run trained on the engine of that span). ``--out`` draws the
learning curves (one panel per task: PPO's deterministic return at each
checkpoint per seed, the baselines as horizontal lines).

    python benchmarks/rl_table.py --out docs/figures/ppo_baselines.png
"""

from __future__ import annotations

import argparse
import json
import subprocess
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "rl"
REPO = Path(__file__).resolve().parents[1]


def run_label(run: dict) -> str:
    """A run's row: its task, ``(sensing)`` for the sensing observation, ``(sensing, shaped)``
    when it trained on the task's dense guidance too (``rl_ppo.py --shaping``)."""
    settings = run["settings"]
    tags = ["sensing"] if settings.get("observe", "blind") == "sensing" else []
    tags += ["shaped"] if settings.get("shaping") else []
    return run["task"] + (f" ({', '.join(tags)})" if tags else "")


def load_runs(root: Path = DATA / "ppo") -> dict[str, list[dict]]:
    """Stored runs by :func:`run_label` (task and observation), seeds in order."""
    runs: dict[str, list[dict]] = {}
    for path in sorted(root.glob("*/run.json")):
        run = json.loads(path.read_text())
        runs.setdefault(run_label(run), []).append(run)
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


def actions(run: dict) -> str:
    """The run's actions: the action mode, and the actuation law where it is not the seed's."""
    from softgym.tasks import get_task

    law = run["settings"].get("actuation") or get_task(run["task"]).engine_settings.get("actuation")
    return run["action_mode"] + (f" ({law})" if law and law != "seed" else "")


def continuous_sinusoid(run: dict) -> float:
    """The return of one episode of the run's env driven by the design's own sinusoid.

    ``drive="controller"``: the engine's continuous drive, what evolution and
    :func:`softgym.evaluate` run, where the stored ``sinusoid`` baseline samples
    the same signal every control step. Computed on the installed engine.
    """
    import gymnasium as gym

    import softgym  # noqa: F401  (registers the ids)

    env = gym.make_vec(run["env"], num_envs=1, vectorization_mode="vector_entry_point",
                       n_threads=1, drive="controller", **run["env_kwargs"])  # fmt: skip
    env.reset(seed=0)
    total, done = 0.0, False
    while not done:
        _, r, term, trunc, _ = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        total += float(r[0])
        done = bool(term[0] or trunc[0])
    env.close()
    return total


def stored_in(run_dir: Path) -> tuple[str, str] | None:
    """The first and the last commit that stored files of ``run_dir`` ("hash date"), or None."""
    try:
        out = subprocess.run(
            ["git", "-C", str(REPO), "log", "--format=%h %ad", "--date=short", "--", str(run_dir)],
            capture_output=True, text=True, timeout=60, check=True,
        ).stdout.split("\n")  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    commits = [line for line in out if line.strip()]
    return (commits[-1], commits[0]) if commits else None


def table(runs: dict[str, list[dict]]) -> str:
    """The markdown table."""
    evo = evolved()
    lines = [
        "| task | seeds | actions | env steps (budget) | PPO (per seed) | PPO > sinusoid | sinusoid "
        "| PPO > continuous | continuous | random | evolved (3 s) |",
        "|---|---:|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for task, rs in runs.items():
        vals = [ppo_value(r) for r in rs]
        sin = rs[0]["baselines"]["sinusoid"][0]
        cont = continuous_sinusoid(rs[0])
        rnd = float(np.mean([np.mean(r["baselines"]["random"]) for r in rs]))
        steps = ", ".join(f"{r['num_timesteps'] // 1000}k" for r in rs)
        ppo = ", ".join(f"{v:.3g}{'' if done else '*'}" for v, done in vals)
        above = sum(v > r["baselines"]["sinusoid"][0] for (v, _), r in zip(vals, rs))
        above_cont = sum(v > cont for v, _ in vals)
        e = evo.get(rs[0]["task"])
        ev = f"{e['evolved_median']:.3g} [{e['evolved_min']:.3g}, {e['evolved_max']:.3g}]" if e else "-"
        lines.append(
            f"| {task} | {len(rs)} | {actions(rs[0])} | {steps} ({rs[0]['timesteps'] // 1000}k) | "
            f"{ppo} | {above}/{len(rs)} | {sin:.3g} | {above_cont}/{len(rs)} | {cont:.3g} | "
            f"{rnd:.3g} | {ev} |"
        )
    return "\n".join(lines)


def notes(root: Path) -> str:
    """What the table's numbers are, and the engine each run trained on."""
    lines = [
        "* unfinished: the last checkpoint's return.",
        "sinusoid: the seed's sinusoid sampled every control step (0.05 s) by the env, stored "
        "with each run (PPO > sinusoid counts against it); continuous: the engine's own drive "
        'of the same sinusoid (drive="controller", what evolution and softgym.evaluate run), '
        "computed now on the installed engine.",
        "actions: contraction = the seed's signal mapped into the contracting range under the "
        "seed's law; temperature (symmetric) = the temperature itself, on a task whose "
        "muscles also expand (swim).",
        "Engine: the run's commit where run.json records one; else the commits that stored "
        "its checkpoints (git log on its folder, oldest .. newest): it trained on the engine "
        "of that span, resumed parts on the later one.",
    ]
    for path in sorted(root.glob("*/run.json")):
        run = json.loads(path.read_text())
        if run.get("commit"):
            lines.append(f"  {path.parent.name}: commit {run['commit']}")
            continue
        span = stored_in(path.parent)
        where = f"stored in {span[0]} .. {span[1]}" if span else "no commit recorded, no git log"
        lines.append(f"  {path.parent.name}: {where}")
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
    print("\n" + notes(Path(args.root)))
    if args.out:
        print(f"wrote {plot(runs, args.out)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
