"""CMA-ES (the ``cma`` package) evolving body and controller through softgym's design vector.

Run: ``python examples/cma_design_vector.py --generations 30 --shape 5 5 5``
"""

import argparse

import cma

import softgym
from softgym.design.vector import DesignVector

ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
ap.add_argument("--generations", type=int, default=30, help="CMA-ES iterations")
ap.add_argument("--popsize", type=int, default=16, help="candidates per iteration")
ap.add_argument("--shape", type=int, nargs=3, default=(5, 5, 5), help="robot grid")
ap.add_argument("--seconds", type=float, default=4.0, help="simulated seconds per robot")
ap.add_argument("--out", default="cma_best.json", help="best design (JSON)")
args = ap.parse_args()

enc = DesignVector(shape=args.shape)  # one gene per cell + 3 controller genes, all in [0, 1]
opts = {"bounds": [enc.lower, enc.upper], "popsize": args.popsize, "seed": 1, "verbose": -9,
        "maxiter": args.generations}  # fmt: skip
es = cma.CMAEvolutionStrategy(enc.random(rng=0), 0.3, opts)
while not es.stop():
    X = es.ask()
    m = softgym.evaluate([enc.decode(x) for x in X], task="flat", seconds=args.seconds)
    es.tell(X, list(-m["norm_final_dist"]))  # cma minimises: maximise the distance
    print(f"iteration {es.countiter}: best {-min(es.fit.fit):.3f} voxel lengths")
best = enc.decode(es.result.xbest)
best.save(args.out)
print(f"best design ({best.n_voxels} voxels, {best.controller}) -> {args.out}")
