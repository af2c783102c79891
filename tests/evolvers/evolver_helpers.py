"""Helpers of the evolver tests: tiny, fast experiments (4x4x4 robots, 1.5 s simulated)."""

from evolvers.evaluation.experiments import get_experiment


def tiny(name: str = "controller-tournament", **overrides):
    kw = {"pop_size": 4, "seconds": 1.5, "shape": (4, 4, 4)}
    kw.update(overrides)
    return get_experiment(name, **kw)
