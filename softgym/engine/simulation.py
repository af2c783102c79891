"""`Simulation`: a batch of voxel robots advanced together by the Cython kernel.

The runtime: it validates the batch, has :func:`softgym.engine.layout.build_layout`
lay it out as flat structure-of-arrays (float64, C-contiguous, per-robot
offsets, every constant of the lattice model computed once), and calls
:func:`softgym.engine._core.advance`, which runs the robots in parallel without
the GIL.

Two presets (``SimConfig.model``, formulas and sources in docs/PHYSICS.md): ``"seed"``
(the default) is the seed study's engine step, reproduced with its quirks; ``"corotational"``
is softgym's own symmetric beam, summarised here:

* voxel: rigid cube, mass ``rho L^3``, inertia ``m L^2 / 6``;
* link between face neighbours: Euler-Bernoulli beam with the harmonic-mean
  modulus ``E = 2 E1 E2 / (E1 + E2)`` (and Poisson ratio), constants
  ``k_axial = E L``, ``k_torsion = E L^3 / (12 (1 + nu))``,
  ``k_bend = E L^3 / 6`` (``b3`` of the seed; its ``b1 = E L`` and
  ``b2 = E L^2 / 2`` follow from the beam element), measured in the frame of
  the link's chord so large rotations are exact;
* bond damping ``zeta_b sqrt(k m)`` (axial, the seed's ``0.5 zeta_b 2 sqrt(a1 m)``),
  ``zeta_b sqrt(k_bend I) / 2`` (bending moments, the seed's coefficient; the
  shear damping follows from the moments) and ``zeta_b sqrt(k_torsion I) / 2``
  (torsion), with the harmonic mean of the masses ``2 m1 m2 / (m1 + m2)``
  (= m for equal voxels; twice the reduced mass) so mixed links are symmetric. Damping acts on deformation rates
  only, so its power is never positive and rigid motion is not damped;
* global damping ``zeta_g 2 sqrt(m E L)`` on velocity and the seed's
  multiplicative factor on angular momentum;
* floor at z = 0: normal force ``2 E L p`` (p: penetration of the voxel's
  half actuated size) minus ``zeta_c 2 sqrt(m E L) v_z`` (never pulling),
  static friction below ``mu_s N``, kinetic ``mu_k N`` against the sliding
  direction;
* terrain boxes (:mod:`softgym.terrain`): the floor's laws along the
  box's outward normal, on every face;
* self-collision (``SimConfig.self_collision``): surface voxels more than
  ``collision_exclusion`` bond hops apart repel when their envelopes of
  diameter ``1.5 s`` overlap (the seed's law), candidates from a per-robot
  spatial hash kept between calls;
* time step ``dt_frac / (2 pi sqrt(max k_axial / m))`` per robot, so a stiff
  robot does not slow the others of its batch;
* actuation: ``scale = L (1 + CTE T)``, ``T = dT sin(2 pi t / period + phase)``
  from ``init_time`` on, or per-voxel temperatures set by the caller.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from softgym.engine import _cache, _core
from softgym.engine._openmp import openmp_enabled
from softgym.engine._sense import cell_sensors as _cell_sensors
from softgym.engine._sense import contact_gaps as _contact_gaps
from softgym.engine.body import Body
from softgym.engine.config import SimConfig
from softgym.engine.layout import (  # noqa: F401 (re-exported: the public API is unchanged)
    MAX_OBSTACLE_VOXELS,
    OBSTACLE_DENSITY,
    OBSTACLE_YOUNGS_MODULUS,
    as_body,
    build_layout,
    memory_estimate,
    obstacle_cells,
    obstacle_mass_and_center,
    time_step,
    voxel_steps_per_second,
)
from softgym.engine.rollout import Rollout
from softgym.exceptions import (
    InvalidActionError,
    InvalidDesignError,
    InvalidIndexError,
    InvalidParameterError,
    InvalidTerrainError,
    SimulationDivergedError,
)
from softgym.validate import threads

__all__ = ["Simulation", "as_body", "default_num_threads", "time_step", "voxel_steps_per_second"]


# state arrays that change while the simulation runs (checkpointed by get_state):
# per voxel, per robot, and the traces
# col_ref: positions and sizes when the seed model last rebuilt its contact candidates
_VOXEL_STATE = ("pos", "vel", "quat", "angvel", "rot", "scale", "temp", "ext_force", "col_ref")
# col_acc / col_vmax: the seed model's displacement since that rebuild and last fastest voxel speed
_ROBOT_STATE = ("diverged", "diverged_time", "diverged_code", "init_done", "cm_init", "use_temp",
                "col_acc", "col_vmax", "aux_init")
_LINK_STATE = ("link_sa", "link_last")  # the seed model's per-link mode and memory
# kept as (rows, n_links) for the kernel's vector loops, shown as (n_links, rows) in states
_TRANSPOSED = ("link_last",)
# kernel arrays that states show in another dtype: the links' mode is int64 in the kernel
# (its modes pass reads it in 64-bit vector lanes), a 0/1 flag in states
_STATE_DTYPE = {"link_sa": np.int8}
_STATE = (*_VOXEL_STATE, *_ROBOT_STATE, *_LINK_STATE, "steps", "trace_n", "trace_t", "trace_cm",
          "trace_aux")


def _env_threads(name: str) -> int | None:
    env = os.environ.get(name)
    if not env:
        return None
    try:
        # OMP_NUM_THREADS may list one count per nesting level: the first is ours
        n = int(env.split(",")[0])
    except ValueError:
        raise InvalidParameterError(f"{name} must be an integer, got {env!r}") from None
    if n < 1:
        raise InvalidParameterError(f"{name} must be >= 1, got {n}")
    return n


def default_num_threads() -> int:
    """Threads used when none is given.

    ``SOFTGYM_NUM_THREADS`` if set, else ``OMP_NUM_THREADS``, else the CPUs
    this process may run on; 1 in a build without OpenMP. It does not read
    OpenMP's run-time setting: libraries sharing the process's OpenMP runtime
    change it (``torch.set_num_threads(1)``, common in RL scripts, would
    otherwise put the engine on one thread).
    """
    if not openmp_enabled():
        return 1
    for name in ("SOFTGYM_NUM_THREADS", "OMP_NUM_THREADS"):
        n = _env_threads(name)
        if n is not None:
            return n
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # no affinity API (macOS, Windows)
        return max(1, os.cpu_count() or 1)


class Simulation:
    """A batch of voxel robots simulated together.

    Parameters
    ----------
    bodies : Body, design, or sequence of them
        The robots. Designs are converted with their ``to_body()`` method.
        Robots may differ in shape, size and materials.
    config : SimConfig, optional
        Shared settings; the seed's by default.
    terrain : Terrain or sequence of Terrain, optional
        The world: boxes in voxel lengths (:mod:`softgym.terrain`). One
        terrain for every robot, or one per robot. Robots never touch each
        other: each lives in its own copy of its world. The floor is
        ``config.floor`` (a terrain built with ``floor=False`` turns it off).
        A terrain's movable objects (``Terrain.objects``) join their robot's
        entry after its voxels: they touch it through the self-collision law
        and stay out of its centre of mass, actuation and per-robot views
        (``positions``, ``all_positions``, ``voxel_offsets``, the rollout's
        voxels); ``object_positions`` and ``aux`` show them.
    n_threads : int, optional
        OpenMP threads used by :meth:`run` (default :func:`default_num_threads`).
        Results are bit-identical for any thread count.

    Examples
    --------
    >>> import numpy as np
    >>> from softgym.engine import Body, Simulation
    >>> sim = Simulation([Body.uniform(np.ones((2, 2, 2)))])
    >>> rollout = sim.run(0.5)
    >>> rollout.cm.shape
    (1, 6, 3)
    """

    def __init__(
        self,
        bodies: Any,
        config: SimConfig | None = None,
        n_threads: int | None = None,
        terrain: Any = None,
    ) -> None:
        if isinstance(bodies, (Body,)) or hasattr(bodies, "to_body"):
            bodies = [bodies]
        if not isinstance(bodies, Sequence) or len(bodies) == 0:
            raise InvalidDesignError("Simulation needs a non-empty sequence of bodies")
        self.bodies: list[Body] = [as_body(b) for b in bodies]
        self.config = SimConfig() if config is None else config
        if not isinstance(self.config, SimConfig):
            raise InvalidParameterError(f"config must be a SimConfig, got {type(config).__name__}")
        checked = threads(n_threads)
        self.n_threads = default_num_threads() if checked is None else checked
        self.terrains = self._terrains(terrain)
        if not self.config.self_collision and any(t.objects for t in self.terrains):
            raise InvalidParameterError(
                "a terrain's movable objects touch the robot through self-collision: "
                "SimConfig.self_collision must be True"
            )
        self._check_memory()
        self._build()
        self._initial = {k: self._a[k].copy() for k in _STATE}
        self._contacts = _cache.ContactCache(self.n_robots)
        self._t_target = 0.0

    #: Memory budget (bytes) of one Simulation: its arrays, what it keeps besides, its
    #: layout's temporaries, its kernels' scratch and contact cache, and its traces.
    #: Checked before anything is allocated (construction, and each :meth:`advance_to`
    #: for the traces), so a batch or a trace interval that would exhaust the machine
    #: is refused with a typed error instead; raise it on the class or an instance for
    #: a larger machine.
    max_bytes: float = 8 * 2**30

    def _check_memory(self) -> None:
        # from the grids alone, before the layout is built: the bytes of what is allocated
        # (softgym.engine.layout.memory_estimate), within 25 % of the measured peak RSS
        est = memory_estimate(self.bodies, self.terrains, self.config, self.n_threads)
        self._memory = est
        need = est["total"]
        if need > self.max_bytes:
            raise InvalidParameterError(
                f"{self.n_robots} robots of {est['voxels']} voxels and {est['links']} links in "
                f"all need about {need / 2**30:.1f} GiB, over Simulation.max_bytes = "
                f"{self.max_bytes / 2**30:.1f} GiB; simulate fewer or smaller robots per batch, "
                f"or raise the budget"
            )

    @property
    def estimated_memory(self) -> dict[str, int]:
        """The bytes this Simulation was estimated to need at its peak, by part.

        What :attr:`max_bytes` is checked against before the layout is built
        (:func:`softgym.engine.layout.memory_estimate`: ``total`` and its parts).
        """
        return dict(self._memory)

    # ------------------------------------------------------------------ layout
    def _terrains(self, terrain: Any) -> list:
        from softgym.terrain import Terrain

        if terrain is None:
            terrain = Terrain.flat()
        if isinstance(terrain, Terrain):
            terrains = [terrain] * self.n_robots
        else:
            terrains = list(terrain)
            if len(terrains) != self.n_robots:
                raise InvalidTerrainError(
                    f"give one terrain or one per robot: {len(terrains)} terrains for "
                    f"{self.n_robots} robots"
                )
        L = self.config.voxel_size
        for t, body in zip(terrains, self.bodies):
            if not isinstance(t, Terrain):
                raise InvalidTerrainError(f"expected a softgym Terrain, got {type(t).__name__}")
            filled = np.argwhere(body.grid > 0)
            lo = body.origin / L + filled.min(axis=0)
            hi = body.origin / L + filled.max(axis=0) + 1
            if self.config.floor and lo[2] < -1e-9:
                # deep in the floor, the penalty force launches the body (issue 31: 5 m
                # below the floor it flew to z = 65 m without diverging)
                raise InvalidDesignError(
                    f"a body's lowest voxel starts at z = {lo[2]:g} voxel lengths, below the "
                    f"floor (z = 0): its origin must put every voxel at or above the floor"
                )
            t.validate(lo, hi)
        return terrains

    def _build(self) -> None:
        # the layout (pure: softgym.engine.layout), then the runtime's views of it
        lay = build_layout(self.bodies, self.terrains, self.config)
        self._a = lay.arrays
        self._settings = lay.settings
        self._grid_index = lay.grid_index
        self._own = lay.own
        self._own_offsets = lay.own_offsets
        self._obstacle_mass = lay.obstacle_mass
        self._obstacle_cm = lay.obstacle_cm

    # --------------------------------------------------------------- properties
    @property
    def n_robots(self) -> int:
        """Number of robots in the batch."""
        return len(self.bodies)

    @property
    def n_voxels(self) -> int:
        """Total number of the robots' voxels over the batch (their objects excluded)."""
        return int(self._own_offsets[-1])

    @property
    def n_links(self) -> int:
        """Total number of links over the batch."""
        return int(self._a["link_start"][-1])

    @property
    def voxel_offsets(self) -> np.ndarray:
        """Ndarray of shape (n_robots + 1,): robot i owns voxels ``[off[i], off[i+1])``.

        Offsets into the robots' voxels (:attr:`all_positions`, the rollout's
        positions), their terrain objects excluded.
        """
        return self._own_offsets.copy()

    @property
    def has_objects(self) -> bool:
        """Whether some robot's terrain holds movable objects."""
        return self._own is not None

    @property
    def dt(self) -> np.ndarray:
        """Ndarray of shape (n_robots,): each robot's time step (s)."""
        return self._a["dt"].copy()

    @property
    def time(self) -> np.ndarray:
        """Ndarray of shape (n_robots,): each robot's simulated time (s)."""
        a = self._a
        t = a["steps"] * a["dt"]
        return np.where(a["diverged"] == 1, a["diverged_time"], t)

    @property
    def diverged(self) -> np.ndarray:
        """Ndarray of shape (n_robots,), bool: robots frozen after divergence."""
        return self._a["diverged"].astype(bool)

    @property
    def cm_init(self) -> np.ndarray:
        """Each robot's fitness reference, shape (n_robots, 3).

        The centre of mass at the first step after ``init_time`` (the seed's
        IniCM); the current one before that.
        """
        a = self._a
        done = a["init_done"].astype(bool)
        return np.where(done[:, None], a["cm_init"], self.center_of_mass())

    @property
    def nbytes(self) -> int:
        """Bytes held by the batch's arrays."""
        return int(sum(v.nbytes for v in self._a.values()))

    def _robot(self, robot: Any) -> int:
        # a robot index: an integer (not a bool) in [0, n_robots)
        if isinstance(robot, (bool, np.bool_)) or not isinstance(robot, (int, np.integer)):
            raise InvalidIndexError(f"robot must be an integer index, got {robot!r:.40}")
        if not 0 <= robot < self.n_robots:
            raise InvalidIndexError(
                f"robot = {robot} is out of range: this batch holds robots 0..{self.n_robots - 1}"
            )
        return int(robot)

    def _slice(self, robot: int) -> slice:
        # the robot's own voxels in the kernel arrays (its objects follow them)
        robot = self._robot(robot)
        return slice(int(self._a["vox_start"][robot]), int(self._a["body_end"][robot]))

    def _object_slice(self, robot: int) -> slice:
        robot = self._robot(robot)
        return slice(int(self._a["body_end"][robot]), int(self._a["vox_start"][robot + 1]))

    def object_positions(self, robot: int) -> np.ndarray:
        """Voxel centres (m) of a robot's terrain objects, shape (n_object_voxels_r, 3) (a copy)."""
        return self._a["pos"][self._object_slice(robot)].copy()

    def object_orientations(self, robot: int) -> np.ndarray:
        """Quaternions (w, x, y, z) of a robot's terrain object voxels, shape (n_object_voxels_r, 4)."""
        return self._a["quat"][self._object_slice(robot)].copy()

    def object_scales(self, robot: int) -> np.ndarray:
        """Edge lengths (m) of a robot's terrain object voxels, shape (n_object_voxels_r,)."""
        return self._a["scale"][self._object_slice(robot)].copy()

    def object_center_of_mass(self) -> np.ndarray:
        """Ndarray of shape (n_robots, 3): centre of mass (m) of each robot's objects (0 if none)."""
        return self.aux()[:, 0:3]

    def aux(self) -> np.ndarray:
        """Each robot's task measures now, as the kernel samples them with the centre of mass.

        Returns
        -------
        ndarray of shape (n_robots, len(AUX_NAMES)), float64
            Columns :data:`softgym.engine.AUX_NAMES`: the objects' centre of
            mass (m; 0 without objects), the heading sum (mass-weighted x axes
            of the robot's voxels: its yaw is ``atan2(heading_y, heading_x)``)
            and the bounding box of its voxel centres (m).
        """
        out = np.zeros((self.n_robots, len(_core.AUX_NAMES)))
        _core.compute_aux(self._a, self._settings, out)
        return out

    def positions(self, robot: int) -> np.ndarray:
        """Voxel centres (m) of one robot, shape (n_voxels_r, 3) (a copy)."""
        return self._a["pos"][self._slice(robot)].copy()

    def collision_candidates(self, robot: int) -> np.ndarray:
        """The robot's self-collision candidate pairs as of their last rebuild.

        Shape (n_pairs, 2), int: i < j, sorted; indices into the robot's voxels
        (``positions`` rows) followed by its objects' (``object_positions``
        rows). Empty before the first step and without self-collision. The
        seed preset rebuilds them on the seed's schedule (once the fastest
        voxel may have moved half a voxel), the corotational preset when a
        voxel may have moved beyond its margin.
        """
        robot = self._robot(robot)
        return self._contacts.pairs(robot) - int(self._a["vox_start"][robot])

    def velocities(self, robot: int) -> np.ndarray:
        """Voxel velocities (m/s) of one robot, shape (n_voxels_r, 3)."""
        return self._a["vel"][self._slice(robot)].copy()

    def orientations(self, robot: int) -> np.ndarray:
        """Voxel quaternions (w, x, y, z) of one robot, shape (n_voxels_r, 4) (a copy)."""
        return self._a["quat"][self._slice(robot)].copy()

    def angular_velocities(self, robot: int) -> np.ndarray:
        """Voxel angular velocities (rad/s, world frame), shape (n_voxels_r, 3)."""
        return self._a["angvel"][self._slice(robot)].copy()

    def scales(self, robot: int) -> np.ndarray:
        """Current actuated voxel edge lengths (m) of one robot, shape (n_voxels_r,)."""
        return self._a["scale"][self._slice(robot)].copy()

    def grid_index(self, robot: int) -> np.ndarray:
        """Lattice index (i, j, k) of each voxel of one robot, shape (n_voxels_r, 3)."""
        return self._grid_index[self._slice(robot)].copy()

    def masses(self, robot: int) -> np.ndarray:
        """Voxel masses (kg) of one robot, shape (n_voxels_r,)."""
        return self._a["mass"][self._slice(robot)].copy()

    def center_of_mass(self) -> np.ndarray:
        """Ndarray of shape (n_robots, 3): current centre of mass of each robot (m), objects excluded."""
        a = self._a
        w = a["mass"][:, None] * a["pos"]
        if self._own is not None:
            w = w[self._own]
        sums = np.add.reduceat(w, self._own_offsets[:-1], axis=0)
        return sums / a["mass_total"][:, None]

    def momentum(self, objects: bool = False) -> np.ndarray:
        """Ndarray of shape (n_robots, 3): total linear momentum of each robot (kg m/s).

        ``objects=True`` adds its terrain objects' (the whole entry's momentum).
        """
        return self._momentum(self._a["mass"][:, None] * self._a["vel"], objects)

    def _momentum(self, p: np.ndarray, objects: bool) -> np.ndarray:
        # momentum() from the voxels' momenta p (n_voxels, 3)
        if objects:
            return np.add.reduceat(p, self._a["vox_start"][:-1], axis=0)
        if self._own is not None:
            p = p[self._own]
        return np.add.reduceat(p, self._own_offsets[:-1], axis=0)

    def energy(self) -> np.ndarray:
        """Mechanical energy per robot (J).

        Returns
        -------
        ndarray of shape (n_robots, 3), float64
            Kinetic (translation + rotation), elastic (links + floor penalty)
            and gravitational potential energy (zero at z = 0).
        """
        out = np.zeros((self.n_robots, 3))
        _core.compute_energy(self._a, self._settings, out)
        return out

    # ------------------------------------------------------------------ control
    def _per_voxel(self, robot: int, values: Any, name: str, width: int | None) -> np.ndarray:
        s = self._slice(robot)
        n = s.stop - s.start
        arr = np.asarray(values, dtype=np.float64)
        grid_shape = self.bodies[robot].grid.shape
        if width is None and arr.shape == grid_shape:
            arr = arr[tuple(self._grid_index[s].T)]
        elif width is not None and arr.shape == (*grid_shape, width):
            arr = arr[tuple(self._grid_index[s].T)]
        want = (n,) if width is None else (n, width)
        if arr.shape != want:
            raise InvalidActionError(
                f"{name} for robot {robot} must have shape {want} (one per voxel) "
                f"or the grid's shape {grid_shape}, got {arr.shape}"
            )
        if not np.isfinite(arr).all():
            raise InvalidActionError(f"{name} for robot {robot} holds NaN or infinite values")
        return arr

    def set_temperature(self, robot: int, temperature: Any) -> None:
        """Replace the sinusoid of one robot by per-voxel temperatures (degC).

        Parameters
        ----------
        robot : int
            Robot index.
        temperature : array_like of shape (n_voxels_r,) or the grid's shape, or None
            Temperature of each voxel until the next call; a voxel's size then
            follows ``L (1 + CTE T)`` under the configured actuation law
            (no settling delay). ``None`` gives the robot back its sinusoid.

        Raises
        ------
        InvalidActionError
            On a wrong shape or a non-finite value; the state is unchanged.
        """
        s = self._slice(robot)
        if temperature is None:
            self._a["use_temp"][robot] = 0
            return
        arr = self._per_voxel(robot, temperature, "temperature", None)
        self._a["temp"][s] = arr
        self._a["use_temp"][robot] = 1

    def set_temperatures(self, temperature: Any, robots: Any = None) -> None:
        """Per-voxel temperatures (degC) for many robots in one call.

        Parameters
        ----------
        temperature : array_like of shape (n_voxels,)
            One value per voxel of the whole batch, in voxel order (robot
            ``i`` owns ``voxel_offsets[i]:voxel_offsets[i + 1]``).
        robots : array_like of bool of shape (n_robots,) or of int, optional
            The robots that take their values and switch to temperature
            control (default all); the others keep theirs.

        Raises
        ------
        InvalidActionError
            On a wrong shape or a non-finite value; the state is unchanged.
        """
        arr = np.asarray(temperature, dtype=np.float64)
        if arr.shape != (self.n_voxels,):
            raise InvalidActionError(
                f"temperatures must have shape ({self.n_voxels},) (one per voxel), got {arr.shape}"
            )
        if not np.isfinite(arr).all():
            raise InvalidActionError("temperatures hold NaN or infinite values")
        a = self._a
        # the robots' voxels in the kernel arrays (their objects, after them, keep T = 0)
        own = slice(None) if self._own is None else self._own
        if robots is None:
            a["temp"][own] = arr
            a["use_temp"][:] = 1
            return
        sel = np.zeros(self.n_robots, dtype=bool)
        sel[np.asarray(robots)] = True
        voxels = np.repeat(sel, np.diff(self._own_offsets))
        if self._own is None:
            a["temp"][voxels] = arr[voxels]
        else:
            a["temp"][self._own[voxels]] = arr[voxels]
        a["use_temp"][sel] = 1

    @property
    def all_positions(self) -> np.ndarray:
        """Voxel centres (m) of the whole batch, shape (n_voxels, 3) (a copy; robots' voxels only)."""
        return self._a["pos"].copy() if self._own is None else self._a["pos"][self._own]

    @property
    def all_velocities(self) -> np.ndarray:
        """Voxel velocities (m/s) of the whole batch, shape (n_voxels, 3) (a copy; robots' voxels only)."""
        return self._a["vel"].copy() if self._own is None else self._a["vel"][self._own]

    @property
    def all_scales(self) -> np.ndarray:
        """Actuated voxel edge lengths (m) of the whole batch, shape (n_voxels,) (robots' voxels only)."""
        return self._a["scale"].copy() if self._own is None else self._a["scale"][self._own]

    def object_velocity(self) -> np.ndarray:
        """Ndarray of shape (n_robots, 3): velocity (m/s) of each robot's objects' centre of mass (0 if none)."""
        a = self._a
        if self._own is None:
            return np.zeros((self.n_robots, 3))
        total = np.add.reduceat(a["mass"], a["vox_start"][:-1])
        m_obj = total - a["mass_total"]
        p = a["mass"][:, None] * a["vel"]  # the voxels' momenta, once for both sums
        p_obj = self._momentum(p, True) - self._momentum(p, False)
        with np.errstate(invalid="ignore", divide="ignore"):
            v = p_obj / m_obj[:, None]
        v[m_obj <= 0.0] = 0.0
        return v

    #: Lattice steps (Manhattan) within which a robot's own voxels never count as touching
    #: each other in :meth:`contact_gaps` (at rest they are neighbours, not contacts).
    SELF_TOUCH_HOPS: int = 3
    #: Robots of more voxels skip the own-voxel part of :meth:`contact_gaps` (it is quadratic).
    SELF_TOUCH_MAX_VOXELS: int = 4096

    def contact_gaps(self, cap: float = math.inf, n_threads: int | None = None) -> np.ndarray:
        """Each robot voxel's smallest surface gap (m) to anything it can touch, now, at most ``cap``.

        The floor (its bottom face's height), the terrain's boxes and obstacle
        voxels, the robot's movable objects and its own voxels more than
        :attr:`SELF_TOUCH_HOPS` lattice steps away (robots of up to
        :attr:`SELF_TOUCH_MAX_VOXELS` voxels), each voxel a cube of its actuated
        edge (obstacle voxels of edge L). Negative values are penetration;
        ``cap`` (m) where nothing is nearer, and for voxels with all six bonds
        (they touch only their neighbours). Computed in compiled code, robots
        in parallel (``softgym.engine._sense``); it reads the state and never
        changes a result.

        Returns
        -------
        ndarray of shape (n_voxels,), float64
            In the order of :attr:`all_positions`.
        """
        a = self._a
        out = np.empty(self.n_voxels)
        threads = self.n_threads if n_threads is None else int(n_threads)
        _contact_gaps(
            a["pos"], a["scale"], a["surface"], a["vox_start"], a["body_end"], self._grid_index,
            a["floor"], a["box_start"], a["boxes"], a["obs_start"], np.ascontiguousarray(a["obs"]),
            float(self.config.voxel_size), self.SELF_TOUCH_HOPS, self.SELF_TOUCH_MAX_VOXELS,
            float(cap), self._own_offsets.astype(np.intp), out, *self._sense_scratch(), threads,
        )  # fmt: skip
        return out

    def _sense_scratch(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        # each robot's voxels sorted by x at the last contact_gaps call (local indices), kept
        # so that the next call's sort is short (any permutation gives the same gaps), and the
        # sweep's scratch (4 doubles and an index per robot voxel)
        scratch = getattr(self, "_sense_buffers", None)
        if scratch is None:
            off = self._own_offsets
            counts = np.diff(off)
            n = int(off[-1])
            order = (np.arange(n) - np.repeat(off[:-1], counts)).astype(np.intp)
            scratch = (order, np.empty(4 * n), np.empty(n, dtype=np.intp))
            self._sense_buffers = scratch
        return scratch

    def cell_sensors(
        self,
        grid_shape: Sequence[int],
        cell_of: np.ndarray,
        voxel_of: np.ndarray,
        rest: np.ndarray,
        out: np.ndarray,
        cov: np.ndarray,
        reach: float,
        bounds: tuple[float, float],
    ) -> tuple[np.ndarray, np.ndarray]:
        """Every robot voxel's sensors on its grid cell, in one compiled pass (robots in parallel).

        Parameters
        ----------
        grid_shape : 3 ints
            The grid every robot's voxels are placed on.
        cell_of : ndarray (n_voxels,), intp
            Each voxel's C-order cell in its robot's grid.
        voxel_of : ndarray (n_robots, n_cells), intp
            Each cell's voxel (an index of :attr:`all_positions`), -1 where empty.
        rest : ndarray (n_robots, n_cells, 3)
            Each cell's lattice position minus its robot's mean (voxel lengths; 0 where empty).
        out : ndarray (n_robots, n_cells, 8)
            Filled, row of each voxel's cell: position and velocity relative to the
            centre of mass (voxel lengths, clipped to ``bounds``), touch (1 in contact,
            falling to 0 at a gap of ``reach`` voxel lengths: :meth:`contact_gaps`),
            the mean stretch of its bonds to its lattice neighbours (clipped to +-1).
            Empty cells' rows are left as they are.
        cov : ndarray (n_robots, 3, 3)
            Filled with each robot's ``sum rest (position - cm)^T`` (the body's rotation).
        reach : float
        bounds : (float, float)
            Bounds of the relative positions and velocities.

        Returns
        -------
        cm, cm_vel : ndarray (n_robots, 3)
            Centre of mass (m) and its velocity (m/s).
        """
        L = float(self.config.voxel_size)
        cm = self.center_of_mass()
        mass = self._a["mass_total"]
        cm_vel = self.momentum() / mass[:, None]
        gaps = self.contact_gaps(cap=reach * L)
        nx, ny, nz = (int(v) for v in grid_shape)
        _cell_sensors(
            self.all_positions, self.all_velocities, gaps, cm, cm_vel,
            self._own_offsets.astype(np.intp), cell_of, voxel_of, nx, ny, nz, L, float(reach),
            float(bounds[0]), float(bounds[1]), rest, out, cov, self.n_threads,
        )  # fmt: skip
        return cm, cm_vel

    def set_external_force(self, robot: int, force: Any) -> None:
        """Apply a constant external force (N) to each voxel of one robot.

        Parameters
        ----------
        robot : int
            Robot index.
        force : array_like of shape (3,), (n_voxels_r, 3) or ``grid_shape + (3,)``
            A shape (3,) force is applied to every voxel.
        """
        s = self._slice(robot)
        arr = np.asarray(force, dtype=np.float64)
        if arr.shape == (3,):
            arr = np.broadcast_to(arr, (s.stop - s.start, 3))
        arr = self._per_voxel(robot, arr, "external force", 3)
        self._a["ext_force"][s] = arr

    # -------------------------------------------------------------------- run
    def _trace_samples(self, t_end: float) -> int:
        """Centre-of-mass samples per robot to reach ``t_end``, refused past :attr:`max_bytes`."""
        need = t_end / self.config.trace_interval + 3
        per_sample = 8 * (1 + 3 + len(_core.AUX_NAMES)) * self.n_robots
        # on top of the rest of the peak (memory_estimate; its traces' first 8 samples)
        if need * per_sample > self.max_bytes - self._memory["total"]:
            raise InvalidParameterError(
                f"SimConfig.trace_interval = {self.config.trace_interval:g} s up to t = "
                f"{t_end:g} s means {need:.3g} centre-of-mass samples per robot "
                f"({need * per_sample / 2**30:.3g} GiB for {self.n_robots} robots), over "
                f"Simulation.max_bytes = {self.max_bytes / 2**30:.1f} GiB; raise trace_interval"
            )
        return int(math.floor(t_end / self.config.trace_interval + 1e-9)) + 3

    def _ensure_trace_capacity(self, t_end: float) -> None:
        need = self._trace_samples(t_end)
        cap = self._a["trace_t"].shape[1]
        if need <= cap:
            return
        new = max(need, 2 * cap)
        for name in ("trace_t", "trace_cm", "trace_aux"):
            old = self._a[name]
            arr = np.zeros((old.shape[0], new, *old.shape[2:]))
            arr[:, :cap] = old
            self._a[name] = arr

    def advance(self, seconds: float) -> None:
        """Advance every robot by ``seconds`` of simulated time (no rollout built).

        Each robot steps with its own ``dt`` until its clock reaches the common
        target time. Diverged robots stay frozen.

        Raises
        ------
        InvalidParameterError
            If ``seconds`` is negative or not finite.
        SimulationDivergedError
            With ``on_divergence="raise"``, naming the first robot that diverged
            during this call (the others have advanced).
        """
        seconds = float(seconds)
        if not (math.isfinite(seconds) and seconds >= 0):
            raise InvalidParameterError(f"seconds must be finite and >= 0, got {seconds}")
        self.advance_to(self._t_target + seconds)

    #: Most voxel-steps one :meth:`advance_to` may plan (checked before it runs:
    #: nothing is lost): about 1.5 h on one core; a 6^3 soft robot's 5 s is 1.7e6.
    max_voxel_steps: float = 5e10

    #: Work between two returns to Python in :meth:`advance_to`, in voxel-steps per
    #: thread (about 0.1 s of wall time): signals (Ctrl-C) act within a fraction of a
    #: second whatever the batch, and results do not depend on it.
    chunk_voxel_steps: int = 1_000_000

    #: Fewest steps a robot should take in one kernel call of :meth:`advance_to`: a
    #: batch whose chunk would give its robots fewer advances group by group (each
    #: group at least 4 robots a thread), so that a robot's state (about 250 KiB for
    #: a 6^3 one) stays in the core's cache from step to step instead of being read
    #: back from memory every few steps. Results do not depend on it.
    min_visit_steps: int = 256

    def advance_to(self, time: float, progress: Any = None) -> None:
        """Advance every robot until its clock reaches ``time`` (s).

        The kernel runs in chunks of simulated time of about
        :attr:`chunk_voxel_steps` voxel-steps per thread each; between two
        chunks Python runs its signal handlers, so Ctrl-C raises
        ``KeyboardInterrupt`` within a fraction of a second, leaving each robot
        at the end of its last chunk (a later call goes on from there).
        A large batch (where a chunk would give each robot fewer than
        :attr:`min_visit_steps` steps) advances in groups of robots, one group
        to ``time`` after the other. There is no Python work per step: the
        result is bit-identical to one kernel call.

        Parameters
        ----------
        time : float
            Target time (s), not before the current one.
        progress : callable, optional
            ``progress(t)`` after each chunk, with the simulated time (s) reached:
            the batch's, or, when it advances in groups, the time in proportion
            to the work done (rising to ``time``).
        """
        time = float(time)
        if not (math.isfinite(time) and time >= self._t_target):
            raise InvalidParameterError(
                f"time must be finite and >= the current target {self._t_target}, got {time}"
            )
        a = self._a
        dt = a["dt"]
        final = np.maximum(np.ceil(time / dt - 1e-9).astype(np.int64), a["steps"])
        planned = float(np.sum((final - a["steps"]) * np.diff(a["vox_start"])))
        if planned > self.max_voxel_steps:
            raise InvalidParameterError(
                f"advancing to t = {time:g} s needs {planned:.3g} voxel-steps (time steps down to "
                f"{dt.min():.3g} s), over Simulation.max_voxel_steps = {self.max_voxel_steps:.3g} "
                f"(about {self.max_voxel_steps / 1e7 / 3600:.0f} h on one core); stiffer or lighter "
                "materials shrink the time step: check the materials or raise the limit"
            )
        self._ensure_trace_capacity(time + dt.max())  # refused past max_bytes before it runs
        a = self._a
        before = a["diverged"].copy()
        threads = min(self.n_threads, self.n_robots)
        budget = max(1, int(self.chunk_voxel_steps)) * threads  # voxel-steps per kernel call
        rates = np.diff(a["vox_start"]) / dt  # voxel-steps per simulated second, per robot
        groups = self._advance_groups(budget, threads)
        start = self._t_target
        work = float(rates.sum()) * (time - start)
        done = 0.0
        for g, (g0, g1) in enumerate(groups):
            # simulated seconds per chunk = work per chunk / the group's voxel-steps per second
            rate = float(rates[g0:g1].sum())
            chunk = budget / max(rate, 1e-300)
            last = g == len(groups) - 1
            t = start
            while True:
                t_prev, t = t, min(time, t + chunk)
                targets = a["steps"].copy()  # the robots outside the group stay
                if t >= time:
                    targets[g0:g1] = final[g0:g1]
                else:
                    reach = np.ceil(t / dt[g0:g1] - 1e-9).astype(np.int64)
                    targets[g0:g1] = np.minimum(np.maximum(reach, a["steps"][g0:g1]), final[g0:g1])
                _core.advance(a, self._settings, targets, threads, self._contacts)
                # back in Python: a pending SIGINT raises KeyboardInterrupt here
                done += rate * (t - t_prev)
                if last:
                    self._t_target = t  # every robot has reached t
                if progress is not None:
                    whole = len(groups) == 1 or (last and t >= time) or work <= 0
                    progress(t if whole else start + (time - start) * min(done / work, 1.0))
                if t >= time:
                    break
        if self.config.on_divergence == "raise":
            new = np.flatnonzero((a["diverged"] == 1) & (before == 0))
            if new.size:
                r = int(new[0])
                raise SimulationDivergedError(
                    r, float(a["diverged_time"][r]), _core.STATUS_NAMES.get(int(a["diverged_code"][r]), "diverged")
                )

    def _advance_groups(self, budget: float, threads: int) -> list[tuple[int, int]]:
        """The robots of :meth:`advance_to` as ranges [g0, g1) advanced one after the other.

        One range holds the whole batch unless a chunk of ``budget`` voxel-steps would give
        each robot fewer than :attr:`min_visit_steps` steps; then consecutive robots up to
        ``budget / min_visit_steps`` voxels a group, but at least 4 robots a thread (the
        kernel's dynamic schedule balances the threads over a group's robots).
        """
        vox = np.diff(self._a["vox_start"])
        n = self.n_robots
        cap = budget / max(1, int(self.min_visit_steps))
        if n == 0 or float(vox.sum()) <= cap:
            return [(0, n)]
        least = 4 * threads
        groups, g0, acc = [], 0, 0
        for r in range(n):
            if r - g0 >= least and acc + int(vox[r]) > cap:
                groups.append((g0, r))
                g0, acc = r, 0
            acc += int(vox[r])
        groups.append((g0, n))
        return groups

    def run(self, seconds: float) -> Rollout:
        """Advance every robot by ``seconds`` and return the rollout since t = 0.

        Parameters
        ----------
        seconds : float
            Simulated time to add (s); 5 s in the seed study.

        Returns
        -------
        Rollout
        """
        self.advance(seconds)
        return self.rollout()

    def rollout(self) -> Rollout:
        """The :class:`Rollout` of the current state (traces since t = 0)."""
        a = self._a
        cfg = self.config
        n_samples = int(math.floor(self._t_target / cfg.trace_interval + 1e-9)) + 1
        n = a["trace_n"]
        idx = np.minimum(np.arange(n_samples)[None, :], np.maximum(n - 1, 0)[:, None])
        rows = np.arange(self.n_robots)[:, None]
        times = a["trace_t"][rows, idx]
        cm = a["trace_cm"][rows, idx]
        aux = a["trace_aux"][rows, idx]
        aux_final = self.aux()
        if (n == 0).any():  # never stepped: the initial centre of mass
            cm0 = self.center_of_mass()
            cm[n == 0] = cm0[n == 0][:, None, :]
            aux[n == 0] = aux_final[n == 0][:, None, :]
            times[n == 0] = 0.0
        init = a["init_done"].astype(bool)
        cm_init = np.where(init[:, None], a["cm_init"], cm[:, 0])
        aux_init = np.where(init[:, None], a["aux_init"], aux[:, 0])
        own = slice(None) if self._own is None else self._own
        return Rollout(
            times=times,
            cm=cm,
            cm_init=cm_init,
            init_reached=init,
            cm_final=self.center_of_mass(),
            positions=a["pos"][own].copy(),
            orientations=a["quat"][own].copy(),
            voxel_offsets=self.voxel_offsets,
            grid_index=self._grid_index[own].copy(),
            dt=a["dt"].copy(),
            steps=a["steps"].copy(),
            time=self.time,
            diverged=a["diverged"].astype(bool),
            diverged_time=a["diverged_time"].copy(),
            mass=a["mass_total"].copy(),
            voxel_size=float(cfg.voxel_size),
            init_time=float(cfg.init_time),
            trace_interval=float(cfg.trace_interval),
            obstacle_mass=self._obstacle_mass.copy(),
            obstacle_cm=self._obstacle_cm.copy(),
            aux=aux,
            aux_init=aux_init,
            aux_final=aux_final,
        )

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Return every robot to its initial state (t = 0, sinusoidal drive)."""
        for k, v in self._initial.items():
            self._put(k, v)
        self._t_target = 0.0
        self._contacts.invalidate()

    def get_state(self) -> dict[str, np.ndarray]:
        """Copy of the full dynamic state (plain arrays, for checkpoints)."""
        state = {k: np.array(self._state_view(k), dtype=_STATE_DTYPE.get(k), copy=True)
                 for k in _STATE}
        state["t_target"] = np.array(self._t_target)
        return state

    def set_state(self, state: dict[str, np.ndarray]) -> None:
        """Restore a state from :meth:`get_state` of an identical batch (copied in)."""
        for k in _STATE:
            if k not in state:
                raise InvalidParameterError(f"state is missing array {k!r}")
            v = np.asarray(state[k])
            cur = self._state_view(k)
            if k in ("trace_t", "trace_cm", "trace_aux"):
                if v.shape[0] != cur.shape[0] or v.shape[2:] != cur.shape[2:]:
                    raise InvalidParameterError(f"state array {k!r} has shape {v.shape}")
            elif v.shape != cur.shape:
                raise InvalidParameterError(
                    f"state array {k!r} has shape {v.shape}, expected {cur.shape}"
                )
        for k in _STATE:
            v = np.asarray(state[k])
            self._put(k, v.T if k in _TRANSPOSED else v)
        self._t_target = float(state.get("t_target", 0.0))
        self._state_changed()

    def _put(self, k: str, v: np.ndarray) -> None:
        # kernel array k becomes a copy of v (cast to its dtype): in place where the
        # shapes agree, which keeps the array's memory layout (the padded rows of
        # link_last, layout._link_rows); else (a trace of another capacity) a new array
        cur = self._a[k]
        if cur.shape == v.shape:
            np.copyto(cur, v, casting="unsafe")
        else:
            self._a[k] = np.array(v, dtype=cur.dtype, order="C", copy=True)

    def _state_view(self, k: str) -> np.ndarray:
        # kernel array k as states show it (a view; see _TRANSPOSED)
        return self._a[k].T if k in _TRANSPOSED else self._a[k]

    def _state_changed(self) -> None:
        # voxels were moved from outside the kernel: re-derive the rotation
        # matrices from the quaternions and rebuild the contact candidates
        _core.refresh_rotations(self._a["quat"], self._a["rot"])
        self._contacts.invalidate()

    def restore_robots(self, state: dict[str, np.ndarray], robots: Any) -> None:
        """Put some robots back into their state from ``state``; the others go on.

        The batch keeps one clock: each restored robot gets the voxel and
        robot state it had in ``state`` (e.g. its settled start) and a step
        count that puts it at the batch's current time; its centre-of-mass
        trace goes on at the batch's sampling times (samples before the
        restore belong to its previous run). Used by vector environments to
        reset one robot.

        Parameters
        ----------
        state : dict of str to ndarray
            From :meth:`get_state` of this batch.
        robots : sequence of int
            Robot indices.
        """
        ids = np.unique(np.asarray(robots, dtype=np.intp))
        if ids.size == 0:
            return
        if ids[0] < 0 or ids[-1] >= self.n_robots:
            raise InvalidIndexError(
                f"robot indices {ids.tolist()} out of range: this batch holds robots "
                f"0..{self.n_robots - 1}"
            )
        missing = [k for k in _STATE if k not in state]
        if missing:
            raise InvalidParameterError(f"state is missing arrays {missing}")
        a = self._a
        off = a["vox_start"]
        for k in _VOXEL_STATE:
            src = np.asarray(state[k])
            if src.shape != a[k].shape:
                raise InvalidParameterError(f"state array {k!r} has shape {src.shape}, expected {a[k].shape}")
            for r in ids:
                s = slice(int(off[r]), int(off[r + 1]))
                a[k][s] = src[s]
        for k in _ROBOT_STATE:
            a[k][ids] = np.asarray(state[k])[ids]
        lo = a["link_start"]
        for k in _LINK_STATE:
            src = np.asarray(state[k])
            dst = self._state_view(k)  # writes go to a[k]
            if src.shape != dst.shape:
                raise InvalidParameterError(f"state array {k!r} has shape {src.shape}, expected {dst.shape}")
            for r in ids:
                s = slice(int(lo[r]), int(lo[r + 1]))
                dst[s] = src[s]
        a["steps"][ids] = np.ceil(self._t_target / a["dt"][ids] - 1e-9).astype(np.int64)
        self._state_changed()
