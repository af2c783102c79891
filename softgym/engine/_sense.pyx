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


cdef inline double _pair_gap(const float64_t* p, const float64_t* q, double reach, double cap,
                             double best) noexcept nogil:
    # the smaller of ``best`` and the gap between two cubes (centre distance minus the sum of
    # their half edges, ``reach``), the square root only for a pair within reach + cap
    cdef double dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2]
    cdef double d2 = dx * dx + dy * dy + dz * dz
    if d2 < (reach + cap) * (reach + cap):
        return min(best, sqrt(d2) - reach)
    return best


cdef void _robot_gaps(
    intp_t r, const float64_t* pos, const float64_t* scale, const flag_t* surface,
    const intp_t* vox_start, const intp_t* body_end, const intp_t* grid, const flag_t* floor,
    const intp_t* box_start, const float64_t* boxes, const intp_t* obs_start,
    const float64_t* obs, double obs_half, intp_t self_hops, intp_t self_max, double cap,
    float64_t* out, intp_t out0, intp_t* order, float64_t* sweep, intp_t* sweep_idx,
) noexcept nogil:
    cdef intp_t a = vox_start[r], e = body_end[r], z = vox_start[r + 1]
    cdef intp_t n = e - a
    cdef intp_t i, j, k, t, u, key, hops, di, dj, dk, stop, ns = 0
    cdef double half, g, x, window, edge = 0.0
    cdef double xi, yi, zi, dx, dy, dz, d2, reach
    cdef float64_t* X
    cdef float64_t* Y
    cdef float64_t* Z
    cdef float64_t* H
    cdef bint own = n <= self_max
    for i in range(a, e):
        out[out0 + i - a] = cap
        edge = max(edge, scale[i])
    # the robot's voxels by x (insertion sort from the last call's order: nearly sorted), so
    # that its own pairs are swept within a window of x: beyond it no pair is within cap
    for t in range(1, n):
        key = order[t]
        x = pos[3 * (a + key)]
        u = t - 1
        while u >= 0 and pos[3 * (a + order[u])] > x:
            order[u + 1] = order[u]
            u -= 1
        order[u + 1] = key
    window = edge + cap
    for t in range(n):
        i = a + order[t]
        if not surface[i]:  # a voxel with all six bonds touches nothing but its neighbours
            continue
        half = 0.5 * scale[i]
        g = cap
        if floor[r]:
            g = min(g, pos[3 * i + 2] - half)
        for k in range(box_start[r], box_start[r + 1]):
            g = min(g, _box_gap(&pos[3 * i], &boxes[6 * k], half))
        for k in range(obs_start[r], obs_start[r + 1]):
            g = _pair_gap(&pos[3 * i], &obs[4 * k], half + obs_half, cap, g)
        for j in range(e, z):  # the terrain's movable objects
            g = _pair_gap(&pos[3 * i], &pos[3 * j], half + 0.5 * scale[j], cap, g)
        out[out0 + i - a] = min(out[out0 + i - a], g)
        # the surface voxels in x order for the sweep of own pairs: rows of x, y, z and half
        # edge, n apart
        sweep[ns] = pos[3 * i]
        sweep[n + ns] = pos[3 * i + 1]
        sweep[2 * n + ns] = pos[3 * i + 2]
        sweep[3 * n + ns] = half
        sweep_idx[ns] = i
        ns += 1
    if not own:
        return
    # each pair of surface voxels once, both take the gap. For voxel t, its partners u > t up
    # to the first whose x is a window or more ahead (beyond it none is within cap); among
    # them the few within reach + cap (lattice neighbours, mostly) take the branch, where the
    # gap is the one _pair_gap gives
    X = sweep
    Y = sweep + n
    Z = sweep + 2 * n
    H = sweep + 3 * n
    for t in range(ns):
        xi = X[t]
        yi = Y[t]
        zi = Z[t]
        half = H[t]
        stop = t + 1
        while stop < ns and not (X[stop] - xi >= window):
            stop += 1
        for u in range(t + 1, stop):
            dx = xi - X[u]
            dy = yi - Y[u]
            dz = zi - Z[u]
            d2 = dx * dx + dy * dy + dz * dz
            reach = half + H[u]
            if d2 < (reach + cap) * (reach + cap):
                i = sweep_idx[t]
                j = sweep_idx[u]
                di = grid[3 * i] - grid[3 * j]
                dj = grid[3 * i + 1] - grid[3 * j + 1]
                dk = grid[3 * i + 2] - grid[3 * j + 2]
                hops = ((di if di >= 0 else -di) + (dj if dj >= 0 else -dj)
                        + (dk if dk >= 0 else -dk))
                if hops > self_hops:
                    g = min(cap, sqrt(d2) - reach)
                    if g < out[out0 + i - a]:
                        out[out0 + i - a] = g
                    if g < out[out0 + j - a]:
                        out[out0 + j - a] = g


def contact_gaps(
    const float64_t[:, ::1] pos, const float64_t[::1] scale, const flag_t[::1] surface,
    const intp_t[::1] vox_start, const intp_t[::1] body_end, const intp_t[:, ::1] grid,
    const flag_t[::1] floor, const intp_t[::1] box_start, const float64_t[:, ::1] boxes,
    const intp_t[::1] obs_start, const float64_t[:, ::1] obs, double obs_edge, intp_t self_hops,
    intp_t self_max, double cap, const intp_t[::1] own_offsets, float64_t[::1] out,
    intp_t[::1] order, float64_t[::1] sweep, intp_t[::1] sweep_idx, int n_threads,
):
    """Fill ``out`` (one value per robot voxel, in the order of ``own_offsets``) with its
    smallest surface gap (m) to the floor, boxes, obstacle voxels (edge ``obs_edge``),
    the entry's objects and its own voxels more than ``self_hops`` lattice steps away
    (robots of more than ``self_max`` voxels skip the last), at most ``cap``. Voxels with
    all six bonds (not ``surface``) get ``cap``: they touch nothing. ``order`` holds, per
    robot (its segment of ``own_offsets``), a permutation of its voxels' local indices,
    sorted by x here (kept between calls: the next sort is short); the result does not
    depend on it. ``sweep`` (4 per robot voxel) and ``sweep_idx`` (1 per robot voxel) are
    scratch."""
    cdef intp_t n = vox_start.shape[0] - 1
    cdef intp_t r
    cdef const float64_t* bx = &boxes[0, 0] if boxes.shape[0] else NULL
    cdef const float64_t* ob = &obs[0, 0] if obs.shape[0] else NULL
    if out.shape[0] != own_offsets[n] or order.shape[0] != own_offsets[n]:
        raise ValueError("out and order must hold one value per robot voxel")
    if sweep.shape[0] != 4 * own_offsets[n] or sweep_idx.shape[0] != own_offsets[n]:
        raise ValueError("sweep and sweep_idx must hold 4 and 1 values per robot voxel")
    if n_threads < 1:
        n_threads = 1
    for r in prange(n, nogil=True, schedule="dynamic", num_threads=n_threads):
        _robot_gaps(r, &pos[0, 0], &scale[0], &surface[0], &vox_start[0], &body_end[0],
                    &grid[0, 0], &floor[0], &box_start[0], bx, &obs_start[0], ob, 0.5 * obs_edge,
                    self_hops, self_max, cap, &out[0], own_offsets[r], &order[own_offsets[r]],
                    &sweep[4 * own_offsets[r]], &sweep_idx[own_offsets[r]])


cdef void _robot_cells(
    intp_t r, const float64_t* pos, const float64_t* vel, const float64_t* gaps,
    const float64_t* cm, const float64_t* cm_vel, const intp_t* own_offsets, const intp_t* cell_of,
    const intp_t* voxel_of, intp_t nx, intp_t ny, intp_t nz, double inv_l, double reach,
    double pos_bound, double vel_bound, const float64_t* rest, float64_t* out, float64_t* cov,
) noexcept nogil:
    cdef intp_t nc = nx * ny * nz
    cdef intp_t v, c, i, j, k, a, w, m, cnt
    cdef intp_t step[3]
    cdef intp_t coord[3]
    cdef intp_t size[3]
    cdef double rel[3]
    cdef double d, dx, dy, dz, s, t
    cdef float64_t* o
    cdef const float64_t* q
    step[0] = ny * nz
    step[1] = nz
    step[2] = 1
    size[0] = nx
    size[1] = ny
    size[2] = nz
    for a in range(9):
        cov[9 * r + a] = 0.0
    for v in range(own_offsets[r], own_offsets[r + 1]):
        c = cell_of[v]
        o = &out[(r * nc + c) * 8]
        for a in range(3):
            rel[a] = (pos[3 * v + a] - cm[3 * r + a]) * inv_l
            o[a] = min(max(rel[a], -pos_bound), pos_bound)
            o[3 + a] = min(max((vel[3 * v + a] - cm_vel[3 * r + a]) * inv_l, -vel_bound), vel_bound)
        t = gaps[v] * inv_l
        t = 1.0 - (t if t > 0.0 else 0.0) / reach
        o[6] = t if t > 0.0 else 0.0
        # strain: the mean stretch of the voxel's bonds to its lattice neighbours
        coord[0] = c // step[0]
        coord[1] = (c // step[1]) % ny
        coord[2] = c % nz
        s = 0.0
        cnt = 0
        for a in range(3):
            for k in range(2):
                m = coord[a] + (1 if k == 0 else -1)
                if m < 0 or m >= size[a]:
                    continue
                w = voxel_of[r * nc + c + (step[a] if k == 0 else -step[a])]
                if w < 0:
                    continue
                q = &pos[3 * w]
                dx = pos[3 * v] - q[0]
                dy = pos[3 * v + 1] - q[1]
                dz = pos[3 * v + 2] - q[2]
                s += sqrt(dx * dx + dy * dy + dz * dz) * inv_l - 1.0
                cnt += 1
        o[7] = min(max(s / cnt if cnt else 0.0, -1.0), 1.0)
        # the cross-covariance of the lattice positions and the current ones (the body's rotation)
        for i in range(3):
            for j in range(3):
                cov[9 * r + 3 * i + j] += rest[(r * nc + c) * 3 + i] * rel[j]


def cell_sensors(
    const float64_t[:, ::1] pos, const float64_t[:, ::1] vel, const float64_t[::1] gaps,
    const float64_t[:, ::1] cm, const float64_t[:, ::1] cm_vel, const intp_t[::1] own_offsets,
    const intp_t[::1] cell_of, const intp_t[:, ::1] voxel_of, intp_t nx, intp_t ny, intp_t nz,
    double voxel_size, double reach, double pos_bound, double vel_bound,
    const float64_t[:, :, ::1] rest, float64_t[:, :, ::1] out, float64_t[:, :, ::1] cov,
    int n_threads,
):
    """Each robot voxel's eight cell sensors into ``out`` (n_robots, n_cells, 8), rows of its
    cell (position and velocity relative to the centre of mass in voxel lengths, clipped to
    the bounds; touch from ``gaps`` (m), 1 at contact, 0 from ``reach`` voxel lengths; the mean
    bond stretch to its lattice neighbours, clipped to +-1), and each robot's cross-covariance
    of its centred lattice positions ``rest`` with the relative positions into ``cov``
    (n_robots, 3, 3). Rows of empty cells are left as they are. Robots in parallel."""
    cdef intp_t n = cm.shape[0]
    cdef intp_t r
    if out.shape[0] != n or out.shape[1] != nx * ny * nz or out.shape[2] != 8:
        raise ValueError("out must have shape (n_robots, n_cells, 8)")
    if n_threads < 1:
        n_threads = 1
    for r in prange(n, nogil=True, schedule="static", num_threads=n_threads):
        _robot_cells(r, &pos[0, 0], &vel[0, 0], &gaps[0], &cm[0, 0], &cm_vel[0, 0],
                     &own_offsets[0], &cell_of[0], &voxel_of[0, 0], nx, ny, nz, 1.0 / voxel_size,
                     reach, pos_bound, vel_bound, &rest[0, 0, 0], &out[0, 0, 0], &cov[0, 0, 0])
