"""Tune the controller of a fixed body with a pymoo single-objective algorithm.

Any optimiser can drive softgym through one call, ``softgym.evaluate``: here
pymoo's differential evolution searches the seed's three controller genes
(temperature amplitude, period, muscle CTE, within the seed's bounds) of the
embedded default walker, maximising its displacement (NormFinalDist, voxel
lengths). The whole population of each generation is simulated in one
batched Simulation.

    python examples/tune_controller_pymoo.py --generations 5 --pop 8 --seconds 3
"""

from __future__ import annotations

import argparse

import numpy as np
from pymoo.algorithms.soo.nonconvex.de import DE
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

import softgym
from softgym.design import CONTROLLER_BOUNDS, Controller, RobotDesign, default_walker

NAMES = ("temp_amplitude", "period", "muscle_cte")


class ControllerProblem(Problem):
    """Minimise ``-NormFinalDist`` of ``body`` over its controller genes (vectorised)."""

    def __init__(self, body: RobotDesign, seconds: float, task: str = "flat") -> None:
        lo = np.array([CONTROLLER_BOUNDS[n][0] for n in NAMES])
        hi = np.array([CONTROLLER_BOUNDS[n][1] for n in NAMES])
        super().__init__(n_var=3, n_obj=1, xl=lo, xu=hi)
        self.body, self.seconds, self.task = body, seconds, task

    def _evaluate(self, X, out, *args, **kwargs):
        designs = [self.body.with_controller(Controller.clipped(*x)) for x in X]
        metrics = softgym.evaluate(designs, task=self.task, seconds=self.seconds)  # one batched run
        out["F"] = -metrics["norm_final_dist"].reshape(-1, 1)


def main() -> None:
    """Parse the arguments, tune, print the default and the tuned controller."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--generations", type=int, default=5)
    ap.add_argument("--pop", type=int, default=8)
    ap.add_argument("--seconds", type=float, default=3.0)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    body = default_walker()
    base = softgym.evaluate(body, seconds=args.seconds)["norm_final_dist"][0]
    res = minimize(ControllerProblem(body, args.seconds), DE(pop_size=args.pop),
                   ("n_gen", args.generations), seed=args.seed, verbose=True)  # fmt: skip
    best = Controller.clipped(*res.X)
    print(f"default controller {Controller()}: {base:.2f} voxel lengths")
    print(f"tuned   controller {best}: {-res.F[0]:.2f} voxel lengths")


if __name__ == "__main__":
    main()
