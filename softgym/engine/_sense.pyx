# The contact sensor of every robot voxel, batched: the smallest surface gap (m)
# between a voxel and anything it can touch (the floor, the terrain's boxes and
# obstacle voxels, the terrain's movable objects, its own robot's voxels more than
# `self_hops` lattice steps away), one robot per OpenMP iteration, nogil. Read by
# softgym.engine.Simulation.contact_gaps after an engine call; the step loop itself
# is untouched (the sensor never changes a result).

from cython.parallel cimport prange
from libc.math cimport sqrt, fabs, INFINITY
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


cdef inline double _pair_gap(const float64_t* p, const float64_t* q, double reach) noexcept nogil:
    # centre distance minus the sum of the two half edges (m)
    cdef double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2]
    return sqrt(dx * dx + dy * dy + dz * dz) - reach


cdef void _robot_gaps(
    intp_t r, const float64_t* pos, const float64_t* scale, const intp_t* vox_start,
    const intp_t* body_end, const intp_t* grid, const flag_t* floor, const intp_t* box_start,
    const float64_t* boxes, const intp_t* obs_start, const float64_t* obs, double obs_half,
    intp_t self_hops, intp_t self_max, float64_t* out, intp_t out0,
) noexcept nogil:
    cdef intp_t a = vox_start[r], e = body_end[r], z = vox_start[r + 1]
    cdef intp_t i, j, k, hops
    cdef double half, g, best
    cdef bint own = (e - a) <= self_max
    for i in range(a, e):
        half = 0.5 * scale[i]
        best = INFINITY
        if floor[r]:
            best = pos[3 * i + 2] - half
        for k in range(box_start[r], box_start[r + 1]):
            g = _box_gap(&pos[3 * i], &boxes[6 * k], half)
            if g < best:
                best = g
        for k in range(obs_start[r], obs_start[r + 1]):
            g = _pair_gap(&pos[3 * i], &obs[4 * k], half + obs_half)
            if g < best:
                best = g
        for j in range(e, z):  # the terrain's movable objects
            g = _pair_gap(&pos[3 * i], &pos[3 * j], half + 0.5 * scale[j])
            if g < best:
                best = g
        if own:
            for j in range(a, e):
                hops = (<intp_t> fabs(<double> (grid[3 * i] - grid[3 * j]))
                        + <intp_t> fabs(<double> (grid[3 * i + 1] - grid[3 * j + 1]))
                        + <intp_t> fabs(<double> (grid[3 * i + 2] - grid[3 * j + 2])))
                if hops <= self_hops:
                    continue
                g = _pair_gap(&pos[3 * i], &pos[3 * j], half + 0.5 * scale[j])
                if g < best:
                    best = g
        out[out0 + i - a] = best


def contact_gaps(
    const float64_t[:, ::1] pos, const float64_t[::1] scale, const intp_t[::1] vox_start,
    const intp_t[::1] body_end, const intp_t[:, ::1] grid, const flag_t[::1] floor,
    const intp_t[::1] box_start, const float64_t[:, ::1] boxes, const intp_t[::1] obs_start,
    const float64_t[:, ::1] obs, double obs_edge, intp_t self_hops, intp_t self_max,
    const intp_t[::1] own_offsets, float64_t[::1] out, int n_threads,
):
    """Fill ``out`` (one value per robot voxel, in the order of ``own_offsets``) with its
    smallest surface gap (m) to the floor, boxes, obstacle voxels (edge ``obs_edge``),
    the entry's objects and its own voxels more than ``self_hops`` lattice steps away
    (robots of more than ``self_max`` voxels skip the last); +inf where nothing is near
    enough to count (no floor, no obstacle)."""
    cdef intp_t n = vox_start.shape[0] - 1
    cdef intp_t r
    cdef const float64_t* bx = &boxes[0, 0] if boxes.shape[0] else NULL
    cdef const float64_t* ob = &obs[0, 0] if obs.shape[0] else NULL
    if out.shape[0] != own_offsets[n]:
        raise ValueError("out must hold one value per robot voxel")
    if n_threads < 1:
        n_threads = 1
    for r in prange(n, nogil=True, schedule="dynamic", num_threads=n_threads):
        _robot_gaps(r, &pos[0, 0], &scale[0], &vox_start[0], &body_end[0], &grid[0, 0],
                    &floor[0], &box_start[0], bx, &obs_start[0], ob, 0.5 * obs_edge,
                    self_hops, self_max, &out[0], own_offsets[r])
