# Self-collision (docs/PHYSICS.md): surface voxels more than
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
# spatial hash (_hash_*); collide / collide_obstacles apply the contact law. The
# contact laws with the floor and terrain boxes are inline in _contact.pxd.

from libc.math cimport sqrt, floor
from libc.stdint cimport int64_t, uint64_t
from libc.stdlib cimport malloc, realloc, qsort
from libc.string cimport memset

from softgym.engine._batch cimport (Batch, STATUS_OK, STATUS_MEMORY, SOFTGYM_FM_STRIDE,
                                    voxel_pos)
from softgym.engine._typedefs cimport float64_t, intp_t, int32, flag_t, lane_flag_t

# ---------------------------------------------------------------------------
# The spatial hash (SpatialHash, _contact.pxd): points binned in cubic cells
# of one edge, keyed by their packed cell coordinates, sorted by (key, index);
# a query walks the 27 cells around a point's cell in (di, dj, dk) order,
# each cell's points in index order: as the key packs k in its lowest bits,
# the three cells dk = -1, 0, +1 of one (di, dj) are one run of the sorted
# points (_hash_first of the first key, then up to the last), so a query
# makes 9 binary searches, not 27. The voxel hash of a robot (cells from its
# lowest centre, a few per axis) also gets a dense table of where each cell's
# run starts (_hash_table), so its 9 runs are found without a search (profiled:
# the searches' dependent loads were the collision list's time); the obstacle
# hash (cells anywhere within +-2^19) keeps the searches. Used for the voxel
# pairs of both models and for the seed's voxel-obstacle pairs.

cdef enum:
    CELL_BITS = 20           # bits of each packed cell coordinate
    VOXEL_OFF = 1            # cell offset of a robot's voxel hash (origin: its lowest centre)
    OBS_OFF = 1 << 19        # cell offset of the obstacle hash (origin 0): cells within +-2^19 cells
    ALL_PAIRS_MAX = 768      # default of _all_pairs_max


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


cdef int _cmp_intp2(const void* a, const void* b) noexcept nogil:
    # (i, m) pairs of one row: by m
    cdef intp_t x = (<const intp_t*> a)[1]
    cdef intp_t y = (<const intp_t*> b)[1]
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
    # the first k with cells[k].key >= key (n if none); branch-free halving
    # (the compiler makes the select a conditional move: the searched keys are
    # unpredictable, the branchy search mispredicted half its steps)
    cdef intp_t base = 0, half
    if n == 0:
        return 0
    while n > 1:
        half = n >> 1
        base = base + half if cells[base + half].key < key else base
        n -= half
    return base + (cells[base].key < key)


cdef inline int64_t _pack(int64_t ci, int64_t cj, int64_t ck) noexcept nogil:
    return (ci << (2 * CELL_BITS)) | (cj << CELL_BITS) | ck


cdef inline void _hash_init(SpatialHash* h, KeyIndex* cells, float64_t cell, float64_t x0,
                            float64_t y0, float64_t z0, int64_t offset) noexcept nogil:
    # an empty hash over the storage `cells`, cells of edge `cell` (m) from
    # the origin (x0, y0, z0), coordinates shifted by `offset`
    h.cells = cells
    h.n = 0
    h.inv_cell = 1.0 / cell
    h.start = NULL
    h.ny = 0
    h.nz = 0
    h.x0 = x0
    h.y0 = y0
    h.z0 = z0
    h.offset = offset


cdef inline void _hash_cell(const SpatialHash* h, const float64_t* p, int64_t* cijk) noexcept nogil:
    # OUT: cijk, the (offset) cell coordinates of point p
    cijk[0] = <int64_t> floor((p[0] - h.x0) * h.inv_cell) + h.offset
    cijk[1] = <int64_t> floor((p[1] - h.y0) * h.inv_cell) + h.offset
    cijk[2] = <int64_t> floor((p[2] - h.z0) * h.inv_cell) + h.offset


cdef inline void _hash_fill(SpatialHash* h, const float64_t* P, intp_t stride,
                            const flag_t* mask, intp_t lo, intp_t hi) noexcept nogil:
    # the points P + stride * i of i in [lo, hi) (those with mask[i] only,
    # unless mask is NULL), sorted by cell
    cdef:
        intp_t i
        int64_t c[3]
    h.n = 0
    for i in range(lo, hi):
        if mask != NULL and not mask[i]:
            continue
        _hash_cell(h, P + stride * i, c)
        h.cells[h.n].key = _pack(c[0], c[1], c[2])
        h.cells[h.n].index = i
        h.n += 1
    qsort(h.cells, h.n, sizeof(KeyIndex), _cmp_key_index)


cdef inline intp_t _hash_first(const SpatialHash* h, int64_t key) noexcept nogil:
    # the first point of cell `key` (its points run while h.cells[k].key == key)
    return _lower_bound(h.cells, h.n, key)


cdef inline intp_t _hash_column(const SpatialHash* h, const int64_t* ijk, int di, int dj,
                                intp_t* end) noexcept nogil:
    # the points of the cells (i + di, j + dj, k - 1 .. k + 1) around the cell
    # ijk: one run, from the returned index up to *end (OUT) exclusive
    cdef int64_t last
    cdef intp_t d
    if h.start != NULL:
        d = ((ijk[0] + di) * h.ny + ijk[1] + dj) * h.nz + ijk[2] - 1
        end[0] = h.start[d + 3]
        return h.start[d]
    last = _pack(ijk[0] + di, ijk[1] + dj, ijk[2] + 1)
    end[0] = _hash_first(h, last + 1)
    return _hash_first(h, last - 2)


cdef inline void _hash_table(SpatialHash* h, Contacts* c) noexcept nogil:
    # the dense cell table of a filled hash whose cells start at 1 on each
    # axis (VOXEL_OFF; a query reaches one cell beyond the occupied ones):
    # start[d] = the number of points in cells before d, i.e. the first point
    # of cell d's run (the packed key and d order cells alike). Skipped (the
    # queries search) when the cells spread too far for a small table or
    # when memory runs out.
    cdef:
        intp_t k, d, nd, total
        int64_t key, mask = (<int64_t> 1 << CELL_BITS) - 1
        int64_t mi = 0, mj = 0, mk = 0
        intp_t* grown
    if h.n == 0:
        return
    for k in range(h.n):
        key = h.cells[k].key
        if key < 0 or (key >> (2 * CELL_BITS)) < 1 or ((key >> CELL_BITS) & mask) < 1 \
                or (key & mask) < 1:
            return  # not a robot's hash from its lowest centre (or a non-finite point)
        mi = max(mi, key >> (2 * CELL_BITS))
        mj = max(mj, (key >> CELL_BITS) & mask)
        mk = max(mk, key & mask)
    nd = (mi + 2) * (mj + 2) * (mk + 2)
    if nd > 8 * h.n + 512:  # at most ~64 bytes per point beyond a 4 KiB floor
        return
    if nd + 1 > c.dense_capacity:
        grown = <intp_t*> realloc(c.dense, (nd + 1) * sizeof(intp_t))
        if grown == NULL:
            return
        c.dense = grown
        c.dense_capacity = nd + 1
    h.ny = mj + 2
    h.nz = mk + 2
    memset(c.dense, 0, (nd + 1) * sizeof(intp_t))
    for k in range(h.n):
        key = h.cells[k].key
        d = ((key >> (2 * CELL_BITS)) * h.ny + ((key >> CELL_BITS) & mask)) * h.nz + (key & mask)
        c.dense[d + 1] += 1
    total = 0
    for d in range(nd + 1):
        total += c.dense[d]
        c.dense[d] = total
    h.start = c.dense


# ---------------------------------------------------------------------------
# Candidate lists

cdef inline int _alloc_lists(Contacts* c, intp_t n) noexcept nogil:
    # the per-voxel scratch of a robot of n voxels (once)
    if c.cells == NULL:
        c.cells = <KeyIndex*> malloc(n * sizeof(KeyIndex))
        c.row = <intp_t*> malloc(n * sizeof(intp_t))
        c.ref = <float64_t*> malloc(3 * n * sizeof(float64_t))
        c.sur = <float64_t*> malloc(4 * n * sizeof(float64_t))
        c.sur_idx = <intp_t*> malloc(2 * n * sizeof(intp_t))
        # (8 more: softgym_pair_idx stores whole vectors of 8 indices)
        c.hit = <lane_flag_t*> malloc((n + 8) * sizeof(lane_flag_t))
        if c.cells == NULL or c.row == NULL or c.ref == NULL or c.sur == NULL \
                or c.sur_idx == NULL or c.hit == NULL:
            return STATUS_MEMORY
    return STATUS_OK


cdef extern from "softgym_pairs.h":
    # the all-pairs test of one surface voxel against the later ones (C, for
    # the vectorising pragma; documented in include/softgym_pairs.h)
    intp_t softgym_pair_hits(int seed_rule, intp_t a, intp_t n, const float64_t* x,
                           const float64_t* y, const float64_t* z, const float64_t* s,
                           const intp_t* rank, float64_t lim2,
                           lane_flag_t* hit) noexcept nogil
    # with AVX-512 or AVX2 (SOFTGYM_PAIR_IDX 1): the same test, the candidates' indices
    # compressed
    intp_t softgym_pair_idx(int seed_rule, intp_t a, intp_t n, const float64_t* x,
                            const float64_t* y, const float64_t* z, const float64_t* s,
                            const intp_t* rank, float64_t lim2, const uint64_t* xb,
                            lane_flag_t* idx) noexcept nogil
    enum: SOFTGYM_PAIR_IDX


# robots with at most this many surface voxels get the all-pairs test
# (_voxel_pairs_all), larger ones the spatial hash. Profiled on the 6^3 robot
# (152 surface voxels): the hash's walk cost 19 cycles a voxel-step, as much
# as the all-pairs test of ~1,000 surface voxels.
cdef intp_t _all_pairs_max = ALL_PAIRS_MAX


def all_pairs_max(n=None):
    """The most surface voxels a robot may have for the all-pairs candidate test (the spatial
    hash above it); ``n`` sets it (for tests: 0 gives every robot the hash). Returns the
    value before the call."""
    global _all_pairs_max
    cdef intp_t old = _all_pairs_max
    if n is not None:
        _all_pairs_max = n
    return old


cdef inline int _append_row(Contacts* c, intp_t i, intp_t n_row) noexcept nogil:
    # append the pairs (i, c.row[k]) of k < n_row to c.pairs. Returns a STATUS.
    cdef intp_t k, m
    cdef intp_t* grown
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


cdef inline bint _not_excluded(Batch* b, intp_t* e, intp_t e_end, intp_t j) noexcept nogil:
    # whether voxel j is not in the sorted exclusion row b.excl_idx[e[0]..e_end) (e[0]
    # moves past the entries below j: the caller asks in increasing j)
    while e[0] < e_end and b.excl_idx[e[0]] < j:
        e[0] += 1
    return not (e[0] < e_end and b.excl_idx[e[0]] == j)


cdef int _exclusion_bits(Batch* b, intp_t r, Contacts* c, intp_t ns) noexcept nogil:
    # c.xbits: for the ns surface voxels of c.sur_idx (in voxel order), row a's bit b set
    # where surface voxels a and b are within collision_exclusion bond hops (b.excl_*),
    # ns // 64 + 2 words a row (softgym_pair_idx reads a word past the last bit). The
    # exclusion lists and the surface are the layout's, so the rows are built once.
    # Uses c.row as scratch (a voxel's surface index, or -1). Returns a STATUS.
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t words = ns // 64 + 2
        intp_t a, i, j, e, k
        uint64_t* bits
    bits = <uint64_t*> realloc(c.xbits, max(ns, 1) * words * sizeof(uint64_t))
    if bits == NULL:
        return STATUS_MEMORY
    c.xbits = bits
    memset(bits, 0, ns * words * sizeof(uint64_t))
    for i in range(ve - vs):
        c.row[i] = -1
    for a in range(ns):
        c.row[c.sur_idx[a] - vs] = a
    for a in range(ns):
        i = c.sur_idx[a]
        for e in range(b.excl_start[i], b.excl_start[i + 1]):
            j = b.excl_idx[e]
            if vs <= j < ve:
                k = c.row[j - vs]
                if k >= 0:
                    bits[a * words + k // 64] |= (<uint64_t> 1) << (k % 64)
    c.xbits_n = ns
    return STATUS_OK


cdef inline int _voxel_pairs_all(Batch* b, intp_t r, Contacts* c, const float64_t* P,
                                 intp_t stride, float64_t horizon,
                                 const int32 seed_rule) noexcept nogil:
    # _voxel_pairs by testing every pair of surface voxels (softgym_pair_hits,
    # one vector loop per voxel): the same pairs, found in (i, j) order
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t cap = ve - vs
        intp_t i, j, a, k, e, e_end, last, ns = 0, n_row
        float64_t L = b.L
        float64_t lim2
        float64_t* X = c.sur
        float64_t* Y = c.sur + cap
        float64_t* Z = c.sur + 2 * cap
        float64_t* S = c.sur + 3 * cap
        intp_t* RK = c.sur_idx + cap
        int status
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        X[ns] = P[stride * i]
        Y[ns] = P[stride * i + 1]
        Z[ns] = P[stride * i + 2]
        if seed_rule:
            S[ns] = P[stride * i + 3]
            RK[ns] = b.seed_rank[i]
        c.sur_idx[ns] = i
        ns += 1
    lim2 = 9.0 * L * L if seed_rule else horizon * horizon
    if SOFTGYM_PAIR_IDX and c.xbits_n != ns:
        status = _exclusion_bits(b, r, c, ns)
        if status != STATUS_OK:
            return status
    for a in range(ns):
        i = c.sur_idx[a]
        n_row = 0
        if SOFTGYM_PAIR_IDX:
            # the candidates' indices, compressed in the vector lanes (c.hit holds them),
            # the excluded pairs dropped there too (a's row of c.xbits)
            last = softgym_pair_idx(seed_rule, a, ns, X, Y, Z, S, RK, lim2,
                                    c.xbits + a * (ns // 64 + 2), c.hit)
            for k in range(last):
                c.row[k] = c.sur_idx[c.hit[k]]
            n_row = last
        else:
            # a flag a pair; the walk over them ends at the last candidate. The candidates
            # come in increasing j (sur_idx is in voxel order) and i's exclusion row is
            # sorted: one walk along it (e) instead of a binary search per candidate,
            # whose branches the predictor could not learn (_not_excluded)
            e = b.excl_start[i]
            e_end = b.excl_start[i + 1]
            last = softgym_pair_hits(seed_rule, a, ns, X, Y, Z, S, RK, lim2, c.hit)
            for k in range(a + 1, last + 1):
                if c.hit[k]:
                    j = c.sur_idx[k]
                    if _not_excluded(b, &e, e_end, j):
                        c.row[n_row] = j
                        n_row += 1
        if n_row:
            status = _append_row(c, i, n_row)
            if status != STATUS_OK:
                return status
    return STATUS_OK


cdef inline int _voxel_pairs(Batch* b, intp_t r, Contacts* c, const float64_t* P, intp_t stride,
                             float64_t horizon, const int32 seed_rule) noexcept nogil:
    # OUT: c.pairs (appended to c.n_pairs), robot r's surface voxel pairs
    # i < j, not excluded, whose centres P + stride * i (m) are closer than
    # `horizon` (the hash's cell edge), sorted by (i, j). seed_rule (a
    # compile-time constant once inlined): instead of the horizon, the
    # seed's rule, closer than 3 L and than twice the size (P[stride * i + 3])
    # of the pair's first voxel in the seed's order. Returns a STATUS.
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t i, j, k, n_row, end, ns = 0
        float64_t L = b.L
        float64_t h2 = horizon * horizon, x0, y0, z0, dx, dy, dz, d2, act
        intp_t first
        int di, dj, status
        int64_t ijk[3]
        SpatialHash h
    for i in range(vs, ve):
        ns += b.surface[i] != 0
    if ns <= _all_pairs_max:
        return _voxel_pairs_all(b, r, c, P, stride, horizon, seed_rule)
    x0 = P[stride * vs]
    y0 = P[stride * vs + 1]
    z0 = P[stride * vs + 2]
    for i in range(vs, ve):
        if P[stride * i] < x0:
            x0 = P[stride * i]
        if P[stride * i + 1] < y0:
            y0 = P[stride * i + 1]
        if P[stride * i + 2] < z0:
            z0 = P[stride * i + 2]
    # only surface voxels (missing a face bond) collide, as the seed intended:
    # an interior voxel is shielded by its six bonded neighbours
    _hash_init(&h, c.cells, horizon, x0, y0, z0, VOXEL_OFF)
    _hash_fill(&h, P, stride, b.surface, vs, ve)
    _hash_table(&h, c)
    for i in range(vs, ve):
        if not b.surface[i]:
            continue
        n_row = 0
        _hash_cell(&h, P + stride * i, ijk)
        for di in range(-1, 2):
            for dj in range(-1, 2):
                k = _hash_column(&h, ijk, di, dj, &end)
                while k < end:
                    j = h.cells[k].index
                    k += 1
                    if j <= i:
                        continue
                    dx = P[stride * j] - P[stride * i]
                    dy = P[stride * j + 1] - P[stride * i + 1]
                    dz = P[stride * j + 2] - P[stride * i + 2]
                    d2 = dx * dx + dy * dy + dz * dz
                    if seed_rule:
                        if d2 >= 9.0 * L * L:
                            continue
                        first = i if b.seed_rank[i] < b.seed_rank[j] else j
                        act = 2.0 * P[stride * first + 3]
                        if d2 >= act * act:
                            continue
                    elif d2 >= h2:
                        continue
                    if _excluded(b, i, j):
                        continue
                    c.row[n_row] = j
                    n_row += 1
        if n_row == 0:
            continue
        qsort(c.row, n_row, sizeof(intp_t), _cmp_intp)
        status = _append_row(c, i, n_row)
        if status != STATUS_OK:
            return status
    return STATUS_OK


cdef int contacts_corotational(Batch* b, intp_t r, Contacts* c) noexcept nogil:
    # OUT: c.pairs, sorted candidate pairs within the horizon. Returns a STATUS.
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t n = ve - vs
        intp_t i
        float64_t L = b.L
        float64_t smax = L, env, horizon
    if _alloc_lists(c, n) != STATUS_OK:
        return STATUS_MEMORY
    # the positions now (the records, or the step loop's state rows: voxel_pos)
    for i in range(n):
        c.ref[3 * i] = voxel_pos(b, vs + i, 0)
        c.ref[3 * i + 1] = voxel_pos(b, vs + i, 1)
        c.ref[3 * i + 2] = voxel_pos(b, vs + i, 2)
    for i in range(vs, ve):
        if b.scale[i] > smax:
            smax = b.scale[i]
    env = 1.5 * smax                 # the largest envelope 0.75 (s1 + s2)
    c.margin = 0.5 * L
    horizon = env + c.margin
    c.built_scale = smax
    c.stale = 0
    c.n_pairs = 0
    return _voxel_pairs(b, r, c, c.ref - 3 * vs, 3, horizon, 0)  # (indexed by voxel)


cdef int contacts_seed(Batch* b, intp_t r, Contacts* c, int32 snapshot) noexcept nogil:
    # The seed's collision list (CalcL1Bonds with its horizon 2): surface voxel
    # pairs more than the exclusion hops apart whose centres are closer than
    # 3 L and than twice the size of the pair's first voxel in the seed's
    # order, measured at the rebuild; then its obstacle pairs. snapshot: 1
    # copies the current positions and sizes into col_ref first (a rebuild);
    # 0 rebuilds the list of the last rebuild from col_ref (after the state
    # was restored).
    cdef:
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        intp_t i
        int status
        float64_t L = b.L
        float64_t smax = 0.0, horizon
        float64_t* R = b.col_ref
    if _alloc_lists(c, ve - vs) != STATUS_OK:
        return STATUS_MEMORY
    if snapshot:
        for i in range(vs, ve):
            R[4 * i] = voxel_pos(b, i, 0)
            R[4 * i + 1] = voxel_pos(b, i, 1)
            R[4 * i + 2] = voxel_pos(b, i, 2)
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
    status = _voxel_pairs(b, r, c, R, 4, horizon, 1)
    if status != STATUS_OK:
        return status
    return _obstacle_pairs(b, r, c, horizon)


cdef int _obstacle_pairs(Batch* b, intp_t r, Contacts* c, float64_t horizon) noexcept nogil:
    # The seed's collision candidates between robot r's surface voxels (at
    # col_ref) and its fixed obstacle voxels (the seed's walls), with the same
    # rule as between voxels: closer than 3 L and than twice the size of the
    # pair's first voxel in the seed's order (an obstacle keeps its size L).
    cdef:
        intp_t o0 = b.obs_start[r]
        intp_t o1 = b.obs_start[r + 1]
        intp_t n_o = o1 - o0
        intp_t i, m, k, n_row, mm, end
        int di, dj
        int64_t ijk[3]
        float64_t L = b.L
        float64_t dx, dy, dz, d2, act, s_first
        float64_t* R = b.col_ref
        intp_t* grown
        SpatialHash h
    c.n_opairs = 0
    if n_o == 0 or horizon <= 0.0:
        return STATUS_OK
    if c.ocells == NULL:
        c.ocells = <KeyIndex*> malloc(n_o * sizeof(KeyIndex))
        if c.ocells == NULL:
            return STATUS_MEMORY
    _hash_init(&h, c.ocells, horizon, 0.0, 0.0, 0.0, OBS_OFF)
    _hash_fill(&h, b.obs, 4, NULL, o0, o1)
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        if not b.surface[i]:
            continue
        n_row = 0
        _hash_cell(&h, R + 4 * i, ijk)
        for di in range(-1, 2):
            for dj in range(-1, 2):
                k = _hash_column(&h, ijk, di, dj, &end)
                while k < end:
                    m = h.cells[k].index
                    k += 1
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


cdef inline float64_t _pair_law(Batch* b, intp_t i, intp_t j, float64_t* d) noexcept nogil:
    # the contact law of voxels i and j (d: p_j - p_i): the force on j is fmag d, on i
    # -fmag d; fmag 0 where their envelopes do not overlap (or they coincide)
    cdef float64_t d2, env, dist, kk
    d[0] = voxel_pos(b, j, 0) - voxel_pos(b, i, 0)
    d[1] = voxel_pos(b, j, 1) - voxel_pos(b, i, 1)
    d[2] = voxel_pos(b, j, 2) - voxel_pos(b, i, 2)
    d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    env = 0.75 * (b.scale[i] + b.scale[j])
    if d2 >= env * env or d2 == 0.0:
        return 0.0
    dist = sqrt(d2)
    # E_h L = harmonic mean of the voxels' E L = k1 k2 / (k1 + k2), k = 2 E L
    kk = b.k_floor[i] * b.k_floor[j] / (b.k_floor[i] + b.k_floor[j])
    return kk * (env - dist) / dist


cdef inline float64_t _obstacle_law(Batch* b, intp_t i, intp_t m, float64_t* d) noexcept nogil:
    # the contact law of voxel i and obstacle voxel m (d: p_i - p_m): the force on i is
    # fmag d (the obstacle is fixed and takes none); fmag 0 where they do not touch
    cdef float64_t d2, env, dist, kk
    d[0] = voxel_pos(b, i, 0) - b.obs[4 * m]
    d[1] = voxel_pos(b, i, 1) - b.obs[4 * m + 1]
    d[2] = voxel_pos(b, i, 2) - b.obs[4 * m + 2]
    d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    env = 0.75 * (b.scale[i] + b.L)
    if d2 >= env * env or d2 == 0.0:
        return 0.0
    dist = sqrt(d2)
    kk = b.k_floor[i] * b.obs[4 * m + 3] / (b.k_floor[i] + b.obs[4 * m + 3])
    return kk * (env - dist) / dist


# collide and collide_obstacles with single-precision links: the same contact forces,
# rounded to float and added to the voxels' float rows of link forces (b.link_f, which the
# voxel update reads instead of b.force; loops of their own, so that the double loops'
# products and sums fuse as they did)
cdef void _collide32(Batch* b, Contacts* c) noexcept nogil:
    cdef:
        intp_t k, i, j, s = b.link_fs
        float64_t fmag
        float64_t d[3]
        float f[3]
        float* lf = b.link_f
        int a
    for k in range(c.n_pairs):
        i = c.pairs[2 * k]
        j = c.pairs[2 * k + 1]
        fmag = _pair_law(b, i, j, d)
        if fmag == 0.0:
            continue
        for a in range(3):
            f[a] = <float> (fmag * d[a])
            lf[a * s + j] += f[a]
            lf[a * s + i] -= f[a]


cdef void _collide_obstacles32(Batch* b, Contacts* c) noexcept nogil:
    cdef:
        intp_t k, i, s = b.link_fs
        float64_t fmag
        float64_t d[3]
        float* lf = b.link_f
        int a
    for k in range(c.n_opairs):
        i = c.opairs[2 * k]
        fmag = _obstacle_law(b, i, c.opairs[2 * k + 1], d)
        if fmag == 0.0:
            continue
        for a in range(3):
            lf[a * s + i] += <float> (fmag * d[a])


cdef void collide_obstacles(Batch* b, Contacts* c) noexcept nogil:
    # OUT (accumulated): force on the voxels touching an obstacle voxel (the
    # seed's contact law; the obstacle is fixed and takes no force)
    cdef:
        intp_t k, i
        float64_t fmag
        float64_t d[3]
    if b.link_f != NULL:
        _collide_obstacles32(b, c)
        return
    for k in range(c.n_opairs):
        i = c.opairs[2 * k]
        fmag = _obstacle_law(b, i, c.opairs[2 * k + 1], d)
        if fmag == 0.0:
            continue
        b.force[SOFTGYM_FM_STRIDE * i] += fmag * d[0]
        b.force[SOFTGYM_FM_STRIDE * i + 1] += fmag * d[1]
        b.force[SOFTGYM_FM_STRIDE * i + 2] += fmag * d[2]


cdef void collide(Batch* b, Contacts* c) noexcept nogil:
    # OUT (accumulated): force of the touching candidate pairs.
    cdef:
        intp_t k, i, j
        float64_t fmag
        float64_t d[3]
    if b.link_f != NULL:
        _collide32(b, c)
        return
    for k in range(c.n_pairs):
        i = c.pairs[2 * k]
        j = c.pairs[2 * k + 1]
        fmag = _pair_law(b, i, j, d)
        if fmag == 0.0:
            continue
        b.force[SOFTGYM_FM_STRIDE * j] += fmag * d[0]
        b.force[SOFTGYM_FM_STRIDE * j + 1] += fmag * d[1]
        b.force[SOFTGYM_FM_STRIDE * j + 2] += fmag * d[2]
        b.force[SOFTGYM_FM_STRIDE * i] -= fmag * d[0]
        b.force[SOFTGYM_FM_STRIDE * i + 1] -= fmag * d[1]
        b.force[SOFTGYM_FM_STRIDE * i + 2] -= fmag * d[2]
