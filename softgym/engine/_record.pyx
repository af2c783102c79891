# Recording: a robot's centre of mass, its auxiliary measurements
# (robot_aux, N_AUX columns), the bookkeeping after each step (record: IniCM
# and the trace samples) and its energy (robot_energy).

from libc.math cimport sqrt

from softgym.engine._batch cimport Batch, N_AUX, voxel_pos, voxel_quat
from softgym.engine._contact cimport box_penetration
from softgym.engine._typedefs cimport float64_t, intp_t, int32


cdef extern from "softgym_simd.h":
    # R = the rotation matrix of the unit quaternion q = (w, x, y, z), row-major
    void _rotation_matrix "softgym_quat_matrix" (const float64_t* q, float64_t* R) noexcept nogil


cdef void robot_cm(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0:3] = mass-weighted centre of the robot's voxels (m).
    cdef:
        intp_t i
        float64_t sx = 0.0, sy = 0.0, sz = 0.0, m
    for i in range(b.vox_start[r], b.body_end[r]):  # its objects excluded
        m = b.mass[i]
        sx += m * voxel_pos(b, i, 0)
        sy += m * voxel_pos(b, i, 1)
        sz += m * voxel_pos(b, i, 2)
    m = 1.0 / b.mass_total[r]
    out[0] = sx * m
    out[1] = sy * m
    out[2] = sz * m


cdef void robot_aux(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0:N_AUX] (see _batch.pxd): the objects' centre of mass, the
    # robot's heading sum and the bounding box of its voxel centres.
    cdef:
        intp_t i, k
        intp_t be = b.body_end[r]
        float64_t m, mo = 0.0
        float64_t x, y, z
        float64_t R[9]
        float64_t q[4]
    for k in range(N_AUX):
        out[k] = 0.0
    out[5] = voxel_pos(b, b.vox_start[r], 0)
    out[6] = out[5]
    out[7] = voxel_pos(b, b.vox_start[r], 1)
    out[8] = out[7]
    out[9] = voxel_pos(b, b.vox_start[r], 2)
    for i in range(b.vox_start[r], be):
        m = b.mass[i]
        # the heading from the quaternion (rot is not up to date within a seed step's
        # run where the build's seed step does not read it): the same bits
        voxel_quat(b, i, q)
        _rotation_matrix(q, R)
        out[3] += m * R[0]
        out[4] += m * R[3]
        x = voxel_pos(b, i, 0)
        y = voxel_pos(b, i, 1)
        z = voxel_pos(b, i, 2)
        if x < out[5]:
            out[5] = x
        if x > out[6]:
            out[6] = x
        if y < out[7]:
            out[7] = y
        if y > out[8]:
            out[8] = y
        if z > out[9]:
            out[9] = z
    for i in range(be, b.vox_start[r + 1]):
        m = b.mass[i]
        mo += m
        out[0] += m * voxel_pos(b, i, 0)
        out[1] += m * voxel_pos(b, i, 1)
        out[2] += m * voxel_pos(b, i, 2)
    if mo > 0.0:
        mo = 1.0 / mo
        out[0] *= mo
        out[1] *= mo
        out[2] *= mo


cdef void record(Batch* b, intp_t r) noexcept nogil:
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
            pen = box_penetration(b.boxes + 6 * k, b.pos + 3 * i, 0.5 * b.scale[i], nrm)
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
