# The contact sensor of every robot voxel, batched: the smallest surface gap (m)
# between a voxel and anything it can touch (the floor, the terrain's boxes and
# obstacle voxels, the terrain's movable objects, its own robot's voxels more than
# `self_hops` lattice steps away), one robot per OpenMP iteration, nogil. Read by
# softgym.engine.Simulation.contact_gaps after an engine call; the step loop itself
# is untouched (the sensor never changes a result).

from cython.parallel cimport prange
from libc.math cimport sqrt
cimport numpy as cnp
from softgym.engine._typedefs cimport float64_t, intp_t, flag_t

cnp.import_array()


cdef inline double _box_gap(const float64_t* p, const float64_t* b, double half) noexcept nogil:
    # distance from the voxel's centre to the box minus its half edge (m); inside: minus the
    # depth to the nearest face, minus the half edge
    cdef double dx = 0.0, dy = 0.0, dz = 0.0, d, inside
    if p[0] < b[0]:
        dx = b[0] - p[0]
    elif p[0] > b[3]:
        dx = p[0] - b[3]
    if p[1] < b[1]:
        dy = b[1] - p[1]
    elif p[1] > b[4]:
        dy = p[1] - b[4]
    if p[2] < b[2]:
        dz = b[2] - p[2]
    elif p[2] > b[5]:
        dz = p[2] - b[5]
    d = sqrt(dx * dx + dy * dy + dz * dz)
    if d > 0.0:
        return d - half
    inside = p[0] - b[0]
    inside = min(inside, b[3] - p[0])
    inside = min(inside, p[1] - b[1])
    inside = min(inside, b[4] - p[1])
    inside = min(inside, p[2] - b[2])
    inside = min(inside, b[5] - p[2])
    return -inside - half


cdef void _robot_gaps(
    intp_t r, const float64_t* pos, const float64_t* scale, const flag_t* surface,
    const intp_t* vox_start, const intp_t* body_end, const intp_t* grid, const flag_t* floor,
    const intp_t* box_start, const float64_t* boxes, const intp_t* obs_start,
    const float64_t* obs, double obs_half, intp_t self_hops, intp_t self_max, double cap,
    float64_t* out, intp_t out0,
) noexcept nogil:
    cdef intp_t a = vox_start[r], e = body_end[r], z = vox_start[r + 1]
    cdef intp_t i, j, k, hops, di, dj, dk
    cdef double half, g, reach, dx, dy, dz, d2
    cdef bint own = (e - a) <= self_max
    for i in range(a, e):
        out[out0 + i - a] = cap
    for i in range(a, e):
        if not surface[i]:  # a voxel with all six bonds touches nothing but its neighbours
            continue
        half = 0.5 * scale[i]
        g = cap
        if floor[r]:
            g = min(g, pos[3 * i + 2] - half)
        for k in range(box_start[r], box_start[r + 1]):
            g = min(g, _box_gap(&pos[3 * i], &boxes[6 * k], half))
        for k in range(obs_start[r], obs_start[r + 1]):
            reach = half + obs_half
            dx = pos[3 * i] - obs[4 * k]
            dy = pos[3 * i + 1] - obs[4 * k + 1]
            dz = pos[3 * i + 2] - obs[4 * k + 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < (reach + cap) * (reach + cap):
                g = min(g, sqrt(d2) - reach)
        for j in range(e, z):  # the terrain's movable objects
            reach = half + 0.5 * scale[j]
            dx = pos[3 * i] - pos[3 * j]
            dy = pos[3 * i + 1] - pos[3 * j + 1]
            dz = pos[3 * i + 2] - pos[3 * j + 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < (reach + cap) * (reach + cap):
                g = min(g, sqrt(d2) - reach)
        out[out0 + i - a] = min(out[out0 + i - a], g)
        if not own:
            continue
        for j in range(i + 1, e):  # each pair once, both voxels take the gap
            if not surface[j]:
                continue
            di = grid[3 * i] - grid[3 * j]
            dj = grid[3 * i + 1] - grid[3 * j + 1]
            dk = grid[3 * i + 2] - grid[3 * j + 2]
            hops = (di if di >= 0 else -di) + (dj if dj >= 0 else -dj) + (dk if dk >= 0 else -dk)
            if hops <= self_hops:
                continue
            reach = half + 0.5 * scale[j]
            dx = pos[3 * i] - pos[3 * j]
            dy = pos[3 * i + 1] - pos[3 * j + 1]
            dz = pos[3 * i + 2] - pos[3 * j + 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < (reach + cap) * (reach + cap):
                g = sqrt(d2) - reach
                if g < out[out0 + i - a]:
                    out[out0 + i - a] = g
                if g < out[out0 + j - a]:
                    out[out0 + j - a] = g


def contact_gaps(
    const float64_t[:, ::1] pos, const float64_t[::1] scale, const flag_t[::1] surface,
    const intp_t[::1] vox_start, const intp_t[::1] body_end, const intp_t[:, ::1] grid,
    const flag_t[::1] floor, const intp_t[::1] box_start, const float64_t[:, ::1] boxes,
    const intp_t[::1] obs_start, const float64_t[:, ::1] obs, double obs_edge, intp_t self_hops,
    intp_t self_max, double cap, const intp_t[::1] own_offsets, float64_t[::1] out, int n_threads,
):
    """Fill ``out`` (one value per robot voxel, in the order of ``own_offsets``) with its
    smallest surface gap (m) to the floor, boxes, obstacle voxels (edge ``obs_edge``),
    the entry's objects and its own voxels more than ``self_hops`` lattice steps away
    (robots of more than ``self_max`` voxels skip the last), at most ``cap``. Voxels with
    all six bonds (not ``surface``) get ``cap``: they touch nothing."""
    cdef intp_t n = vox_start.shape[0] - 1
    cdef intp_t r
    cdef const float64_t* bx = &boxes[0, 0] if boxes.shape[0] else NULL
    cdef const float64_t* ob = &obs[0, 0] if obs.shape[0] else NULL
    if out.shape[0] != own_offsets[n]:
        raise ValueError("out must hold one value per robot voxel")
    if n_threads < 1:
        n_threads = 1
    for r in prange(n, nogil=True, schedule="dynamic", num_threads=n_threads):
        _robot_gaps(r, &pos[0, 0], &scale[0], &surface[0], &vox_start[0], &body_end[0],
                    &grid[0, 0], &floor[0], &box_start[0], bx, &obs_start[0], ob, 0.5 * obs_edge,
                    self_hops, self_max, cap, &out[0], own_offsets[r])
