"""`Simulation`: a batch of voxel robots advanced together by the Cython kernel.

The wrapper validates and lays out the batch as flat structure-of-arrays
(float64, C-contiguous, per-robot offsets), computes every constant of the
lattice model once, and calls :func:`softgym.engine._core.advance`, which runs
the robots in parallel without the GIL.

The physics is the seed's engine (SEED_REFERENCE section 1), re-derived:

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
  (torsion), with the reduced mass ``2 m1 m2 / (m1 + m2)`` (= m for equal
  voxels) so mixed links are symmetric. Damping acts on deformation rates
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

from softgym.engine import _core
from softgym.engine._openmp import openmp_enabled
from softgym.engine.body import Body
from softgym.engine.config import SimConfig
from softgym.engine.rollout import Rollout
from softgym.exceptions import (
    InvalidActionError,
    InvalidDesignError,
    InvalidParameterError,
    InvalidTerrainError,
    SimulationDivergedError,
)

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


def as_body(obj: Any) -> Body:
    """Return ``obj`` as a :class:`Body` (a Body, or anything with ``to_body()``)."""
    if isinstance(obj, Body):
        return obj
    to_body = getattr(obj, "to_body", None)
    if callable(to_body):
        body = to_body()
        if not isinstance(body, Body):
            raise InvalidDesignError(f"{type(obj).__name__}.to_body() did not return a Body")
        return body
    raise InvalidDesignError(
        f"expected a softgym Body or a design with to_body(), got {type(obj).__name__}"
    )


def _hop_neighbours(n: int, v1: np.ndarray, v2: np.ndarray, hops: int):
    """Voxels within ``hops`` bond hops of each voxel (itself excluded), as CSR.

    Returns
    -------
    start : ndarray of shape (n + 1,), int64
    index : ndarray of shape (start[-1],), int64
        Row ``i`` (``index[start[i]:start[i+1]]``) lists, sorted, the voxels
        reachable from ``i`` through at most ``hops`` links.
    """
    src = np.concatenate([v1, v2]).astype(np.int64)
    dst = np.concatenate([v2, v1]).astype(np.int64)
    order = np.argsort(src, kind="stable")
    adj_start = np.concatenate([[0], np.cumsum(np.bincount(src, minlength=n))])
    adj = dst[order]
    reach = np.arange(n, dtype=np.int64) * (n + 1)  # pairs (a, b) encoded a * n + b
    frontier = reach
    for _ in range(hops):
        a, b = np.divmod(frontier, n)
        deg = adj_start[b + 1] - adj_start[b]
        rep_a = np.repeat(a, deg)
        offs = np.repeat(adj_start[b], deg) + (np.arange(deg.sum()) - np.repeat(np.cumsum(deg) - deg, deg))
        new = np.unique(rep_a * n + adj[offs])
        frontier = np.setdiff1d(new, reach, assume_unique=True)
        reach = np.union1d(reach, frontier)
    a, b = np.divmod(reach, n)
    keep = a != b
    a, b = a[keep], b[keep]  # np.union1d sorted: rows by a, then b
    start = np.concatenate([[0], np.cumsum(np.bincount(a, minlength=n))])
    return start, b


#: The seed's obstacle voxels (its material 5, SEED_REFERENCE §2.2): E (Pa), density (kg/m^3).
OBSTACLE_YOUNGS_MODULUS = 5e9
OBSTACLE_DENSITY = 1e6
#: Most lattice cells a terrain may turn into seed-model obstacle voxels.
MAX_OBSTACLE_VOXELS = 200_000
_RANK_W = 1 << 20  # lattice coordinates of the seed order key: (z, y, x) in base 2^20
_RANK_OFF = 1 << 19


def _seed_rank(g: np.ndarray) -> np.ndarray:
    # index of world lattice cells in the seed engine's voxel order (x fastest, then y, then z)
    g = np.asarray(g, dtype=np.int64) + _RANK_OFF
    return ((g[:, 2] * _RANK_W + g[:, 1]) * _RANK_W + g[:, 0]).astype(np.intp)


def obstacle_cells(terrain: Any) -> np.ndarray | None:
    """The lattice cells (n, 3) of a terrain's boxes, or None if a box is off the lattice.

    The seed engine has no boxes: its walls are fixed voxels of its obstacle
    material in the lattice. The seed model turns a terrain whose boxes have
    integer corners (in voxel lengths) into such voxels; other boxes keep the
    penalty contact of the corotational model.
    """
    cells = []
    total = 0.0
    for b in terrain.boxes:
        lo = np.asarray(b.lo, dtype=np.float64)
        hi = np.asarray(b.hi, dtype=np.float64)
        if not (np.all(np.abs(lo - np.rint(lo)) < 1e-9) and np.all(np.abs(hi - np.rint(hi)) < 1e-9)):
            return None
        total += float(np.prod(hi - lo))
        if total > MAX_OBSTACLE_VOXELS:
            return None
        lo = np.rint(lo).astype(np.int64)
        hi = np.rint(hi).astype(np.int64)
        g = np.mgrid[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]].reshape(3, -1).T
        cells.append(g)
    if not cells:
        return np.zeros((0, 3), dtype=np.int64)
    return np.unique(np.concatenate(cells), axis=0)


def obstacle_mass_and_center(terrain: Any, voxel_size: float) -> tuple[float, np.ndarray]:
    """Mass (kg) and centre of mass (m) of a terrain's boxes as the seed's obstacle voxels.

    The seed's centre of mass counts its 44 fixed wall voxels (SEED_REFERENCE
    §1.8); this is what dilutes its obstacle metrics
    (:func:`softgym.metrics.dilute`).
    """
    boxes = terrain.as_array(voxel_size)
    if len(boxes) == 0:
        return 0.0, np.zeros(3)
    vol = np.prod(boxes[:, 3:] - boxes[:, :3], axis=1)
    mass = OBSTACLE_DENSITY * vol
    centres = 0.5 * (boxes[:, :3] + boxes[:, 3:])
    return float(mass.sum()), (mass[:, None] * centres).sum(axis=0) / mass.sum()



def _time_step(k_axial, m, E, v1, v2, cfg: SimConfig) -> float:
    # the seed's CalcMaxDt over a robot's links: dt_frac / (2 pi sqrt(max k_axial / m))
    L = float(cfg.voxel_size)
    if v1.size:
        w2 = float(np.max(np.maximum(k_axial / m[v1], k_axial / m[v2])))
    else:
        # no link: the seed's CalcMaxDt falls back to max E / M (its units)
        w2 = float(np.max(E / m)) if cfg.model == "seed" else float(np.max(E * L / m))
    if cfg.model == "seed":
        # the seed's CalcMaxDt writes pi as 3.1415926 and its DtFrac is single precision
        return float(np.float32(cfg.dt_frac)) / (2.0 * 3.1415926 * math.sqrt(w2))
    return cfg.dt_frac / (2.0 * math.pi * math.sqrt(w2))


def time_step(body: Any, config: SimConfig | None = None) -> float:
    """The time step (s) the engine takes for a robot (a Body or a design).

    ``dt_frac / (2 pi sqrt(max k_axial / m))`` over its face links, k_axial the
    harmonic mean of the two voxels' E times L (the seed's CalcMaxDt): a link
    between stiff or light voxels shortens it, and so raises the cost of a
    simulated second (:func:`voxel_steps_per_second`).
    """
    cfg = SimConfig() if config is None else config
    body = as_body(body)
    L = float(cfg.voxel_size)
    grid = body.grid
    idx = np.argwhere(grid > 0)
    vmap = np.full(grid.shape, -1, dtype=np.int64)
    vmap[tuple(idx.T)] = np.arange(idx.shape[0])
    mat = grid[tuple(idx.T)]
    E = body.youngs_modulus[mat]
    m = body.density[mat] * L**3
    v1s, v2s = [], []
    for ax in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax] = slice(0, -1)
        hi[ax] = slice(1, None)
        a, b = vmap[tuple(lo)], vmap[tuple(hi)]
        ok = (a >= 0) & (b >= 0)
        v1s.append(a[ok])
        v2s.append(b[ok])
    v1, v2 = np.concatenate(v1s), np.concatenate(v2s)
    if body.fixed is not None:
        fixed = body.fixed[tuple(idx.T)] != 0
        keep = ~(fixed[v1] & fixed[v2])
        v1, v2 = v1[keep], v2[keep]
    k_axial = _harmonic(E[v1], E[v2]) * L
    return _time_step(k_axial, m, E, v1, v2, cfg)


def voxel_steps_per_second(body: Any, config: SimConfig | None = None) -> float:
    """Voxel-steps per simulated second of a robot: its cost (n_voxels / dt)."""
    body = as_body(body)
    return float(np.count_nonzero(body.grid)) / time_step(body, config)


def _component(body: Body | None, block: Any, L: float) -> dict[str, Any]:
    """One component of a simulation entry (the robot's body, or a movable block).

    Its voxels in C order of its grid: lattice index, material id and
    properties, fixed flags, origin (m), exposed-face bits (``faces`` of
    ``_core.pxd``), and its face links along each axis as local voxel pairs.
    """
    if body is not None:
        grid = body.grid
        idx = np.argwhere(grid > 0)
        mat = grid[tuple(idx.T)]
        out = {
            "idx": idx, "mat": mat, "E": body.youngs_modulus[mat], "rho": body.density[mat],
            "nu": body.poisson[mat], "mu_s": body.mu_static[mat], "mu_k": body.mu_kinetic[mat],
            "origin": np.asarray(body.origin, dtype=np.float64),
            "fixed": (np.zeros(idx.shape[0], dtype=np.int8) if body.fixed is None
                      else body.fixed[tuple(idx.T)].astype(np.int8)),
        }  # fmt: skip
    else:
        grid = block.cells.astype(np.int8)
        idx = np.argwhere(grid > 0)
        k = idx.shape[0]
        out = {
            "idx": idx, "mat": np.full(k, -1, dtype=np.int64),
            "E": np.full(k, block.youngs_modulus), "rho": np.full(k, block.density),
            "nu": np.full(k, block.poisson), "mu_s": np.full(k, block.mu_static),
            "mu_k": np.full(k, block.mu_kinetic), "fixed": np.zeros(k, dtype=np.int8),
            "origin": np.asarray(block.origin, dtype=np.float64) * L,
        }  # fmt: skip
    n = idx.shape[0]
    vmap = np.full(grid.shape, -1, dtype=np.int64)
    vmap[tuple(idx.T)] = np.arange(n)
    v1s, v2s = [], []
    faces = np.zeros(n, dtype=np.int64)
    for ax in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax] = slice(0, -1)
        hi[ax] = slice(1, None)
        a = vmap[tuple(lo)]
        b = vmap[tuple(hi)]
        ok = (a >= 0) & (b >= 0)
        v1s.append(a[ok])
        v2s.append(b[ok])
        # faces of voxels without a neighbour on that side are exposed
        plus = np.ones(n, dtype=bool)
        plus[a[ok]] = False
        minus = np.ones(n, dtype=bool)
        minus[b[ok]] = False
        faces |= (minus.astype(np.int64) << (2 * ax)) | (plus.astype(np.int64) << (2 * ax + 1))
    out.update(v1=v1s, v2=v2s, faces=faces.astype(np.int8))
    return out


def _harmonic(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    s = a + b
    out = np.zeros_like(s)
    nz = s > 0
    out[nz] = 2.0 * a[nz] * b[nz] / s[nz]
    return out


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
        self.n_threads = default_num_threads() if n_threads is None else int(n_threads)
        if self.n_threads < 1:
            raise InvalidParameterError(f"n_threads must be >= 1, got {n_threads}")
        self.terrains = self._terrains(terrain)
        if not self.config.self_collision and any(t.objects for t in self.terrains):
            raise InvalidParameterError(
                "a terrain's movable objects touch the robot through self-collision: "
                "SimConfig.self_collision must be True"
            )
        self._build()
        self._initial = {k: self._a[k].copy() for k in _STATE}
        self._contacts = _core.ContactCache(self.n_robots)
        self._t_target = 0.0

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
            t.validate(lo, hi)
        return terrains

    def _build(self) -> None:
        cfg = self.config
        L = float(cfg.voxel_size)
        n_robots = len(self.bodies)
        per_vox: dict[str, list[np.ndarray]] = {}
        per_link: dict[str, list[np.ndarray]] = {}
        vox_start = [0]
        link_start = [0]
        dts, masses, axis_counts, excl, body_end = [], [], [], [], []
        grid_index = []

        def add(store, name, value):
            store.setdefault(name, []).append(np.asarray(value))

        for body, terrain in zip(self.bodies, self.terrains):
            # the entry: the robot's voxels, then its terrain's movable blocks, each
            # a component with its own links (none between components)
            parts = [_component(body, None, L)]
            parts += [_component(None, blk, L) for blk in terrain.objects]
            idx = np.concatenate([p["idx"] for p in parts])
            n = idx.shape[0]
            n_own = parts[0]["idx"].shape[0]
            E = np.concatenate([p["E"] for p in parts])
            rho = np.concatenate([p["rho"] for p in parts])
            nu = np.concatenate([p["nu"] for p in parts])
            mat = np.concatenate([p["mat"] for p in parts])
            m = rho * L**3
            inertia = m * L**2 / 6.0
            fixed = np.concatenate([p["fixed"] for p in parts])
            # links along +x, +y, +z between filled face neighbours of each component
            v1s, v2s, axes = [], [], []
            off = 0
            for p in parts:
                v1s += [a + off for a in p["v1"]]
                v2s += [b + off for b in p["v2"]]
                axes += [np.full(a.size, ax, dtype=np.int32) for ax, a in enumerate(p["v1"])]
                off += p["idx"].shape[0]
            v1 = np.concatenate(v1s)
            v2 = np.concatenate(v2s)
            axis = np.concatenate(axes)
            if len(parts) > 1:  # links stay sorted by axis, each component's in order
                order = np.argsort(axis, kind="stable")
                v1, v2, axis = v1[order], v2[order], axis[order]
            keep = ~((fixed[v1] == 1) & (fixed[v2] == 1))
            v1, v2, axis = v1[keep], v2[keep], axis[keep]
            axis_counts.append(np.bincount(axis, minlength=3))  # links stay sorted by axis
            Eh = _harmonic(E[v1], E[v2])
            nuh = _harmonic(nu[v1], nu[v2])
            mr = _harmonic(m[v1], m[v2])
            Ir = _harmonic(inertia[v1], inertia[v2])
            k_axial = Eh * L
            k_torsion = Eh * L**3 / (12.0 * (1.0 + nuh))
            k_bend = Eh * L**3 / 6.0
            zb = cfg.bond_damping
            add(per_link, "v1", v1 + vox_start[-1])
            add(per_link, "v2", v2 + vox_start[-1])
            add(per_link, "axis", axis)
            add(per_link, "k_axial", k_axial)
            add(per_link, "k_torsion", k_torsion)
            add(per_link, "k_bend", k_bend)
            add(per_link, "c_axial", zb * np.sqrt(k_axial * mr))
            add(per_link, "c_bend", 0.5 * zb * np.sqrt(k_bend * Ir))
            add(per_link, "c_torsion", 0.5 * zb * np.sqrt(k_torsion * Ir))
            # the seed model's damping constants 2 sqrt(k m) for each end:
            # (a1 M, b2 FM, a2 I, b3 I), b2 = E L^2 / 2, FM = M L / 2
            b2 = 0.5 * k_axial * L
            ends = []
            for v in (v1, v2):
                ends += [2.0 * np.sqrt(k_axial * m[v]), 2.0 * np.sqrt(b2 * 0.5 * m[v] * L),
                         2.0 * np.sqrt(k_torsion * inertia[v]), 2.0 * np.sqrt(k_bend * inertia[v])]
            add(per_link, "c_seed", np.stack(ends, axis=1).reshape(-1, 8))
            add(per_link, "homog", (mat[v1] == mat[v2]).astype(np.int8))
            dt = _time_step(k_axial, m, E, v1, v2, cfg)
            dts.append(dt)
            masses.append(float(m[:n_own].sum()))
            body_end.append(vox_start[-1] + n_own)
            crit = 2.0 * np.sqrt(m * E * L)
            origin = np.concatenate([np.broadcast_to(p["origin"], p["idx"].shape) for p in parts])
            if cfg.model == "seed":
                # the seed's lattice positions carry its 1e-6 L offset in x and y
                # (VX_Object::GetXYZ), which decides exact-zero tests downstream
                pos = origin + L * ((idx + 0.5) + np.array([1e-6, 1e-6, 0.0]))
            else:
                pos = origin + (idx + 0.5) * L
            add(per_vox, "pos", pos)
            faces = np.concatenate([p["faces"] for p in parts])
            add(per_vox, "faces", faces)
            add(per_vox, "mass", m)
            add(per_vox, "inv_mass", 1.0 / m)
            add(per_vox, "inv_inertia", 1.0 / inertia)
            cte = np.zeros(n)
            cte[:n_own] = body.cte[mat[:n_own]]
            phase = np.zeros(n)
            phase[:n_own] = body.phase[mat[:n_own]]
            add(per_vox, "cte", cte)
            add(per_vox, "cos_phase", np.cos(phase))
            add(per_vox, "sin_phase", np.sin(phase))
            add(per_vox, "k_floor", 2.0 * E * L)
            add(per_vox, "c_floor", cfg.collision_damping * crit)
            add(per_vox, "c_global", cfg.global_damping * crit)
            rot_damp = 1.0 - 10.0 * cfg.global_damping * 2.0 * np.sqrt(inertia * E * L**3) / inertia * dt
            add(per_vox, "rot_damp", np.clip(rot_damp, 0.0, 1.0))
            mu_s = np.concatenate([p["mu_s"] for p in parts])
            mu_k = np.concatenate([p["mu_k"] for p in parts])
            if cfg.friction != 1.0:
                mu_s = mu_s * float(cfg.friction)
                mu_k = mu_k * float(cfg.friction)
            add(per_vox, "mu_s", mu_s)
            add(per_vox, "mu_k", mu_k)
            if cfg.incline != 0.0:  # the slope's pull along -x, per voxel
                ext = np.zeros((n, 3))
                ext[:, 0] = -m * float(cfg.gravity) * math.sin(math.radians(cfg.incline))
            else:
                ext = np.zeros((n, 3))
            add(per_vox, "ext_force", ext)
            add(per_vox, "fixed", fixed)
            grid_index.append(idx)
            degree = np.bincount(np.concatenate([v1, v2]), minlength=n)
            add(per_vox, "surface", (degree < 6).astype(np.int8))
            # the seed engine's voxel order (x fastest, then y, then z) over
            # the world lattice: it decides which voxel of a pair sets the
            # seed's candidate horizon
            lattice = np.concatenate(
                [np.broadcast_to(np.rint(p["origin"] / L).astype(np.int64), p["idx"].shape) for p in parts]
            )
            add(per_vox, "seed_rank", _seed_rank(lattice + idx))
            ex_start, ex_idx = _hop_neighbours(n, v1, v2, cfg.collision_exclusion)
            add(per_vox, "excl_count", np.diff(ex_start))
            excl.append(ex_idx + vox_start[-1])
            vox_start.append(vox_start[-1] + n)
            link_start.append(link_start[-1] + v1.size)

        n_vox = vox_start[-1]
        a: dict[str, np.ndarray] = {}
        for name, parts in per_vox.items():
            a[name] = np.ascontiguousarray(np.concatenate(parts))
        a["fixed"] = a["fixed"].astype(np.int8)
        a["surface"] = a["surface"].astype(np.int8)
        a["excl_start"] = np.concatenate([[0], np.cumsum(a.pop("excl_count"))]).astype(np.intp)
        a["excl_idx"] = np.ascontiguousarray(np.concatenate(excl), dtype=np.intp)
        # the seed model: lattice boxes become the seed's fixed obstacle voxels
        # (contact through its self-collision law), other boxes keep the penalty contact
        boxes, obs, obs_rank, obs_start = [], [], [], [0]
        k_obs = 2.0 * OBSTACLE_YOUNGS_MODULUS * L
        for t in self.terrains:
            cells = obstacle_cells(t) if cfg.model == "seed" and t.box_contact == "auto" else None
            if cells is None:
                boxes.append(t.as_array(L))
                cells = np.zeros((0, 3), dtype=np.int64)
            else:
                boxes.append(np.zeros((0, 6)))
            centre = L * ((cells + 0.5) + np.array([1e-6, 1e-6, 0.0]))
            obs.append(np.column_stack([centre, np.full(len(cells), k_obs)]))
            obs_rank.append(_seed_rank(cells))
            obs_start.append(obs_start[-1] + len(cells))
        a["obs_start"] = np.asarray(obs_start, dtype=np.intp)
        a["obs"] = np.ascontiguousarray(np.concatenate(obs), dtype=np.float64).reshape(-1, 4)
        a["obs_rank"] = np.ascontiguousarray(np.concatenate(obs_rank), dtype=np.intp)
        a["box_start"] = np.concatenate([[0], np.cumsum([len(b) for b in boxes])]).astype(np.intp)
        a["boxes"] = np.ascontiguousarray(np.concatenate(boxes), dtype=np.float64).reshape(-1, 6)
        a["floor"] = np.array([int(t.floor and cfg.floor) for t in self.terrains], dtype=np.int8)
        for name, parts in per_link.items():
            a[name] = np.ascontiguousarray(np.concatenate(parts))
        for name in ("v1", "v2"):
            a[name] = a[name].astype(np.intp)
        # (8, n_links): one row per constant, for the kernel's vector loops
        a["c_seed"] = np.ascontiguousarray(np.asarray(a["c_seed"], dtype=np.float64).reshape(-1, 8).T)
        a["homog"] = a["homog"].astype(np.int8)
        a["link_sa"] = np.ones(a["v1"].shape[0], dtype=np.int8)  # links start in small-angle mode
        a["link_last"] = np.zeros((9, a["v1"].shape[0]))  # see _TRANSPOSED
        a["axis"] = a["axis"].astype(np.int32)
        a["quat"] = np.zeros((n_vox, 4))
        a["quat"][:, 0] = 1.0
        a["rot"] = np.zeros((n_vox, 9))
        a["rot"][:, [0, 4, 8]] = 1.0
        for name in ("vel", "angvel", "force", "moment"):
            a[name] = np.zeros((n_vox, 3))
        a["ext_force"] = np.ascontiguousarray(a["ext_force"], dtype=np.float64).reshape(-1, 3)
        a["faces"] = a["faces"].astype(np.int8)
        a["body_end"] = np.asarray(body_end, dtype=np.intp)
        a["aux_init"] = np.zeros((n_robots, len(_core.AUX_NAMES)))
        a["trace_aux"] = np.zeros((n_robots, 8, len(_core.AUX_NAMES)))
        a["scale"] = np.full(n_vox, L)
        a["seed_rank"] = a["seed_rank"].astype(np.intp)
        a["col_ref"] = np.zeros((n_vox, 4))
        a["col_acc"] = np.full(n_robots, np.inf)  # first step builds the candidates
        a["col_vmax"] = np.zeros(n_robots)
        a["temp"] = np.zeros(n_vox)
        a["vox_start"] = np.asarray(vox_start, dtype=np.intp)
        a["link_start"] = np.asarray(link_start, dtype=np.intp)
        a["link_axis_count"] = np.ascontiguousarray(np.asarray(axis_counts), dtype=np.intp)
        a["dt"] = np.asarray(dts, dtype=np.float64)
        a["steps"] = np.zeros(n_robots, dtype=np.int64)
        a["temp_amp"] = np.array([b.temp_amplitude for b in self.bodies], dtype=np.float64)
        a["period"] = np.array([b.period for b in self.bodies], dtype=np.float64)
        a["use_temp"] = np.zeros(n_robots, dtype=np.int8)
        a["diverged"] = np.zeros(n_robots, dtype=np.int8)
        a["diverged_time"] = np.full(n_robots, np.inf)
        a["diverged_code"] = np.zeros(n_robots, dtype=np.int32)
        a["init_done"] = np.zeros(n_robots, dtype=np.int8)
        a["cm_init"] = np.zeros((n_robots, 3))
        a["mass_total"] = np.asarray(masses, dtype=np.float64)
        a["trace_n"] = np.zeros(n_robots, dtype=np.intp)
        a["trace_t"] = np.zeros((n_robots, 8))
        a["trace_cm"] = np.zeros((n_robots, 8, 3))
        walls = [obstacle_mass_and_center(t, L) for t in self.terrains]
        self._obstacle_mass = np.array([m for m, _ in walls], dtype=np.float64)
        self._obstacle_cm = np.array([c for _, c in walls], dtype=np.float64).reshape(-1, 3)
        missing = [k for k in _core.KERNEL_ARRAYS if k not in a]
        if missing:  # the kernel's declared contract (_core.KERNEL_ARRAYS)
            raise RuntimeError(f"softgym engine: arrays {missing} missing for the kernel")
        self._a = a
        self._grid_index = np.ascontiguousarray(np.concatenate(grid_index)).astype(np.int64)
        self._settings = {
            "n_robots": n_robots,
            "L": L,
            "gravity": -float(cfg.gravity) * (math.cos(math.radians(cfg.incline)) if cfg.incline else 1.0),
            "init_time": float(cfg.init_time),
            "min_scale": float(cfg.min_scale),
            "max_strain": float(cfg.max_strain),
            "trace_interval": float(cfg.trace_interval),
            "self_collision": int(bool(cfg.self_collision)),
            "actuation_mode": 0 if cfg.actuation == "seed" else 1,
            "model": 0 if cfg.model == "seed" else 1,
            "bond_zeta": float(cfg.bond_damping),
            "fluid_drag": float(cfg.fluid_drag),
        }
        # robots' own voxels in the kernel arrays (None: no objects, all of them)
        own = [np.arange(vox_start[r], body_end[r]) for r in range(n_robots)]
        self._own = None if body_end == vox_start[1:] else np.concatenate(own).astype(np.intp)
        counts = np.asarray(body_end) - np.asarray(vox_start[:-1])
        self._own_offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)

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

    def _slice(self, robot: int) -> slice:
        # the robot's own voxels in the kernel arrays (its objects follow them)
        if not 0 <= robot < self.n_robots:
            raise IndexError(f"robot index {robot} out of range for {self.n_robots} robots")
        return slice(int(self._a["vox_start"][robot]), int(self._a["body_end"][robot]))

    def _object_slice(self, robot: int) -> slice:
        if not 0 <= robot < self.n_robots:
            raise IndexError(f"robot index {robot} out of range for {self.n_robots} robots")
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
        a = self._a
        p = a["mass"][:, None] * a["vel"]
        if objects:
            return np.add.reduceat(p, a["vox_start"][:-1], axis=0)
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

    def set_external_force(self, robot: int, force: Any) -> None:
        """Apply a constant external force (N) to each voxel of one robot.

        Parameters
        ----------
        robot : int
            Robot index.
        force : array_like of shape (3,), (n_voxels_r, 3) or (*grid_shape, 3)
            A shape (3,) force is applied to every voxel.
        """
        s = self._slice(robot)
        arr = np.asarray(force, dtype=np.float64)
        if arr.shape == (3,):
            arr = np.broadcast_to(arr, (s.stop - s.start, 3))
        arr = self._per_voxel(robot, arr, "external force", 3)
        self._a["ext_force"][s] = arr

    # -------------------------------------------------------------------- run
    def _ensure_trace_capacity(self, t_end: float) -> None:
        need = int(math.floor(t_end / self.config.trace_interval + 1e-9)) + 3
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

    def advance_to(self, time: float, progress: Any = None) -> None:
        """Advance every robot until its clock reaches ``time`` (s).

        The kernel runs in chunks of simulated time of about
        :attr:`chunk_voxel_steps` voxel-steps per thread each; between two
        chunks Python runs its signal handlers, so Ctrl-C raises
        ``KeyboardInterrupt`` within a fraction of a second, leaving the batch
        at the end of the last chunk (a later call goes on from there).
        There is no Python work per step: the result is bit-identical to one
        kernel call.

        Parameters
        ----------
        time : float
            Target time (s), not before the current one.
        progress : callable, optional
            ``progress(t)`` after each chunk, with the simulated time (s) reached.
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
        self._ensure_trace_capacity(time + dt.max())
        a = self._a
        before = a["diverged"].copy()
        # simulated seconds per chunk = work per chunk / voxel-steps per simulated second
        rate = float(np.sum(np.diff(a["vox_start"]) / dt))
        threads = min(self.n_threads, self.n_robots)
        chunk = max(1, int(self.chunk_voxel_steps)) * threads / max(rate, 1e-300)
        t = self._t_target
        while True:
            t = min(time, t + chunk)
            if t >= time:
                targets = final
            else:
                targets = np.minimum(np.maximum(np.ceil(t / dt - 1e-9).astype(np.int64), a["steps"]), final)
            _core.advance(a, self._settings, targets, threads, self._contacts)
            # back in Python: a pending SIGINT raises KeyboardInterrupt here
            self._t_target = t
            if progress is not None:
                progress(t)
            if t >= time:
                break
        if self.config.on_divergence == "raise":
            new = np.flatnonzero((a["diverged"] == 1) & (before == 0))
            if new.size:
                r = int(new[0])
                raise SimulationDivergedError(
                    r, float(a["diverged_time"][r]), _core.STATUS_NAMES.get(int(a["diverged_code"][r]), "diverged")
                )

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
            self._a[k] = v.copy()
        self._t_target = 0.0
        self._contacts.invalidate()

    def get_state(self) -> dict[str, np.ndarray]:
        """Copy of the full dynamic state (plain arrays, for checkpoints)."""
        state = {k: self._state_view(k).copy() for k in _STATE}
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
            v = v.T if k in _TRANSPOSED else v
            self._a[k] = np.array(v, dtype=self._a[k].dtype, order="C", copy=True)
        self._t_target = float(state.get("t_target", 0.0))
        self._state_changed()

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
            raise IndexError(f"robot indices {ids.tolist()} out of range for {self.n_robots} robots")
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
