"""`Rollout`: what a simulation run returns, as plain arrays."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from softgym.exceptions import InvalidIndexError

__all__ = ["Rollout"]


@dataclass(frozen=True, eq=False)
class Rollout:
    """The result of :meth:`softgym.engine.Simulation.run` for a batch of robots.

    All arrays cover the batch; per-voxel arrays are concatenated over robots
    and sliced with ``voxel_offsets``.

    Attributes
    ----------
    times : ndarray of shape (n_robots, n_samples), float64
        Simulated time (s) of each centre-of-mass sample. Sample k is taken at
        the first step with ``t >= k * trace_interval``; robots have their own
        time step, so the times differ by less than one step between robots.
    cm : ndarray of shape (n_robots, n_samples, 3), float64
        Centre of mass (m) of each robot's voxels (obstacles excluded) at ``times``.
    cm_init : ndarray of shape (n_robots, 3), float64
        Centre of mass at the first step with ``t > init_time`` (the seed's
        ``IniCM``); equal to the first sample if ``init_time`` was not reached
        (see ``init_reached``).
    init_reached : ndarray of shape (n_robots,), bool
        Whether the run got past ``init_time``.
    cm_final : ndarray of shape (n_robots, 3), float64
        Centre of mass at the end of the run.
    positions : ndarray of shape (n_voxels, 3), float64
        Final voxel centres (m).
    orientations : ndarray of shape (n_voxels, 4), float64
        Final voxel orientations as unit quaternions (w, x, y, z).
    voxel_offsets : ndarray of shape (n_robots + 1,), int64
        Robot ``i`` owns voxels ``voxel_offsets[i]:voxel_offsets[i + 1]``.
    grid_index : ndarray of shape (n_voxels, 3), int64
        Lattice index (i, j, k) of each voxel in its robot's grid.
    dt : ndarray of shape (n_robots,), float64
        Time step (s) of each robot.
    steps : ndarray of shape (n_robots,), int64
        Steps taken by each robot since the simulation started.
    time : ndarray of shape (n_robots,), float64
        Simulated time (s) reached by each robot (``steps * dt`` unless it diverged).
    diverged : ndarray of shape (n_robots,), bool
        Robots frozen because their state became non-finite or a link's strain
        exceeded ``SimConfig.max_strain``.
    diverged_time : ndarray of shape (n_robots,), float64
        Time (s) at which divergence was detected; ``inf`` when not diverged.
    mass : ndarray of shape (n_robots,), float64
        Total mass (kg) of each robot.
    voxel_size : float
        Lattice dimension L (m): metrics in voxel lengths divide by it.
    init_time : float
        Settling time (s) before the fitness reference (the seed's InitCmTime).
    trace_interval : float
        Seconds between centre-of-mass samples.
    obstacle_mass : ndarray of shape (n_robots,), float64
        Mass (kg) of each robot's terrain as the seed's fixed obstacle voxels
        (its walls: 1 kg per lattice cell); 0 on flat ground.
    obstacle_cm : ndarray of shape (n_robots, 3), float64
        Their centre of mass (m). With ``obstacle_mass`` it gives the seed's
        own centre of mass, which counts the walls
        (:func:`softgym.metrics.dilute`).
    aux : ndarray of shape (n_robots, n_samples, n_aux), float64, optional
        The kernel's task measures at ``times`` (columns
        :data:`softgym.engine.AUX_NAMES`: the terrain objects' centre of mass,
        the robot's heading sum, the bounding box of its voxel centres; m).
    aux_init, aux_final : ndarray of shape (n_robots, n_aux), float64, optional
        The same when ``cm_init`` was taken, and at the end of the run.
    """

    times: np.ndarray
    cm: np.ndarray
    cm_init: np.ndarray
    init_reached: np.ndarray
    cm_final: np.ndarray
    positions: np.ndarray
    orientations: np.ndarray
    voxel_offsets: np.ndarray
    grid_index: np.ndarray
    dt: np.ndarray
    steps: np.ndarray
    time: np.ndarray
    diverged: np.ndarray
    diverged_time: np.ndarray
    mass: np.ndarray
    voxel_size: float
    init_time: float
    trace_interval: float
    obstacle_mass: np.ndarray | None = None
    obstacle_cm: np.ndarray | None = None
    aux: np.ndarray | None = None
    aux_init: np.ndarray | None = None
    aux_final: np.ndarray | None = None

    #: Fields with one entry (row) per robot.
    PER_ROBOT = ("times", "cm", "cm_init", "init_reached", "cm_final", "dt", "steps", "time",
                 "diverged", "diverged_time", "mass", "obstacle_mass", "obstacle_cm", "aux",
                 "aux_init", "aux_final")  # fmt: skip
    #: Fields with one row per voxel (sliced with ``voxel_offsets``).
    PER_VOXEL = ("positions", "orientations", "grid_index")

    def take(self, indices) -> Rollout:
        """The rollout of the robots ``indices``, in that order (repeats allowed).

        Parameters
        ----------
        indices : sequence of int

        Returns
        -------
        Rollout
        """
        idx = np.asarray(indices, dtype=np.intp).reshape(-1)
        off = self.voxel_offsets
        pieces = [np.arange(off[i], off[i + 1]) for i in idx]
        vox = np.concatenate(pieces) if pieces else np.zeros(0, dtype=np.intp)
        counts = np.array([len(p) for p in pieces], dtype=np.int64)
        changes = {k: getattr(self, k)[idx] for k in self.PER_ROBOT if getattr(self, k) is not None}
        changes.update({k: getattr(self, k)[vox] for k in self.PER_VOXEL})
        changes["voxel_offsets"] = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        return replace(self, **changes)

    @property
    def n_robots(self) -> int:
        """Number of robots in the batch."""
        return int(self.dt.shape[0])

    def robot_positions(self, i: int) -> np.ndarray:
        """Final voxel centres of robot ``i``, shape (n_voxels_i, 3)."""
        return self.positions[self.voxel_offsets[i] : self.voxel_offsets[i + 1]]

    def robot_orientations(self, i: int) -> np.ndarray:
        """Final voxel quaternions (w, x, y, z) of robot ``i``, shape (n_voxels_i, 4)."""
        return self.orientations[self.voxel_offsets[i] : self.voxel_offsets[i + 1]]

    def trace(self, i: int, since: float | None = None) -> np.ndarray:
        """Centre-of-mass trace of robot ``i`` as rows (x, y, z, t).

        Parameters
        ----------
        i : int
            Robot index.
        since : float, optional
            Keep only samples with ``t >= since`` (s). ``None`` keeps all; pass
            ``rollout.init_time`` for the seed's traces, which start after
            the settling time.

        Returns
        -------
        ndarray of shape (n_points, 4), float64
            Positions in metres, time in seconds (the layout of the seed's CMTrace).

        Raises
        ------
        InvalidIndexError
            If ``i`` is not an integer in ``[0, n_robots)`` (as
            :class:`~softgym.engine.Simulation` indexes robots: no negative index).
        """
        n = len(self.times)
        if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)):
            raise InvalidIndexError(f"robot must be an integer index, got {i!r:.40}")
        if not 0 <= i < n:
            raise InvalidIndexError(f"robot = {i} is out of range: this rollout holds robots 0..{n - 1}")
        t = self.times[i]
        keep = np.ones(t.shape, dtype=bool) if since is None else t >= since
        return np.column_stack([self.cm[i][keep], t[keep]])
