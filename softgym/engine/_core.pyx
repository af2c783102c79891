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
#   M2 = -k_b (b1 + 2 b2), torsion +-k_t tau u, axial force -k_a e u on voxel 2
#   and the shear force that balances the moments, r x (M1 + M2) / L.
#   Damping uses the same forms with the deformation rates, so its power is
#   never positive.
# - floor: penalty normal force, collision damping and Coulomb friction
#   (static threshold, kinetic coefficient) as the seed's engine.
#
# The code walks flat arrays through raw pointers; bounds are checked by the
# Python wrapper (simulation.py) once, never here.

from cython.parallel cimport prange, parallel
from libc.math cimport sin, cos, sqrt, fabs, M_PI
from libc.string cimport memset

cimport numpy as cnp

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


cdef inline void _actuate(Batch* b, intp_t r) noexcept nogil:
    # OUT: b.scale of robot r's voxels at the robot's current time.
    cdef:
        intp_t i
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        float64_t t = b.steps[r] * b.dt[r]
        float64_t L = b.L
        float64_t lo = b.min_scale * L
        float64_t f, new, s, c, amp, w
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
        return
    if t < b.init_time:
        return  # nominal sizes until the settling time is over (scale starts at L)
    w = 2.0 * M_PI / b.period[r]
    s = sin(w * t)
    c = cos(w * t)
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


cdef inline int _links_along(Batch* b, intp_t lo, intp_t hi,
                             const intp_t ax, const intp_t p, const intp_t q) noexcept nogil:
    # Links lo..hi, all along lattice axis `ax`; (ax, p, q) is a cyclic
    # permutation of (0, 1, 2).
    cdef:
        intp_t li, i, j
        float64_t dx, dy, dz, ell, inv_l, ux, uy, uz, e
        float64_t a1x, a1y, a1z, a2x, a2y, a2z
        float64_t b1x, b1y, b1z, b2x, b2y, b2z
        float64_t tw, twdot, edot, uw
        float64_t dvx, dvy, dvz, w1x, w1y, w1z, w2x, w2y, w2z, wcx, wcy, wcz
        float64_t r1x, r1y, r1z, r2x, r2y, r2z
        float64_t kb, cb, tor, fa
        float64_t m1x, m1y, m1z, m2x, m2y, m2z, sx, sy, sz, fx, fy, fz
        float64_t max_ext = b.max_strain * b.L
        float64_t inv_L = 1.0 / b.L
        float64_t rx, ry, rz, inv_r, cx, cy, cz
        const float64_t* R1
        const float64_t* R2
        const float64_t* pos = b.pos
        const float64_t* vel = b.vel
        const float64_t* av = b.angvel
        const float64_t* scale = b.scale
        float64_t* force = b.force
        float64_t* moment = b.moment
    for li in range(lo, hi):
        i = b.v1[li]
        j = b.v2[li]
        dx = pos[3 * j] - pos[3 * i]
        dy = pos[3 * j + 1] - pos[3 * i + 1]
        dz = pos[3 * j + 2] - pos[3 * i + 2]
        ell = sqrt(dx * dx + dy * dy + dz * dz)
        e = ell - 0.5 * (scale[i] + scale[j])
        if not (fabs(e) <= max_ext):
            return STATUS_STRAIN  # also catches NaN
        inv_l = 1.0 / ell
        ux = dx * inv_l
        uy = dy * inv_l
        uz = dz * inv_l
        R1 = b.rot + 9 * i
        R2 = b.rot + 9 * j
        # lattice axis of the link in each voxel (column ax of its rotation)
        # and the link's frame axis r, their bisector
        a1x = R1[ax]; a1y = R1[3 + ax]; a1z = R1[6 + ax]
        a2x = R2[ax]; a2y = R2[3 + ax]; a2z = R2[6 + ax]
        rx = a1x + a2x
        ry = a1y + a2y
        rz = a1z + a2z
        inv_r = 1.0 / sqrt(rx * rx + ry * ry + rz * rz)
        rx = rx * inv_r
        ry = ry * inv_r
        rz = rz * inv_r
        # transverse offset of voxel 2 as an angle on the nominal length,
        # c = r x d / L (the seed's Pos2.y / L: stiffness does not grow when
        # actuated voxels shrink)
        cx = (ry * dz - rz * dy) * inv_L
        cy = (rz * dx - rx * dz) * inv_L
        cz = (rx * dy - ry * dx) * inv_L
        # bending: rotation of each voxel relative to the chord, b = r x a - c
        b1x = ry * a1z - rz * a1y - cx
        b1y = rz * a1x - rx * a1z - cy
        b1z = rx * a1y - ry * a1x - cz
        b2x = ry * a2z - rz * a2y - cx
        b2y = rz * a2x - rx * a2z - cy
        b2z = rx * a2y - ry * a2x - cz
        # twist of voxel 2 relative to voxel 1 about the link: with y, z the
        # voxels' two other lattice axes, sin(twist) = (z1 . y2 - y1 . z2) / 2
        tw = 0.5 * (R1[q] * R2[p] + R1[3 + q] * R2[3 + p] + R1[6 + q] * R2[6 + p]
                    - R1[p] * R2[q] - R1[3 + p] * R2[3 + q] - R1[6 + p] * R2[6 + q])
        # rates
        dvx = vel[3 * j] - vel[3 * i]
        dvy = vel[3 * j + 1] - vel[3 * i + 1]
        dvz = vel[3 * j + 2] - vel[3 * i + 2]
        w1x = av[3 * i]
        w1y = av[3 * i + 1]
        w1z = av[3 * i + 2]
        w2x = av[3 * j]
        w2y = av[3 * j + 1]
        w2z = av[3 * j + 2]
        edot = ux * dvx + uy * dvy + uz * dvz
        # rate of the transverse angle c (perpendicular to r)
        wcx = (ry * dvz - rz * dvy) * inv_L
        wcy = (rz * dvx - rx * dvz) * inv_L
        wcz = (rx * dvy - ry * dvx) * inv_L
        uw = rx * w1x + ry * w1y + rz * w1z
        r1x = w1x - wcx - uw * rx
        r1y = w1y - wcy - uw * ry
        r1z = w1z - wcz - uw * rz
        twdot = -uw
        uw = rx * w2x + ry * w2y + rz * w2z
        r2x = w2x - wcx - uw * rx
        r2y = w2y - wcy - uw * ry
        r2z = w2z - wcz - uw * rz
        twdot = twdot + uw
        # moments on the two voxels
        kb = b.k_bend[li]
        cb = b.c_bend[li]
        tor = b.k_torsion[li] * tw + b.c_torsion[li] * twdot
        m1x = -kb * (2.0 * b1x + b2x) - cb * (2.0 * r1x + r2x) + tor * rx
        m1y = -kb * (2.0 * b1y + b2y) - cb * (2.0 * r1y + r2y) + tor * ry
        m1z = -kb * (2.0 * b1z + b2z) - cb * (2.0 * r1z + r2z) + tor * rz
        m2x = -kb * (b1x + 2.0 * b2x) - cb * (r1x + 2.0 * r2x) - tor * rx
        m2y = -kb * (b1y + 2.0 * b2y) - cb * (r1y + 2.0 * r2y) - tor * ry
        m2z = -kb * (b1z + 2.0 * b2z) - cb * (r1z + 2.0 * r2z) - tor * rz
        # force on voxel 2: axial along the chord, plus the shear that balances
        # the moments over the nominal length
        sx = m1x + m2x
        sy = m1y + m2y
        sz = m1z + m2z
        fa = b.k_axial[li] * e + b.c_axial[li] * edot
        fx = (ry * sz - rz * sy) * inv_L - fa * ux
        fy = (rz * sx - rx * sz) * inv_L - fa * uy
        fz = (rx * sy - ry * sx) * inv_L - fa * uz
        force[3 * j] += fx
        force[3 * j + 1] += fy
        force[3 * j + 2] += fz
        force[3 * i] -= fx
        force[3 * i + 1] -= fy
        force[3 * i + 2] -= fz
        moment[3 * i] += m1x
        moment[3 * i + 1] += m1y
        moment[3 * i + 2] += m1z
        moment[3 * j] += m2x
        moment[3 * j + 1] += m2y
        moment[3 * j + 2] += m2z
    return STATUS_OK


cdef inline int _integrate(Batch* b, intp_t r) noexcept nogil:
    # IN: force, moment. OUT: pos, vel, quat, angvel, rot (symplectic Euler).
    cdef:
        intp_t i
        float64_t dt = b.dt[r]
        float64_t fx, fy, fz, vx, vy, vz, m, h, pen, fn, fxy, vxy, fk, cg, rd
        float64_t wx, wy, wz, qw, qx, qy, qz, nq
        float64_t* pos = b.pos
        float64_t* vel = b.vel
        float64_t* av = b.angvel
        float64_t* qq
        float64_t g = b.gravity
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        if b.fixed[i]:
            vel[3 * i] = 0.0
            vel[3 * i + 1] = 0.0
            vel[3 * i + 2] = 0.0
            av[3 * i] = 0.0
            av[3 * i + 1] = 0.0
            av[3 * i + 2] = 0.0
            continue
        m = b.mass[i]
        vx = vel[3 * i]
        vy = vel[3 * i + 1]
        vz = vel[3 * i + 2]
        cg = b.c_global[i]
        fx = b.force[3 * i] + b.ext_force[3 * i] - cg * vx
        fy = b.force[3 * i + 1] + b.ext_force[3 * i + 1] - cg * vy
        fz = b.force[3 * i + 2] + b.ext_force[3 * i + 2] - cg * vz + m * g
        if b.floor_enabled:
            pen = 0.5 * b.scale[i] - pos[3 * i + 2]
            if pen > 0.0:
                fn = b.k_floor[i] * pen - b.c_floor[i] * vz
                if fn < 0.0:
                    fn = 0.0  # the floor pushes, never pulls
                fz = fz + fn
                if vx == 0.0 and vy == 0.0:
                    # at rest: static friction holds below mu_s N; above it the
                    # voxel starts to slide (no friction on this first step)
                    fxy = sqrt(fx * fx + fy * fy)
                    if fxy <= b.mu_s[i] * fn:
                        fx = 0.0
                        fy = 0.0
                else:
                    vxy = sqrt(vx * vx + vy * vy)
                    fk = b.mu_k[i] * fn
                    if fk * dt >= m * vxy:
                        # kinetic friction would reverse the motion: stop (static)
                        vel[3 * i] = 0.0
                        vel[3 * i + 1] = 0.0
                        fx = 0.0
                        fy = 0.0
                    else:
                        fx = fx - fk * vx / vxy
                        fy = fy - fk * vy / vxy
        h = dt * b.inv_mass[i]
        vel[3 * i] += fx * h
        vel[3 * i + 1] += fy * h
        vel[3 * i + 2] += fz * h
        pos[3 * i] += vel[3 * i] * dt
        pos[3 * i + 1] += vel[3 * i + 1] * dt
        pos[3 * i + 2] += vel[3 * i + 2] * dt
        if not (fabs(pos[3 * i]) + fabs(pos[3 * i + 1]) + fabs(pos[3 * i + 2]) < RUNAWAY):
            return STATUS_NONFINITE
        # rotation: w += M dt / I, global damping, q += 0.5 dt (0, w) q
        h = dt * b.inv_inertia[i]
        rd = b.rot_damp[i]
        av[3 * i] = (av[3 * i] + b.moment[3 * i] * h) * rd
        av[3 * i + 1] = (av[3 * i + 1] + b.moment[3 * i + 1] * h) * rd
        av[3 * i + 2] = (av[3 * i + 2] + b.moment[3 * i + 2] * h) * rd
        wx = av[3 * i] * 0.5 * dt
        wy = av[3 * i + 1] * 0.5 * dt
        wz = av[3 * i + 2] * 0.5 * dt
        qq = b.quat + 4 * i
        qw = qq[0] - wx * qq[1] - wy * qq[2] - wz * qq[3]
        qx = qq[1] + wx * qq[0] + wy * qq[3] - wz * qq[2]
        qy = qq[2] + wy * qq[0] + wz * qq[1] - wx * qq[3]
        qz = qq[3] + wz * qq[0] + wx * qq[2] - wy * qq[1]
        nq = 1.0 / sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
        qq[0] = qw * nq
        qq[1] = qx * nq
        qq[2] = qy * nq
        qq[3] = qz * nq
        _rotation_matrix(qq, b.rot + 9 * i)
    return STATUS_OK


cdef void robot_cm(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0:3] = mass-weighted centre of the robot's voxels (m).
    cdef:
        intp_t i
        float64_t sx = 0.0, sy = 0.0, sz = 0.0, m
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        m = b.mass[i]
        sx += m * b.pos[3 * i]
        sy += m * b.pos[3 * i + 1]
        sz += m * b.pos[3 * i + 2]
    m = 1.0 / b.mass_total[r]
    out[0] = sx * m
    out[1] = sy * m
    out[2] = sz * m


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
        b.trace_n[r] += 1


cdef int advance_robot(Batch* b, intp_t r, step_t target) noexcept nogil:
    """Step robot r until steps[r] == target, or until it diverges.

    Modifies in place every per-voxel state array of the robot, its step count,
    traces and divergence flags. Returns a STATUS_* code.
    """
    cdef:
        int status = STATUS_OK
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
    if b.diverged[r]:
        return STATUS_OK
    if b.steps[r] == 0:
        _record(b, r)
    while b.steps[r] < target:
        _actuate(b, r)
        memset(b.force + 3 * vs, 0, 3 * (ve - vs) * sizeof(float64_t))
        memset(b.moment + 3 * vs, 0, 3 * (ve - vs) * sizeof(float64_t))
        status = _link_forces(b, r)
        if status == STATUS_OK:
            status = _integrate(b, r)
        if status != STATUS_OK:
            b.diverged[r] = 1
            b.diverged_code[r] = status
            b.diverged_time[r] = b.steps[r] * b.dt[r]
            return status
        b.steps[r] += 1
        _record(b, r)
    return STATUS_OK


cdef void robot_energy(Batch* b, intp_t r, float64_t* out) noexcept nogil:
    # OUT: out[0] kinetic (translation + rotation), out[1] elastic (links + floor),
    # out[2] gravitational potential m |g|... relative to z = 0 (J).
    cdef:
        intp_t i, j, li, ax, p, q
        float64_t ke = 0.0, pe = 0.0, ge = 0.0
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
        if b.floor_enabled:
            pen = 0.5 * b.scale[i] - b.pos[3 * i + 2]
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
        inv_r = 1.0 / sqrt(rx * rx + ry * ry + rz * rz)
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
    b.floor_enabled = s["floor_enabled"]
    b.actuation_mode = s["actuation_mode"]
    b.trace_capacity = a["trace_t"].shape[1]
    b.vox_start = <intp_t*> _p(a, "vox_start")
    b.link_start = <intp_t*> _p(a, "link_start")
    b.dt = _f(a, "dt")
    b.steps = <step_t*> _p(a, "steps")
    b.temp_amp = _f(a, "temp_amp")
    b.period = _f(a, "period")
    b.use_temp = <flag_t*> _p(a, "use_temp")
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
    b.link_axis_count = <intp_t*> _p(a, "link_axis_count")
    # links: a robot without links leaves these arrays empty (never dereferenced)
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
    return 0


def advance(dict arrays, dict settings, step_t[::1] targets, int n_threads):
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
        intp_t r
        intp_t n
    _bind(&b, arrays, settings)
    n = b.n_robots
    if targets.shape[0] != n:
        raise ValueError("targets must hold one step count per robot")
    with nogil, parallel(num_threads=n_threads):
        # dynamic: robots of one batch differ in cost by 10x or more (bone shrinks dt)
        for r in prange(n, schedule="dynamic", chunksize=1):
            advance_robot(&b, r, targets[r])


def compute_energy(dict arrays, dict settings, float64_t[:, ::1] out):
    """Fill ``out`` (n_robots, 3) with kinetic, elastic and gravitational energy (J)."""
    cdef Batch b
    cdef intp_t r
    _bind(&b, arrays, settings)
    for r in range(b.n_robots):
        robot_energy(&b, r, &out[r, 0])


def refresh_rotations(float64_t[:, ::1] quat, float64_t[:, ::1] rot):
    """Recompute ``rot`` (n_voxels, 9) from ``quat`` (n_voxels, 4) after the state was set."""
    cdef intp_t i
    with nogil:
        for i in range(quat.shape[0]):
            _rotation_matrix(&quat[i, 0], &rot[i, 0])
