"""Policies for the SoftWalker environments (observation -> action).

Not to be confused with :mod:`softgym.design.controller`, a design's own
sinusoidal controller (run by the engine; ``drive="controller"`` in the envs).

:class:`Sinusoid` is the seed's open-loop controller as an env policy: every
cell gets ``amplitude * sin(2 pi t / period + phase)``, so each muscle voxel's
temperature is ``dT sin(2 pi t / period)`` as in the engine's built-in drive
(docs/PHYSICS.md; the counter-phase of the two muscle kinds comes
from the sign of their CTE).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from softgym.exceptions import InvalidParameterError

__all__ = ["Sinusoid"]


class Sinusoid:
    """The seed's sinusoidal drive as a policy ``observation -> action``.

    The env observes the phase of its clock, ``(sin, cos)(2 pi t / period)``
    (the last two observation entries, ``t`` counted from the robot's
    placement, so the seed's 1 s settling is included). The policy reads it
    and returns ``amplitude * sin(2 pi t / period + phase)`` on every cell,
    held for the coming control step (a zero-order hold, as a digital
    controller would): the muscle temperatures are then the seed's
    ``dT sin(2 pi t / period)`` sampled every ``control_dt``.

    The engine's built-in drive samples the same signal every engine step
    (~0.64 ms). Under the seed's contraction-only law (a muscle keeps its last
    size while the command would expand it) the gait is sensitive to the
    sampling: with the default walker, ``control_dt = 0.005`` s (50 samples
    per period) covers the same distance as the engine's drive to 0.01 %,
    0.0025 s to 0.5 %, while coarser steps change the gait (0.01 s: -21 %,
    0.05 s: -83 %). Use ``control_dt <= 0.005`` to reproduce the seed.

    Parameters
    ----------
    n_cells : int
        Action length (216 for a 6x6x6 grid).
    period : float or ndarray of shape (n_envs,)
        The env's phase period (s): the design's controller period (0.25 s
        by default); one per robot for a vector env.
    control_dt : float
        The env's control step (s); informative (the policy reads the phase
        from the observation).
    amplitude : float
        Action amplitude in [0, 1] (1: the design's full ``dT``).
    phase : float
        Phase offset (rad).

    Examples
    --------
    >>> import gymnasium as gym
    >>> import softgym
    >>> env = gym.make("SoftWalker-Flat-v0")
    >>> policy = Sinusoid.from_env(env)
    >>> obs, info = env.reset(seed=0)
    >>> obs, reward, terminated, truncated, info = env.step(policy(obs))
    """

    def __init__(
        self,
        n_cells: int = 216,
        period: float | np.ndarray = 0.25,
        control_dt: float = 0.05,
        amplitude: float = 1.0,
        phase: float = 0.0,
        clock: int | None = None,
    ) -> None:
        self.n_cells = int(n_cells)
        # where the observation holds sin(2 pi t / period) (cos follows): the last two entries
        # of the blind observation, after the cells and the robot's first values when sensing
        self.clock = None if clock is None else int(clock)
        if self.n_cells < 1:
            raise InvalidParameterError(f"n_cells must be >= 1, got {n_cells}")
        self.period = np.asarray(period, dtype=np.float64)
        if not (np.isfinite(self.period).all() and (self.period > 0).all()):
            raise InvalidParameterError(f"period must be finite and > 0, got {period!r}")
        self.control_dt = float(control_dt)
        if not (math.isfinite(self.control_dt) and self.control_dt > 0):
            raise InvalidParameterError(f"control_dt must be finite and > 0, got {control_dt!r}")
        self.amplitude = float(amplitude)
        if not (0.0 <= self.amplitude <= 1.0):
            raise InvalidParameterError(f"amplitude must be in [0, 1], got {amplitude!r}")
        self.phase = float(phase)
        if not math.isfinite(self.phase):
            raise InvalidParameterError(f"phase must be finite, got {phase!r}")

    @classmethod
    def from_env(cls, env: Any, amplitude: float = 1.0, phase: float = 0.0) -> Sinusoid:
        """The policy matching a SoftWalker env or vector env (its period, control step, grid)."""
        base = env.unwrapped
        space = getattr(base, "single_action_space", None) or base.action_space
        n = int(np.prod(space.shape))
        clock = None
        if getattr(base, "observe", "blind") == "sensing":
            from softgym.tasks.sensing import CELL_SENSORS, ROBOT_SENSORS

            clock = len(CELL_SENSORS) * n + [r[0] for r in ROBOT_SENSORS].index("clock_sin")
        return cls(
            n_cells=n,
            period=base.period,
            control_dt=base.control_dt,
            amplitude=amplitude,
            phase=phase,
            clock=clock,
        )

    def _values(self, theta: np.ndarray) -> np.ndarray:
        return self.amplitude * np.sin(theta + self.phase)

    def __call__(self, observation: Any) -> np.ndarray:
        """Action(s) for observation(s).

        Parameters
        ----------
        observation : ndarray of shape (obs_size,) or (n_envs, obs_size)

        Returns
        -------
        ndarray of shape (n_cells,) or (n_envs, n_cells), float32
        """
        obs = np.asarray(observation, dtype=np.float64)
        if self.clock is None:
            theta = np.arctan2(obs[..., -2], obs[..., -1])
        else:
            theta = np.arctan2(obs[..., self.clock], obs[..., self.clock + 1])
        value = self._values(theta)
        out = np.broadcast_to(np.asarray(value)[..., None], (*theta.shape, self.n_cells))
        return np.ascontiguousarray(out, dtype=np.float32)

    def action_at(self, t: float | np.ndarray) -> np.ndarray:
        """Action(s) for the control step that starts at clock time ``t`` (s)."""
        theta = 2.0 * np.pi * np.asarray(t, dtype=np.float64) / self.period
        value = self._values(theta)
        out = np.broadcast_to(np.asarray(value)[..., None], (*np.shape(value), self.n_cells))
        return np.ascontiguousarray(out, dtype=np.float32)
