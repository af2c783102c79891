# The step kernel of softgym: a co-rotational beam lattice of rigid voxels,
# integrated with symplectic Euler, batched over robots and parallel over them.
#
# Physics (see SEED_REFERENCE section 1 and softgym/engine/simulation.py):
# - each voxel is a rigid cube (position, quaternion, velocity, angular velocity);
# - each face-adjacent pair is joined by an Euler-Bernoulli beam measured in a
#   frame that turns with the link (co-rotational), so large rigid rotations are
#   exact:
#       axial extension   e    = |d| - (s1 + s2) / 2   along u = d / |d|
#       bending vectors   b_i  = r x a_i - r x d / L
#                         (a_i = voxel i's lattice axis of the link,
#                          r = (a1 + a2) / |a1 + a2|, L the nominal size: the
#                          seed's small-angle beam, whose stiffness does not
#                          grow when actuated voxels shrink)
#       twist             tau  = (z1 . y2 - y1 . z2) / 2  (y, z: the other lattice axes)
#   with the Hermite beam element's moments M1 = -k_b (2 b1 + b2),
#   M2 = -k_b (b1 + 2 b2), torsion +-k_t tau r, axial force -k_a e u on voxel 2
#   and the shear force that balances the moments, r x (M1 + M2) / L.
#   Damping uses the same forms with the deformation rates, so its power is
#   never positive.
# - floor and terrain boxes: penalty normal force, collision damping and
#   Coulomb friction (static threshold, kinetic coefficient) as the seed's
#   floor, along the surface's normal;
# - self-collision between surface voxels far apart in the lattice graph (the
#   seed's spherical-envelope law), candidates from a per-robot spatial hash.
#
# The link forces come from a branch-free kernel over restrict pointers that
# the compiler vectorises (gathers + SIMD), then are scattered in link order,
# so results are deterministic and independent of threads and batching.
#
# The code walks flat arrays through raw pointers; bounds are checked by the
# Python wrapper (simulation.py) once, never here.

from cython.parallel cimport prange, parallel, threadid
from libc.math cimport sin, cos, acos, sqrt, fabs, floor, M_PI
from libc.stdint cimport int64_t
from libc.stdlib cimport calloc, malloc, realloc, free, qsort
from libc.string cimport memcpy, memset

cimport numpy as cnp
import numpy as np

from softgym.engine._typedefs cimport float64_t, intp_t, step_t, int32, flag_t

cnp.import_array()

cdef float64_t RUNAWAY = 1.0e6  # |coordinate| (m) beyond which a robot diverged


cdef inline void _rotation_matrix(const float64_t* q, float64_t* R) noexcept nogil:
    # R = rotation matrix of the unit quaternion q = (w, x, y, z), row-major.
    cdef float64_t w = q[0], x = q[1], y = q[2], z = q[3]
    R[0] = 1.0 - 2.0 * (y * y + z * z)
    R[1] = 2.0 * (x * y - w * z)
    R[2] = 2.0 * (x * z + w * y)
    R[3] = 2.0 * (x * y + w * z)
    R[4] = 1.0 - 2.0 * (x * x + z * z)
    R[5] = 2.0 * (y * z - w * x)
    R[6] = 2.0 * (x * z - w * y)
    R[7] = 2.0 * (y * z + w * x)
    R[8] = 1.0 - 2.0 * (x * x + y * y)


cdef inline float64_t _actuate(Batch* b, intp_t r) noexcept nogil:
    # OUT: b.scale of robot r's voxels at the robot's current time.
    # Returns the largest size written this step (0 if none).
    cdef:
        intp_t i
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        float64_t t = b.steps[r] * b.dt[r]
        float64_t L = b.L
        float64_t lo = b.min_scale * L
        float64_t f, new, s, c, amp, w
        float64_t smax = 0.0
        int32 seed = b.actuation_mode == 0
    if b.use_temp[r]:
        for i in range(vs, ve):
            if b.cte[i] == 0.0:
                continue
            new = L * (1.0 + b.cte[i] * b.temp[i])
            if seed:
                if new >= lo and new <= L:
                    b.scale[i] = new
            else:
                b.scale[i] = new if new > lo else lo
            if b.scale[i] > smax:
                smax = b.scale[i]
        return smax
    if t < b.init_time:
        return smax  # nominal sizes until the settling time is over (scale starts at L)
    if b.model == 0:
        w = SEED_2PI_DRIVE * (t / b.period[r])  # the seed's sin(2 pi_f (t / T))
    else:
        w = 2.0 * M_PI / b.period[r] * t
    s = sin(w)
    c = cos(w)
    amp = b.temp_amp[r]
    for i in range(vs, ve):
        if b.cte[i] == 0.0:
            continue
        f = b.cte[i] * amp * (s * b.cos_phase[i] + c * b.sin_phase[i])
        new = L * (1.0 + f)
        if seed:
            # the seed's engine: outside [min_scale L, L] the previous size is kept
            if new >= lo and new <= L:
                b.scale[i] = new
        else:
            b.scale[i] = new if new > lo else lo
        if b.scale[i] > smax:
            smax = b.scale[i]
    return smax


cdef inline int _link_forces(Batch* b, intp_t r) noexcept nogil:
    # IN: positions, rotations, velocities, scales. OUT (accumulated): force, moment.
    # A robot's links are sorted by axis (x, then y, then z); each run gets a
    # copy of the loop with constant axis indices.
    cdef:
        intp_t lo = b.link_start[r]
        intp_t hi = b.link_start[r + 1]
        intp_t nx = b.link_axis_count[3 * r]
        intp_t ny = b.link_axis_count[3 * r + 1]
    if _links_along(b, lo, lo + nx, 0, 1, 2) != STATUS_OK:
        return STATUS_STRAIN
    if _links_along(b, lo + nx, lo + nx + ny, 1, 2, 0) != STATUS_OK:
        return STATUS_STRAIN
    return _links_along(b, lo + nx + ny, hi, 2, 0, 1)


cdef extern from *:
    # restrict-qualified pointers: the link kernel's inputs and outputs never
    # alias, which lets the compiler vectorise it (gathers + SIMD arithmetic)
    ctypedef double* f64_rp "double * __restrict__"
    ctypedef const double* cf64_rp "const double * __restrict__"
    ctypedef const Py_ssize_t* cintp_rp "const Py_ssize_t * __restrict__"


cdef enum:
    N_LINK_OUT = 25  # rows of the per-link scratch (see _link_kernel, _seed_links_along)
    N_VOX_OUT = 4    # rows of the per-voxel scratch (see _seed_orient)


cdef void _link_kernel(intp_t lo, intp_t hi, intp_t ax, intp_t p, intp_t q,
                       float64_t inv_L, cintp_rp v1, cintp_rp v2,
                       cf64_rp pos, cf64_rp vel, cf64_rp av, cf64_rp rot, cf64_rp scale,
                       cf64_rp k_axial, cf64_rp c_axial, cf64_rp k_bend, cf64_rp c_bend,
                       cf64_rp k_torsion, cf64_rp c_torsion,
                       f64_rp ext, f64_rp fx, f64_rp fy, f64_rp fz,
                       f64_rp m1x, f64_rp m1y, f64_rp m1z,
                       f64_rp m2x, f64_rp m2y, f64_rp m2z) noexcept nogil:
    # Links lo..hi, all along lattice axis `ax` ((ax, p, q) a cyclic
    # permutation of (0, 1, 2)). IN: the voxels' state. OUT, per link: |axial
    # extension| (ext), force on voxel 2 (f; voxel 1 gets -f) and moments on
    # voxels 1 and 2 (m1, m2). No branches and no scatter: the loop vectorises.
    cdef:
        intp_t li, i, j
        float64_t dx, dy, dz, ell, inv_l, e, edot, fa, ax_x, ax_y, ax_z
        float64_t dvx, dvy, dvz, a1x, a1y, a1z, a2x, a2y, a2z
        float64_t rx, ry, rz, inv_r, cx, cy, cz, hx, hy, hz, tw, twdot, uw
        float64_t wcx, wcy, wcz, w1x, w1y, w1z, w2x, w2y, w2z
        float64_t kb, cb, tor, n1x, n1y, n1z, n2x, n2y, n2z, sx, sy, sz
    for li in range(lo, hi):
        i = v1[li]
        j = v2[li]
        dx = pos[3 * j] - pos[3 * i]
        dy = pos[3 * j + 1] - pos[3 * i + 1]
        dz = pos[3 * j + 2] - pos[3 * i + 2]
        ell = sqrt(dx * dx + dy * dy + dz * dz)
        e = ell - 0.5 * (scale[i] + scale[j])
        ext[li] = fabs(e)  # NaN stays NaN: the caller's check catches it
        # axial force on voxel 2 along the chord u = d / |d| (elastic + damping)
        dvx = vel[3 * j] - vel[3 * i]
        dvy = vel[3 * j + 1] - vel[3 * i + 1]
        dvz = vel[3 * j + 2] - vel[3 * i + 2]
        inv_l = 1.0 / ell
        edot = (dx * dvx + dy * dvy + dz * dvz) * inv_l
        fa = (k_axial[li] * e + c_axial[li] * edot) * inv_l
        ax_x = -fa * dx
        ax_y = -fa * dy
        ax_z = -fa * dz
        # lattice axis of the link in each voxel (column ax of its rotation)
        # and the link's frame axis r, their bisector
        a1x = rot[9 * i + ax]
        a1y = rot[9 * i + 3 + ax]
        a1z = rot[9 * i + 6 + ax]
        a2x = rot[9 * j + ax]
        a2y = rot[9 * j + 3 + ax]
        a2z = rot[9 * j + 6 + ax]
        rx = a1x + a2x
        ry = a1y + a2y
        rz = a1z + a2z
        # 1 / |a1 + a2| by one Newton step from 1/2 (|a1 + a2|^2 = 4 - |a1 - a2|^2
        # is near 4): relative error 0.14 % at 0.5 rad of relative bending
        inv_r = 0.5 * (1.5 - 0.125 * (rx * rx + ry * ry + rz * rz))
        rx = rx * inv_r
        ry = ry * inv_r
        rz = rz * inv_r
        # transverse offset of voxel 2 as an angle on the nominal length,
        # c = r x d / L (the seed's Pos2.y / L: stiffness does not grow when
        # actuated voxels shrink)
        cx = (ry * dz - rz * dy) * inv_L
        cy = (rz * dx - rx * dz) * inv_L
        cz = (rx * dy - ry * dx) * inv_L
        # bending of each voxel relative to the link, b_i = r x a_i - c; as r
        # bisects a1 and a2, r x a2 = -(r x a1) = h = inv_r (a1 x a2), so
        # b1 = -h - c and b2 = h - c
        hx = (a1y * a2z - a1z * a2y) * inv_r
        hy = (a1z * a2x - a1x * a2z) * inv_r
        hz = (a1x * a2y - a1y * a2x) * inv_r
        # twist of voxel 2 relative to voxel 1 about the link: with y, z the
        # voxels' two other lattice axes, sin(twist) = (z1 . y2 - y1 . z2) / 2
        tw = 0.5 * (rot[9 * i + q] * rot[9 * j + p] + rot[9 * i + 3 + q] * rot[9 * j + 3 + p]
                    + rot[9 * i + 6 + q] * rot[9 * j + 6 + p] - rot[9 * i + p] * rot[9 * j + q]
                    - rot[9 * i + 3 + p] * rot[9 * j + 3 + q]
                    - rot[9 * i + 6 + p] * rot[9 * j + 6 + q])
        # rates: transverse angle (wc = r x dv / L), the voxels' angular
        # velocities across the link (w_i minus its part along r) and twist
        wcx = (ry * dvz - rz * dvy) * inv_L
        wcy = (rz * dvx - rx * dvz) * inv_L
        wcz = (rx * dvy - ry * dvx) * inv_L
        w1x = av[3 * i]
        w1y = av[3 * i + 1]
        w1z = av[3 * i + 2]
        uw = rx * w1x + ry * w1y + rz * w1z
        w1x = w1x - uw * rx
        w1y = w1y - uw * ry
        w1z = w1z - uw * rz
        twdot = -uw
        w2x = av[3 * j]
        w2y = av[3 * j + 1]
        w2z = av[3 * j + 2]
        uw = rx * w2x + ry * w2y + rz * w2z
        w2x = w2x - uw * rx
        w2y = w2y - uw * ry
        w2z = w2z - uw * rz
        twdot = twdot + uw
        # bending moments: elastic -k_b (2 b1 + b2) = k_b (h + 3 c) on voxel 1,
        # -k_b (b1 + 2 b2) = k_b (3 c - h) on voxel 2; damping the same form
        # with the bending rates (w_i - wc)
        kb = k_bend[li]
        cb = c_bend[li]
        n1x = kb * (hx + 3.0 * cx) - cb * (2.0 * w1x + w2x - 3.0 * wcx)
        n1y = kb * (hy + 3.0 * cy) - cb * (2.0 * w1y + w2y - 3.0 * wcy)
        n1z = kb * (hz + 3.0 * cz) - cb * (2.0 * w1z + w2z - 3.0 * wcz)
        n2x = kb * (3.0 * cx - hx) - cb * (w1x + 2.0 * w2x - 3.0 * wcx)
        n2y = kb * (3.0 * cy - hy) - cb * (w1y + 2.0 * w2y - 3.0 * wcy)
        n2z = kb * (3.0 * cz - hz) - cb * (w1z + 2.0 * w2z - 3.0 * wcz)
        # force on voxel 2: axial plus the shear that balances the bending
        # moments over the nominal length
        sx = n1x + n2x
        sy = n1y + n2y
        sz = n1z + n2z
        fx[li] = ax_x + (ry * sz - rz * sy) * inv_L
        fy[li] = ax_y + (rz * sx - rx * sz) * inv_L
        fz[li] = ax_z + (rx * sy - ry * sx) * inv_L
        # torsion, equal and opposite along r
        tor = k_torsion[li] * tw + c_torsion[li] * twdot
        m1x[li] = n1x + tor * rx
        m1y[li] = n1y + tor * ry
        m1z[li] = n1z + tor * rz
        m2x[li] = n2x - tor * rx
        m2y[li] = n2y - tor * ry
        m2z[li] = n2z - tor * rz


cdef inline int _links_along(Batch* b, intp_t lo, intp_t hi,
                             const intp_t ax, const intp_t p, const intp_t q) noexcept nogil:
    # Links lo..hi along axis `ax`: the vectorised kernel, then the strain
    # check and the scatter of forces and moments in link order.
    cdef:
        intp_t li, i, j
        intp_t n = b.link_stride  # the scratch's row stride
        float64_t max_ext = b.max_strain * b.L
        float64_t* o = b.link_out
        float64_t* force = b.force
        float64_t* moment = b.moment
    if hi <= lo:
        return STATUS_OK
    _link_kernel(lo, hi, ax, p, q, 1.0 / b.L, b.v1, b.v2, b.pos, b.vel, b.angvel, b.rot,
                 b.scale, b.k_axial, b.c_axial, b.k_bend, b.c_bend, b.k_torsion, b.c_torsion,
                 o, o + n, o + 2 * n, o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n,
                 o + 7 * n, o + 8 * n, o + 9 * n)
    for li in range(lo, hi):
        if not (o[li] <= max_ext):
            return STATUS_STRAIN  # also catches NaN
        i = b.v1[li]
        j = b.v2[li]
        force[3 * j] += o[n + li]
        force[3 * j + 1] += o[2 * n + li]
        force[3 * j + 2] += o[3 * n + li]
        force[3 * i] -= o[n + li]
        force[3 * i + 1] -= o[2 * n + li]
        force[3 * i + 2] -= o[3 * n + li]
        moment[3 * i] += o[4 * n + li]
        moment[3 * i + 1] += o[5 * n + li]
        moment[3 * i + 2] += o[6 * n + li]
        moment[3 * j] += o[7 * n + li]
        moment[3 * j + 1] += o[8 * n + li]
        moment[3 * j + 2] += o[9 * n + li]
    return STATUS_OK



# ---------------------------------------------------------------------------
# Model 0, "seed": the step of the seed study's engine (evosoro's bundled
# VoxCAD-era Voxelyze, SEED_REFERENCE section 1), written anew from its
# documented behaviour and checked against that engine's output
# (benchmarks/fidelity_seed.py):
# - each link is a beam measured in the frame of its first voxel (the one on
#   the negative side): rotate the relative position and voxel 2's
#   orientation into voxel 1's frame (the link axis turned onto +x); while the
#   relative rotation stays under ~1 degree, the transverse offset is under
#   5 % of the axial distance and the extension under 30 % (with 10 %
#   hysteresis on leaving) the "small-angle" beam applies (voxel 1's angle is
#   zero, offsets taken along voxel 1's axes); otherwise the "large-angle"
#   beam is measured from the chord (offsets zero, both ends' angles relative
#   to it);
# - link damping acts on finite differences of those bond-frame quantities
#   (so it also sees the rate of the actuated rest length), and is skipped,
#   with its memory left untouched, on a step where the link changed mode;
# - a link between voxels of two materials gives voxel 2 its own damping
#   (with voxel 2's mass); one of a single material gives voxel 2 exactly -F1;
# - floor: normal force 2 E L pen without clamping, damping on top, friction
#   bounded by mu 2 E L pen (damping excluded); static friction zeroes the
#   in-plane force of a voxel whose in-plane velocity is exactly zero;
# - orientations renormalised exactly and snapped to the identity when
#   w >= 1; voxel sizes follow the drive at the end of the step (so the
#   link forces of a step use the previous step's sizes);
# - every voxel is a self-collision candidate (the seed's surface test is
#   always true), the drive's 2 pi is the single-precision constant.

cdef float64_t SEED_PI = 3.14159265358979         # the seed's PI macro
cdef float64_t SEED_2PI_DRIVE = 2.0 * <float64_t> (<float> 3.1415926)
cdef float64_t SMALL_ANGLE_RAD = 1.732e-2          # relative rotation of a small-angle link
cdef float64_t HYSTERESIS = 1.1
cdef float64_t SMALL_ANGLE_W = cos(0.5 * SMALL_ANGLE_RAD)
cdef float64_t SMALLISH_ANGLE_W = cos(HYSTERESIS * SMALL_ANGLE_RAD * 0.5)
cdef float64_t SLTHRESH_ACOS2SQRT = 1.0 - 0.9988 * 0.9988
cdef float64_t DISCARD_ANGLE_RAD = 1.0e-7
cdef float64_t SA_BOND_BEND_RAD = 0.05
cdef float64_t SA_BOND_EXT_PERC = 1.30


cdef inline void _qmul(const float64_t* a, const float64_t* c, float64_t* o) noexcept nogil:
    # o = a c (o must not alias a or c)
    o[0] = a[0] * c[0] - a[1] * c[1] - a[2] * c[2] - a[3] * c[3]
    o[1] = a[0] * c[1] + a[1] * c[0] + a[2] * c[3] - a[3] * c[2]
    o[2] = a[0] * c[2] - a[1] * c[3] + a[2] * c[0] + a[3] * c[1]
    o[3] = a[0] * c[3] + a[1] * c[2] - a[2] * c[1] + a[3] * c[0]


cdef inline void _qrot_inv(const float64_t* q, const float64_t* f, float64_t* o) noexcept nogil:
    # o = q* f q: f expressed in the frame q (o must not alias f)
    cdef float64_t tw, tx, ty, tz
    tw = q[1] * f[0] + q[2] * f[1] + q[3] * f[2]
    tx = q[0] * f[0] - q[2] * f[2] + q[3] * f[1]
    ty = q[0] * f[1] + q[1] * f[2] - q[3] * f[0]
    tz = q[0] * f[2] - q[1] * f[1] + q[2] * f[0]
    o[0] = tw * q[1] + tx * q[0] + ty * q[3] - tz * q[2]
    o[1] = tw * q[2] - tx * q[3] + ty * q[0] + tz * q[1]
    o[2] = tw * q[3] + tx * q[2] - ty * q[1] + tz * q[0]


cdef inline void _rotvec(const float64_t* q, float64_t* o) noexcept nogil:
    # rotation vector of the unit quaternion q (angle from w, as the seed)
    cdef float64_t sl = 1.0 - q[0] * q[0], w = q[0] if q[0] < 1.0 else 1.0, k
    if sl <= 0.0:
        o[0] = 0.0
        o[1] = 0.0
        o[2] = 0.0
        return
    if sl < SLTHRESH_ACOS2SQRT:
        k = 2.0 * sqrt((2.0 - 2.0 * w) / sl)
    else:
        k = 2.0 * acos(w) / sqrt(sl)
    o[0] = q[1] * k
    o[1] = q[2] * k
    o[2] = q[3] * k


cdef inline void _to_pos_x(const float64_t* v, float64_t* q) noexcept nogil:
    # q: the rotation (axis normal to x) that turns v onto +x
    cdef float64_t yx, zx, l, nx, ny, nz, th, am, s
    q[0] = 1.0
    q[1] = 0.0
    q[2] = 0.0
    q[3] = 0.0
    if v[0] == 0.0 and v[1] == 0.0 and v[2] == 0.0:
        return
    yx = v[1] / v[0]
    zx = v[2] / v[0]
    if yx < SMALL_ANGLE_RAD and yx > -SMALL_ANGLE_RAD and zx < SMALL_ANGLE_RAD and zx > -SMALL_ANGLE_RAD:
        q[2] = 0.5 * zx
        q[3] = -0.5 * yx
        q[0] = 1.0 + 0.5 * (-q[2] * q[2] - q[3] * q[3])
        return
    l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    nx = v[0] / l
    ny = v[1] / l
    nz = v[2] / l
    th = acos(nx)
    if th > SEED_PI - DISCARD_ANGLE_RAD:
        q[0] = 0.0
        q[2] = 1.0
        return
    am = 1.0 / sqrt(nz * nz + ny * ny)
    s = sin(0.5 * th)
    q[0] = cos(0.5 * th)
    q[2] = nz * am * s
    q[3] = -ny * am * s


cdef inline void _to_x(intp_t ax, float64_t* v) noexcept nogil:
    # lattice axis ax turned onto +x (a proper rotation, as the seed's bond frame)
    cdef float64_t t
    if ax == 1:
        t = v[0]
        v[0] = v[1]
        v[1] = -t
    elif ax == 2:
        t = v[0]
        v[0] = v[2]
        v[2] = -t


cdef inline void _from_x(intp_t ax, float64_t* v) noexcept nogil:
    # inverse of _to_x
    cdef float64_t t
    if ax == 1:
        t = v[1]
        v[1] = v[0]
        v[0] = -t
    elif ax == 2:
        t = v[2]
        v[2] = v[0]
        v[0] = -t


cdef inline float64_t _rotvec_k(float64_t w) noexcept nogil:
    # the seed's rotation vector of a unit quaternion (w, x, y, z) is k (x, y, z)
    # (angle from w, with its acos approximation near the identity)
    cdef float64_t sl = 1.0 - w * w
    if sl <= 0.0:
        return 0.0
    if w > 1.0:
        w = 1.0
    if sl < SLTHRESH_ACOS2SQRT:
        return 2.0 * sqrt((2.0 - 2.0 * w) / sl)
    return 2.0 * acos(w) / sqrt(sl)


cdef inline void _bond_to_world(const int ax, const float64_t* R, float64_t v0, float64_t v1,
                                float64_t v2, float64_t* o) noexcept nogil:
    # o = R P^T v: a bond-frame vector v back to the world through the inverse
    # axis turn P^T (ax: a compile-time constant once inlined) and the voxel
    # rotation R (row-major 3x3)
    cdef float64_t x, y, z
    if ax == 0:
        x = v0
        y = v1
        z = v2
    elif ax == 1:
        x = -v1
        y = v0
        z = v2
    else:
        x = -v2
        y = v1
        z = v0
    o[0] = R[0] * x + R[1] * y + R[2] * z
    o[1] = R[3] * x + R[4] * y + R[5] * z
    o[2] = R[6] * x + R[7] * y + R[8] * z


cdef inline void _add_bond_to_world(const int ax, const float64_t* R, float64_t v0, float64_t v1,
                                    float64_t v2, float64_t* acc) noexcept nogil:
    # acc += R P^T v (_bond_to_world, then the sum)
    cdef float64_t w[3]
    _bond_to_world(ax, R, v0, v1, v2, w)
    acc[0] += w[0]
    acc[1] += w[1]
    acc[2] += w[2]


cdef void _seed_geom(intp_t lo, intp_t hi, intp_t ax, cintp_rp v1, cintp_rp v2,
                     cf64_rp pos, cf64_rp rot, cf64_rp quat, cf64_rp scale,
                     f64_rp o_p0, f64_rp o_p1, f64_rp o_p2, f64_rp o_qw,
                     f64_rp o_n1, f64_rp o_n2, f64_rp o_n3, f64_rp o_nom,
                     f64_rp o_len, f64_rp o_st) noexcept nogil:
    # Model 0's link geometry for links lo..hi, all along axis ax, without
    # branches so the loop vectorises: the relative position p and voxel 2's
    # orientation relative to voxel 1 (q1* q2 = (qw, n)), both in the bond
    # frame (voxel 1's frame turned by the proper rotation P that takes the
    # link axis onto +x, the seed's ToXDirBond: (x, y, z) -> (x, y, z),
    # (y, -x, z), (z, y, -x) for ax 0, 1, 2); the nominal length, the chord
    # length and the transverse ratio. Component c of a bond-frame vector is
    # s_c times local component a_c (s = +-1: exact).
    cdef:
        intp_t li, i, j
        intp_t a0 = ax
        intp_t a1 = 0 if ax == 1 else 1
        intp_t a2 = 0 if ax == 2 else 2
        float64_t s1 = -1.0 if ax == 1 else 1.0
        float64_t s2 = -1.0 if ax == 2 else 1.0
        # n = W (qx, qy, qz): W's rows one-hot (x 1 + y 0 + z 0 = x exactly)
        float64_t w00 = 1.0 if a0 == 0 else 0.0
        float64_t w01 = 1.0 if a0 == 1 else 0.0
        float64_t w02 = 1.0 if a0 == 2 else 0.0
        float64_t w10 = s1 if a1 == 0 else 0.0
        float64_t w11 = s1 if a1 == 1 else 0.0
        float64_t w12 = s1 if a1 == 2 else 0.0
        float64_t w20 = s2 if a2 == 0 else 0.0
        float64_t w21 = s2 if a2 == 1 else 0.0
        float64_t w22 = s2 if a2 == 2 else 0.0
        float64_t dx, dy, dz, qw, qx, qy, qz, p0, p1, p2
    for li in range(lo, hi):
        i = v1[li]
        j = v2[li]
        dx = pos[3 * j] - pos[3 * i]
        dy = pos[3 * j + 1] - pos[3 * i + 1]
        dz = pos[3 * j + 2] - pos[3 * i + 2]
        # relative position in voxel 1's frame (column a of its rotation . d)
        p0 = rot[9 * i + a0] * dx + rot[9 * i + 3 + a0] * dy + rot[9 * i + 6 + a0] * dz
        p1 = s1 * (rot[9 * i + a1] * dx + rot[9 * i + 3 + a1] * dy + rot[9 * i + 6 + a1] * dz)
        p2 = s2 * (rot[9 * i + a2] * dx + rot[9 * i + 3 + a2] * dy + rot[9 * i + 6 + a2] * dz)
        qw = (quat[4 * i] * quat[4 * j] + quat[4 * i + 1] * quat[4 * j + 1]
              + quat[4 * i + 2] * quat[4 * j + 2] + quat[4 * i + 3] * quat[4 * j + 3])
        qx = (quat[4 * i] * quat[4 * j + 1] - quat[4 * i + 1] * quat[4 * j]
              - quat[4 * i + 2] * quat[4 * j + 3] + quat[4 * i + 3] * quat[4 * j + 2])
        qy = (quat[4 * i] * quat[4 * j + 2] + quat[4 * i + 1] * quat[4 * j + 3]
              - quat[4 * i + 2] * quat[4 * j] - quat[4 * i + 3] * quat[4 * j + 1])
        qz = (quat[4 * i] * quat[4 * j + 3] - quat[4 * i + 1] * quat[4 * j + 2]
              + quat[4 * i + 2] * quat[4 * j + 1] - quat[4 * i + 3] * quat[4 * j])
        o_p0[li] = p0
        o_p1[li] = p1
        o_p2[li] = p2
        o_qw[li] = qw
        o_n1[li] = qx * w00 + qy * w01 + qz * w02
        o_n2[li] = qx * w10 + qy * w11 + qz * w12
        o_n3[li] = qx * w20 + qy * w21 + qz * w22
        o_nom[li] = 0.5 * (scale[i] + scale[j])
        o_len[li] = sqrt(dx * dx + dy * dy + dz * dz)
        o_st[li] = (fabs(p2) + fabs(p1)) / p0


cdef intp_t _seed_modes(Batch* b, intp_t lo, intp_t hi, float64_t* o, intp_t n) noexcept nogil:
    # First pass of _seed_links_along over its links [lo, hi): each link's
    # mode, small or large angle, with the seed's hysteresis (updates
    # link_sa), then the strain check. Row 9 (the transverse ratio) becomes
    # the mode as 1.0 / 0.0, row 22 1.0 on a mode-change step, row 23 1.0
    # when voxel 2 takes -F1 (then or for a single material). Returns hi, or
    # the first link whose extension is beyond max_strain.
    cdef:
        intp_t li
        float64_t max_ext = b.max_strain * b.L
        float64_t sa_w = SMALL_ANGLE_W
        float64_t sah_w = SMALLISH_ANGLE_W
        float64_t st_in = SA_BOND_BEND_RAD
        float64_t ex_in = SA_BOND_EXT_PERC
        float64_t st_out = HYSTERESIS * SA_BOND_BEND_RAD
        float64_t ex_out = HYSTERESIS * SA_BOND_EXT_PERC
        flag_t* link_sa = b.link_sa
        const flag_t* homog = b.homog
        float64_t qw, p0, nom, st, ex, P0
        int32 sa, changed
    for li in range(lo, hi):
        p0 = o[li]
        qw = o[3 * n + li]
        nom = o[7 * n + li]
        st = o[9 * n + li]
        ex = p0 / nom
        sa = link_sa[li]
        changed = 0
        if not sa and qw > sa_w and st < st_in and ex < ex_in:
            sa = 1
            changed = 1
        elif sa and (not (qw > sah_w) or st > st_out or ex > ex_out):
            sa = 0
            changed = 1
        link_sa[li] = sa
        o[9 * n + li] = 1.0 if sa else 0.0
        o[22 * n + li] = 1.0 if changed else 0.0
        o[23 * n + li] = 1.0 if changed or homog[li] else 0.0
        P0 = p0 - nom if sa else o[8 * n + li] - nom
        if not (fabs(P0) <= max_ext):
            return li  # also catches NaN
    return hi


cdef extern from "softgym_seed.h":
    # see include/softgym_seed.h
    void softgym_seed_frames(intp_t lo, intp_t hi, float64_t sa_rad, float64_t thr,
                             const float64_t* p0_, const float64_t* p1_, const float64_t* p2_,
                             const float64_t* qw_, const float64_t* n1_, const float64_t* n2_,
                             const float64_t* n3_, const float64_t* nom_, const float64_t* len_,
                             const float64_t* sa_, float64_t* o_P0, float64_t* o_P1,
                             float64_t* o_P2, float64_t* o_a1y, float64_t* o_a1z,
                             float64_t* o_a2x, float64_t* o_a2y, float64_t* o_a2z,
                             float64_t* o_rw, float64_t* o_ry, float64_t* o_rz,
                             float64_t* o_fix) noexcept nogil


cdef extern from "softgym_seed.h":
    # see include/softgym_seed.h
    void softgym_seed_forces(intp_t lo, intp_t hi, intp_t n, float64_t L, float64_t bz,
                             float64_t bzh, float64_t inv_dt, const float64_t* const* inp,
                             const float64_t* k_axial, const float64_t* k_torsion,
                             const float64_t* k_bend, const float64_t* c_seed,
                             float64_t* link_last, float64_t* const* out) noexcept nogil


cdef void _seed_frame_one(intp_t li, float64_t* o, intp_t n) noexcept nogil:
    # softgym_seed_frames for one link, with the seed's branches (its acos
    # approximation and the backward-chord rule)
    cdef:
        float64_t sa_rad = SMALL_ANGLE_RAD
        float64_t th_discard = SEED_PI - DISCARD_ANGLE_RAD
        float64_t p0 = o[li], p1 = o[n + li], p2 = o[2 * n + li], qw = o[3 * n + li]
        float64_t n1 = o[4 * n + li], n2 = o[5 * n + li], n3 = o[6 * n + li]
        float64_t nom = o[7 * n + li]
        float64_t k, rw = 1.0, ry = 0.0, rz = 0.0, tw, tx, ty, tz
        float64_t a1y = 0.0, a1z = 0.0, a2x, a2y, a2z, P0, P1, P2
        float64_t len_, nx, ny, nz, rho, ch, sh, yx, zx
    if o[9 * n + li] != 0.0:
        # small angle: voxel 1's frame, offsets along its axes
        k = _rotvec_k(qw)
        a2x = n1 * k
        a2y = n2 * k
        a2z = n3 * k
        P0 = p0 - nom
        P1 = p1
        P2 = p2
    else:
        # large angle: the frame turned by rq = (rw, 0, ry, rz) onto the
        # chord (the seed's ToXDirBond of the relative position)
        if not (p0 == 0.0 and p1 == 0.0 and p2 == 0.0):
            yx = p1 / p0
            zx = p2 / p0
            if yx < sa_rad and yx > -sa_rad and zx < sa_rad and zx > -sa_rad:
                ry = 0.5 * zx
                rz = -0.5 * yx
                rw = 1.0 + 0.5 * (-ry * ry - rz * rz)
            else:
                len_ = sqrt(p0 * p0 + p1 * p1 + p2 * p2)
                nx = p0 / len_
                ny = p1 / len_
                nz = p2 / len_
                # acos(nx) > pi - 1e-7 (acos(x) <= acos(-0.5) < 2.1 for x >= -0.5)
                if nx < -0.5 and acos(nx) > th_discard:
                    rw = 0.0
                    ry = 1.0
                else:
                    rho = 1.0 / sqrt(nz * nz + ny * ny)
                    ch = sqrt(0.5 * (1.0 + nx))  # cos(th / 2)
                    sh = sqrt(0.5 * (1.0 - nx))  # sin(th / 2)
                    rw = ch
                    ry = nz * rho * sh
                    rz = -ny * rho * sh
            k = _rotvec_k(rw)  # the seed's, with its acos approximation
            a1y = ry * k
            a1z = rz * k
        # tq = rq nq (rq's x part is zero)
        tw = rw * qw - ry * n2 - rz * n3
        tx = rw * n1 + ry * n3 - rz * n2
        ty = rw * n2 + ry * qw + rz * n1
        tz = rw * n3 - ry * n1 + rz * qw
        k = _rotvec_k(tw)
        a2x = tx * k
        a2y = ty * k
        a2z = tz * k
        P0 = o[8 * n + li] - nom
        P1 = 0.0
        P2 = 0.0
    o[10 * n + li] = P0
    o[11 * n + li] = P1
    o[12 * n + li] = P2
    o[13 * n + li] = a1y
    o[14 * n + li] = a1z
    o[15 * n + li] = a2x
    o[16 * n + li] = a2y
    o[17 * n + li] = a2z
    o[18 * n + li] = rw
    o[19 * n + li] = ry
    o[20 * n + li] = rz


cdef inline int _seed_links_along(Batch* b, intp_t lo, intp_t hi, const int ax,
                                  float64_t inv_dt) noexcept nogil:
    # _links_seed for its links [lo, hi), all along axis ax (a compile-time
    # constant once inlined), in passes over the link scratch b.link_out
    # (profiled: the square roots and divisions of the large-angle frames
    # dominated the step; one branch-free vector loop does them for many links
    # at once, the same IEEE operations as the seed's scalar code):
    #   _seed_geom           rows 0-9: relative position p, orientation (qw, n),
    #                        nominal length, chord length, transverse ratio
    #   _seed_modes          the mode (link_sa; row 9 becomes 1.0 small / 0.0
    #                        large angle), row 22 1.0 on a mode-change step,
    #                        row 23 1.0 where voxel 2 takes -F1, the strain
    #                        check (stops at the first strained link)
    #   softgym_seed_frames  rows 10-20: displacement P, rotation vectors a1
    #                        (y, z) and a2, the large-angle frame rq; row 21
    #                        marks links whose rotation needs the acos branch
    #   _seed_frame_one      redoes those links with the seed's branches
    #   softgym_seed_forces  rows 0-9, 21, 24: forces and moments in the bond
    #                        frame (stiffness, the seed's damping from the
    #                        link's memory; rq^-1 for large angles)
    #   the loop below       back to the world, scattered in link order
    # The bond frame is voxel 1's frame turned by the proper rotation P that
    # takes the link axis onto +x (the seed's ToXDirBond): (x, y, z) ->
    # (x, y, z), (y, -x, z), (z, y, -x) for ax 0, 1, 2.
    cdef:
        intp_t li, i, j, k, end
        float64_t bz = 0.5 * b.bond_zeta
        float64_t bzh = 0.5 * bz
        const float64_t* rot = b.rot
        const intp_t* v1 = b.v1
        const intp_t* v2 = b.v2
        intp_t n = b.link_stride  # the scratch's row stride
        float64_t* o = b.link_out
        float64_t* force = b.force
        float64_t* moment = b.moment
        const float64_t* inp[14]
        float64_t* out[12]
        const float64_t* R1
    if hi <= lo:
        return STATUS_OK
    _seed_geom(lo, hi, ax, v1, v2, b.pos, rot, b.quat, b.scale, o, o + n, o + 2 * n,
               o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n, o + 7 * n, o + 8 * n, o + 9 * n)
    end = _seed_modes(b, lo, hi, o, n)
    softgym_seed_frames(lo, end, SMALL_ANGLE_RAD, SLTHRESH_ACOS2SQRT, o, o + n, o + 2 * n,
                        o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n, o + 7 * n, o + 8 * n,
                        o + 9 * n, o + 10 * n, o + 11 * n, o + 12 * n, o + 13 * n, o + 14 * n,
                        o + 15 * n, o + 16 * n, o + 17 * n, o + 18 * n, o + 19 * n, o + 20 * n,
                        o + 21 * n)
    for li in range(lo, end):
        if o[21 * n + li] != 0.0:
            _seed_frame_one(li, o, n)
    for k in range(11):
        inp[k] = o + (10 + k) * n
    inp[11] = o + 9 * n
    inp[12] = o + 22 * n
    inp[13] = o + 23 * n
    for k in range(10):
        out[k] = o + k * n
    out[10] = o + 21 * n
    out[11] = o + 24 * n
    softgym_seed_forces(lo, end, b.n_links, b.L, bz, bzh, inv_dt, inp, b.k_axial, b.k_torsion,
                        b.k_bend, b.c_seed, b.link_last, out)
    for li in range(lo, end):
        # back to the world (the inverse axis turn, voxel 1's rotation) and
        # the scatter, in link order (the seed's summation order)
        i = v1[li]
        j = v2[li]
        R1 = rot + 9 * i
        _add_bond_to_world(ax, R1, o[li], o[n + li], o[2 * n + li], force + 3 * i)
        _add_bond_to_world(ax, R1, o[3 * n + li], o[4 * n + li], o[5 * n + li], force + 3 * j)
        _add_bond_to_world(ax, R1, o[6 * n + li], o[7 * n + li], o[8 * n + li], moment + 3 * i)
        _add_bond_to_world(ax, R1, o[9 * n + li], o[21 * n + li], o[24 * n + li], moment + 3 * j)
    return STATUS_OK if end == hi else STATUS_STRAIN


cdef int _links_seed(Batch* b, intp_t r) noexcept nogil:
    # IN: positions, orientations, sizes, the links' mode and memory.
    # OUT (accumulated): force, moment; the links' mode and memory.
    # Quantities are those of the seed's bond frame (the link axis turned
    # onto +x, voxel 1's orientation removed); rotations back to the world
    # go through voxel 1's rotation matrix. A robot's links are sorted by
    # axis (x, then y, then z): each run gets a copy with the axis constant.
    cdef:
        intp_t lo = b.link_start[r]
        intp_t hi = b.link_start[r + 1]
        intp_t nx = b.link_axis_count[3 * r]
        intp_t ny = b.link_axis_count[3 * r + 1]
        float64_t inv_dt = 1.0 / b.dt[r]
    if _seed_links_along(b, lo, lo + nx, 0, inv_dt) != STATUS_OK:
        return STATUS_STRAIN
    if _seed_links_along(b, lo + nx, lo + nx + ny, 1, inv_dt) != STATUS_OK:
        return STATUS_STRAIN
    return _seed_links_along(b, lo + nx + ny, hi, 2, inv_dt)


cdef inline void _surface_contact(Batch* b, intp_t i, float64_t nx, float64_t ny, float64_t nz,
                                  float64_t pen, float64_t dt, float64_t* f) noexcept nogil:
    # Penalty contact of voxel i with a static surface of outward unit normal n,
    # penetration pen > 0: normal force 2 E L pen minus collision damping (never
    # pulling), then Coulomb friction in the tangent plane (the seed's floor law,
    # SEED_REFERENCE 1.6, for any normal). IN/OUT: f (force on the voxel), and
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


cdef inline void _fluid_drag(Batch* b, intp_t i, float64_t* f) noexcept nogil:
    # Quadratic fluid drag on voxel i's exposed faces (b.faces): a face of area
    # s^2 moving into the fluid along its outward normal n at speed v.n > 0 takes
    # -fluid_drag s^2 (v.n)^2 n (fluid_drag = rho C_d / 2); a face moving away
    # takes none. Applied at the voxel's centre. IN/OUT: f.
    cdef:
        const float64_t* R = b.rot + 9 * i
        const float64_t* v = b.vel + 3 * i
        float64_t k = b.fluid_drag * b.scale[i] * b.scale[i]
        float64_t vn, g
        int32 a, bit
        int32 exposed = b.faces[i]
    for a in range(3):
        vn = v[0] * R[a] + v[1] * R[3 + a] + v[2] * R[6 + a]
        bit = 2 * a + 1 if vn > 0.0 else 2 * a
        if exposed & (1 << bit):
            g = k * vn * fabs(vn)
            f[0] -= g * R[a]
            f[1] -= g * R[3 + a]
            f[2] -= g * R[6 + a]


cdef inline float64_t _box_penetration(const float64_t* B, const float64_t* p, float64_t rad,
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


cdef inline void _clear(Batch* b, intp_t i) noexcept nogil:
    b.force[3 * i] = 0.0
    b.force[3 * i + 1] = 0.0
    b.force[3 * i + 2] = 0.0
    b.moment[3 * i] = 0.0
    b.moment[3 * i + 1] = 0.0
    b.moment[3 * i + 2] = 0.0


cdef void _clear_robot(Batch* b, intp_t r) noexcept nogil:
    # zero the robot's force/moment scratch (after an early exit)
    cdef intp_t vs = b.vox_start[r], ve = b.vox_start[r + 1]
    memset(b.force + 3 * vs, 0, 3 * (ve - vs) * sizeof(float64_t))
    memset(b.moment + 3 * vs, 0, 3 * (ve - vs) * sizeof(float64_t))


cdef inline int _integrate(Batch* b, intp_t r, const float64_t* ref,
                           float64_t* dmax2) noexcept nogil:
    # IN: force, moment. OUT: pos, vel, quat, angvel, rot (symplectic Euler).
    # If ref (the robot's positions when its contact list was built) is not
    # NULL, dmax2 gets the largest squared displacement from it, relative to
    # the first voxel's (any common shift c bounds the approach of two voxels:
    # |dp_i - dp_j| <= |dp_i - c| + |dp_j - c|).
    cdef:
        intp_t i, k
        float64_t dt = b.dt[r]
        float64_t m, h, pen, cg, rd, d2, mx, my, mz
        float64_t c0 = 0.0, c1 = 0.0, c2 = 0.0
        float64_t wx, wy, wz, qw, qx, qy, qz, nq
        float64_t f[3]
        float64_t n[3]
        float64_t* pos = b.pos
        float64_t* vel = b.vel
        float64_t* av = b.angvel
        float64_t* qq
        float64_t g = b.gravity
        int32 has_floor = b.floor[r]
        int32 has_fluid = b.fluid_drag > 0.0
        intp_t k0 = b.box_start[r]
        intp_t k1 = b.box_start[r + 1]
        intp_t vs = b.vox_start[r]
    dmax2[0] = 0.0
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        if b.fixed[i]:
            vel[3 * i] = 0.0
            vel[3 * i + 1] = 0.0
            vel[3 * i + 2] = 0.0
            av[3 * i] = 0.0
            av[3 * i + 1] = 0.0
            av[3 * i + 2] = 0.0
            _clear(b, i)
            continue
        m = b.mass[i]
        cg = b.c_global[i]
        f[0] = b.force[3 * i] + b.ext_force[3 * i] - cg * vel[3 * i]
        f[1] = b.force[3 * i + 1] + b.ext_force[3 * i + 1] - cg * vel[3 * i + 1]
        f[2] = b.force[3 * i + 2] + b.ext_force[3 * i + 2] - cg * vel[3 * i + 2] + m * g
        mx = b.moment[3 * i]
        my = b.moment[3 * i + 1]
        mz = b.moment[3 * i + 2]
        _clear(b, i)  # the scratch is zero again for the next step
        if has_fluid:
            _fluid_drag(b, i, f)
        if has_floor:
            pen = 0.5 * b.scale[i] - pos[3 * i + 2]
            if pen > 0.0:
                _surface_contact(b, i, 0.0, 0.0, 1.0, pen, dt, f)
        for k in range(k0, k1):
            pen = _box_penetration(b.boxes + 6 * k, pos + 3 * i, 0.5 * b.scale[i], n)
            if pen > 0.0:
                _surface_contact(b, i, n[0], n[1], n[2], pen, dt, f)
        h = dt * b.inv_mass[i]
        vel[3 * i] += f[0] * h
        vel[3 * i + 1] += f[1] * h
        vel[3 * i + 2] += f[2] * h
        pos[3 * i] += vel[3 * i] * dt
        pos[3 * i + 1] += vel[3 * i + 1] * dt
        pos[3 * i + 2] += vel[3 * i + 2] * dt
        if not (fabs(pos[3 * i]) + fabs(pos[3 * i + 1]) + fabs(pos[3 * i + 2]) < RUNAWAY):
            _clear_robot(b, r)
            return STATUS_NONFINITE
        if ref != NULL:
            # displacement since the rebuild, less the first voxel's: a common
            # translation does not bring voxels closer, so walking costs no rebuild
            k = 3 * (i - vs)
            if i == vs:
                c0 = pos[3 * i] - ref[k]
                c1 = pos[3 * i + 1] - ref[k + 1]
                c2 = pos[3 * i + 2] - ref[k + 2]
            d2 = ((pos[3 * i] - ref[k] - c0) ** 2 + (pos[3 * i + 1] - ref[k + 1] - c1) ** 2
                  + (pos[3 * i + 2] - ref[k + 2] - c2) ** 2)
            if d2 > dmax2[0]:
                dmax2[0] = d2
        # rotation: w += M dt / I, global damping, q += 0.5 dt (0, w) q
        h = dt * b.inv_inertia[i]
        rd = b.rot_damp[i]
        av[3 * i] = (av[3 * i] + mx * h) * rd
        av[3 * i + 1] = (av[3 * i + 1] + my * h) * rd
        av[3 * i + 2] = (av[3 * i + 2] + mz * h) * rd
        wx = av[3 * i] * 0.5 * dt
        wy = av[3 * i + 1] * 0.5 * dt
        wz = av[3 * i + 2] * 0.5 * dt
        qq = b.quat + 4 * i
        qw = qq[0] - wx * qq[1] - wy * qq[2] - wz * qq[3]
        qx = qq[1] + wx * qq[0] + wy * qq[3] - wz * qq[2]
        qy = qq[2] + wy * qq[0] + wz * qq[1] - wx * qq[3]
        qz = qq[3] + wz * qq[0] + wx * qq[2] - wy * qq[1]
        # renormalise: |q|^2 = 1 + O((w dt)^2), so one Newton step of 1/sqrt
        # from 1 is exact to rounding
        nq = 1.5 - 0.5 * (qw * qw + qx * qx + qy * qy + qz * qz)
        qq[0] = qw * nq
        qq[1] = qx * nq
        qq[2] = qy * nq
        qq[3] = qz * nq
        _rotation_matrix(qq, b.rot + 9 * i)
    return STATUS_OK


cdef inline void _seed_floor(Batch* b, intp_t i, float64_t dt, float64_t* f) noexcept nogil:
    # The seed's floor (SEED_REFERENCE 1.6) on voxel i. IN/OUT: f, the voxel's
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


cdef extern from "softgym_seed.h":
    # see include/softgym_seed.h
    void softgym_seed_quats(intp_t lo, intp_t hi, intp_t n, float64_t dt, const float64_t* av,
                            const float64_t* quat, float64_t* q_out) noexcept nogil


cdef inline void _seed_orient(Batch* b, intp_t lo, intp_t hi, float64_t dt) noexcept nogil:
    # the orientation step of _integrate_seed for voxels lo..hi (fixed voxels
    # keep theirs): new quaternions, then their rotation matrices
    cdef:
        intp_t i
        intp_t n = b.vox_stride  # the scratch's row stride
        float64_t* qo = b.vox_out
        float64_t* qq
    softgym_seed_quats(lo, hi, n, dt, b.angvel, b.quat, qo)
    for i in range(lo, hi):
        if b.fixed[i]:
            continue
        qq = b.quat + 4 * i
        qq[0] = qo[i]
        qq[1] = qo[n + i]
        qq[2] = qo[2 * n + i]
        qq[3] = qo[3 * n + i]
        _rotation_matrix(qq, b.rot + 9 * i)


cdef inline int _integrate_seed(Batch* b, intp_t r, const float64_t* ref,
                                float64_t* dmax2) noexcept nogil:
    # Model 0's voxel update (the seed's EulerStep): as _integrate, with the
    # seed's floor and exact quaternion renormalisation snapped to the identity
    # at w >= 1 (_seed_orient, after the loop: no voxel's update reads
    # another's orientation). Terrain boxes use the common surface contact.
    cdef:
        intp_t i, k
        float64_t dt = b.dt[r]
        float64_t h, pen, cg, rd, d2, mx, my, mz
        float64_t c0 = 0.0, c1 = 0.0, c2 = 0.0
        float64_t f[3]
        float64_t n[3]
        float64_t* pos = b.pos
        float64_t* vel = b.vel
        float64_t* av = b.angvel
        int32 has_floor = b.floor[r]
        int32 has_fluid = b.fluid_drag > 0.0
        intp_t k0 = b.box_start[r]
        intp_t k1 = b.box_start[r + 1]
        intp_t vs = b.vox_start[r]
    dmax2[0] = 0.0
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        if b.fixed[i]:
            for k in range(3):
                vel[3 * i + k] = 0.0
                av[3 * i + k] = 0.0
            _clear(b, i)
            continue
        cg = b.c_global[i]
        f[0] = -cg * vel[3 * i] + b.force[3 * i] + b.ext_force[3 * i]
        f[1] = -cg * vel[3 * i + 1] + b.force[3 * i + 1] + b.ext_force[3 * i + 1]
        f[2] = -cg * vel[3 * i + 2] + b.force[3 * i + 2] + b.mass[i] * b.gravity + b.ext_force[3 * i + 2]
        mx = b.moment[3 * i]
        my = b.moment[3 * i + 1]
        mz = b.moment[3 * i + 2]
        _clear(b, i)
        if has_fluid:
            _fluid_drag(b, i, f)
        for k in range(k0, k1):
            pen = _box_penetration(b.boxes + 6 * k, pos + 3 * i, 0.5 * b.scale[i], n)
            if pen > 0.0:
                _surface_contact(b, i, n[0], n[1], n[2], pen, dt, f)
        if has_floor:
            _seed_floor(b, i, dt, f)
        h = dt * b.inv_mass[i]
        vel[3 * i] += f[0] * h
        vel[3 * i + 1] += f[1] * h
        vel[3 * i + 2] += f[2] * h
        pos[3 * i] += vel[3 * i] * dt
        pos[3 * i + 1] += vel[3 * i + 1] * dt
        pos[3 * i + 2] += vel[3 * i + 2] * dt
        if not (fabs(pos[3 * i]) + fabs(pos[3 * i + 1]) + fabs(pos[3 * i + 2]) < RUNAWAY):
            _seed_orient(b, vs, i, dt)  # the voxels before it were stepped
            _clear_robot(b, r)
            return STATUS_NONFINITE
        if ref != NULL:
            k = 3 * (i - vs)
            if i == vs:
                c0 = pos[3 * i] - ref[k]
                c1 = pos[3 * i + 1] - ref[k + 1]
                c2 = pos[3 * i + 2] - ref[k + 2]
            d2 = ((pos[3 * i] - ref[k] - c0) ** 2 + (pos[3 * i + 1] - ref[k + 1] - c1) ** 2
                  + (pos[3 * i + 2] - ref[k + 2] - c2) ** 2)
            if d2 > dmax2[0]:
                dmax2[0] = d2
        h = dt * b.inv_inertia[i]
        rd = b.rot_damp[i]
        av[3 * i] = (av[3 * i] + mx * h) * rd
        av[3 * i + 1] = (av[3 * i + 1] + my * h) * rd
        av[3 * i + 2] = (av[3 * i + 2] + mz * h) * rd
    _seed_orient(b, vs, b.vox_start[r + 1], dt)
    return STATUS_OK


# ---------------------------------------------------------------------------
# Self-collision (SEED_REFERENCE 1.7): surface voxels more than
# `collision_exclusion` bond hops apart repel when their spherical envelopes, of diameter
# 1.5 x their actuated size, overlap: F = E_h L (0.75 (s1 + s2) - |d|) along d,
# E_h the harmonic mean of their moduli; no damping, no friction. Candidate
# pairs come from a spatial hash (cells of the candidate horizon) and are kept
# until some voxel may have crossed the horizon's slack, so the cost grows
# about linearly with the number of voxels. The candidate list is always a
# superset of the touching pairs and is sorted, so forces do not depend on
# when it was rebuilt: results stay bit-identical.

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


cdef int _rebuild_contacts(Batch* b, intp_t r, Contacts* c) noexcept nogil:
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


cdef int _seed_candidates(Batch* b, intp_t r, Contacts* c, int32 snapshot) noexcept nogil:
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


cdef inline void _collide_obstacles(Batch* b, Contacts* c) noexcept nogil:
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


cdef inline void _collide(Batch* b, Contacts* c) noexcept nogil:
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


cdef void robot_cm(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0:3] = mass-weighted centre of the robot's voxels (m).
    cdef:
        intp_t i
        float64_t sx = 0.0, sy = 0.0, sz = 0.0, m
    for i in range(b.vox_start[r], b.body_end[r]):  # its objects excluded
        m = b.mass[i]
        sx += m * b.pos[3 * i]
        sy += m * b.pos[3 * i + 1]
        sz += m * b.pos[3 * i + 2]
    m = 1.0 / b.mass_total[r]
    out[0] = sx * m
    out[1] = sy * m
    out[2] = sz * m


cdef void robot_aux(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0:N_AUX] (see _core.pxd): the objects' centre of mass, the
    # robot's heading sum and the bounding box of its voxel centres.
    cdef:
        intp_t i, k
        intp_t be = b.body_end[r]
        float64_t m, mo = 0.0
    for k in range(N_AUX):
        out[k] = 0.0
    out[5] = b.pos[3 * b.vox_start[r]]
    out[6] = out[5]
    out[7] = b.pos[3 * b.vox_start[r] + 1]
    out[8] = out[7]
    out[9] = b.pos[3 * b.vox_start[r] + 2]
    for i in range(b.vox_start[r], be):
        m = b.mass[i]
        out[3] += m * b.rot[9 * i]
        out[4] += m * b.rot[9 * i + 3]
        if b.pos[3 * i] < out[5]:
            out[5] = b.pos[3 * i]
        if b.pos[3 * i] > out[6]:
            out[6] = b.pos[3 * i]
        if b.pos[3 * i + 1] < out[7]:
            out[7] = b.pos[3 * i + 1]
        if b.pos[3 * i + 1] > out[8]:
            out[8] = b.pos[3 * i + 1]
        if b.pos[3 * i + 2] > out[9]:
            out[9] = b.pos[3 * i + 2]
    for i in range(be, b.vox_start[r + 1]):
        m = b.mass[i]
        mo += m
        out[0] += m * b.pos[3 * i]
        out[1] += m * b.pos[3 * i + 1]
        out[2] += m * b.pos[3 * i + 2]
    if mo > 0.0:
        mo = 1.0 / mo
        out[0] *= mo
        out[1] *= mo
        out[2] *= mo


cdef inline void _record(Batch* b, intp_t r) noexcept nogil:
    # Centre-of-mass bookkeeping after a step: IniCM and the trace samples.
    cdef:
        float64_t t = b.steps[r] * b.dt[r]
        float64_t cm[3]
        int32 have = 0
        intp_t k
    if not b.init_done[r] and t > b.init_time:
        robot_cm(b, r, cm)
        have = 1
        b.cm_init[3 * r] = cm[0]
        b.cm_init[3 * r + 1] = cm[1]
        b.cm_init[3 * r + 2] = cm[2]
        robot_aux(b, r, b.aux_init + N_AUX * r)
        b.init_done[r] = 1
    # sample k at the first step with t >= k * trace_interval (to within 1e-6 dt)
    while (b.trace_n[r] < b.trace_capacity
           and t >= b.trace_n[r] * b.trace_interval - 1e-6 * b.dt[r]):
        if not have:
            robot_cm(b, r, cm)
            have = 1
        k = r * b.trace_capacity + b.trace_n[r]
        b.trace_t[k] = t
        b.trace_cm[3 * k] = cm[0]
        b.trace_cm[3 * k + 1] = cm[1]
        b.trace_cm[3 * k + 2] = cm[2]
        robot_aux(b, r, b.trace_aux + N_AUX * k)
        b.trace_n[r] += 1


cdef inline float64_t _max_speed(Batch* b, intp_t r) noexcept nogil:
    # the fastest voxel speed of robot r (m/s)
    cdef intp_t i
    cdef float64_t v2, m = 0.0
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        v2 = b.vel[3 * i] * b.vel[3 * i] + b.vel[3 * i + 1] * b.vel[3 * i + 1] + b.vel[3 * i + 2] * b.vel[3 * i + 2]
        if v2 > m:
            m = v2
    return sqrt(m)


cdef int _advance_seed(Batch* b, intp_t r, step_t target, Contacts* c) noexcept nogil:
    # advance_robot for model 0: links, contacts, voxels, then the drive at
    # the step's start time sets the sizes the next step's links see
    cdef:
        int status = STATUS_OK
        float64_t smax = 0.0, dmax2 = 0.0
    while b.steps[r] < target:
        if b.self_collision:
            # the seed's schedule: rebuild once the fastest voxel may have
            # covered half a voxel since the last rebuild
            b.col_acc[r] += fabs(b.col_vmax[r] * b.dt[r] / b.L)
            if b.col_acc[r] > 0.5:
                status = _seed_candidates(b, r, c, 1)
                b.col_acc[r] = 0.0
            elif c.stale:
                status = _seed_candidates(b, r, c, 0)
        if status == STATUS_OK:
            status = _links_seed(b, r)
        if status == STATUS_OK and b.self_collision:
            _collide(b, c)
            _collide_obstacles(b, c)
        if status == STATUS_OK:
            status = _integrate_seed(b, r, NULL, &dmax2)
        if status != STATUS_OK:
            _clear_robot(b, r)
            b.diverged[r] = 1
            b.diverged_code[r] = status
            b.diverged_time[r] = b.steps[r] * b.dt[r]
            break
        if b.self_collision:
            b.col_vmax[r] = _max_speed(b, r)
        smax = _actuate(b, r)
        b.steps[r] += 1
        _record(b, r)
    return status


cdef int advance_robot(Batch* b, intp_t r, step_t target, Contacts* c) noexcept nogil:
    """Step robot r until steps[r] == target, or until it diverges.

    Modifies in place every per-voxel state array of the robot, its step count,
    traces and divergence flags, and its self-collision candidates ``c``
    (kept between calls; the wrapper marks them stale when it moves voxels).
    Returns a STATUS_* code.
    """
    cdef:
        int status = STATUS_OK
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        float64_t smax, dmax2 = 0.0
    if b.diverged[r]:
        return STATUS_OK
    if b.steps[r] == 0:
        _record(b, r)
    if b.model == 0:
        return _advance_seed(b, r, target, c)
    while b.steps[r] < target:
        # force and moment scratch are zero here: _integrate clears them
        smax = _actuate(b, r)
        status = _link_forces(b, r)
        if status == STATUS_OK and b.self_collision:
            if c.stale or smax > c.built_scale:
                status = _rebuild_contacts(b, r, c)
            _collide(b, c)
        if status == STATUS_OK:
            status = _integrate(b, r, c.ref if b.self_collision else NULL, &dmax2)
        if status != STATUS_OK:
            _clear_robot(b, r)
            b.diverged[r] = 1
            b.diverged_code[r] = status
            b.diverged_time[r] = b.steps[r] * b.dt[r]
            break
        if b.self_collision:
            # two voxels approach by at most twice the largest (relative)
            # displacement since the list was built: rebuild before that can
            # eat the slack
            if 4.0 * dmax2 >= c.margin * c.margin:
                c.stale = 1
        b.steps[r] += 1
        _record(b, r)
    return status


cdef void robot_energy(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0] kinetic (translation + rotation), out[1] elastic (links, floor
    # and box contact; self-contact is not included),
    # out[2] gravitational potential m |g|... relative to z = 0 (J).
    cdef:
        intp_t i, j, li, ax, p, q, k
        float64_t ke = 0.0, pe = 0.0, ge = 0.0
        float64_t nrm[3]
        float64_t dx, dy, dz, ell, e, pen, tw, rx, ry, rz, inv_r, cx, cy, cz
        float64_t b1x, b1y, b1z, b2x, b2y, b2z
        const float64_t* R1
        const float64_t* R2
        float64_t* vv = b.vel
        float64_t* av = b.angvel
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        ke += 0.5 * b.mass[i] * (vv[3 * i] ** 2 + vv[3 * i + 1] ** 2 + vv[3 * i + 2] ** 2)
        ke += 0.5 / b.inv_inertia[i] * (av[3 * i] ** 2 + av[3 * i + 1] ** 2 + av[3 * i + 2] ** 2)
        ge -= b.mass[i] * b.gravity * b.pos[3 * i + 2]
        if b.floor[r]:
            pen = 0.5 * b.scale[i] - b.pos[3 * i + 2]
            if pen > 0.0:
                pe += 0.5 * b.k_floor[i] * pen * pen
        for k in range(b.box_start[r], b.box_start[r + 1]):
            pen = _box_penetration(b.boxes + 6 * k, b.pos + 3 * i, 0.5 * b.scale[i], nrm)
            if pen > 0.0:
                pe += 0.5 * b.k_floor[i] * pen * pen
    for li in range(b.link_start[r], b.link_start[r + 1]):
        i = b.v1[li]
        j = b.v2[li]
        ax = b.axis[li]
        p = (ax + 1) % 3
        q = 3 - ax - p
        dx = b.pos[3 * j] - b.pos[3 * i]
        dy = b.pos[3 * j + 1] - b.pos[3 * i + 1]
        dz = b.pos[3 * j + 2] - b.pos[3 * i + 2]
        ell = sqrt(dx * dx + dy * dy + dz * dz)
        e = ell - 0.5 * (b.scale[i] + b.scale[j])
        R1 = b.rot + 9 * i
        R2 = b.rot + 9 * j
        rx = R1[ax] + R2[ax]
        ry = R1[3 + ax] + R2[3 + ax]
        rz = R1[6 + ax] + R2[6 + ax]
        inv_r = 0.5 * (1.5 - 0.125 * (rx * rx + ry * ry + rz * rz))  # as the link forces
        rx = rx * inv_r
        ry = ry * inv_r
        rz = rz * inv_r
        cx = (ry * dz - rz * dy) / b.L
        cy = (rz * dx - rx * dz) / b.L
        cz = (rx * dy - ry * dx) / b.L
        b1x = ry * R1[6 + ax] - rz * R1[3 + ax] - cx
        b1y = rz * R1[ax] - rx * R1[6 + ax] - cy
        b1z = rx * R1[3 + ax] - ry * R1[ax] - cz
        b2x = ry * R2[6 + ax] - rz * R2[3 + ax] - cx
        b2y = rz * R2[ax] - rx * R2[6 + ax] - cy
        b2z = rx * R2[3 + ax] - ry * R2[ax] - cz
        tw = 0.5 * (R1[q] * R2[p] + R1[3 + q] * R2[3 + p] + R1[6 + q] * R2[6 + p]
                    - R1[p] * R2[q] - R1[3 + p] * R2[3 + q] - R1[6 + p] * R2[6 + q])
        pe += 0.5 * b.k_axial[li] * e * e
        pe += 0.5 * b.k_torsion[li] * tw * tw
        pe += b.k_bend[li] * (b1x * b1x + b1y * b1y + b1z * b1z
                              + b1x * b2x + b1y * b2y + b1z * b2z
                              + b2x * b2x + b2y * b2y + b2z * b2z)
    out[0] = ke
    out[1] = pe
    out[2] = ge


# ---------------------------------------------------------------------------
# Python-facing entry points. The wrapper (simulation.py) has validated dtypes,
# shapes and contiguity; here arrays are only bound to the struct.

#: What each STATUS_* code of a diverged robot means (``diverged_code``).
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_STRAIN: "link strain above max_strain (or NaN)",
    STATUS_NONFINITE: "non-finite or runaway voxel state",
    STATUS_MEMORY: "out of memory for the self-collision candidates",
}

#: The arrays that cross into the kernel (bound by _bind; shapes, dtypes and
#: units in _core.pxd's Batch): the Python side must provide every one.
KERNEL_ARRAYS = (
    "vox_start", "link_start", "link_axis_count", "dt", "steps", "temp_amp", "period",
    "use_temp", "floor", "box_start", "boxes", "diverged", "diverged_time", "diverged_code",
    "init_done", "cm_init", "mass_total", "trace_n", "trace_t", "trace_cm",
    "pos", "vel", "quat", "angvel", "rot", "force", "moment", "ext_force", "mass", "inv_mass",
    "inv_inertia", "scale", "cte", "cos_phase", "sin_phase", "temp", "k_floor", "c_floor",
    "c_global", "rot_damp", "mu_s", "mu_k", "fixed", "surface", "excl_start", "excl_idx",
    "seed_rank", "col_ref", "col_acc", "col_vmax", "obs_start", "obs", "obs_rank",
    "v1", "v2", "axis", "k_axial", "k_torsion", "k_bend", "c_axial", "c_torsion",
    "c_bend", "c_seed", "homog", "link_sa", "link_last",
    "body_end", "aux_init", "trace_aux", "faces",
)


cdef inline float64_t* _f(object arrays, str name) except NULL:
    cdef cnp.ndarray a = arrays[name]
    return <float64_t*> cnp.PyArray_DATA(a)


cdef inline void* _p(object arrays, str name) except NULL:
    cdef cnp.ndarray a = arrays[name]
    return cnp.PyArray_DATA(a)


cdef int _bind(Batch* b, dict a, dict s) except -1:
    b.n_robots = s["n_robots"]
    b.L = s["L"]
    b.gravity = s["gravity"]
    b.init_time = s["init_time"]
    b.min_scale = s["min_scale"]
    b.max_strain = s["max_strain"]
    b.trace_interval = s["trace_interval"]
    b.self_collision = s["self_collision"]
    b.actuation_mode = s["actuation_mode"]
    b.model = s["model"]
    b.bond_zeta = s["bond_zeta"]
    b.trace_capacity = a["trace_t"].shape[1]
    b.fluid_drag = s["fluid_drag"]
    b.body_end = <intp_t*> _p(a, "body_end")
    b.aux_init = _f(a, "aux_init")
    b.trace_aux = _f(a, "trace_aux")
    b.faces = <flag_t*> _p(a, "faces")
    b.vox_start = <intp_t*> _p(a, "vox_start")
    b.link_start = <intp_t*> _p(a, "link_start")
    b.dt = _f(a, "dt")
    b.steps = <step_t*> _p(a, "steps")
    b.temp_amp = _f(a, "temp_amp")
    b.period = _f(a, "period")
    b.use_temp = <flag_t*> _p(a, "use_temp")
    b.floor = <flag_t*> _p(a, "floor")
    b.box_start = <intp_t*> _p(a, "box_start")
    b.boxes = _f(a, "boxes") if a["boxes"].shape[0] > 0 else NULL
    b.diverged = <flag_t*> _p(a, "diverged")
    b.diverged_time = _f(a, "diverged_time")
    b.diverged_code = <int32*> _p(a, "diverged_code")
    b.init_done = <flag_t*> _p(a, "init_done")
    b.cm_init = _f(a, "cm_init")
    b.mass_total = _f(a, "mass_total")
    b.trace_n = <intp_t*> _p(a, "trace_n")
    b.trace_t = _f(a, "trace_t")
    b.trace_cm = _f(a, "trace_cm")
    b.pos = _f(a, "pos")
    b.vel = _f(a, "vel")
    b.quat = _f(a, "quat")
    b.angvel = _f(a, "angvel")
    b.rot = _f(a, "rot")
    b.force = _f(a, "force")
    b.vox_out = NULL  # per thread, set by advance
    b.vox_stride = 0
    b.moment = _f(a, "moment")
    b.ext_force = _f(a, "ext_force")
    b.mass = _f(a, "mass")
    b.inv_mass = _f(a, "inv_mass")
    b.inv_inertia = _f(a, "inv_inertia")
    b.scale = _f(a, "scale")
    b.cte = _f(a, "cte")
    b.cos_phase = _f(a, "cos_phase")
    b.sin_phase = _f(a, "sin_phase")
    b.temp = _f(a, "temp")
    b.k_floor = _f(a, "k_floor")
    b.c_floor = _f(a, "c_floor")
    b.c_global = _f(a, "c_global")
    b.rot_damp = _f(a, "rot_damp")
    b.mu_s = _f(a, "mu_s")
    b.mu_k = _f(a, "mu_k")
    b.fixed = <flag_t*> _p(a, "fixed")
    b.seed_rank = <intp_t*> _p(a, "seed_rank")
    b.col_ref = _f(a, "col_ref")
    b.col_acc = _f(a, "col_acc")
    b.col_vmax = _f(a, "col_vmax")
    b.obs_start = <intp_t*> _p(a, "obs_start")
    b.obs = _f(a, "obs") if a["obs"].shape[0] > 0 else NULL
    b.obs_rank = <intp_t*> _p(a, "obs_rank") if a["obs_rank"].shape[0] > 0 else NULL
    b.surface = <flag_t*> _p(a, "surface")
    b.link_axis_count = <intp_t*> _p(a, "link_axis_count")
    b.excl_start = <intp_t*> _p(a, "excl_start")
    b.excl_idx = <intp_t*> _p(a, "excl_idx") if a["excl_idx"].shape[0] > 0 else NULL
    # links: a robot without links leaves these arrays empty (never dereferenced)
    b.n_links = a["v1"].shape[0]
    b.link_out = NULL  # per thread, set by advance
    b.link_stride = 0
    if a["v1"].shape[0] > 0:
        b.v1 = <intp_t*> _p(a, "v1")
        b.v2 = <intp_t*> _p(a, "v2")
        b.axis = <int32*> _p(a, "axis")
        b.k_axial = _f(a, "k_axial")
        b.k_torsion = _f(a, "k_torsion")
        b.k_bend = _f(a, "k_bend")
        b.c_axial = _f(a, "c_axial")
        b.c_torsion = _f(a, "c_torsion")
        b.c_bend = _f(a, "c_bend")
        b.c_seed = _f(a, "c_seed")
        b.homog = <flag_t*> _p(a, "homog")
        b.link_sa = <flag_t*> _p(a, "link_sa")
        b.link_last = _f(a, "link_last")
    return 0


cdef class ContactCache:
    """Self-collision candidate lists of a batch's robots, kept between calls.

    Owned by a :class:`~softgym.engine.Simulation`; :meth:`invalidate` must be
    called whenever voxels are moved from outside the kernel (set_state, reset).
    Whether and when a list is rebuilt never changes results: a list always
    holds every touching pair, in sorted order. Also holds the kernels'
    scratch (one block per thread), reused from call to call.
    """

    cdef Contacts* items
    cdef intp_t n
    cdef float64_t* link_scratch
    cdef intp_t link_scratch_size

    def __cinit__(self, intp_t n_robots):
        self.n = n_robots
        self.items = <Contacts*> calloc(n_robots if n_robots > 0 else 1, sizeof(Contacts))
        if self.items == NULL:
            raise MemoryError("cannot allocate the self-collision cache")
        self.invalidate()

    def invalidate(self):
        """Mark every robot's candidate list for a rebuild before its next use."""
        cdef intp_t r
        for r in range(self.n):
            self.items[r].stale = 1

    def __dealloc__(self):
        cdef intp_t r
        if self.items != NULL:
            for r in range(self.n):
                free(self.items[r].pairs)
                free(self.items[r].cells)
                free(self.items[r].row)
                free(self.items[r].ref)
                free(self.items[r].opairs)
                free(self.items[r].ocells)
            free(self.items)
        free(self.link_scratch)

    cdef float64_t* scratch(self, intp_t size) except NULL:
        # at least `size` doubles of scratch (contents undefined)
        cdef float64_t* p
        if size > self.link_scratch_size:
            p = <float64_t*> realloc(self.link_scratch, size * sizeof(float64_t))
            if p == NULL:
                raise MemoryError("no memory for the kernels' scratch")
            self.link_scratch = p
            self.link_scratch_size = size
        return self.link_scratch


def advance(dict arrays, dict settings, step_t[::1] targets, int n_threads, ContactCache cache):
    """Advance every robot of a batch to its target step count.

    Parameters
    ----------
    arrays : dict of str to ndarray
        The batch state (see ``_core.pxd`` for names, shapes and units);
        modified in place.
    settings : dict
        Global scalars of the batch (``L``, ``gravity``...).
    targets : ndarray of shape (n_robots,), int64
        Step count each robot must reach.
    n_threads : int
        OpenMP threads; robots are distributed over them.

    Divergence is reported through ``arrays["diverged"]`` and friends.
    """
    cdef:
        Batch b
        Batch bt
        intp_t r, n, t
        intp_t stride = 0, vstride = 0, block
        float64_t* scratch
    _bind(&b, arrays, settings)
    n = b.n_robots
    if targets.shape[0] != n or cache.n != n:
        raise ValueError("targets and cache must hold one entry per robot")
    n_threads = max(n_threads, 1)
    # the kernels' scratch, one block per thread, sized for the robot with
    # the most links and voxels: it stays in the core's cache however large
    # the batch (kept in the cache object from call to call)
    for r in range(n):
        stride = max(stride, b.link_start[r + 1] - b.link_start[r])
        vstride = max(vstride, b.vox_start[r + 1] - b.vox_start[r])
    b.link_stride = stride
    b.vox_stride = vstride
    block = N_LINK_OUT * stride + N_VOX_OUT * vstride
    scratch = cache.scratch(max(n_threads * block, 1))
    with nogil, parallel(num_threads=n_threads):
        # dynamic: robots of one batch differ in cost by 10x or more (bone shrinks dt)
        for r in prange(n, schedule="dynamic", chunksize=1):
            t = threadid()
            bt = b
            # row k of link li sits at link_out[k * stride + li], of voxel i
            # at vox_out[k * vstride + i]: the thread's block, offset by the
            # robot's first link and voxel
            bt.link_out = scratch + t * block - b.link_start[r]
            bt.vox_out = scratch + t * block + N_LINK_OUT * stride - b.vox_start[r]
            advance_robot(&bt, r, targets[r], &cache.items[r])


def compute_energy(dict arrays, dict settings, float64_t[:, ::1] out):
    """Fill ``out`` (n_robots, 3) with kinetic, elastic and gravitational energy (J)."""
    cdef Batch b
    cdef intp_t r
    _bind(&b, arrays, settings)
    for r in range(b.n_robots):
        robot_energy(&b, r, &out[r, 0])


#: Columns of robot_aux (Rollout.aux, aux_init): what each one holds.
AUX_NAMES = ("object_x", "object_y", "object_z", "heading_x", "heading_y",
             "x_lo", "x_hi", "y_lo", "y_hi", "z_hi")


def compute_aux(dict arrays, dict settings, float64_t[:, ::1] out):
    """Fill ``out`` (n_robots, N_AUX) with each robot's current ``robot_aux`` (see ``AUX_NAMES``)."""
    cdef Batch b
    cdef intp_t r
    _bind(&b, arrays, settings)
    if out.shape[0] != b.n_robots or out.shape[1] != N_AUX:
        raise ValueError("out must have shape (n_robots, N_AUX)")
    for r in range(b.n_robots):
        robot_aux(&b, r, &out[r, 0])


def refresh_rotations(float64_t[:, ::1] quat, float64_t[:, ::1] rot):
    """Recompute ``rot`` (n_voxels, 9) from ``quat`` (n_voxels, 4) after the state was set."""
    cdef intp_t i
    with nogil:
        for i in range(quat.shape[0]):
            _rotation_matrix(&quat[i, 0], &rot[i, 0])


def seed_frames(float64_t[:, ::1] geom, bint scalar=False):
    """The seed model's bond-frame pass on given link geometry (for tests).

    ``geom`` is (10, n): rows 0-9 of the link scratch as ``_seed_geom`` and
    ``_seed_modes`` leave them (relative position p0, p1, p2; relative
    orientation qw, n1, n2, n3; nominal length; chord length; the mode, 1.0
    small / 0.0 large angle). Returns (11, n): the displacement P, voxel 1's
    rotation vector (y, z), voxel 2's, the large-angle frame (rw, ry, rz),
    from the vectorised kernel with its scalar fix-ups, or (``scalar``) from
    the seed's branchy scalar code for every link. The two must be equal bit
    for bit.
    """
    cdef:
        intp_t n = geom.shape[1], li, k
        cnp.ndarray[float64_t, ndim=2] o = np.zeros((N_LINK_OUT, max(n, 1)))
        float64_t* op = <float64_t*> cnp.PyArray_DATA(o)
        intp_t stride = o.shape[1]
    if geom.shape[0] != 10:
        raise ValueError("geom must have 10 rows")
    for k in range(10):
        for li in range(n):
            op[k * stride + li] = geom[k, li]
    with nogil:
        if scalar:
            for li in range(n):
                _seed_frame_one(li, op, stride)
        else:
            softgym_seed_frames(0, n, SMALL_ANGLE_RAD, SLTHRESH_ACOS2SQRT, op, op + stride,
                                op + 2 * stride, op + 3 * stride, op + 4 * stride,
                                op + 5 * stride, op + 6 * stride, op + 7 * stride,
                                op + 8 * stride, op + 9 * stride, op + 10 * stride,
                                op + 11 * stride, op + 12 * stride, op + 13 * stride,
                                op + 14 * stride, op + 15 * stride, op + 16 * stride,
                                op + 17 * stride, op + 18 * stride, op + 19 * stride,
                                op + 20 * stride, op + 21 * stride)
            for li in range(n):
                if op[21 * stride + li] != 0.0:
                    _seed_frame_one(li, op, stride)
    return o[10:21, :n].copy()
