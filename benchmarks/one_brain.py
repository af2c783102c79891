"""One brain for many bodies: a distributed controller evolved on a few bodies, run on unseen ones.

A distributed brain (one network per voxel, the same weights in every voxel,
one signal per neighbour) is evolved by pymoo's CMA-ES on ``--train`` random
CPPN bodies at once (its fitness: the median score over them), then run with
no fine-tuning on ``--held-out`` other random bodies of several grid shapes.
Against it, a *specialist* brain is evolved on each held-out body alone with
the same number of candidate brains (``--candidates``; every candidate of the
generalist is scored on each training body, so each body sees as many
candidates in both). Both searches start from
:func:`softgym.tasks.brains.sinusoid_brain` (the seed's gait as a network),
whose score on each held-out body is reported too. The ratio of the medians
(generalist over specialists, on the held-out bodies) is the headline.

Every finished search is a JSON file under ``--out`` (written atomically; a
rerun skips them, so the study resumes after a kill). ``--report`` prints the
table.

    python benchmarks/one_brain.py --out benchmarks/data/one_brain          # ~20 min on 2 cores
    python benchmarks/one_brain.py --out benchmarks/data/one_brain --report
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
from evolvers.operators.genome import Individual
from softgym.design import CompositionRules
from softgym.io import atomic_write_json
from softgym.tasks import get_task
from softgym.tasks.brains import brain_spec, sinusoid_brain

#: Grid shapes of the random bodies (a body's CPPN draws in one of them).
SHAPES = ((6, 6, 6), (5, 5, 5), (4, 6, 5), (6, 4, 4), (7, 5, 4))
HIDDEN = 4


#: The body sets a study can draw (``--family``).
FAMILIES = ("random", "lineage")


def bodies(n: int, seed: int) -> list:
    """``n`` random valid CPPN bodies (the seed's rules), grid shapes cycling through SHAPES."""
    rng = np.random.default_rng(seed)
    rules = CompositionRules.seed()
    out = []
    for i in range(n):
        shape = SHAPES[i % len(SHAPES)]
        out.append(Individual.random(rng, i, shape=shape, rules=rules).design(shape))
    return out


def lineage(n_train: int, n_held: int, seed: int) -> tuple[list, list]:
    """Bodies of one family: a tree of descendants of one random 6x6x6 CPPN body.

    Each new body is one NEAT mutation (:meth:`CPPN.mutate`, the seed's rules)
    of a member drawn at random from the family so far (the common ancestor
    included; it is in neither set); every grid is distinct. The first
    ``n_train`` are the training bodies, the next ``n_held`` the held-out ones:
    siblings and cousins, not copies.
    """
    rng = np.random.default_rng(seed)
    rules = CompositionRules.seed()
    shape = SHAPES[0]
    family = [Individual.random(rng, 0, shape=shape, rules=rules).cppn]
    seen = {family[0].to_grid(shape).tobytes()}
    while len(family) < 1 + n_train + n_held:
        child = family[rng.integers(len(family))].mutate(rng, shape, is_valid=rules).genome
        key = child.to_grid(shape).tobytes()
        if key not in seen:
            seen.add(key)
            family.append(child)
    out = [Individual(cppn=g, id=i).design(shape) for i, g in enumerate(family[1:], 1)]
    return out[:n_train], out[n_train:]


class BrainProblem(Problem):
    """Maximise the median score of one brain over a set of bodies: F = -median."""

    def __init__(self, task, body_set, spec, threads):
        self.task, self.bodies, self.spec, self.threads = task, body_set, spec, threads
        lo, hi = spec.bounds
        super().__init__(n_var=spec.n_params, n_obj=1, xl=lo, xu=hi)
        self.best = (-np.inf, None)
        self.curve: list[float] = []

    def scores(self, X) -> np.ndarray:
        designs = [b.replace(brain=self.spec.clipped(x)) for x in X for b in self.bodies]
        s = softgym.evaluate(designs, task=self.task, n_threads=self.threads)["score"]
        return s.reshape(len(X), len(self.bodies))

    def _evaluate(self, X, out, *args, **kwargs):
        med = np.median(self.scores(X), axis=1)
        for x, m in zip(X, med):
            if m > self.best[0]:
                self.best = (float(m), x.copy())
            self.curve.append(self.best[0])
        out["F"] = -med[:, None]


def search(task, body_set, spec, candidates, pop, seed, threads) -> BrainProblem:
    prob = BrainProblem(task, body_set, spec, threads)
    x0 = sinusoid_brain(spec, 2.0).weights
    restart = 0
    while len(prob.curve) < candidates:  # restarted when CMA-ES stops early
        minimize(prob, CMAES(x0=x0, sigma=0.1, pop_size=pop, restarts=0),
                 ("n_evals", candidates - len(prob.curve)), seed=seed + 1000 * restart,
                 verbose=False)  # fmt: skip
        restart += 1
    return prob


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--task", default="flat")
    ap.add_argument("--family", choices=FAMILIES, default="random",
                    help="random: unrelated random CPPN bodies of five grid shapes; lineage: "
                         "descendants of one random body (default: random)")  # fmt: skip
    ap.add_argument("--train", type=int, default=8)
    ap.add_argument("--held-out", type=int, default=20)
    ap.add_argument("--candidates", type=int, default=320, help="candidate brains per search")
    ap.add_argument("--pop", type=int, default=16)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--out", type=Path, default=Path("benchmarks/data/one_brain"))
    ap.add_argument("--report", action="store_true")
    args = ap.parse_args(argv)
    if args.report:
        print(report(args.out))
        return
    task = get_task(args.task)
    spec = brain_spec("distributed", task, (6, 6, 6), hidden=HIDDEN, signals=1)
    if args.family == "lineage":
        train, held = lineage(args.train, args.held_out, seed=30_000 + args.seed)
    else:
        train = bodies(args.train, seed=10_000 + args.seed)
        held = bodies(args.held_out, seed=20_000 + args.seed)
    args.out.mkdir(parents=True, exist_ok=True)
    command = " ".join(["python", "benchmarks/one_brain.py", *sys.argv[1:]])
    gpath = args.out / "generalist.json"
    if not gpath.exists():
        t0 = time.time()
        prob = search(task, train, spec, args.candidates, args.pop, args.seed, args.threads)
        brain = spec.clipped(prob.best[1])
        zero_shot = softgym.evaluate([b.replace(brain=brain) for b in held], task=task,
                                     n_threads=args.threads)["score"]  # fmt: skip
        start = softgym.evaluate([b.replace(brain=sinusoid_brain(spec, 2.0)) for b in held],
                                 task=task, n_threads=args.threads)["score"]  # fmt: skip
        atomic_write_json(gpath, {
            "task": args.task, "family": args.family, "train_bodies": args.train, "candidates": args.candidates,
            "train_median": prob.best[0], "curve": prob.curve, "held_out_scores": zero_shot.tolist(),
            "sinusoid_brain_held_out": start.tolist(), "brain": brain.to_dict(),
            "held_out_shapes": [list(b.shape) for b in held], "wall_s": time.time() - t0,
            "command": command,
        })  # fmt: skip
        print(f"generalist: train median {prob.best[0]:.3f}, held-out median "
              f"{np.median(zero_shot):.3f} ({time.time() - t0:.0f} s)", flush=True)  # fmt: skip
    for i, body in enumerate(held):
        path = args.out / f"specialist-{i:02d}.json"
        if path.exists():
            continue
        t0 = time.time()
        prob = search(task, [body], spec, args.candidates, args.pop, args.seed + i, args.threads)
        atomic_write_json(path, {"body": i, "shape": list(body.shape), "score": prob.best[0],
                                 "curve": prob.curve, "wall_s": time.time() - t0,
                                 "command": command})  # fmt: skip
        print(f"specialist {i}: {prob.best[0]:.3f} ({time.time() - t0:.0f} s)", flush=True)


def report(out: Path) -> str:
    """The held-out table: per body the generalist's zero-shot score, the specialist's, the start's."""
    g = json.loads((out / "generalist.json").read_text())
    spec = {json.loads(p.read_text())["body"]: json.loads(p.read_text())
            for p in sorted(out.glob("specialist-*.json"))}  # fmt: skip
    gen = np.array(g["held_out_scores"])
    start = np.array(g["sinusoid_brain_held_out"])
    done = sorted(spec)
    sp = np.array([spec[i]["score"] for i in done])
    lines = [f"task {g['task']}, bodies: {g.get('family', 'random')}, {g['train_bodies']} training bodies, {g['candidates']} candidate "
             f"brains per search; held-out bodies with a specialist: {len(done)} of {gen.size}",
             "", "| | median | IQR |", "|---|---|---|"]  # fmt: skip
    for name, v in (("generalist, zero-shot (all held-out)", gen),
                    ("generalist, zero-shot (bodies with a specialist)", gen[done]),
                    ("specialists (one search per body)", sp),
                    ("start: the sinusoid as a network", start[done])):  # fmt: skip
        if v.size:
            q1, q3 = np.percentile(v, [25, 75])
            lines.append(f"| {name} | {np.median(v):.3f} | [{q1:.3f}, {q3:.3f}] |")
    if sp.size:
        lines.append(f"\nratio of medians, generalist / specialists: "
                     f"**{np.median(gen[done]) / np.median(sp):.2f}**")  # fmt: skip
    return "\n".join(lines)


if __name__ == "__main__":
    main()
