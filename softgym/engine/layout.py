"""The layout of a batch: bodies, terrains and settings -> the kernel's flat arrays.

:func:`build_layout` is pure: it reads the robots (:class:`Body`), their
terrains and a :class:`SimConfig`, computes every constant of the lattice
model once (links, stiffness and damping constants, time steps, contact
constants, exclusion lists, the seed model's obstacle voxels) and returns a
:class:`Layout`: the structure-of-arrays state the kernel walks (float64,
C-contiguous, per-robot offsets; names, shapes and units in ``_batch.pxd``'s
``Batch``) and the scalar settings. :class:`~softgym.engine.Simulation` is the
runtime around it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from softgym.engine import _bind, _core, contract
from softgym.engine.body import Body
from softgym.engine.config import SimConfig
from softgym.exceptions import InvalidDesignError, InvalidParameterError

__all__ = [
    "MAX_OBSTACLE_VOXELS",
    "OBSTACLE_DENSITY",
    "OBSTACLE_YOUNGS_MODULUS",
    "Layout",
    "as_body",
    "build_layout",
    "memory_estimate",
    "obstacle_cells",
    "obstacle_mass_and_center",
    "time_step",
    "voxel_steps_per_second",
]


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


def _lattice_ball(hops: int) -> int:
    """Lattice cells within ``hops`` face steps of a cell, itself included (63 for 3)."""
    return sum(
        2 * (hops - abs(i) - abs(j)) + 1
        for i in range(-hops, hops + 1) for j in range(-hops, hops + 1) if abs(i) + abs(j) <= hops
    )


def _hop_chunk(hops: int) -> int:
    # rows of _hop_neighbours per chunk: ~64k (row, voxel) pairs of a lattice body
    # reached, so its temporaries stay near 10 MB whatever the body's size
    return max(16, 65536 // _lattice_ball(hops))


def _unique_sorted(x: np.ndarray) -> np.ndarray:
    # np.unique(x), by a sort and a mask (np.unique's hash table was 6x slower here)
    x = np.sort(x)
    if x.size > 1:
        keep = np.empty(x.size, dtype=bool)
        keep[0] = True
        np.not_equal(x[1:], x[:-1], out=keep[1:])
        x = x[keep]
    return x


def _hop_neighbours(n: int, v1: np.ndarray, v2: np.ndarray, hops: int):
    """Voxels within ``hops`` bond hops of each voxel (itself excluded), as CSR.

    Returns
    -------
    start : ndarray of shape (n + 1,), int64
    index : ndarray of shape (start[-1],), int64
        Row ``i`` (``index[start[i]:start[i+1]]``) lists, sorted, the voxels
        reachable from ``i`` through at most ``hops`` links.

    A breadth-first search from every voxel at once, in chunks of rows
    (:func:`_hop_chunk`): linear in voxels, and its temporaries stay small (one
    search over every row sorted pairs of all rows, 20 s for 125k voxels).
    """
    src = np.concatenate([v1, v2]).astype(np.int64)
    dst = np.concatenate([v2, v1]).astype(np.int64)
    order = np.argsort(src, kind="stable")
    adj_start = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=n), out=adj_start[1:])
    adj = dst[order]
    del src, dst, order
    counts = np.zeros(n, dtype=np.int64)
    rows_of: list[np.ndarray] = []
    chunk = _hop_chunk(hops)
    for r0 in range(0, n, chunk):
        r1 = min(n, r0 + chunk)
        # pairs (a, b), a a row of the chunk, encoded (a - r0) * n + b, kept sorted
        reach = np.arange(r1 - r0, dtype=np.int64) * n + np.arange(r0, r1, dtype=np.int64)
        frontier = reach
        for _ in range(hops):
            a, b = np.divmod(frontier, n)
            lo = adj_start[b]
            deg = adj_start[b + 1] - lo
            total = int(deg.sum())
            if total == 0:
                break
            # the neighbours of every frontier voxel: adj[lo[k]:lo[k] + deg[k]]
            offs = np.arange(total, dtype=np.int64) + np.repeat(lo - (np.cumsum(deg) - deg), deg)
            new = _unique_sorted(np.repeat(a * n, deg) + adj[offs])
            pos = np.searchsorted(reach, new)
            fresh = reach[np.minimum(pos, reach.size - 1)] != new
            frontier = new[fresh]
            reach = np.insert(reach, pos[fresh], frontier)  # stays sorted: rows by a, then b
        a, b = np.divmod(reach, n)
        keep = a + r0 != b
        counts[r0:r1] = np.bincount(a[keep], minlength=r1 - r0)
        rows_of.append(b[keep])
    start = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=start[1:])
    index = np.concatenate(rows_of) if rows_of else np.zeros(0, dtype=np.int64)
    return start, index


#: The seed's obstacle voxels (its material 5, docs/PHYSICS.md): E (Pa), density (kg/m^3).
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

    The seed's centre of mass counts its 44 fixed wall voxels (docs/PHYSICS.md); this
    is what dilutes its obstacle metrics (:func:`softgym.metrics.dilute`).
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
        dt = float(np.float32(cfg.dt_frac)) / (2.0 * 3.1415926 * math.sqrt(w2))
    else:
        dt = cfg.dt_frac / (2.0 * math.pi * math.sqrt(w2))
    if not (math.isfinite(dt) and dt > 0.0):
        # the materials' and voxel size's ranges keep it a normal number; a step of 0
        # would never advance, an infinite one never stop
        raise InvalidParameterError(
            f"the time step came out as {dt!r} s (max k_axial / m = {w2:g} 1/s^2): check "
            f"the materials' Young's modulus and density and SimConfig.voxel_size"
        )
    return dt


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
    ``_batch.pxd``), and its face links along each axis as local voxel pairs.
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


@dataclass
class Layout:
    """A batch laid out for the kernel (see :func:`build_layout`).

    Attributes
    ----------
    arrays : dict of str to ndarray
        Every array of ``contract.KERNEL_ARRAYS`` (and the state the runtime
        checkpoints), robot after robot: robot ``r`` owns voxels
        ``vox_start[r]:vox_start[r + 1]`` and links
        ``link_start[r]:link_start[r + 1]``.
    settings : dict
        The batch's scalars for the kernel (``L``, ``gravity``, ``model``...).
    grid_index : ndarray of shape (n_voxels, 3), int64
        Each voxel's index in its component's grid.
    own : ndarray of intp or None
        The robots' own voxels (terrain objects excluded); None when there
        are no objects (every voxel is a robot's).
    own_offsets : ndarray of shape (n_robots + 1,), int64
        Offsets of each robot's own voxels in ``own`` order.
    obstacle_mass, obstacle_cm : ndarray
        (n_robots,) mass (kg) and (n_robots, 3) centre (m) of each terrain's
        boxes as the seed's obstacle voxels.
    """

    arrays: dict[str, np.ndarray]
    settings: dict[str, Any]
    grid_index: np.ndarray
    own: np.ndarray | None
    own_offsets: np.ndarray
    obstacle_mass: np.ndarray
    obstacle_cm: np.ndarray


def _robot_entry(body: Body, terrain: Any, cfg: SimConfig) -> dict[str, Any]:
    """One robot's entry of the batch: its voxels, then its terrain's movable blocks.

    Each part is a component with its own links (none between components).
    Returns its per-voxel arrays (``vox``) and per-link arrays (``link``;
    voxel indices local to the entry), its counts, time step, mass, grid
    indices and exclusion lists (CSR columns, local).
    """
    L = float(cfg.voxel_size)
    vox: dict[str, np.ndarray] = {}
    link: dict[str, np.ndarray] = {}
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
    Eh = _harmonic(E[v1], E[v2])
    nuh = _harmonic(nu[v1], nu[v2])
    mr = _harmonic(m[v1], m[v2])
    Ir = _harmonic(inertia[v1], inertia[v2])
    k_axial = Eh * L
    k_torsion = Eh * L**3 / (12.0 * (1.0 + nuh))
    k_bend = Eh * L**3 / 6.0
    zb = cfg.bond_damping
    link["v1"] = v1  # local: build_layout adds the entry's first voxel
    link["v2"] = v2
    link["axis"] = axis
    link["k_axial"] = k_axial
    link["k_torsion"] = k_torsion
    link["k_bend"] = k_bend
    link["c_axial"] = zb * np.sqrt(k_axial * mr)
    link["c_bend"] = 0.5 * zb * np.sqrt(k_bend * Ir)
    link["c_torsion"] = 0.5 * zb * np.sqrt(k_torsion * Ir)
    # the seed model's damping constants 2 sqrt(k m) for each end:
    # (a1 M, b2 FM, a2 I, b3 I), b2 = E L^2 / 2, FM = M L / 2
    b2 = 0.5 * k_axial * L
    ends = []
    for v in (v1, v2):
        ends += [2.0 * np.sqrt(k_axial * m[v]), 2.0 * np.sqrt(b2 * 0.5 * m[v] * L),
                 2.0 * np.sqrt(k_torsion * inertia[v]), 2.0 * np.sqrt(k_bend * inertia[v])]
    link["c_seed"] = np.stack(ends, axis=1).reshape(-1, 8)
    # voxel 2 takes exactly -F1 (the scatter subtracts voxel 1's turned force)
    # where the seed's formulas make it so: one material, or two whose ends
    # have the same damping constants a M and b2 FM (equal masses: muscles of
    # one tissue that differ only in CTE). There the seed's own f2 = -f1 + bz
    # (-a v ...) is exactly minus voxel 1's damped force in IEEE arithmetic;
    # a build that fuses multiply-adds may fuse the two forms differently
    # (single-precision links did: 1e-8 relative momentum drift)
    ends = link["c_seed"]
    link["homog"] = ((mat[v1] == mat[v2])
                     | ((ends[:, 0] == ends[:, 4]) & (ends[:, 1] == ends[:, 5]))).astype(np.int8)
    dt = _time_step(k_axial, m, E, v1, v2, cfg)
    crit = 2.0 * np.sqrt(m * E * L)
    origin = np.concatenate([np.broadcast_to(p["origin"], p["idx"].shape) for p in parts])
    if cfg.model == "seed":
        # the seed's lattice positions carry its 1e-6 L offset in x and y
        # (VX_Object::GetXYZ), which decides exact-zero tests downstream
        pos = origin + L * ((idx + 0.5) + np.array([1e-6, 1e-6, 0.0]))
    else:
        pos = origin + (idx + 0.5) * L
    vox["pos"] = pos
    faces = np.concatenate([p["faces"] for p in parts])
    vox["faces"] = faces
    vox["mass"] = m
    vox["inv_mass"] = 1.0 / m
    vox["inv_inertia"] = 1.0 / inertia
    cte = np.zeros(n)
    cte[:n_own] = body.cte[mat[:n_own]]
    phase = np.zeros(n)
    phase[:n_own] = body.phase[mat[:n_own]]
    vox["cte"] = cte
    vox["cos_phase"] = np.cos(phase)
    vox["sin_phase"] = np.sin(phase)
    vox["k_floor"] = 2.0 * E * L
    vox["c_floor"] = cfg.collision_damping * crit
    vox["c_global"] = cfg.global_damping * crit
    rot_damp = 1.0 - 10.0 * cfg.global_damping * 2.0 * np.sqrt(inertia * E * L**3) / inertia * dt
    vox["rot_damp"] = np.clip(rot_damp, 0.0, 1.0)
    mu_s = np.concatenate([p["mu_s"] for p in parts])
    mu_k = np.concatenate([p["mu_k"] for p in parts])
    if cfg.friction != 1.0:
        mu_s = mu_s * float(cfg.friction)
        mu_k = mu_k * float(cfg.friction)
    vox["mu_s"] = mu_s
    vox["mu_k"] = mu_k
    if cfg.incline != 0.0:  # the slope's pull along -x, per voxel
        ext = np.zeros((n, 3))
        ext[:, 0] = -m * float(cfg.gravity) * math.sin(math.radians(cfg.incline))
    else:
        ext = np.zeros((n, 3))
    vox["ext_force"] = ext
    vox["fixed"] = fixed
    degree = np.bincount(np.concatenate([v1, v2]), minlength=n)
    vox["surface"] = (degree < 6).astype(np.int8)
    # the seed engine's voxel order (x fastest, then y, then z) over
    # the world lattice: it decides which voxel of a pair sets the
    # seed's candidate horizon
    lattice = np.concatenate(
        [np.broadcast_to(np.rint(p["origin"] / L).astype(np.int64), p["idx"].shape) for p in parts]
    )
    vox["seed_rank"] = _seed_rank(lattice + idx)
    ex_start, ex_idx = _hop_neighbours(n, v1, v2, cfg.collision_exclusion)
    vox["excl_count"] = np.diff(ex_start)
    return {
        "vox": vox,
        "link": link,
        "n": n,
        "n_own": n_own,
        "n_links": v1.size,
        "axis_count": np.bincount(axis, minlength=3),  # links stay sorted by axis
        "dt": dt,
        "mass": float(m[:n_own].sum()),
        "grid_index": idx,
        "excl_idx": ex_idx,  # local, as v1 and v2
    }


def _terrain_arrays(terrains: list, cfg: SimConfig) -> dict[str, np.ndarray]:
    """The terrains' boxes, obstacle voxels and floors, robot after robot.

    The seed model: lattice boxes become the seed's fixed obstacle voxels
    (contact through its self-collision law), other boxes keep the penalty
    contact.
    """
    L = float(cfg.voxel_size)
    a: dict[str, np.ndarray] = {}
    boxes, obs, obs_rank, obs_start = [], [], [], [0]
    k_obs = 2.0 * OBSTACLE_YOUNGS_MODULUS * L
    for t in terrains:
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
    a["floor"] = np.array([int(t.floor and cfg.floor) for t in terrains], dtype=np.int8)
    return a


def _link_rows(rows: np.ndarray) -> np.ndarray:
    """``rows`` (k, n_links) copied into rows ``_bind.row_stride(n_links)`` elements apart.

    A view of shape (k, n_links) whose rows are contiguous: the forces pass reads
    c_seed, k_seed32 and link_last with one row stride (the kernel checks it), and
    padded rows keep apart in the cache at every batch size.
    """
    k, n = rows.shape
    out = np.zeros((k, _bind.row_stride(n)), dtype=rows.dtype)[:, :n]
    out[...] = rows
    return out


def _to_contract(a: dict[str, np.ndarray], settings: dict[str, Any]) -> None:
    """Cast the kernel's arrays of ``a`` to the contract's dtypes (in place), then check
    every one's dtype and shape (``contract.check_arrays``) and the settings.

    A value that does not keep its kind (a float array where the kernel reads integers)
    is not cast. Raises RuntimeError naming the array: the layout is wrong, not the input.
    """
    try:
        contract.check_settings(settings)
        for spec in contract.ARRAYS:
            x = a.get(spec.name)
            want = np.dtype(contract.expected_dtype(spec, bool(settings["link_f32"])))
            if x is None or x.dtype == want:
                continue
            if not np.can_cast(x.dtype, want, casting="same_kind"):
                raise ValueError(f"kernel array {spec.name!r} has dtype {x.dtype}, the kernel "
                                 f"reads {want} ({spec.ctype})")  # fmt: skip
            a[spec.name] = x.astype(want)
        contract.check_arrays(a, {**contract.counts_of(a, settings), **_KERNEL_COUNTS})
    except ValueError as err:
        raise RuntimeError(f"softgym engine: the layout breaks the kernel's contract: {err}") from None


CACHE_LINE = 64  # bytes


def _line_aligned(x: np.ndarray) -> np.ndarray:
    """``x`` itself if it starts on a cache line, else a copy that does, with its strides.

    A view of padded rows (:func:`_link_rows`) keeps its row stride. The kernel's
    vector loops read and write its arrays 32 or 64 bytes at a time from their
    starts (a robot's first link and voxel, for the first robot of a batch): where an
    array starts 16 bytes into a line (NumPy's default), many of those accesses span
    two lines, which an Intel Xeon pays for (``benchmarks/RESULTS.md``).
    """
    if x.ctypes.data % CACHE_LINE == 0 or x.size == 0:
        return x
    span = x.strides[0] * x.shape[0] if x.ndim else x.itemsize
    buf = np.zeros(span + CACHE_LINE, dtype=np.uint8)
    out = np.ndarray(x.shape, x.dtype, buffer=buf, offset=(-buf.ctypes.data) % CACHE_LINE,
                     strides=x.strides)
    out[...] = x
    return out


# ---------------------------------------------------------------------- memory
# Bytes of what a Simulation allocates, per item (build_layout's arrays, robot after
# robot; tests/engine/test_memory.py checks these tables against a built layout)

#: the kernel's constants that the contract's shapes name
_KERNEL_COUNTS = {"N_AUX": len(_core.AUX_NAMES), "FM_STRIDE": _core.FM_STRIDE}


def _bytes_per(count: str, single: bool = False) -> int:
    """Bytes of the kernel's arrays per ``count`` (``"n_voxels"``...): the contract's arrays
    whose rows are ``count`` (or ``count + 1``), each row's elements times their size.
    """
    total = 0
    for spec in contract.ARRAYS:
        if spec.shape[0] in (count, f"{count} + 1"):
            row = contract.expected_shape(spec, {**_KERNEL_COUNTS, count: 1})[1:]
            total += int(np.prod(row)) * np.dtype(contract.expected_dtype(spec, single)).itemsize
    return total


def _padded_bytes(single: bool) -> int:
    """Bytes of the padded link rows (contract ``padded``: c_seed, link_last, k_seed32) per
    element of their row stride, with or without single-precision links.
    """
    return sum(spec.shape[0] * np.dtype(contract.expected_dtype(spec, single)).itemsize
               for spec in contract.ARRAYS if spec.padded and (single or not spec.single_only))


#: per voxel: the per-voxel arrays of the contract (mass, pos, force, excl_start...)
_VOXEL_BYTES = _bytes_per("n_voxels")
#: per link: the per-link arrays of the contract but the padded rows (_padded_bytes)
_LINK_BYTES = _bytes_per("n_links")
#: per voxel, what Simulation keeps besides the layout's arrays: the initial state
#: (its _VOXEL_STATE: pos, vel, quat, angvel, rot, scale, temp, ext_force, col_ref)
#: and the grid indices (int64, 3)
_VOXEL_KEPT = 8 * (3 + 3 + 4 + 3 + 9 + 1 + 1 + 3 + 4) + 3 * 8
#: per robot: its counters, time steps, traces of 8 samples, their initial copies
#: and its contact cache's header, rounded up
_ROBOT_BYTES = 4096
#: per voxel with self-collision: the contact cache's lists (_contact.pyx,
#: _alloc_lists: cells 16, row 8, ref 24, sur 32, sur_idx 16, hit 8 bytes) and the
#: spatial hash's cell table (at most 8 entries of 8 bytes a voxel)
_CONTACT_VOXEL_BYTES = 104 + 64
#: rows of the kernels' scratch per voxel and per link, one block per thread
#: (_core.advance: SOFTGYM_VOXEL_ROWS, N_LINK_OUT); the seed model's link
#: passes work in fixed chunks and touch no per-link rows
_SCRATCH_ROWS = 25
#: the all-pairs contact test's largest robot (_contact.pyx ALL_PAIRS_MAX): its
#: exclusion bits, a row of words per surface voxel
_ALL_PAIRS_MAX = 768
#: per seed-model obstacle cell: obs (4 float64) and obs_rank; the contact cache's
#: cell entry (run) and obstacle_cells' temporaries (lattice cells, np.unique: build)
_OBSTACLE_BYTES = 40
_OBSTACLE_RUN_BYTES = 16
_OBSTACLE_BUILD_BYTES = 96


def _component_counts(filled: np.ndarray, fixed: np.ndarray | None, hops: int) -> tuple[int, int, int]:
    """(voxels, links, exclusion entries at most) of one component, from its grid alone.

    Links as :func:`_component` and :func:`_robot_entry` make them (face neighbours,
    those between two fixed voxels dropped); the exclusion lists at most
    ``_lattice_ball(hops) - 1`` a voxel (bond hops are at least lattice steps: exact
    inside a solid body, an upper bound elsewhere).
    """
    n = int(np.count_nonzero(filled))
    links = 0
    for ax in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[ax] = slice(0, -1)
        hi[ax] = slice(1, None)
        both = filled[tuple(lo)] & filled[tuple(hi)]
        if fixed is not None:
            both &= ~(fixed[tuple(lo)] & fixed[tuple(hi)])
        links += int(np.count_nonzero(both))
    return n, links, n * min(_lattice_ball(hops) - 1, max(n - 1, 0))


def memory_estimate(bodies: list[Body], terrains: list, config: SimConfig, n_threads: int = 1) -> dict[str, int]:
    """Bytes a Simulation of these robots needs at its peak, counted before anything is built.

    From the robots' grids alone (no layout is made): their voxels, links and
    exclusion-list entries (an upper bound: ``_component_counts``), times the bytes
    each one takes in what is allocated (the tables above). Returns the parts:

    ``arrays``
        the layout's arrays (``Simulation._a``: padded link rows included);
    ``kept``
        what the Simulation keeps besides (initial state, grid indices);
    ``build``
        the layout's temporaries at the build's peak: a second copy of the exclusion
        lists (made robot by robot, then joined) and of the grid indices;
    ``run``
        what the first steps allocate: the kernels' scratch (one block per thread)
        and, with self-collision, the contact cache's lists;
    ``total``
        the peak: ``arrays + max(build, kept + run)``.

    Not counted: the centre-of-mass traces past their first 8 samples (checked as
    they grow, :meth:`Simulation.advance_to`) and the contact pairs the run finds
    (a few per surface voxel of a folded body). Within 25 % of the measured peak RSS
    (``tests/engine/test_memory.py``, ``benchmarks/bench_memory.py``).
    """
    cfg = config
    hops = int(cfg.collision_exclusion)
    single = cfg.effective_link_precision == "single"
    n = links = excl = obstacles = boxes = 0
    max_n = max_links = 0
    contacts = 0
    for body, terrain in zip(bodies, terrains):
        fixed = None if body.fixed is None else np.asarray(body.fixed) != 0
        rn, rl, re = _component_counts(np.asarray(body.grid) > 0, fixed, hops)
        for blk in terrain.objects:
            bn, bl, be = _component_counts(np.asarray(blk.cells, dtype=bool), None, hops)
            rn, rl, re = rn + bn, rl + bl, re + be
        n, links, excl = n + rn, links + rl, excl + re
        max_n, max_links = max(max_n, rn), max(max_links, rl)
        if cfg.self_collision:
            m = min(rn, _ALL_PAIRS_MAX)
            contacts += _CONTACT_VOXEL_BYTES * rn + 8 * 512 + 8 * m * (m // 64 + 2)
        if cfg.model == "seed" and terrain.box_contact == "auto":
            # lattice boxes become obstacle voxels (obstacle_cells), at most MAX_OBSTACLE_VOXELS
            vol = sum(float(np.prod(np.subtract(b.hi, b.lo))) for b in terrain.boxes)
            obstacles += int(min(max(vol, 0.0), MAX_OBSTACLE_VOXELS))
        else:
            boxes += len(terrain.boxes)
    n_robots = len(bodies)
    stride = int(_bind.row_stride(links))
    w = 4 if single else 8  # link_last's floats
    # c_seed (8 float64 rows), link_last (9 rows), k_seed32 (11 float32 rows, single only)
    rows = stride * _padded_bytes(single)
    arrays = (_VOXEL_BYTES * n + _LINK_BYTES * links + rows + 8 * excl
              + _OBSTACLE_BYTES * obstacles + 48 * boxes + _ROBOT_BYTES * n_robots)
    kept = _VOXEL_KEPT * n + (8 + 9 * w) * links  # + link_sa, link_last copies
    build = 8 * excl + 24 * n + _OBSTACLE_BUILD_BYTES * obstacles
    per_thread = 8 * _SCRATCH_ROWS * (int(_bind.row_stride(max_n))
                                      + (int(_bind.row_stride(max_links)) if cfg.model != "seed" else 0))
    run = per_thread * max(1, min(int(n_threads), n_robots)) + contacts + _OBSTACLE_RUN_BYTES * obstacles
    total = arrays + max(build, kept + run)
    return {"voxels": n, "links": links, "exclusions": excl, "obstacles": obstacles,
            "arrays": arrays, "kept": kept,
            "build": build, "run": run, "total": total}


def build_layout(bodies: list[Body], terrains: list, config: SimConfig) -> Layout:
    """Lay out robots and their terrains (one each, validated) for the kernel.

    Each robot's entry holds its voxels (C order of its grid), then its
    terrain's movable blocks; links join face neighbours within a component,
    sorted by axis. Pure: the inputs are not modified.
    """
    cfg = config
    L = float(cfg.voxel_size)
    n_robots = len(bodies)
    per_vox: dict[str, list[np.ndarray]] = {}
    per_link: dict[str, list[np.ndarray]] = {}
    vox_start = [0]
    link_start = [0]
    dts, masses, axis_counts, excl, body_end = [], [], [], [], []
    grid_index = []

    entries = [_robot_entry(body, terrain, cfg) for body, terrain in zip(bodies, terrains)]
    for e in entries:
        off = vox_start[-1]
        for name, value in e["vox"].items():
            per_vox.setdefault(name, []).append(value)
        for name, value in e["link"].items():
            # the entry's voxel indices, offset to the batch's
            per_link.setdefault(name, []).append(value + off if name in ("v1", "v2") and off else value)
        axis_counts.append(e["axis_count"])
        dts.append(e["dt"])
        masses.append(e["mass"])
        body_end.append(off + e["n_own"])
        grid_index.append(e["grid_index"])
        excl.append(e["excl_idx"] + off if off else e["excl_idx"])
        vox_start.append(off + e["n"])
        link_start.append(link_start[-1] + e["n_links"])
    # from here the parts live only in per_vox, per_link and excl: each is freed as soon
    # as its batch array is made, so the build holds about one copy of the layout
    # (layout_bytes counts it)
    del entries, e

    n_vox = vox_start[-1]
    a: dict[str, np.ndarray] = {}
    for name in list(per_vox):
        a[name] = np.ascontiguousarray(np.concatenate(per_vox.pop(name)))
    a["excl_start"] = np.concatenate([[0], np.cumsum(a.pop("excl_count"))])
    a["excl_idx"] = np.ascontiguousarray(excl[0] if len(excl) == 1 else np.concatenate(excl))
    del excl
    a.update(_terrain_arrays(terrains, cfg))
    for name in list(per_link):
        a[name] = np.ascontiguousarray(np.concatenate(per_link.pop(name)))
    # (8, n_links): one row per constant, for the kernel's vector loops
    a["c_seed"] = _link_rows(np.asarray(a["c_seed"], dtype=np.float64).reshape(-1, 8).T)
    a["link_sa"] = np.ones(a["v1"].shape[0], dtype=np.int64)  # links start in small-angle mode
    single = cfg.effective_link_precision == "single"
    # see _TRANSPOSED; float32 with single-precision links, whose forces pass keeps float values
    a["link_last"] = _link_rows(np.zeros((9, a["v1"].shape[0]), dtype=np.float32 if single else np.float64))
    # (11, n_links) float32, for single-precision links only (else no columns): k_axial,
    # k_torsion, k_bend and the 8 rows of c_seed, rounded once
    a["k_seed32"] = (
        _link_rows(np.vstack([a["k_axial"], a["k_torsion"], a["k_bend"], a["c_seed"]]).astype(np.float32))
        if single
        else np.empty((11, 0), dtype=np.float32)
    )
    a["quat"] = np.zeros((n_vox, 4))
    a["quat"][:, 0] = 1.0
    a["rot"] = np.zeros((n_vox, 9))
    a["rot"][:, [0, 4, 8]] = 1.0
    for name in ("vel", "angvel"):
        a[name] = np.zeros((n_vox, 3))
    # each voxel's force (columns 0-2) and moment (4-6) in one row, 3 and 7 padding for
    # whole-row vector adds (_batch.pxd)
    a["force"] = np.zeros((n_vox, _core.FM_STRIDE))
    a["ext_force"] = np.ascontiguousarray(a["ext_force"], dtype=np.float64).reshape(-1, 3)
    a["body_end"] = np.asarray(body_end, dtype=np.intp)
    a["aux_init"] = np.zeros((n_robots, len(_core.AUX_NAMES)))
    a["trace_aux"] = np.zeros((n_robots, 8, len(_core.AUX_NAMES)))
    a["scale"] = np.full(n_vox, L)
    a["col_ref"] = np.zeros((n_vox, 4))
    a["col_acc"] = np.full(n_robots, np.inf)  # first step builds the candidates
    a["col_vmax"] = np.zeros(n_robots)
    a["temp"] = np.zeros(n_vox)
    a["vox_start"] = np.asarray(vox_start, dtype=np.intp)
    a["link_start"] = np.asarray(link_start, dtype=np.intp)
    a["link_axis_count"] = np.ascontiguousarray(np.asarray(axis_counts), dtype=np.intp)
    a["dt"] = np.asarray(dts, dtype=np.float64)
    a["steps"] = np.zeros(n_robots, dtype=np.int64)
    a["temp_amp"] = np.array([b.temp_amplitude for b in bodies], dtype=np.float64)
    a["period"] = np.array([b.period for b in bodies], dtype=np.float64)
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
    walls = [obstacle_mass_and_center(t, L) for t in terrains]
    settings = {
        "n_robots": n_robots,
        "L": L,
        "gravity": -float(cfg.gravity) * (math.cos(math.radians(cfg.incline)) if cfg.incline else 1.0),
        "init_time": float(cfg.init_time),
        "min_scale": float(cfg.min_scale),
        "max_strain": float(cfg.max_strain),
        "trace_interval": float(cfg.trace_interval),
        "self_collision": int(bool(cfg.self_collision)),
        "actuation_mode": contract.ACTUATION[cfg.actuation],
        "model": contract.MODEL[cfg.model],
        "bond_zeta": float(cfg.bond_damping),
        "fluid_drag": float(cfg.fluid_drag),
        "link_f32": int(single),
    }
    _to_contract(a, settings)
    for name in contract.KERNEL_ARRAYS:
        a[name] = _line_aligned(a[name])
    # robots' own voxels in the kernel arrays (None: no objects, all of them)
    own = [np.arange(vox_start[r], body_end[r]) for r in range(n_robots)]
    counts = np.asarray(body_end) - np.asarray(vox_start[:-1])
    return Layout(
        arrays=a,
        settings=settings,
        grid_index=np.ascontiguousarray(np.concatenate(grid_index)).astype(np.int64),
        own=None if body_end == vox_start[1:] else np.concatenate(own).astype(np.intp),
        own_offsets=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
        obstacle_mass=np.array([m for m, _ in walls], dtype=np.float64),
        obstacle_cm=np.array([c for _, c in walls], dtype=np.float64).reshape(-1, 3),
    )
