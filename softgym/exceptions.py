"""Typed errors of softgym.

Every error raised on purpose by the library is a :class:`SoftGymError`.
Each subclass also subclasses the builtin exception it refines, so callers
that only know the builtin (``ValueError``, ``RuntimeError``...) still catch it.
"""

from __future__ import annotations

__all__ = [
    "CheckpointError",
    "DesignFileError",
    "InvalidActionError",
    "InvalidDesignError",
    "InvalidIndexError",
    "InvalidParameterError",
    "InvalidTerrainError",
    "RunFolderLockedError",
    "SimulationDivergedError",
    "SoftGymError",
]


class SoftGymError(Exception):
    """Base class of every error softgym raises on purpose."""


class InvalidParameterError(SoftGymError, ValueError):
    """A physical or numerical parameter is non-finite, non-physical or out of range."""


class InvalidIndexError(SoftGymError, IndexError):
    """An index (a robot of a batch...) is not an integer in its range."""


class InvalidDesignError(SoftGymError, ValueError):
    """A robot design breaks a rule: shape, dtype, material ids, connectivity, composition."""


class DesignFileError(InvalidDesignError, OSError):
    """A design file cannot be read: missing, a folder, unreadable, not text, or too large.

    Also an :class:`OSError`, so code that caught the builtin file errors keeps working.
    """


class InvalidTerrainError(SoftGymError, ValueError):
    """A terrain is malformed: non-positive box sizes, overlap with the robot's start..."""


class InvalidActionError(SoftGymError, ValueError):
    """An action given to an environment or simulation is NaN, infinite or malformed."""


class SimulationDivergedError(SoftGymError, RuntimeError):
    """A simulated robot diverged (non-finite state or runaway strain).

    Parameters
    ----------
    robot : int
        Index of the robot in its batch.
    time : float
        Simulated time (s) of that robot when divergence was detected.
    reason : str
        What was detected.
    """

    def __init__(self, robot: int, time: float, reason: str = "diverged") -> None:
        self.robot = int(robot)
        self.time = float(time)
        self.reason = reason
        super().__init__(f"robot {self.robot} diverged at t = {self.time:.6g} s: {reason}")

    def __reduce__(self):
        return (type(self), (self.robot, self.time, self.reason))


class CheckpointError(SoftGymError, OSError):
    """A checkpoint or run file is corrupt, truncated, of an unknown version or missing."""


class RunFolderLockedError(SoftGymError, RuntimeError):
    """A run folder is already being written by another process (see :class:`softgym.io.RunLock`)."""
