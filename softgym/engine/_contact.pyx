# Self-collision (SEED_REFERENCE 1.7): surface voxels more than
# `collision_exclusion` bond hops apart repel when their spherical envelopes, of diameter
# 1.5 x their actuated size, overlap: F = E_h L (0.75 (s1 + s2) - |d|) along d,
# E_h the harmonic mean of their moduli; no damping, no friction. Candidate
# pairs come from a spatial hash (cells of the candidate horizon) and are kept
# until some voxel may have crossed the horizon's slack, so the cost grows
# about linearly with the number of voxels. The candidate list is always a
# superset of the touching pairs and is sorted, so forces do not depend on
# when it was rebuilt: results stay bit-identical.
#
# Both models' candidate lists (contacts_corotational, contacts_seed: the
# seed's own rule and schedule, with its obstacle voxels) come from one
# spatial hash; collide / collide_obstacles apply the contact law. The
# contact laws with the floor and terrain boxes are inline in _contact.pxd.

from libc.math cimport sqrt, floor
from libc.stdint cimport int64_t
from libc.stdlib cimport malloc, realloc, qsort
from libc.string cimport memcpy

from softgym.engine._batch cimport Batch, STATUS_OK, STATUS_MEMORY
from softgym.engine._typedefs cimport float64_t, intp_t, int32

cdef enum:
    CELL_BITS = 20


cdef int _cmp_key_index(const void* a, const void* b) noexcept nogil:
    cdef const KeyIndex* x = <const KeyIndex*> a
    cdef const KeyIndex* y = <const KeyIndex*> b
    if x.key != y.key:
        return -1 if x.key < y.key else 1
    return -1 if x.index < y.index else (1 if x.index > y.index else 0)


cdef int _cmp_intp(const void* a, const void* b) noexcept nogil:
    cdef intp_t x = (<const intp_t*> a)[0]
    cdef intp_t y = (<const intp_t*> b)[0]
    return -1 if x < y else (1 if x > y else 0)


cdef inline bint _excluded(Batch* b, intp_t i, intp_t j) noexcept nogil:
    # binary search of j in voxel i's sorted exclusion row
    cdef intp_t lo = b.excl_start[i], hi = b.excl_start[i + 1], mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if b.excl_idx[mid] < j:
            lo = mid + 1
        else:
            hi = mid
    return lo < b.excl_start[i + 1] and b.excl_idx[lo] == j


cdef inline intp_t _lower_bound(const KeyIndex* cells, intp_t n, int64_t key) noexcept nogil:
    cdef intp_t lo = 0, hi = n, mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if cells[mid].key < key:
            lo = mid + 1
        else:
            hi = mid
    return lo


cdef int contacts_corotational(Batch* b, intp_t r, Contacts* c) noexcept nogil:
    # OUT: c.pairs, sorted candidate pairs within the horizon. Returns a STATUS.
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t n = ve - vs
        intp_t i, j, k, m, pos_, n_row, n_surf
        int64_t ci, cj, ck, key
        int di, dj, dk
        float64_t L = b.L
        float64_t smax = L, env, horizon, h2, inv_cell, x0, y0, z0, dx, dy, dz
        const float64_t* P = b.pos
        intp_t* grown
    if c.cells == NULL:
        c.cells = <KeyIndex*> malloc(n * sizeof(KeyIndex))
        c.row = <intp_t*> malloc(n * sizeof(intp_t))
        c.ref = <float64_t*> malloc(3 * n * sizeof(float64_t))
        if c.cells == NULL or c.row == NULL or c.ref == NULL:
            return STATUS_MEMORY
    memcpy(c.ref, P + 3 * vs, 3 * n * sizeof(float64_t))
    for i in range(vs, ve):
        if b.scale[i] > smax:
            smax = b.scale[i]
    env = 1.5 * smax                 # the largest envelope 0.75 (s1 + s2)
    c.margin = 0.5 * L
    horizon = env + c.margin
    h2 = horizon * horizon
    inv_cell = 1.0 / horizon
    c.built_scale = smax
    c.stale = 0
    c.n_pairs = 0
    x0 = P[3 * vs]
    y0 = P[3 * vs + 1]
    z0 = P[3 * vs + 2]
    for i in range(vs, ve):
        if P[3 * i] < x0:
            x0 = P[3 * i]
        if P[3 * i + 1] < y0:
            y0 = P[3 * i + 1]
        if P[3 * i + 2] < z0:
            z0 = P[3 * i + 2]
    # only surface voxels (missing a face bond) collide, as the seed intended:
    # an interior voxel is shielded by its six bonded neighbours
    n_surf = 0
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        ci = <int64_t> floor((P[3 * i] - x0) * inv_cell) + 1
        cj = <int64_t> floor((P[3 * i + 1] - y0) * inv_cell) + 1
        ck = <int64_t> floor((P[3 * i + 2] - z0) * inv_cell) + 1
        c.cells[n_surf].key = (ci << (2 * CELL_BITS)) | (cj << CELL_BITS) | ck
        c.cells[n_surf].index = i
        n_surf += 1
    qsort(c.cells, n_surf, sizeof(KeyIndex), _cmp_key_index)
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        ci = <int64_t> floor((P[3 * i] - x0) * inv_cell) + 1
        cj = <int64_t> floor((P[3 * i + 1] - y0) * inv_cell) + 1
        ck = <int64_t> floor((P[3 * i + 2] - z0) * inv_cell) + 1
        n_row = 0
        for di in range(-1, 2):
            for dj in range(-1, 2):
                for dk in range(-1, 2):
                    key = ((ci + di) << (2 * CELL_BITS)) | ((cj + dj) << CELL_BITS) | (ck + dk)
                    pos_ = _lower_bound(c.cells, n_surf, key)
                    while pos_ < n_surf and c.cells[pos_].key == key:
                        j = c.cells[pos_].index
                        pos_ += 1
                        if j <= i:
                            continue
                        dx = P[3 * j] - P[3 * i]
                        dy = P[3 * j + 1] - P[3 * i + 1]
                        dz = P[3 * j + 2] - P[3 * i + 2]
                        if dx * dx + dy * dy + dz * dz >= h2:
                            continue
                        if _excluded(b, i, j):
                            continue
                        c.row[n_row] = j
                        n_row += 1
        if n_row == 0:
            continue
        qsort(c.row, n_row, sizeof(intp_t), _cmp_intp)
        if c.n_pairs + n_row > c.capacity:
            m = 2 * (c.n_pairs + n_row) + 64
            grown = <intp_t*> realloc(c.pairs, 2 * m * sizeof(intp_t))
            if grown == NULL:
                return STATUS_MEMORY
            c.pairs = grown
            c.capacity = m
        for k in range(n_row):
            c.pairs[2 * c.n_pairs] = i
            c.pairs[2 * c.n_pairs + 1] = c.row[k]
            c.n_pairs += 1
    return STATUS_OK


cdef int contacts_seed(Batch* b, intp_t r, Contacts* c, int32 snapshot) noexcept nogil:
    # The seed's collision list (CalcL1Bonds with its horizon 2): surface voxel
    # pairs more than the exclusion hops apart whose centres are closer than
    # 3 L and than twice the size of the pair's first voxel in the seed's
    # order, measured at the rebuild. snapshot: 1 copies the current positions
    # and sizes into col_ref first (a rebuild); 0 rebuilds the list of the
    # last rebuild from col_ref (after the state was restored).
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t n = ve - vs
        intp_t i, j, k, m, pos_, n_row, n_surf, first
        int64_t ci, cj, ck, key
        int di, dj, dk
        float64_t L = b.L
        float64_t smax = 0.0, horizon, inv_cell, x0, y0, z0, dx, dy, dz, d2, act
        float64_t* R = b.col_ref
        intp_t* grown
    if c.cells == NULL:
        c.cells = <KeyIndex*> malloc(n * sizeof(KeyIndex))
        c.row = <intp_t*> malloc(n * sizeof(intp_t))
        c.ref = <float64_t*> malloc(3 * n * sizeof(float64_t))
        if c.cells == NULL or c.row == NULL or c.ref == NULL:
            return STATUS_MEMORY
    if snapshot:
        for i in range(vs, ve):
            R[4 * i] = b.pos[3 * i]
            R[4 * i + 1] = b.pos[3 * i + 1]
            R[4 * i + 2] = b.pos[3 * i + 2]
            R[4 * i + 3] = b.scale[i]
    c.stale = 0
    c.n_pairs = 0
    c.built_scale = 1.0e300  # model 0 rebuilds on its own schedule, never for sizes
    c.margin = 1.0e300
    for i in range(vs, ve):
        if R[4 * i + 3] > smax:
            smax = R[4 * i + 3]
    horizon = 2.0 * smax
    if horizon < 2.0 * L and b.obs_start[r + 1] > b.obs_start[r]:
        horizon = 2.0 * L  # an obstacle voxel keeps its size L
    if horizon > 3.0 * L:
        horizon = 3.0 * L
    if horizon <= 0.0:
        return STATUS_OK
    inv_cell = 1.0 / horizon
    x0 = R[4 * vs]
    y0 = R[4 * vs + 1]
    z0 = R[4 * vs + 2]
    for i in range(vs, ve):
        if R[4 * i] < x0:
            x0 = R[4 * i]
        if R[4 * i + 1] < y0:
            y0 = R[4 * i + 1]
        if R[4 * i + 2] < z0:
            z0 = R[4 * i + 2]
    n_surf = 0
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        ci = <int64_t> floor((R[4 * i] - x0) * inv_cell) + 1
        cj = <int64_t> floor((R[4 * i + 1] - y0) * inv_cell) + 1
        ck = <int64_t> floor((R[4 * i + 2] - z0) * inv_cell) + 1
        c.cells[n_surf].key = (ci << (2 * CELL_BITS)) | (cj << CELL_BITS) | ck
        c.cells[n_surf].index = i
        n_surf += 1
    qsort(c.cells, n_surf, sizeof(KeyIndex), _cmp_key_index)
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        ci = <int64_t> floor((R[4 * i] - x0) * inv_cell) + 1
        cj = <int64_t> floor((R[4 * i + 1] - y0) * inv_cell) + 1
        ck = <int64_t> floor((R[4 * i + 2] - z0) * inv_cell) + 1
        n_row = 0
        for di in range(-1, 2):
            for dj in range(-1, 2):
                for dk in range(-1, 2):
                    key = ((ci + di) << (2 * CELL_BITS)) | ((cj + dj) << CELL_BITS) | (ck + dk)
                    pos_ = _lower_bound(c.cells, n_surf, key)
                    while pos_ < n_surf and c.cells[pos_].key == key:
                        j = c.cells[pos_].index
                        pos_ += 1
                        if j <= i:
                            continue
                        dx = R[4 * j] - R[4 * i]
                        dy = R[4 * j + 1] - R[4 * i + 1]
                        dz = R[4 * j + 2] - R[4 * i + 2]
                        d2 = dx * dx + dy * dy + dz * dz
                        if d2 >= 9.0 * L * L:
                            continue
                        first = i if b.seed_rank[i] < b.seed_rank[j] else j
                        act = 2.0 * R[4 * first + 3]
                        if d2 >= act * act:
                            continue
                        if _excluded(b, i, j):
                            continue
                        c.row[n_row] = j
                        n_row += 1
        if n_row == 0:
            continue
        qsort(c.row, n_row, sizeof(intp_t), _cmp_intp)
        if c.n_pairs + n_row > c.capacity:
            m = 2 * (c.n_pairs + n_row) + 64
            grown = <intp_t*> realloc(c.pairs, 2 * m * sizeof(intp_t))
            if grown == NULL:
                return STATUS_MEMORY
            c.pairs = grown
            c.capacity = m
        for k in range(n_row):
            c.pairs[2 * c.n_pairs] = i
            c.pairs[2 * c.n_pairs + 1] = c.row[k]
            c.n_pairs += 1
    return _seed_obstacle_candidates(b, r, c, horizon)


cdef enum:
    OBS_OFF = 1 << 19  # cell offset of the obstacle hash: cells within +-2^19 horizons


cdef inline int64_t _okey(int64_t ci, int64_t cj, int64_t ck) noexcept nogil:
    return ((ci + OBS_OFF) << 40) | ((cj + OBS_OFF) << 20) | (ck + OBS_OFF)


cdef int _seed_obstacle_candidates(Batch* b, intp_t r, Contacts* c, float64_t horizon) noexcept nogil:
    # The seed's collision candidates between robot r's surface voxels (at
    # col_ref) and its fixed obstacle voxels (the seed's walls), with the same
    # rule as between voxels: closer than 3 L and than twice the size of the
    # pair's first voxel in the seed's order (an obstacle keeps its size L).
    cdef:
        intp_t o0 = b.obs_start[r]
        intp_t o1 = b.obs_start[r + 1]
        intp_t n_o = o1 - o0
        intp_t i, m, k, pos_, n_row, mm
        int64_t ci, cj, ck, key
        int di, dj, dk
        float64_t L = b.L
        float64_t inv_cell, dx, dy, dz, d2, act, s_first
        float64_t* R = b.col_ref
        intp_t* grown
    c.n_opairs = 0
    if n_o == 0 or horizon <= 0.0:
        return STATUS_OK
    if c.ocells == NULL:
        c.ocells = <KeyIndex*> malloc(n_o * sizeof(KeyIndex))
        if c.ocells == NULL:
            return STATUS_MEMORY
    inv_cell = 1.0 / horizon
    for m in range(o0, o1):
        c.ocells[m - o0].key = _okey(<int64_t> floor(b.obs[4 * m] * inv_cell),
                                     <int64_t> floor(b.obs[4 * m + 1] * inv_cell),
                                     <int64_t> floor(b.obs[4 * m + 2] * inv_cell))
        c.ocells[m - o0].index = m
    qsort(c.ocells, n_o, sizeof(KeyIndex), _cmp_key_index)
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        if not b.surface[i]:
            continue
        ci = <int64_t> floor(R[4 * i] * inv_cell)
        cj = <int64_t> floor(R[4 * i + 1] * inv_cell)
        ck = <int64_t> floor(R[4 * i + 2] * inv_cell)
        n_row = 0
        for di in range(-1, 2):
            for dj in range(-1, 2):
                for dk in range(-1, 2):
                    key = _okey(ci + di, cj + dj, ck + dk)
                    pos_ = _lower_bound(c.ocells, n_o, key)
                    while pos_ < n_o and c.ocells[pos_].key == key:
                        m = c.ocells[pos_].index
                        pos_ += 1
                        dx = b.obs[4 * m] - R[4 * i]
                        dy = b.obs[4 * m + 1] - R[4 * i + 1]
                        dz = b.obs[4 * m + 2] - R[4 * i + 2]
                        d2 = dx * dx + dy * dy + dz * dz
                        if d2 >= 9.0 * L * L:
                            continue
                        s_first = R[4 * i + 3] if b.seed_rank[i] < b.obs_rank[m] else L
                        act = 2.0 * s_first
                        if d2 >= act * act:
                            continue
                        if c.n_opairs + 1 > c.ocapacity:
                            mm = 2 * (c.n_opairs + 1) + 64
                            grown = <intp_t*> realloc(c.opairs, 2 * mm * sizeof(intp_t))
                            if grown == NULL:
                                return STATUS_MEMORY
                            c.opairs = grown
                            c.ocapacity = mm
                        c.opairs[2 * c.n_opairs] = i
                        c.opairs[2 * c.n_opairs + 1] = m
                        c.n_opairs += 1
                        n_row += 1
        if n_row > 1:
            # the row's obstacles in index order (results independent of the hash)
            qsort(c.opairs + 2 * (c.n_opairs - n_row), n_row, 2 * sizeof(intp_t), _cmp_intp2)
    return STATUS_OK


cdef int _cmp_intp2(const void* a, const void* b) noexcept nogil:
    # (i, m) pairs of one row: by m
    cdef intp_t x = (<const intp_t*> a)[1]
    cdef intp_t y = (<const intp_t*> b)[1]
    return -1 if x < y else (1 if x > y else 0)


cdef void collide_obstacles(Batch* b, Contacts* c) noexcept nogil:
    # OUT (accumulated): force on the voxels touching an obstacle voxel (the
    # seed's contact law; the obstacle is fixed and takes no force)
    cdef:
        intp_t k, i, m
        float64_t dx, dy, dz, d2, env, dist, kk, fmag
    for k in range(c.n_opairs):
        i = c.opairs[2 * k]
        m = c.opairs[2 * k + 1]
        dx = b.pos[3 * i] - b.obs[4 * m]
        dy = b.pos[3 * i + 1] - b.obs[4 * m + 1]
        dz = b.pos[3 * i + 2] - b.obs[4 * m + 2]
        d2 = dx * dx + dy * dy + dz * dz
        env = 0.75 * (b.scale[i] + b.L)
        if d2 >= env * env or d2 == 0.0:
            continue
        dist = sqrt(d2)
        kk = b.k_floor[i] * b.obs[4 * m + 3] / (b.k_floor[i] + b.obs[4 * m + 3])
        fmag = kk * (env - dist) / dist
        b.force[3 * i] += fmag * dx
        b.force[3 * i + 1] += fmag * dy
        b.force[3 * i + 2] += fmag * dz


cdef void collide(Batch* b, Contacts* c) noexcept nogil:
    # OUT (accumulated): force of the touching candidate pairs.
    cdef:
        intp_t k, i, j
        float64_t dx, dy, dz, d2, env, dist, kk, fmag
        const float64_t* P = b.pos
    for k in range(c.n_pairs):
        i = c.pairs[2 * k]
        j = c.pairs[2 * k + 1]
        dx = P[3 * j] - P[3 * i]
        dy = P[3 * j + 1] - P[3 * i + 1]
        dz = P[3 * j + 2] - P[3 * i + 2]
        d2 = dx * dx + dy * dy + dz * dz
        env = 0.75 * (b.scale[i] + b.scale[j])
        if d2 >= env * env or d2 == 0.0:
            continue
        dist = sqrt(d2)
        # E_h L = harmonic mean of the voxels' E L = k1 k2 / (k1 + k2), k = 2 E L
        kk = b.k_floor[i] * b.k_floor[j] / (b.k_floor[i] + b.k_floor[j])
        fmag = kk * (env - dist) / dist
        b.force[3 * j] += fmag * dx
        b.force[3 * j + 1] += fmag * dy
        b.force[3 * j + 2] += fmag * dz
        b.force[3 * i] -= fmag * dx
        b.force[3 * i + 1] -= fmag * dy
        b.force[3 * i + 2] -= fmag * dz
