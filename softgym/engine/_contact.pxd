# Contact and collision: the self-collision candidate lists of one robot
# (one spatial hash for both models), the contact law between voxels and with
# the seed's obstacle voxels (_contact.pyx), and the contact laws with the
# floor and terrain boxes, inline here because the voxel update calls them
# per voxel (_integrate.pyx; box_penetration also _record.robot_energy).

from libc.math cimport sqrt
from libc.stdint cimport int64_t, uint64_t

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport float64_t, intp_t, int32, lane_flag_t


# Self-collision candidates of one robot, rebuilt inside _core.advance_robot (scratch
# owned by the calling thread, freed before it returns).
cdef struct KeyIndex:
    int64_t key              # cell key of a voxel
    intp_t index             # the voxel


cdef struct Contacts:
    intp_t* pairs            # (capacity, 2) candidate pairs i < j, sorted by (i, j)
    intp_t n_pairs           # pairs in use
    intp_t capacity          # pairs allocated
    KeyIndex* cells          # (n_voxels_r,) voxels sorted by spatial-hash cell
    intp_t* row              # (n_voxels_r,) scratch: candidates of one voxel
    float64_t* ref           # (n_voxels_r, 3) positions when the list was built (m)
    float64_t margin         # horizon - largest contact envelope (m)
    float64_t built_scale    # largest voxel size when the list was built (m)
    int32 stale              # 1: rebuild before the next use
    intp_t* opairs           # model 0: (ocapacity, 2) candidate (voxel, obstacle) pairs
    intp_t n_opairs          # obstacle pairs in use
    intp_t ocapacity         # obstacle pairs allocated
    KeyIndex* ocells         # (n_obs_r,) obstacles sorted by spatial-hash cell
    intp_t* dense            # the voxel hash's cell table (SpatialHash.start), kept
    intp_t dense_capacity    # entries allocated in dense
    float64_t* sur           # (4, n_voxels_r) scratch of the all-pairs test: the surface
                             #   voxels' x, y, z and size
    intp_t* sur_idx          # (2, n_voxels_r) scratch: their voxel indices, then their
                             #   ranks in the seed's order
    lane_flag_t* hit         # (n_voxels_r + 8,) scratch: 1 where a pair is a candidate
                             #   (64-bit: softgym_pair_hits' vector lanes), or with AVX-512
                             #   or AVX2 the candidates' indices (softgym_pair_idx)
    uint64_t* xbits          # with AVX-512 or AVX2: the all-pairs test's exclusions, a row of bits
                             #   per surface voxel (bit b of row a: surface voxels a and b are
                             #   within collision_exclusion hops; _exclusion_bits), or NULL
    intp_t xbits_n           # the surface voxels xbits was built for (0: not built)


# The spatial hash of the candidate lists (_contact.pyx, _hash_*): points in
# cubic cells, sorted by cell; a query walks the 27 cells around a point's.
cdef struct SpatialHash:
    KeyIndex* cells          # (n,) the points sorted by (cell key, index) (storage not owned)
    intp_t n                 # points in the hash
    float64_t inv_cell       # 1 / the cells' edge (1/m)
    float64_t x0             # origin (m): cell coordinates are floor((x - x0) / edge) + offset
    float64_t y0
    float64_t z0
    int64_t offset           # keeps the packed cell coordinates (20 bits each) non-negative
    intp_t* start            # NULL, or a dense table over the cells (0..nx-1, 0..ny-1,
                             # 0..nz-1): start[(i ny + j) nz + k] = the first point whose
                             # cell is not before (i, j, k), for lookups without a search
    intp_t ny                # the table's extent along j and k
    intp_t nz


# Candidate lists (called once per robot per rebuild; each returns a STATUS_*).
cdef int contacts_corotational(Batch* b, intp_t r, Contacts* c) noexcept nogil
    # model 1: surface pairs within the horizon of the current positions
cdef int contacts_seed(Batch* b, intp_t r, Contacts* c, int32 snapshot) noexcept nogil
    # model 0: the seed's list at col_ref (snapshot 1: col_ref = now first),
    # then the obstacle pairs

# The contact law (once per robot per step). OUT (accumulated): b.force.
cdef void collide(Batch* b, Contacts* c) noexcept nogil
cdef void collide_obstacles(Batch* b, Contacts* c) noexcept nogil


# ---- contact with static surfaces (inline: called per voxel) ---------------

cdef inline void surface_contact(Batch* b, intp_t i, float64_t nx, float64_t ny, float64_t nz,
                                 float64_t pen, float64_t dt, float64_t* f) noexcept nogil:
    # Penalty contact of voxel i with a static surface of outward unit normal n,
    # penetration pen > 0: normal force 2 E L pen minus collision damping (never
    # pulling), then Coulomb friction in the tangent plane (the seed's floor law,
    # docs/PHYSICS.md, for any normal). IN/OUT: f (force on the voxel), and
    # the voxel's velocity when kinetic friction stops it.
    cdef:
        float64_t* v = b.vel + 3 * i
        float64_t vn, fn, vtx, vty, vtz, vt, ftn, ftx, fty, ftz, fk
    vn = v[0] * nx + v[1] * ny + v[2] * nz
    fn = b.k_floor[i] * pen - b.c_floor[i] * vn
    if fn <= 0.0:
        return  # the surface pushes, never pulls
    f[0] += fn * nx
    f[1] += fn * ny
    f[2] += fn * nz
    vtx = v[0] - vn * nx
    vty = v[1] - vn * ny
    vtz = v[2] - vn * nz
    ftn = f[0] * nx + f[1] * ny + f[2] * nz
    ftx = f[0] - ftn * nx
    fty = f[1] - ftn * ny
    ftz = f[2] - ftn * nz
    if vtx == 0.0 and vty == 0.0 and vtz == 0.0:
        # at rest: static friction holds below mu_s N; above it the voxel
        # starts to slide (no friction on this first step)
        if ftx * ftx + fty * fty + ftz * ftz <= (b.mu_s[i] * fn) ** 2:
            f[0] -= ftx
            f[1] -= fty
            f[2] -= ftz
        return
    vt = sqrt(vtx * vtx + vty * vty + vtz * vtz)
    fk = b.mu_k[i] * fn
    if fk * dt >= b.mass[i] * vt:
        # kinetic friction would reverse the sliding: stop (static from now on)
        v[0] -= vtx
        v[1] -= vty
        v[2] -= vtz
        f[0] -= ftx
        f[1] -= fty
        f[2] -= ftz
    else:
        fk = fk / vt
        f[0] -= fk * vtx
        f[1] -= fk * vty
        f[2] -= fk * vtz


cdef inline float64_t box_penetration(const float64_t* B, const float64_t* p, float64_t rad,
                                      float64_t* n) noexcept nogil:
    # Penetration (m, > 0 when touching) of a sphere of radius rad centred at p
    # into the box B = (x0, y0, z0, x1, y1, z1); n gets the outward unit normal.
    cdef:
        float64_t cx, cy, cz, dx, dy, dz, d2, dist, depth
        intp_t k, a
    if (p[0] + rad <= B[0] or p[0] - rad >= B[3] or p[1] + rad <= B[1]
            or p[1] - rad >= B[4] or p[2] + rad <= B[2] or p[2] - rad >= B[5]):
        return 0.0
    cx = B[0] if p[0] < B[0] else (B[3] if p[0] > B[3] else p[0])
    cy = B[1] if p[1] < B[1] else (B[4] if p[1] > B[4] else p[1])
    cz = B[2] if p[2] < B[2] else (B[5] if p[2] > B[5] else p[2])
    dx = p[0] - cx
    dy = p[1] - cy
    dz = p[2] - cz
    d2 = dx * dx + dy * dy + dz * dz
    if d2 > 0.0:
        if d2 >= rad * rad:
            return 0.0
        dist = sqrt(d2)
        n[0] = dx / dist
        n[1] = dy / dist
        n[2] = dz / dist
        return rad - dist
    # centre inside the box: push out through the nearest face
    n[0] = 0.0
    n[1] = 0.0
    n[2] = 0.0
    depth = p[0] - B[0]
    k = 0
    for a in range(3):
        if p[a] - B[a] < depth:
            depth = p[a] - B[a]
            k = 2 * a
        if B[3 + a] - p[a] < depth:
            depth = B[3 + a] - p[a]
            k = 2 * a + 1
    n[k // 2] = 1.0 if k % 2 == 1 else -1.0
    return rad + depth


cdef inline void seed_floor(Batch* b, intp_t i, float64_t dt, float64_t* f) noexcept nogil:
    # The seed's floor (docs/PHYSICS.md) on voxel i. IN/OUT: f, the voxel's
    # force before the floor (its in-plane part decides static friction), and
    # its velocity when kinetic friction stops it.
    cdef:
        float64_t* v = b.vel + 3 * i
        float64_t pen = 0.5 * b.scale[i] - b.pos[3 * i + 2]
        float64_t n, fd, vs
        int32 stick = 0
    if pen <= 0.0:
        return
    n = b.k_floor[i] * pen
    fd = b.mu_k[i] * n
    if v[0] == 0.0 and v[1] == 0.0:
        if sqrt(f[0] * f[0] + f[1] * f[1]) < b.mu_s[i] * n:
            stick = 1
    else:
        vs = sqrt(v[0] * v[0] + v[1] * v[1])
        if fd * dt < b.mass[i] * vs:
            f[0] -= fd * v[0] / vs
            f[1] -= fd * v[1] / vs
        else:
            stick = 1
            v[0] = 0.0
            v[1] = 0.0
    f[2] += n - b.c_floor[i] * v[2]
    if stick:
        f[0] = 0.0
        f[1] = 0.0
