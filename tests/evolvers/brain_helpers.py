"""Helpers of the brain tests: tiny network experiments and a 4x4x4 fixed body."""

from evolver_helpers import tiny

from softgym.design import default_walker
from softgym.design.robot import RobotDesign


def small_body() -> RobotDesign:
    """The walker's 4x4x4 corner: muscles of both phases under a soft top layer."""
    w = default_walker()
    grid = w.grid[1:5, :4, :4].copy()
    grid[:, :, 3] = 1
    return RobotDesign(grid, palette=w.palette, controller=w.controller)


def brainy(controller: str = "distributed", name: str = "controller-tournament", body=False,
           **overrides):  # fmt: skip
    """A tiny experiment whose robots carry a network (on the small fixed body with ``body``)."""
    if body:
        overrides["body"] = small_body().to_dict()
    return tiny(name, controller=controller, **overrides)
