# The voxel update of both models (symplectic Euler): forces and moments
# accumulated by the link and collision kernels, plus gravity, global
# damping, external forces, fluid drag and contact with the floor and
# terrain boxes (the contact laws are inline in _contact.pxd), become new
# velocities, positions and orientations.
#   integrate_corotational  model 1 (co-rotational), with the displacement
#                           since the last collision-list rebuild
#   integrate_seed          model 0 (the seed's EulerStep)

from libc.math cimport fabs, sqrt
from libc.string cimport memset

from softgym.engine._batch cimport (Batch, MODEL_SEED, STATUS_OK, STATUS_NONFINITE,
                                   SOFTGYM_FM_STRIDE)
from softgym.engine._contact cimport surface_contact, box_penetration, seed_floor
from softgym.engine._prof cimport softgym_prof_tsc, softgym_prof_add, prof_counts
from softgym.engine._typedefs cimport float64_t, intp_t, int32, flag_t

cdef float64_t RUNAWAY = 1.0e6  # |coordinate| (m) beyond which a robot diverged
# whether the voxel updates and the orientation steps run their blocks of vector lanes
# where the build has them (set_vector_blocks: off, the scalar loops, with the same bits)
cdef int _vector_blocks = 1


cdef extern from "softgym_simd.h":
    # R = the rotation matrix of the unit quaternion q = (w, x, y, z), row-major
    void _rotation_matrix "softgym_quat_matrix" (const float64_t* q, float64_t* R) noexcept nogil
    # 1 where both models' step loops keep the voxels' state in the voxel rows of vox_out
    # (include/softgym_simd.h: SOFTGYM_ROW_POS ...)
    enum: SOFTGYM_STATE_ROWS
    # 1 where neither model's step reads the voxels' rotation matrices (the seed's
    # scatter takes voxel 1's from the geometry's rows, the corotational links from rows
    # computed from the quaternions): the voxel updates do not store them,
    # refresh_robot_rotations does at the end of advance_robot
    enum: SOFTGYM_ROT_DEFERRED
    # |v|^2 with the same bits in every build that inlines it
    float64_t speed_squared "softgym_speed2" (float64_t vx, float64_t vy, float64_t vz) noexcept nogil


cdef inline void _fluid_drag(Batch* b, intp_t i, float64_t* f) noexcept nogil:
    # Quadratic fluid drag on voxel i's exposed faces (b.faces): a face of area
    # s^2 moving into the fluid along its outward normal n at speed v.n > 0 takes
    # -fluid_drag s^2 (v.n)^2 n (fluid_drag = rho C_d / 2); a face moving away
    # takes none. Applied at the voxel's centre. IN/OUT: f.
    cdef:
        float64_t R[9]
        const float64_t* v = b.vel + 3 * i
        float64_t k = b.fluid_drag * b.scale[i] * b.scale[i]
        float64_t vn, g
        int32 a, bit
        int32 exposed = b.faces[i]
    # the voxel's rotation matrix from its quaternion (the bits b.rot holds where it is
    # kept up to date: the seed step may leave it to the end of advance_robot)
    _rotation_matrix(b.quat + 4 * i, R)
    for a in range(3):
        vn = v[0] * R[a] + v[1] * R[3 + a] + v[2] * R[6 + a]
        bit = 2 * a + 1 if vn > 0.0 else 2 * a
        if exposed & (1 << bit):
            g = k * vn * fabs(vn)
            f[0] -= g * R[a]
            f[1] -= g * R[3 + a]
            f[2] -= g * R[6 + a]


cdef inline void _clear(Batch* b, intp_t i) noexcept nogil:
    # voxel i's force and moment row (padding included), or its float link forces
    cdef int k
    if b.link_f != NULL:
        for k in range(6):
            b.link_f[k * b.link_fs + i] = 0.0
    else:
        memset(b.force + SOFTGYM_FM_STRIDE * i, 0, SOFTGYM_FM_STRIDE * sizeof(float64_t))


cdef inline const float64_t* _forces_of(const Batch* b, intp_t i, float64_t* buf) noexcept nogil:
    # voxel i's accumulated force (columns 0-2) and moment (4-6): its row of b.force, or
    # its float link forces widened (exactly) into buf
    cdef int k
    if b.link_f == NULL:
        return b.force + SOFTGYM_FM_STRIDE * i
    for k in range(3):
        buf[k] = b.link_f[k * b.link_fs + i]
        buf[4 + k] = b.link_f[(3 + k) * b.link_fs + i]
    return buf


cdef void clear_robot(Batch* b, intp_t r) noexcept nogil:
    # zero the robot's force/moment scratch (before its steps, after an early exit): its
    # rows of b.force, and the thread's float rows of link forces with their slack
    cdef intp_t vs = b.vox_start[r], ve = b.vox_start[r + 1]
    memset(b.force + SOFTGYM_FM_STRIDE * vs, 0, SOFTGYM_FM_STRIDE * (ve - vs) * sizeof(float64_t))
    if b.link_f != NULL:
        memset(b.link_f + vs, 0, (6 * b.link_fs + 64) * sizeof(float))


cdef inline float64_t _drift2(const float64_t* pos, const float64_t* ref, intp_t i, intp_t vs,
                               float64_t* c) noexcept nogil:
    # squared displacement of voxel i since the contact list's rebuild (ref), less
    # the robot's first voxel's (c, set when i == vs): a common translation does not
    # bring voxels closer, so walking costs no rebuild
    cdef intp_t k = 3 * (i - vs)
    if i == vs:
        c[0] = pos[3 * i] - ref[k]
        c[1] = pos[3 * i + 1] - ref[k + 1]
        c[2] = pos[3 * i + 2] - ref[k + 2]
    return ((pos[3 * i] - ref[k] - c[0]) ** 2 + (pos[3 * i + 1] - ref[k + 1] - c[1]) ** 2
            + (pos[3 * i + 2] - ref[k + 2] - c[2]) ** 2)


cdef inline float64_t _raise(float64_t best, float64_t v) noexcept nogil:
    # best raised to v (a NaN v never: the running maxima of the voxel updates)
    return v if v > best else best


cdef inline float64_t _translate(float64_t* v, float64_t* p, const float64_t* f, float64_t h,
                                 float64_t dt) noexcept nogil:
    # one voxel's symplectic Euler step of translation: v += f h, then p += v dt
    # (h = dt / m); returns |p_x| + |p_y| + |p_z| for the runaway check. The new
    # values are kept in locals: the stores to v may alias p for the compiler,
    # which otherwise reloaded each velocity just stored (a store-to-load wait)
    cdef float64_t vx = v[0] + f[0] * h, vy = v[1] + f[1] * h, vz = v[2] + f[2] * h
    cdef float64_t px, py, pz
    v[0] = vx
    v[1] = vy
    v[2] = vz
    px = p[0] + vx * dt
    py = p[1] + vy * dt
    pz = p[2] + vz * dt
    p[0] = px
    p[1] = py
    p[2] = pz
    return fabs(px) + fabs(py) + fabs(pz)


cdef inline void _spin(Batch* b, intp_t i, float64_t dt, float64_t mx, float64_t my,
                       float64_t mz) noexcept nogil:
    # angular velocity: w += M dt / I, then the global damping factor
    cdef:
        float64_t h = dt * b.inv_inertia[i]
        float64_t rd = b.rot_damp[i]
        float64_t* av = b.angvel
    av[3 * i] = (av[3 * i] + mx * h) * rd
    av[3 * i + 1] = (av[3 * i + 1] + my * h) * rd
    av[3 * i + 2] = (av[3 * i + 2] + mz * h) * rd


cdef extern from "softgym_voxels.h":
    # the voxel updates of a block of voxels in vector lanes (both models; AVX-512: 8,
    # AVX2: 4, SSE2: 2; SOFTGYM_VOXELS8 is 1 where any); 1: stepped, 0: nothing written
    # (a fixed or runaway voxel among them: the scalar loop steps them). Documented in
    # include/softgym_voxels.h
    int SOFTGYM_VOXELS8
    int SOFTGYM_VOXEL_BLOCK  # the lanes of a block (8: AVX-512, 4: AVX2, 2: SSE2)
    int SOFTGYM_VOXEL_BLOCK_COROT  # whether the corotational model has blocks
    int voxels8 "softgym_voxels8" (
        int seed, intp_t i, intp_t vs, float64_t dt, float64_t g, int has_floor,
        float64_t* force, float64_t* moment, const float64_t* c_global, const float64_t* mass,
        const float64_t* inv_mass, const float64_t* inv_inertia, const float64_t* rot_damp,
        const float64_t* scale, const float64_t* k_floor, const float64_t* c_floor,
        const float64_t* mu_s, const float64_t* mu_k, const flag_t* fixed,
        const float64_t* ref, float64_t* c, int track_speed, float64_t runaway,
        float64_t* dmax, float64_t* vmax2, float64_t* rows, intp_t rn, float* lf,
        intp_t lfs, float64_t* pos, float64_t* vel, float64_t* av,
        const float64_t* ext) noexcept nogil


cdef inline intp_t _scalar_run(Batch* b, intp_t r, intp_t* lo, int seed, const float64_t* ref,
                               float64_t* c, float64_t* dmax,
                               float64_t* vmax2) noexcept nogil:
    # The voxel updates' schedule from voxel lo[0] on: blocks of SOFTGYM_VOXEL_BLOCK go to
    # the vector lanes while they take them (where the build has them, set_vector_blocks
    # left them on, and the robot has no fluid and no terrain box; lo[0] moves past each block stepped; the block from the robot's first
    # voxel sets c, the drift reference's offset, as the scalar loop would); returns the
    # end of the run the scalar loop must do from lo[0]: a block the lanes left (a fixed
    # or runaway voxel), or the rest
    cdef:
        intp_t vs = b.vox_start[r], ve = b.vox_start[r + 1]
    if not SOFTGYM_VOXELS8 or b.fluid_drag > 0.0 or b.box_start[r] != b.box_start[r + 1]:
        return ve
    if not _vector_blocks or (not seed and not SOFTGYM_VOXEL_BLOCK_COROT):
        return ve
    while lo[0] + SOFTGYM_VOXEL_BLOCK <= ve:
        if not voxels8(seed, lo[0], vs, b.dt[r], b.gravity, b.floor[r], b.force, b.moment,
                     b.c_global, b.mass, b.inv_mass, b.inv_inertia,
                     b.rot_damp, b.scale, b.k_floor, b.c_floor, b.mu_s, b.mu_k, b.fixed, ref,
                     c, b.self_collision and seed, RUNAWAY, dmax, vmax2, b.vox_out,
                     b.vox_stride, b.link_f, b.link_fs, b.pos, b.vel, b.angvel, b.ext_force):
            return lo[0] + SOFTGYM_VOXEL_BLOCK
        lo[0] += SOFTGYM_VOXEL_BLOCK
    return ve


cdef inline void _box_contacts(Batch* b, intp_t i, intp_t k0, intp_t k1, float64_t dt,
                               float64_t* f) noexcept nogil:
    # voxel i against the robot's terrain boxes k0..k1 (the common surface contact)
    cdef intp_t k
    cdef float64_t pen
    cdef float64_t n[3]
    for k in range(k0, k1):
        pen = box_penetration(b.boxes + 6 * k, b.pos + 3 * i, 0.5 * b.scale[i], n)
        if pen > 0.0:
            surface_contact(b, i, n[0], n[1], n[2], pen, dt, f)


cdef inline int _ran_away(Batch* b, intp_t r, intp_t i, float64_t dt, const int seed,
                          float64_t dmax, float64_t* dmax2) noexcept nogil:
    # voxel i ran away: the voxels before it were stepped; their orientations, the
    # robot's force scratch cleared, STATUS_NONFINITE
    dmax2[0] = dmax
    _orient(b, b.vox_start[r], i, dt, seed)
    clear_robot(b, r)
    return STATUS_NONFINITE


cdef int integrate_corotational(Batch* b, intp_t r, const float64_t* ref,
                                float64_t* dmax2) noexcept nogil:
    # IN: force, moment. OUT: pos, vel, quat, angvel, rot (symplectic Euler).
    # If ref (the robot's positions when its contact list was built) is not
    # NULL, dmax2 gets the largest squared displacement from it, relative to
    # the first voxel's (any common shift c bounds the approach of two voxels:
    # |dp_i - dp_j| <= |dp_i - c| + |dp_j - c|).
    cdef:
        intp_t i, k
        float64_t dt = b.dt[r]
        float64_t m, pen, cg, mx, my, mz
        const float64_t* fm
        float64_t fbuf[8]
        float64_t c[3]
        float64_t f[3]
        float64_t* pos = b.pos
        float64_t* vel = b.vel
        float64_t* av = b.angvel
        float64_t g = b.gravity
        int32 has_floor = b.floor[r]
        int32 has_fluid = b.fluid_drag > 0.0
        intp_t k0 = b.box_start[r]
        intp_t k1 = b.box_start[r + 1]
        intp_t vs = b.vox_start[r]
        float64_t dmax = 0.0, vmax2 = 0.0  # (vmax2: not tracked by this model)
        intp_t lo, hi
        intp_t ve = b.vox_start[r + 1]
    dmax2[0] = 0.0
    c[0] = 0.0
    c[1] = 0.0
    c[2] = 0.0
    lo = vs  # (blocks of 8 voxels in vector lanes where they can: _scalar_run)
    while lo < ve:
        hi = _scalar_run(b, r, &lo, 0, ref, c, &dmax, &vmax2)
        _run_from_rows(b, lo, hi)  # (as integrate_seed's)
        for i in range(lo, hi):
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
            fm = _forces_of(b, i, fbuf)  # the voxel's force, then moment (+ 4)
            f[0] = fm[0] + b.ext_force[3 * i] - cg * vel[3 * i]
            f[1] = fm[1] + b.ext_force[3 * i + 1] - cg * vel[3 * i + 1]
            f[2] = fm[2] + b.ext_force[3 * i + 2] - cg * vel[3 * i + 2] + m * g
            mx = fm[4]
            my = fm[5]
            mz = fm[6]
            _clear(b, i)  # the scratch is zero again for the next step
            if has_fluid:
                _fluid_drag(b, i, f)
            if has_floor:
                pen = 0.5 * b.scale[i] - pos[3 * i + 2]
                if pen > 0.0:
                    surface_contact(b, i, 0.0, 0.0, 1.0, pen, dt, f)
            _box_contacts(b, i, k0, k1, dt, f)
            if not (_translate(vel + 3 * i, pos + 3 * i, f, dt * b.inv_mass[i], dt) < RUNAWAY):
                _run_to_rows(b, lo, hi)
                return _ran_away(b, r, i, dt, 0, dmax, dmax2)
            if ref != NULL:
                dmax = _raise(dmax, _drift2(pos, ref, i, vs, c))
            # rotation: w += M dt / I, global damping; q += 0.5 dt (0, w) q after
            # the loop (_orient: no voxel's update reads another's orientation)
            _spin(b, i, dt, mx, my, mz)
        _run_to_rows(b, lo, hi)
        lo = hi
    dmax2[0] = dmax
    _orient(b, vs, ve, dt, 0)
    return STATUS_OK


cdef extern from "softgym_orient.h":
    # the voxels' orientation step of both models (C, for the vectorising pragma;
    # documented in include/softgym_orient.h), and the seed step's state in the voxel rows
    void softgym_seed_quats_rows(intp_t lo, intp_t hi, intp_t n, float64_t dt,
                                 const flag_t* fixed, const float64_t* quat,
                                 float64_t* rows, int newton) noexcept nogil
    void softgym_corot_quats_rows(intp_t lo, intp_t hi, intp_t n, float64_t dt,
                                  const flag_t* fixed, const float64_t* quat,
                                  float64_t* rows) noexcept nogil
    int SOFTGYM_ORIENT_BLOCK  # the lanes of the orientation step's blocks (0: none)
    void softgym_orient_records(intp_t lo, intp_t hi, intp_t n, float64_t dt,
                                const flag_t* fixed, const float64_t* av, float64_t* quat,
                                float64_t* q_out, float64_t* rot, int model,
                                int blocks) noexcept nogil
    void softgym_state_rows(intp_t lo, intp_t hi, intp_t n, const float64_t* pos,
                                 const float64_t* quat, const float64_t* vel,
                                 const float64_t* av, const float64_t* ext,
                                 float64_t* rows) noexcept nogil
    void softgym_state_back(intp_t lo, intp_t hi, intp_t n, const float64_t* rows,
                                 float64_t* pos, float64_t* quat, float64_t* vel,
                                 float64_t* av) noexcept nogil


cdef inline void _orient(Batch* b, intp_t lo, intp_t hi, float64_t dt, const int seed) noexcept nogil:
    # the orientation step of voxels lo..hi (fixed voxels keep theirs): new
    # quaternions (the seed's renormalisation: with double-precision links its exact
    # square root and division, with single-precision ones two Newton steps near unit
    # length; or the corotational model's Newton step), then their rotation matrices
    cdef:
        intp_t n = b.vox_stride  # the scratch's row stride
        float64_t* qo = b.vox_out
    if b.state_rows != NULL:
        # the step's state in the voxel rows: the quaternion rows updated in place (the
        # rotation matrices: refresh_robot_rotations, when the step loop returns)
        if seed:
            softgym_seed_quats_rows(lo, hi, n, dt, b.fixed, b.quat, qo, b.link_f32)
        else:
            softgym_corot_quats_rows(lo, hi, n, dt, b.fixed, b.quat, qo)
        return
    # from the records to the records (the rotation matrices: refresh_robot_rotations,
    # where the step does not read them)
    softgym_orient_records(lo, hi, n, dt, b.fixed, b.angvel, b.quat, qo,
                           NULL if rotations_deferred(b) else b.rot,
                           (2 if b.link_f32 else 1) if seed else 0, _vector_blocks)


cdef inline void _run_from_rows(Batch* b, intp_t lo, intp_t hi) noexcept nogil:
    # where the step's state is in the voxel rows: voxels lo..hi's state into their
    # records, for the scalar voxel loop (which steps the records)
    if b.state_rows != NULL and lo < hi:
        softgym_state_back(lo, hi, b.vox_stride, b.vox_out, b.pos, b.quat, b.vel, b.angvel)


cdef inline void _run_to_rows(Batch* b, intp_t lo, intp_t hi) noexcept nogil:
    # the reverse, after the scalar loop (or where it stops)
    if b.state_rows != NULL and lo < hi:
        softgym_state_rows(lo, hi, b.vox_stride, b.pos, b.quat, b.vel, b.angvel, NULL,
                           b.vox_out)


cdef void voxel_state_enter(Batch* b, intp_t r) noexcept nogil:
    # robot r's state into the voxel rows where its step loop keeps it there (_integrate.pxd)
    if SOFTGYM_STATE_ROWS and b.fluid_drag <= 0.0 and b.box_start[r] == b.box_start[r + 1]:
        softgym_state_rows(b.vox_start[r], b.vox_start[r + 1], b.vox_stride, b.pos, b.quat,
                           b.vel, b.angvel, b.ext_force, b.vox_out)
        b.state_rows = b.vox_out


cdef void voxel_link_rows(Batch* b, intp_t r, int seed) noexcept nogil:
    # robot r's voxel rows that its link kernels read, from the records (_integrate.pxd)
    if not SOFTGYM_STATE_ROWS or b.state_rows != NULL:
        return
    if seed:
        softgym_state_rows(b.vox_start[r], b.vox_start[r + 1], b.vox_stride, b.pos, b.quat,
                           NULL, NULL, NULL, b.vox_out)
    else:
        softgym_state_rows(b.vox_start[r], b.vox_start[r + 1], b.vox_stride, b.pos, b.quat,
                           b.vel, b.angvel, NULL, b.vox_out)


cdef void voxel_state_leave(Batch* b, intp_t r) noexcept nogil:
    # robot r's state from the voxel rows back into its records (_integrate.pxd)
    if b.state_rows != NULL:
        softgym_state_back(b.vox_start[r], b.vox_start[r + 1], b.vox_stride, b.vox_out,
                           b.pos, b.quat, b.vel, b.angvel)
    b.state_rows = NULL


cdef bint rotations_deferred(const Batch* b) noexcept nogil:
    # whether the step loop leaves the rotation matrices (b.rot) to refresh_robot_rotations
    # (_integrate.pxd)
    return SOFTGYM_ROT_DEFERRED or (b.model == MODEL_SEED and b.link_f32)


cdef void refresh_robot_rotations(Batch* b, intp_t r) noexcept nogil:
    # robot r's rotation matrices from its quaternions (where the step leaves them)
    cdef intp_t i
    if not rotations_deferred(b):
        return
    for i in range(b.vox_start[r], b.vox_start[r + 1]):
        _rotation_matrix(b.quat + 4 * i, b.rot + 9 * i)


cdef int integrate_seed(Batch* b, intp_t r, const float64_t* ref,
                        float64_t* dmax2) noexcept nogil:
    # Model 0's voxel update (the seed's EulerStep): as integrate_corotational, with the
    # seed's floor and exact quaternion renormalisation snapped to the identity
    # at w >= 1 (_orient, after the loop: no voxel's update reads
    # another's orientation). Terrain boxes use the common surface contact.
    # With self-collision, also OUT: b.col_vmax[r], the fastest voxel's new speed
    # (the seed's collision schedule), from the velocities as they are computed.
    cdef:
        intp_t i, k
        float64_t dt = b.dt[r]
        float64_t cg, mx, my, mz
        const float64_t* fm
        float64_t fbuf[8]
        float64_t c[3]
        float64_t f[3]
        float64_t* pos = b.pos
        float64_t* vel = b.vel
        float64_t* av = b.angvel
        int32 has_floor = b.floor[r]
        int32 has_fluid = b.fluid_drag > 0.0
        intp_t k0 = b.box_start[r]
        intp_t k1 = b.box_start[r + 1]
        intp_t vs = b.vox_start[r]
        float64_t vmax2 = 0.0, dmax = 0.0
        int32 track_speed = b.self_collision
        intp_t lo, hi
        intp_t ve = b.vox_start[r + 1]
        unsigned long long t0 = softgym_prof_tsc()
    dmax2[0] = 0.0
    c[0] = 0.0
    c[1] = 0.0
    c[2] = 0.0
    lo = vs  # (blocks of 8 voxels in vector lanes where they can: _scalar_run)
    while lo < ve:
        hi = _scalar_run(b, r, &lo, 1, ref, c, &dmax, &vmax2)
        _run_from_rows(b, lo, hi)  # the scalar loop's voxels' state, back after it
        for i in range(lo, hi):
            if b.fixed[i]:
                for k in range(3):
                    vel[3 * i + k] = 0.0
                    av[3 * i + k] = 0.0
                _clear(b, i)
                continue
            cg = b.c_global[i]
            fm = _forces_of(b, i, fbuf)  # the voxel's force, then moment (+ 4)
            f[0] = -cg * vel[3 * i] + fm[0] + b.ext_force[3 * i]
            f[1] = -cg * vel[3 * i + 1] + fm[1] + b.ext_force[3 * i + 1]
            f[2] = (-cg * vel[3 * i + 2] + fm[2] + b.mass[i] * b.gravity
                    + b.ext_force[3 * i + 2])
            mx = fm[4]
            my = fm[5]
            mz = fm[6]
            _clear(b, i)
            if has_fluid:
                _fluid_drag(b, i, f)
            _box_contacts(b, i, k0, k1, dt, f)
            if has_floor:
                seed_floor(b, i, dt, f)
            if not (_translate(vel + 3 * i, pos + 3 * i, f, dt * b.inv_mass[i], dt) < RUNAWAY):
                _run_to_rows(b, lo, hi)
                return _ran_away(b, r, i, dt, 1, dmax, dmax2)
            if ref != NULL:
                dmax = _raise(dmax, _drift2(pos, ref, i, vs, c))
            if track_speed:
                vmax2 = _raise(vmax2, speed_squared(vel[3 * i], vel[3 * i + 1], vel[3 * i + 2]))
            _spin(b, i, dt, mx, my, mz)
        _run_to_rows(b, lo, hi)
        lo = hi
    dmax2[0] = dmax
    softgym_prof_add(0, t0)
    t0 = softgym_prof_tsc()
    _orient(b, vs, ve, dt, 1)
    softgym_prof_add(1, t0)
    if track_speed:
        b.col_vmax[r] = sqrt(vmax2)
    return STATUS_OK


#: the parts of integrate_seed that the cycle probes time, in slot order: the
#: translation and spin (the vector lanes and the scalar loop), the orientation
CYCLE_PASSES = ("voxels", "orient")


def set_vector_blocks(bint enabled):
    """Whether the voxel updates and orientation steps run in blocks of vector lanes
    where the build has them (the default), or in the scalar loops only: the same
    bits either way (tests/engine/test_vector_blocks.py holds them to it). Not to be
    called while a simulation steps."""
    global _vector_blocks
    _vector_blocks = 1 if enabled else 0


def vector_blocks():
    """The lanes of this build's blocks (0: none): the seed and corotational models'
    voxel updates, and the orientation step on the records (AVX-512 builds step the
    orientations in the voxel rows instead)."""
    return {"seed_voxels": SOFTGYM_VOXEL_BLOCK if SOFTGYM_VOXELS8 else 0,
            "corotational_voxels": (SOFTGYM_VOXEL_BLOCK if SOFTGYM_VOXELS8
                                    and SOFTGYM_VOXEL_BLOCK_COROT else 0),
            "orientation": SOFTGYM_ORIENT_BLOCK}


def cycle_counts(bint reset=False):
    """TSC cycles spent in each of ``CYCLE_PASSES`` since the last reset (a dict), or
    None when the module was built without SOFTGYM_PROFILE_CYCLES (setup.py)."""
    return prof_counts(CYCLE_PASSES, reset)


def refresh_rotations(float64_t[:, ::1] quat, float64_t[:, ::1] rot):
    """Recompute ``rot`` (n_voxels, 9) from ``quat`` (n_voxels, 4) after the state was set."""
    cdef intp_t i
    with nogil:
        for i in range(quat.shape[0]):
            _rotation_matrix(&quat[i, 0], &rot[i, 0])
