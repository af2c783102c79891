"""How actions become muscle temperatures: one map for the envs' actions and the brains' outputs.

:class:`ActionMap` is what :class:`softgym.tasks.EpisodeBatch` applies to an
action of the Gymnasium envs and to the outputs of a design's
:class:`~softgym.design.Brain` alike, so an env action and a network output of
the same value drive a muscle the same way.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from softgym.exceptions import InvalidParameterError
from softgym.validate import show

if TYPE_CHECKING:
    from softgym.tasks.episode import EpisodeBatch

__all__ = ["ACTION_MODES", "ActionMap"]

#: How an action entry drives its muscle (``action_mode``; see :class:`softgym.envs.SoftWalkerEnv`).
ACTION_MODES: tuple[str, ...] = ("contraction", "temperature")


class ActionMap:
    """How the actions of a batch become the muscle temperatures :meth:`EpisodeBatch.apply` sets.

    ``"temperature"``: an entry ``a`` is the temperature ``a * dT`` (the seed's
    signal; under the seed's law a command that would expand a muscle keeps
    its last size). ``"contraction"``: the temperature ``(a - s) dT / 2``,
    ``s = sign(CTE)`` of the cell's muscle: the seed's signal halved and
    shifted into the range the seed's contraction-only law always follows, so
    every action sets the muscle's size and none holds it. The muscle
    contracts by ``(1 - s a) / 2`` of its full range: ``a = -1`` fully
    contracts the positive-CTE muscles and rests the negative ones, ``+1`` the
    reverse, ``0`` half contracts both. As with temperatures, one signal on
    every cell drives the two muscle kinds in counter-phase (the seed's gait).

    Parameters
    ----------
    batch : EpisodeBatch
        The robots (their designs, cells and engine settings).
    mode : {"contraction", "temperature"} or None
        None: ``"contraction"`` under the seed's actuation law, ``"temperature"``
        under ``"symmetric"`` (whose muscles also expand): either way the
        action's range covers every size the law reaches, once.

    Raises
    ------
    InvalidParameterError
        For another ``mode``.
    """

    def __init__(self, batch: EpisodeBatch, mode: str | None) -> None:
        if mode is None:
            mode = "contraction" if batch.config.actuation == "seed" else "temperature"
        if not (isinstance(mode, str) and mode in ACTION_MODES):
            raise InvalidParameterError(
                f"action_mode must be None or one of {list(ACTION_MODES)}, got {show(mode)}"
            )
        self.mode = mode
        #: ndarray of shape (n_robots, n_cells): each cell's CTE sign (0: no muscle)
        self.sign = np.zeros((batch.n_robots, batch.n_cells))
        for r, d in enumerate(batch.designs):
            gi = batch.sim.grid_index(r)
            self.sign[r, batch.cells[r]] = np.sign(batch.sim.bodies[r].cte[d.grid[tuple(gi.T)]])

    def __call__(self, actions: np.ndarray) -> np.ndarray:
        """Temperatures in units of ``dT`` for checked actions of shape (n_robots, n_cells)."""
        if self.mode == "temperature":
            return actions
        return 0.5 * (actions - self.sign)  # (passive cells: ignored by EpisodeBatch.apply)

    def from_temperatures(self, fraction: Any) -> np.ndarray:
        """The actions that give each muscle the size the temperature ``fraction * dT`` gives it.

        Under the seed's law without its hold: a command that would expand a
        muscle leaves it at rest. This runs a temperature signal, such as
        :class:`softgym.policies.Sinusoid`'s (the seed's drive), in any mode.

        Parameters
        ----------
        fraction : array_like of shape (n_robots, n_cells), values in [-1, 1]

        Returns
        -------
        ndarray of shape (n_robots, n_cells), float32
        """
        f = np.clip(np.asarray(fraction, dtype=np.float64), -1.0, 1.0)
        if self.mode == "temperature":
            return f.astype(np.float32)
        level = np.clip(-self.sign * f, 0.0, 1.0)  # the contraction the seed's law gives
        return (self.sign * (1.0 - 2.0 * level)).astype(np.float32)
