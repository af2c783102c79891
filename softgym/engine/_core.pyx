# The step loop of softgym's engine and its Python entry points.
#
# advance_robot steps one robot of a batch (Batch, _batch.pxd) until its
# target step count, calling the concept modules once per step:
#   _corotational.pyx  model 1's link forces (co-rotational beams)
#   _seed.pyx          model 0's link forces (the seed engine's bonds)
#   _contact.pyx       self-collision: one spatial hash, both models' candidate
#                      lists, the contact law; _contact.pxd: floor and box laws
#   _integrate.pyx     the voxel update (symplectic Euler) of both models
#   _record.pyx        centre of mass, trace samples, aux, energy
# and the drive (_actuate, here). advance() runs the robots of a batch in
# parallel (OpenMP, one robot per thread at a time): results are
# deterministic and independent of threads and batching. Its Batch is bound
# by _bind.pyx (from the table in contract.py); what it keeps between calls
# (the self-collision candidates, the scratch) is a _cache.ContactCache.
#
# The code walks flat arrays through raw pointers; dtypes and shapes are checked
# once when the batch is laid out (layout.build_layout, contract.check_arrays),
# never here.

from cython.parallel cimport prange, parallel, threadid
from libc.math cimport sin, cos, sqrt, fabs, M_PI

from softgym.engine._batch cimport (Batch, STATUS_OK, STATUS_STRAIN, STATUS_NONFINITE,
                                    STATUS_MEMORY, N_AUX, N_LINK_OUT, SOFTGYM_VOXEL_ROWS,
                                    SOFTGYM_FM_STRIDE, MODEL_SEED, ACTUATION_SEED)
from softgym.engine._bind cimport bind, row_stride
from softgym.engine._cache cimport ContactCache
from softgym.engine._contact cimport (Contacts, contacts_corotational, contacts_seed, collide,
                                      collide_obstacles)
from softgym.engine._corotational cimport links_corotational
from softgym.engine._integrate cimport (integrate_corotational, integrate_seed, clear_robot,
                                       refresh_robot_rotations, voxel_state_enter,
                                       voxel_state_leave, voxel_link_rows)
from softgym.engine._record cimport record, robot_aux, robot_energy
from softgym.engine._prof cimport softgym_prof_tsc, softgym_prof_add, prof_counts
from softgym.engine._seed cimport (links_seed, SOFTGYM_CHUNK_STRIDE, SOFTGYM_CHUNK_ROWS,
                                  SOFTGYM_CHUNK_FSTRIDE, SOFTGYM_CHUNK_FROWS)
from softgym.engine._typedefs cimport float64_t, intp_t, step_t, int32, flag_t, lane_flag_t

from softgym.engine._integrate import refresh_rotations  # noqa: F401 (Python API)
from softgym.engine._seed import seed_frames  # noqa: F401 (Python API, for tests)
from softgym.engine._seed import cycle_counts as seed_cycle_counts
from softgym.engine._integrate import cycle_counts as integrate_cycle_counts

# the robots that the threads of advance step at one time are this many apart
cdef intp_t ROBOT_SPREAD = 8
cdef float64_t SEED_2PI_DRIVE = 2.0 * <float64_t> (<float> 3.1415926)  # model 0's drive


cdef inline float64_t _driven_size(const Batch* b, intp_t i, float64_t L, float64_t amp,
                                   float64_t s, float64_t c) noexcept nogil:
    # voxel i's size under the sinusoidal drive (s, c: sine and cosine of its phase
    # angle at this time; amp: the robot's temperature amplitude), before the limits
    return L * (1.0 + b.cte[i] * amp * (s * b.cos_phase[i] + c * b.sin_phase[i]))


cdef inline float64_t _actuate(Batch* b, intp_t r) noexcept nogil:
    # OUT: b.scale of robot r's voxels at the robot's current time.
    # Returns the largest size written this step (0 if none; always 0 for the
    # seed's step with the seed's actuation, which does not use it).
    cdef:
        intp_t i
        intp_t vs = b.vox_start[r]
        intp_t ve = b.vox_start[r + 1]
        float64_t t = b.steps[r] * b.dt[r]
        float64_t L = b.L
        float64_t lo = b.min_scale * L
        float64_t new, s, c, amp, w
        float64_t smax = 0.0
        int32 seed = b.actuation_mode == ACTUATION_SEED
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
    if b.model == MODEL_SEED:
        w = SEED_2PI_DRIVE * (t / b.period[r])  # the seed's sin(2 pi_f (t / T))
    else:
        w = 2.0 * M_PI / b.period[r] * t
    s = sin(w)
    c = cos(w)
    amp = b.temp_amp[r]
    if seed and b.model == MODEL_SEED:
        # the seed step does not use smax: the same sizes without branches, a
        # loop the compiler vectorises (a voxel without expansion, cte 0, or a size
        # outside [min_scale L, L] keeps its size)
        for i in range(vs, ve):
            new = _driven_size(b, i, L, amp, s, c)
            b.scale[i] = new if (new >= lo) & (new <= L) & (b.cte[i] != 0.0) else b.scale[i]
        return smax
    for i in range(vs, ve):
        if b.cte[i] == 0.0:
            continue
        new = _driven_size(b, i, L, amp, s, c)
        if seed:
            # the seed's engine: outside [min_scale L, L] the previous size is kept
            if new >= lo and new <= L:
                b.scale[i] = new
        else:
            b.scale[i] = new if new > lo else lo
        if b.scale[i] > smax:
            smax = b.scale[i]
    return smax


#: the stages of the seed model's step that the cycle probes time, in slot order
CYCLE_STAGES = ("contacts", "links", "collide", "integrate", "drive_record")


def cycle_counts(bint reset=False):
    """TSC cycles spent in each stage of the seed model's step (``CYCLE_STAGES``) and in
    each pass of its links and voxel update (``_seed.CYCLE_PASSES``,
    ``_integrate.CYCLE_PASSES``) since the last reset, as a dict; None
    unless the engine was built with SOFTGYM_PROFILE_CYCLES (setup.py;
    ``benchmarks/profile_engine.py --cycles`` builds such a copy). One thread only."""
    out = prof_counts(CYCLE_STAGES, reset)
    if out is not None:
        out.update(seed_cycle_counts(reset))
        out.update(integrate_cycle_counts(reset))
    return out


cdef int _advance_seed(Batch* b, intp_t r, step_t target, Contacts* c) noexcept nogil:
    # advance_robot for model 0: links, contacts, voxels, then the drive at
    # the step's start time sets the sizes the next step's links see
    # (softgym_prof_*: cycle probes, empty in a normal build)
    cdef:
        int status = STATUS_OK
        float64_t dmax2 = 0.0
        unsigned long long t0
    # the voxels' state into the voxel rows, where the build keeps it there through the
    # loop (the geometry, the voxel update and the orientation read and write the rows;
    # everything else reads positions and quaternions through voxel_pos / voxel_quat,
    # _batch.pxd); else the rows are filled from the records once a step
    voxel_state_enter(b, r)
    clear_robot(b, r)  # (the thread's float rows of the link forces: another robot's)
    while b.steps[r] < target:
        t0 = softgym_prof_tsc()
        voxel_link_rows(b, r, 1)  # (where the records are the state: the geometry's rows)
        if b.self_collision:
            # the seed's schedule: rebuild once the fastest voxel may have
            # covered half a voxel since the last rebuild
            b.col_acc[r] += fabs(b.col_vmax[r] * b.dt[r] / b.L)
            if b.col_acc[r] > 0.5:
                status = contacts_seed(b, r, c, 1)
                b.col_acc[r] = 0.0
            elif c.stale:
                status = contacts_seed(b, r, c, 0)
        softgym_prof_add(0, t0)
        t0 = softgym_prof_tsc()
        if status == STATUS_OK:
            status = links_seed(b, r)
        softgym_prof_add(1, t0)
        t0 = softgym_prof_tsc()
        if status == STATUS_OK and b.self_collision:
            collide(b, c)
            collide_obstacles(b, c)
        softgym_prof_add(2, t0)
        t0 = softgym_prof_tsc()
        if status == STATUS_OK:
            status = integrate_seed(b, r, NULL, &dmax2)
        softgym_prof_add(3, t0)
        t0 = softgym_prof_tsc()
        if status != STATUS_OK:
            clear_robot(b, r)
            b.diverged[r] = 1
            b.diverged_code[r] = status
            b.diverged_time[r] = b.steps[r] * b.dt[r]
            break
        # the sizes of the next step (their largest is for the corotational loop);
        # integrate_seed has set col_vmax for the next step's schedule
        _actuate(b, r)
        b.steps[r] += 1
        record(b, r)
        softgym_prof_add(4, t0)
    voxel_state_leave(b, r)  # the state back into the records
    return status


cdef int _advance_corotational(Batch* b, intp_t r, step_t target,
                               Contacts* c) noexcept nogil:
    # advance_robot for model 1: drive, links, contacts, voxels
    cdef:
        int status = STATUS_OK
        float64_t smax, dmax2 = 0.0
    # the voxels' state into the voxel rows for the loop, as _advance_seed (the link
    # kernel, the voxel update and the orientation read and write the rows)
    voxel_state_enter(b, r)
    while b.steps[r] < target:
        # force and moment scratch are zero here: integrate_corotational clears them
        smax = _actuate(b, r)
        voxel_link_rows(b, r, 0)  # (where the records are the state: the kernel's rows)
        status = links_corotational(b, r)
        if status == STATUS_OK and b.self_collision:
            if c.stale or smax > c.built_scale:
                status = contacts_corotational(b, r, c)
            collide(b, c)
        if status == STATUS_OK:
            status = integrate_corotational(b, r, c.ref if b.self_collision else NULL, &dmax2)
        if status != STATUS_OK:
            clear_robot(b, r)
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
        record(b, r)
    voxel_state_leave(b, r)
    return status


cdef int advance_robot(Batch* b, intp_t r, step_t target, Contacts* c) noexcept nogil:
    """Step robot r until steps[r] == target, or until it diverges.

    Modifies in place every per-voxel state array of the robot, its step count,
    traces and divergence flags, and its self-collision candidates ``c``
    (kept between calls; the wrapper marks them stale when it moves voxels).
    Returns a STATUS_* code.
    """
    cdef int status
    if b.diverged[r]:
        return STATUS_OK
    if b.steps[r] == 0:
        record(b, r)
    if b.model == MODEL_SEED:
        status = _advance_seed(b, r, target, c)
    else:
        status = _advance_corotational(b, r, target, c)
    # the rotation matrices, where the steps leave them (_integrate.rotations_deferred: the
    # AVX-512 builds, whose seed scatter takes voxel 1's from its geometry and corotational
    # links rows computed from the quaternions; the seed model's single-precision links in
    # every build): up to date whenever the kernel returns
    refresh_robot_rotations(b, r)
    return status


# ---------------------------------------------------------------------------
# Python-facing entry points. The layout (layout.build_layout) has checked dtypes
# and shapes against the contract; here arrays are only bound to the struct
# (_bind.bind).

#: What each STATUS_* code of a diverged robot means (``diverged_code``).
STATUS_NAMES = {
    STATUS_OK: "ok",
    STATUS_STRAIN: "link strain above max_strain (or NaN)",
    STATUS_NONFINITE: "non-finite or runaway voxel state",
    STATUS_MEMORY: "out of memory for the self-collision candidates",
}

#: Doubles in a voxel's row of the force scratch ("force": its force in columns 0-2, its
#: moment in 4-6; _batch.pxd)
FM_STRIDE = SOFTGYM_FM_STRIDE


def advance(dict arrays, dict settings, step_t[::1] targets, int n_threads, ContactCache cache):
    """Advance every robot of a batch to its target step count.

    Parameters
    ----------
    arrays : dict of str to ndarray
        The batch state (see ``_batch.pxd`` for names, shapes and units);
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
        intp_t stride = 0, vstride = 0, block, fblock, i, m, vox_at, chunk_at, f32_at, link_at
        intp_t lf_at, lfblock
        float64_t* scratch
    bind(&b, arrays, settings)
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
    stride = row_stride(stride)
    vstride = row_stride(vstride)
    b.link_stride = stride
    b.vox_stride = vstride
    # the float rows' floats rounded up to doubles (a multiple of 8: they start on a line)
    fblock = (SOFTGYM_CHUNK_FROWS * SOFTGYM_CHUNK_FSTRIDE + 15) // 16 * 8
    # a thread's block, in doubles from its start: the robot's link rows (link_out), its
    # voxel rows (vox_out), the chunk's output rows (chunk_out), float rows (chunk_f32)
    # and link scratch rows (chunk_link)
    vox_at = N_LINK_OUT * stride
    chunk_at = vox_at + SOFTGYM_VOXEL_ROWS * vstride
    f32_at = chunk_at + SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE
    link_at = f32_at + fblock
    # the link forces' 6 float rows (single-precision links of model 0), a multiple of 16
    # floats apart (each row starts on a line), and 64 floats of slack (the push's windows
    # of 16 voxels may reach 47 past a robot's last voxel), in doubles
    lf_at = link_at + N_LINK_OUT * SOFTGYM_CHUNK_STRIDE
    b.link_fs = (vstride + 15) // 16 * 16
    lfblock = (6 * b.link_fs + 64) // 2 if b.link_f32 and b.model == MODEL_SEED else 0
    block = lf_at + lfblock
    scratch = cache.scratch(max(n_threads * block, 1))
    # robots in the order 0, 8, 16, ..., then 1, 9, 17, ...: the robots that the
    # threads step at one time are ROBOT_SPREAD apart, so no two of them write
    # one cache line (a robot's first and last voxels share lines of every
    # per-voxel array with its neighbours', and the per-robot counters steps,
    # col_acc, col_vmax are 8 to a line). In index order the two threads often
    # stepped neighbours and passed those lines back and forth every step: a
    # batch of 2,048 robots of 3^3 voxels ran no faster on 2 threads than on 1
    # (benchmarks/RESULTS.md). Each robot's result does not depend on the order.
    m = (n + ROBOT_SPREAD - 1) // ROBOT_SPREAD
    with nogil, parallel(num_threads=n_threads):
        # dynamic: robots of one batch differ in cost by 10x or more (bone shrinks dt)
        for i in prange(ROBOT_SPREAD * m, schedule="dynamic", chunksize=1):
            r = ROBOT_SPREAD * (i % m) + i // m
            if r < n:
                t = threadid()
                bt = b
                # row k of link li sits at link_out[k * stride + li], of voxel i
                # at vox_out[k * vstride + i]: the thread's block, offset by the
                # robot's first link and voxel
                bt.link_out = scratch + t * block - b.link_start[r]
                bt.vox_out = scratch + t * block + vox_at - b.vox_start[r]
                bt.chunk_out = scratch + t * block + chunk_at
                bt.chunk_f32 = <float*> (scratch + t * block + f32_at)
                bt.chunk_link = scratch + t * block + link_at
                if lfblock > 0:
                    bt.link_f = <float*> (scratch + t * block + lf_at) - b.vox_start[r]
                advance_robot(&bt, r, targets[r], &cache.items[r])


def compute_energy(dict arrays, dict settings, float64_t[:, ::1] out):
    """Fill ``out`` (n_robots, 3) with kinetic, elastic and gravitational energy (J)."""
    cdef Batch b
    cdef intp_t r
    bind(&b, arrays, settings)
    for r in range(b.n_robots):
        robot_energy(&b, r, &out[r, 0])


#: Columns of robot_aux (Rollout.aux, aux_init): what each one holds.
AUX_NAMES = ("object_x", "object_y", "object_z", "heading_x", "heading_y",
             "x_lo", "x_hi", "y_lo", "y_hi", "z_hi")


def compute_aux(dict arrays, dict settings, float64_t[:, ::1] out):
    """Fill ``out`` (n_robots, N_AUX) with each robot's current ``robot_aux`` (see ``AUX_NAMES``)."""
    cdef Batch b
    cdef intp_t r
    bind(&b, arrays, settings)
    if out.shape[0] != b.n_robots or out.shape[1] != N_AUX:
        raise ValueError("out must have shape (n_robots, N_AUX)")
    for r in range(b.n_robots):
        robot_aux(&b, r, &out[r, 0])
