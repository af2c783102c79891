"""Closed loop against open loop: the seed's sinusoid against a sensing brain, same budget.

On a fixed body (the default walker), for each task and seed, pymoo's CMA-ES
(``pymoo.algorithms.soo.nonconvex.cmaes.CMAES``, which drives the ``cma``
package) searches

* ``open``: the seed's open-loop controller, its three genes (amplitude,
  period, muscle CTE) scaled into [0, 1];
* ``distributed``: the same three genes and a distributed brain's weights
  (one network per voxel, shared weights, the task's senses and one signal
  per neighbour in; :func:`softgym.tasks.brains.brain_spec`), started from
  :func:`~softgym.tasks.brains.sinusoid_brain` (the clock alone drives the
  muscles: the seed's gait as a network), so both searches start from the
  seed's gait;

with the same number of evaluations (``--evals``; CMA-ES is restarted from
its start with another seed when it stops early, as on a flat landscape), each scored by
:func:`softgym.evaluate` on the task's measure. Every finished run is a JSON
file under ``--out`` (its best score, its best-so-far curve, its best design,
the command), written atomically; a rerun skips the finished ones, so the
study resumes after a kill. ``--report`` prints the table of medians with
bootstrap 95 % confidence intervals and writes the figure.

    python benchmarks/closed_loop.py --tasks push carry turn gap rough stairs --seeds 5 \\
        --evals 320 --out benchmarks/data/closed_loop          # runs, resumable
    python benchmarks/closed_loop.py --out benchmarks/data/closed_loop --report \\
        --figure docs/figures/closed_loop.png
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from pymoo.algorithms.soo.nonconvex.cmaes import CMAES
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

import softgym
from softgym.design import CONTROLLER_BOUNDS, Controller, default_walker
from softgym.io import atomic_write_json
from softgym.tasks import get_task
from softgym.tasks.brains import brain_spec, sinusoid_brain

CONDITIONS = ("open", "distributed")
HIDDEN = 4


def _controller(x: np.ndarray) -> Controller:
    vals = {}
    for v, (name, (lo, hi, _)) in zip(x, CONTROLLER_BOUNDS.items()):
        vals[name] = lo + float(np.clip(v, 0.0, 1.0)) * (hi - lo)
    return Controller.clipped(**vals)


def _unit(c: Controller) -> np.ndarray:
    return np.array([(getattr(c, n) - lo) / (hi - lo) for n, (lo, hi, _) in CONTROLLER_BOUNDS.items()])


class ControllerProblem(Problem):
    """Maximise a task's score over a fixed body's controller (and brain): F = -score."""

    def __init__(self, task_name: str, condition: str, threads: int | None) -> None:
        self.task = get_task(task_name)
        self.body = default_walker()
        self.condition = condition
        self.threads = threads
        self.spec = None
        n = 3
        xl, xu = np.zeros(3), np.ones(3)
        if condition == "distributed":
            self.spec = brain_spec("distributed", self.task, self.body.shape, hidden=HIDDEN, signals=1)
            lo, hi = self.spec.bounds
            n += self.spec.n_params
            xl, xu = np.concatenate([xl, lo]), np.concatenate([xu, hi])
        super().__init__(n_var=n, n_obj=1, xl=xl, xu=xu)
        self.curve: list[float] = []
        self.best = (-np.inf, None)

    def design(self, x: np.ndarray):
        d = self.body.with_controller(_controller(x[:3]))
        if self.spec is not None:
            d = d.replace(brain=self.spec.clipped(x[3:]))
        return d

    def x0(self) -> np.ndarray:
        x = _unit(Controller())
        if self.spec is not None:
            x = np.concatenate([x, sinusoid_brain(self.spec, 2.0).weights])
        return x

    def _evaluate(self, X, out, *args, **kwargs):
        designs = [self.design(x) for x in X]
        score = softgym.evaluate(designs, task=self.task, n_threads=self.threads)["score"]
        for x, s in zip(X, score):
            if s > self.best[0]:
                self.best = (float(s), x.copy())
            self.curve.append(self.best[0])
        out["F"] = -score[:, None]


def run_one(task: str, condition: str, seed: int, evals: int, pop: int, threads: int | None) -> dict:
    """One CMA-ES run; its result as a JSON-ready dict."""
    prob = ControllerProblem(task, condition, threads)
    t0 = time.time()
    restart = 0
    while len(prob.curve) < evals:  # CMA-ES stops early on a flat landscape: restart it
        algo = CMAES(x0=prob.x0(), sigma=0.1, pop_size=pop, restarts=0)
        minimize(prob, algo, ("n_evals", evals - len(prob.curve)), seed=seed + 1000 * restart,
                 verbose=False)  # fmt: skip
        restart += 1
    best_score, best_x = prob.best
    return {
        "task": task, "condition": condition, "seed": seed, "evals": len(prob.curve),
        "best_score": best_score, "curve": prob.curve,
        "n_params": int(prob.n_var), "hidden": HIDDEN if condition != "open" else None,
        "wall_s": time.time() - t0, "cma_runs": restart,
        "design": prob.design(best_x).to_dict(),
        "command": " ".join(["python", "benchmarks/closed_loop.py", *sys.argv[1:]]),
    }  # fmt: skip


def _ci(values: np.ndarray, rng: np.random.Generator, n: int = 4000) -> tuple[float, float]:
    boots = np.median(rng.choice(values, size=(n, len(values)), replace=True), axis=1)
    return float(np.percentile(boots, 2.5)), float(np.percentile(boots, 97.5))


def rescore(runs: list[dict]) -> None:
    """Each run's best design scored again by this softgym (``best_score`` then is that score).

    The engine is deterministic, so this repeats the search's own figure unless the scoring
    changed since (e.g. a closed-loop run's samples: every control step before, every
    ``trace_interval`` as for the open loop now); ``search_score`` keeps the search's.
    """
    from softgym.design import RobotDesign

    by_task: dict[str, list[dict]] = {}
    for r in runs:
        by_task.setdefault(r["task"], []).append(r)
    for task, group in by_task.items():
        scores = softgym.evaluate([RobotDesign.from_dict(r["design"]) for r in group], task=task)["score"]
        for r, s in zip(group, scores):
            r["search_score"], r["best_score"] = r["best_score"], float(s)


def report(out: Path, again: bool = True, figure: Path | None = None) -> str:
    """The table of medians with bootstrap 95 % intervals, and the figure ``closed_loop.png``."""
    runs = [json.loads(p.read_text()) for p in sorted((out / "runs").glob("*.json"))]
    if again:
        rescore(runs)
    tasks = sorted({r["task"] for r in runs})
    rng = np.random.default_rng(0)
    lines = ["| task | open loop: median [95 % CI] (n) | distributed brain: median [95 % CI] (n) "
             "| brain / open |", "|---|---|---|---|"]  # fmt: skip
    fig_data = {}
    for t in tasks:
        cells = []
        med = {}
        for c in CONDITIONS:
            v = np.array([r["best_score"] for r in runs if r["task"] == t and r["condition"] == c])
            fig_data[(t, c)] = v
            if v.size == 0:
                cells.append("-")
                continue
            lo, hi = _ci(v, rng)
            med[c] = float(np.median(v))
            cells.append(f"{med[c]:.2f} [{lo:.2f}, {hi:.2f}] ({v.size})")
        ratio = (f"{med['distributed'] / med['open']:.2f}x" if len(med) == 2 and med["open"] > 0
                 else "-")  # fmt: skip
        lines.append(f"| {t} | {cells[0]} | {cells[1]} | {ratio} |")
    from softgym.render.figures import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(1.6 * max(len(tasks), 1) + 2, 3.6))
    for k, c in enumerate(CONDITIONS):
        for i, t in enumerate(tasks):
            v = fig_data.get((t, c), np.array([]))
            ax.scatter(np.full(v.size, i + (k - 0.5) * 0.3), v, s=14,
                       color=("tab:grey", "tab:blue")[k], label=c if i == 0 else None)  # fmt: skip
            if v.size:
                ax.hlines(np.median(v), i + (k - 0.5) * 0.3 - 0.12, i + (k - 0.5) * 0.3 + 0.12,
                          color=("black", "navy")[k])  # fmt: skip
    ax.set_xticks(range(len(tasks)), tasks)
    ax.set_ylabel("best score (task measure)")
    ax.set_title("open-loop sinusoid vs distributed sensing brain, same CMA-ES budget")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "closed_loop.png" if figure is None else figure, dpi=110)
    plt.close(fig)
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tasks", nargs="+", default=["push", "carry", "turn", "gap", "rough", "stairs"])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--evals", type=int, default=320, help="evaluations per run (default 320)")
    ap.add_argument("--pop", type=int, default=16, help="CMA-ES population (default 16)")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--conditions", nargs="+", default=list(CONDITIONS), choices=CONDITIONS)
    ap.add_argument("--out", type=Path, default=Path("benchmarks/data/closed_loop"))
    ap.add_argument("--report", action="store_true", help="print the table and write the figure")
    ap.add_argument("--figure", type=Path, default=None,
                    help="where --report writes the figure (default OUT/closed_loop.png)")
    ap.add_argument("--no-rescore", action="store_true",
                    help="report the searches' own best scores (default: score each best design again)")
    args = ap.parse_args(argv)
    if args.report:
        print(report(args.out, again=not args.no_rescore, figure=args.figure))
        return
    (args.out / "runs").mkdir(parents=True, exist_ok=True)
    # seeds outermost: an interrupted study has every task at its first seeds
    for seed in range(1, args.seeds + 1):
        for task in args.tasks:
            for cond in args.conditions:
                path = args.out / "runs" / f"{task}-{cond}-{seed}.json"
                if path.exists():
                    continue
                res = run_one(task, cond, seed, args.evals, args.pop, args.threads)
                atomic_write_json(path, res)
                print(f"{task:8s} {cond:12s} seed {seed}: best {res['best_score']:.3f} "
                      f"({res['evals']} evals, {res['wall_s']:.0f} s)", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
