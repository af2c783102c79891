# Model 0, "seed": the step of the seed study's engine (evosoro's bundled
# VoxCAD-era Voxelyze, docs/PHYSICS.md), written anew from its
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
# - the drive's 2 pi is the single-precision constant.
# One departure: the seed's surface test is always true (every voxel is a
# self-collision candidate there); here only surface voxels (missing a face
# bond) are, as the seed intended: an interior voxel is shielded by its six
# bonded neighbours, and fidelity_seed.py's targets hold.
#
# This module holds the seed's link forces (links_seed); its voxel update
# (integrate_seed, the floor law) is in _integrate.pyx / _contact.pxd, its
# collision list in _contact.pyx, the drive and the step loop in _core.pyx.
# The vectorised passes are C in include/softgym_seed.h.

from libc.math cimport cos, acos, sqrt, fabs

cimport numpy as cnp
import numpy as np

from softgym.engine._batch cimport Batch, STATUS_OK, STATUS_STRAIN, N_LINK_OUT
from softgym.engine._prof cimport softgym_prof_tsc, softgym_prof_add, prof_counts
from softgym.engine._typedefs cimport float64_t, intp_t, lane_flag_t

cnp.import_array()

cdef float64_t SEED_PI = 3.14159265358979         # the seed's PI macro
cdef float64_t SMALL_ANGLE_RAD = 1.732e-2          # relative rotation of a small-angle link
cdef float64_t HYSTERESIS = 1.1
cdef float64_t SMALL_ANGLE_W = cos(0.5 * SMALL_ANGLE_RAD)
cdef float64_t SMALLISH_ANGLE_W = cos(HYSTERESIS * SMALL_ANGLE_RAD * 0.5)
cdef float64_t SLTHRESH_ACOS2SQRT = 1.0 - 0.9988 * 0.9988
cdef float64_t ACOS2SQRT_W = 0.9988  # the same cut on w (1 - w^2 < it: w > 0.9988)
cdef float64_t DISCARD_ANGLE_RAD = 1.0e-7
cdef float64_t SA_BOND_BEND_RAD = 0.05
cdef float64_t SA_BOND_EXT_PERC = 1.30


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


cdef extern from "softgym_seed.h":
    # the passes of links_seed (C, for the vectorising pragma and one
    # copy per link axis; documented in include/softgym_seed.h)
    # (the two frames passes return whether any link needs _seed_frame_one)
    int softgym_seed_frames(intp_t lo, intp_t hi, float64_t sa_rad, float64_t thr,
                            const float64_t* p0_, const float64_t* p1_, const float64_t* p2_,
                            const float64_t* qw_, const float64_t* n1_, const float64_t* n2_,
                            const float64_t* n3_, const float64_t* nom_, const float64_t* len_,
                            const float64_t* sa_, float64_t* o_P0, float64_t* o_P1,
                            float64_t* o_P2, float64_t* o_a1y, float64_t* o_a1z,
                            float64_t* o_a2x, float64_t* o_a2y, float64_t* o_a2z,
                            float64_t* o_rw, float64_t* o_ry, float64_t* o_rz,
                            float64_t* o_fix) noexcept nogil
    void softgym_seed_forces(intp_t lo, intp_t hi, intp_t n, float64_t L, float64_t bz,
                             float64_t bzh, float64_t inv_dt, const float64_t* inp,
                             intp_t in_stride, const float64_t* sa_, const float64_t* chg_,
                             const float64_t* neg2_, const float64_t* ka_,
                             const float64_t* kt_, const float64_t* kb_, const float64_t* cs_,
                             float64_t* link_last, float64_t* out) noexcept nogil
    # the geometry and then the modes of links lo..hi along ax (softgym_seed_geom,
    # softgym_seed_modes; with AVX-512 the modes of its vector blocks in its loop); m: the
    # modes' thresholds and the links' state
    ctypedef struct softgym_modes_args:
        float64_t max_ext, sa_w, sah_w, st_in, ex_in, st_out, ex_out
        long long* link_sa  # (the header's type; lane_flag_t is the same 64 bits)
        const long long* homog
        int keep_len
    intp_t softgym_seed_geom_modes(int ax, intp_t lo, intp_t hi, intp_t n, const intp_t* v1,
                                   const intp_t* v2, intp_t vend, const float64_t* pos,
                                   const float64_t* quat, const float64_t* vr, intp_t vn,
                                   const float64_t* scale, float64_t* o, float64_t* rr,
                                   float* rf, const softgym_modes_args* m) noexcept nogil
    void softgym_seed_scatter(int ax, intp_t lo, intp_t hi, const intp_t* v1, const intp_t* v2,
                              const float64_t* rot, const float64_t* o,
                              const float64_t* neg2_row, float64_t* force,
                              float64_t* moment) noexcept nogil
    # single-precision links: their forces turned in float and added to the voxels' float
    # rows lf (row stride lfs), voxel 1's then voxel 2's (rf: the geometry's float rows of
    # voxel 1's rotation)
    void softgym_seed_push32(int ax, intp_t lo, intp_t hi, const intp_t* v1, const intp_t* v2,
                             const float* rf, const float* of, const float64_t* neg2_row,
                             float* lf, intp_t lfs) noexcept nogil
    # the rows of the chunk's scratch that hold voxel 1's rotation (the geometry writes
    # them, the scatter reads them, where the build's SOFTGYM_SEED_R_USED is 1: AVX-512)
    enum: SOFTGYM_SEED_R_ROWS
    # the float rows of the chunk's scratch that hold it rounded (single-precision links:
    # the geometry writes them in every build)
    enum: SOFTGYM_CHUNK_FR
    int softgym_seed_frames32(intp_t lo, intp_t hi, intp_t n, float sa_rad, float w_acos,
                              const float64_t* o, float* f) noexcept nogil
    void softgym_seed_forces32(intp_t lo, intp_t hi, intp_t n, float L, float bz, float bzh,
                               float inv_dt, const float* inp, intp_t in_stride,
                               const float64_t* sa_, const float64_t* chg_,
                               const float64_t* neg2_, const float* ka_,
                               const float* kt_, const float* kb_, const float* cs_,
                               float* link_last, float* out) noexcept nogil


#: the passes of links_seed that the cycle probes time, in slot order
CYCLE_PASSES = ("geometry", "modes", "frames", "frames_acos", "forces", "scatter")


def cycle_counts(bint reset=False):
    """TSC cycles spent in each of ``CYCLE_PASSES`` since the last reset (a dict), or
    None when the module was built without SOFTGYM_PROFILE_CYCLES (setup.py)."""
    return prof_counts(CYCLE_PASSES, reset)


cdef void _seed_frame_one(intp_t li, float64_t* o, intp_t n, float* f) noexcept nogil:
    # softgym_seed_frames for one link, with the seed's branches (its acos
    # approximation and the backward-chord rule), into the scratch's double rows
    # 10-20, or (f not NULL) into the single-precision passes' float rows (_put)
    cdef:
        float64_t sa_rad = SMALL_ANGLE_RAD
        float64_t th_discard = SEED_PI - DISCARD_ANGLE_RAD
        float64_t p0 = o[li], p1 = o[n + li], p2 = o[2 * n + li], qw = o[3 * n + li]
        float64_t n1 = o[4 * n + li], n2 = o[5 * n + li], n3 = o[6 * n + li]
        float64_t k, rw = 1.0, ry = 0.0, rz = 0.0, tw, tx, ty, tz
        float64_t a1y = 0.0, a1z = 0.0, a2x, a2y, a2z, P0, P1, P2
        float64_t len_, lp, inv_s, inv_p0, yx, zx
    if o[9 * n + li] != 0.0:
        # small angle: voxel 1's frame, offsets along its axes
        k = _rotvec_k(qw)
        a2x = n1 * k
        a2y = n2 * k
        a2z = n3 * k
        P0 = o[10 * n + li]  # p0 - nom, as the modes pass leaves it
        P1 = p1
        P2 = p2
    else:
        # large angle: the frame turned by rq = (rw, 0, ry, rz) onto the
        # chord (the seed's ToXDirBond of the relative position)
        if not (p0 == 0.0 and p1 == 0.0 and p2 == 0.0):
            inv_p0 = 1.0 / p0
            yx = p1 * inv_p0
            zx = p2 * inv_p0
            if yx < sa_rad and yx > -sa_rad and zx < sa_rad and zx > -sa_rad:
                ry = 0.5 * zx
                rz = -0.5 * yx
                rw = 1.0 + 0.5 * (-ry * ry - rz * rz)
            else:
                len_ = sqrt(p0 * p0 + p1 * p1 + p2 * p2)
                # acos(nx) > pi - 1e-7, nx = p0 / |p| (acos(x) <= acos(-0.5) < 2.1
                # for x >= -0.5)
                if p0 < -0.5 * len_ and acos(p0 / len_) > th_discard:
                    rw = 0.0
                    ry = 1.0
                else:
                    # (cos(th / 2), 0, nz sin(th / 2) / |n_yz|, -ny ...) with
                    # nx = cos(th): (|p| + p0, 0, p2, -p1) / sqrt(2 |p| (|p| + p0))
                    lp = len_ + p0
                    inv_s = 1.0 / sqrt(2.0 * len_ * lp)
                    rw = lp * inv_s
                    ry = p2 * inv_s
                    rz = -p1 * inv_s
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
        P0 = o[10 * n + li]  # the chord's length - nom, as the modes pass leaves it
        P1 = 0.0
        P2 = 0.0
    _put(o, n, f, 10, li, P0)
    _put(o, n, f, 11, li, P1)
    _put(o, n, f, 12, li, P2)
    _put(o, n, f, 13, li, a1y)
    _put(o, n, f, 14, li, a1z)
    _put(o, n, f, 15, li, a2x)
    _put(o, n, f, 16, li, a2y)
    _put(o, n, f, 17, li, a2z)
    _put(o, n, f, 18, li, rw)
    _put(o, n, f, 19, li, ry)
    _put(o, n, f, 20, li, rz)


cdef inline void _put(float64_t* o, intp_t n, float* f, intp_t k, intp_t li,
                      float64_t v) noexcept nogil:
    # row k of link li: the scratch's double, or (f not NULL) a float of the chunk's
    # float rows (row k - 10 of f, SOFTGYM_CHUNK_FSTRIDE apart)
    if f != NULL:
        f[(k - 10) * SOFTGYM_CHUNK_FSTRIDE + li] = <float> v
    else:
        o[k * n + li] = v


cdef inline void _seed_frames_forces32(Batch* b, intp_t lo, intp_t end, float64_t* o,
                                       intp_t n, float64_t inv_dt) noexcept nogil:
    # links_seed's frames and forces passes in single precision
    # (SimConfig.link_precision = "single"; include/softgym_seed.h): the chunk's float
    # rows in b.chunk_f32 from the frames, and from the forces its rows SOFTGYM_CHUNK_FOUT
    # on, which softgym_seed_push32 turns to the world (links lo..end: one chunk)
    cdef:
        intp_t li
        int fix
        float* f = b.chunk_f32 - lo  # indexed by link
        const float* k32
        unsigned long long t0
    t0 = softgym_prof_tsc()
    fix = softgym_seed_frames32(lo, end, n, <float> SMALL_ANGLE_RAD, <float> ACOS2SQRT_W, o, f)
    softgym_prof_add(2, t0)
    t0 = softgym_prof_tsc()
    if fix:  # rare: links turned past 120 degrees, or a backward chord
        for li in range(lo, end):
            if f[11 * SOFTGYM_CHUNK_FSTRIDE + li] != 0.0:
                _seed_frame_one(li, o, n, f)
    softgym_prof_add(3, t0)
    t0 = softgym_prof_tsc()
    k32 = b.k_seed32
    softgym_seed_forces32(lo, end, b.link_rows, <float> b.L, <float> (0.5 * b.bond_zeta),
                          <float> (0.25 * b.bond_zeta), <float> inv_dt, f, SOFTGYM_CHUNK_FSTRIDE,
                          o + 9 * n, o + 22 * n, o + 23 * n, k32, k32 + b.link_rows,
                          k32 + 2 * b.link_rows, k32 + 3 * b.link_rows, b.link_last32,
                          f + SOFTGYM_CHUNK_FOUT * SOFTGYM_CHUNK_FSTRIDE)
    softgym_prof_add(4, t0)


cdef inline void _seed_frames_forces(Batch* b, intp_t lo, intp_t end, float64_t* o,
                                     intp_t n, float64_t inv_dt) noexcept nogil:
    # links_seed's frames and forces passes in double precision (the seed's
    # own operations)
    cdef:
        intp_t li
        int fix
        float64_t bz = 0.5 * b.bond_zeta
        unsigned long long t0
    t0 = softgym_prof_tsc()
    fix = softgym_seed_frames(lo, end, SMALL_ANGLE_RAD, SLTHRESH_ACOS2SQRT, o, o + n, o + 2 * n,
                              o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n, o + 7 * n, o + 8 * n,
                              o + 9 * n, o + 10 * n, o + 11 * n, o + 12 * n, o + 13 * n,
                              o + 14 * n, o + 15 * n, o + 16 * n, o + 17 * n, o + 18 * n,
                              o + 19 * n, o + 20 * n, o + 21 * n)
    softgym_prof_add(2, t0)
    t0 = softgym_prof_tsc()
    if fix:  # links whose rotation needs the seed's acos branch
        for li in range(lo, end):
            if o[21 * n + li] != 0.0:
                _seed_frame_one(li, o, n, NULL)
    softgym_prof_add(3, t0)
    t0 = softgym_prof_tsc()
    # the forces pass writes the chunk's rows of b.chunk_out (f1 0-2, f2 3-5, m1 6-8, m2
    # 9-11, SOFTGYM_CHUNK_STRIDE apart, indexed by link), which softgym_seed_scatter reads
    softgym_seed_forces(lo, end, b.link_rows, b.L, bz, 0.5 * bz, inv_dt, o + 10 * n, n,
                        o + 9 * n, o + 22 * n, o + 23 * n, b.k_axial, b.k_torsion, b.k_bend,
                        b.c_seed, b.link_last, b.chunk_out - lo)
    softgym_prof_add(4, t0)


cdef inline intp_t _seed_geom_modes(Batch* b, int ax, intp_t lo, intp_t hi, intp_t n,
                                   float64_t* o, intp_t vend, float64_t* rr, float* rf,
                                   const softgym_modes_args* m) noexcept nogil:
    # the geometry and the modes of links lo..hi along axis ax (m: _modes_args), the
    # modes while the geometry's rows are in the cache: hi, or the first strained link
    cdef:
        intp_t end
        unsigned long long t0
    t0 = softgym_prof_tsc()
    # vend: the robot's voxels end there (the geometry reads no other robot's records)
    # (b.vox_out: the voxel rows, the step's state in AVX-512 builds; _integrate.pxd
    # voxel_state_enter). The modes are decided in the geometry's loop in AVX-512 builds
    # (softgym_seed_geom_modes), so the probes charge them to the geometry's slot there
    end = softgym_seed_geom_modes(ax, lo, hi, n, b.v1, b.v2, vend, b.pos, b.quat, b.vox_out,
                                  b.vox_stride, b.scale, o, rr, rf, m)
    softgym_prof_add(0, t0)
    return end


cdef inline void _modes_args(Batch* b, softgym_modes_args* m) noexcept nogil:
    # the modes pass's thresholds and the links' state, for every axis run of a step
    m.max_ext = b.max_strain * b.L
    m.sa_w = SMALL_ANGLE_W
    m.sah_w = SMALLISH_ANGLE_W
    m.st_in = SA_BOND_BEND_RAD
    m.ex_in = SA_BOND_EXT_PERC
    m.st_out = HYSTERESIS * SA_BOND_BEND_RAD
    m.ex_out = HYSTERESIS * SA_BOND_EXT_PERC
    m.link_sa = <long long*> b.link_sa
    m.homog = <const long long*> b.homog
    # the double-precision frames pass reads rows 7 and 8, the single-precision one row 8
    # (the geometry stores row 8 in either case where it decides the modes: AVX-512)
    m.keep_len = not b.link_f32


cdef int links_seed(Batch* b, intp_t r) noexcept nogil:
    # IN: positions, orientations, sizes, the links' mode and memory.
    # OUT (accumulated): force, moment; the links' mode and memory.
    # Quantities are those of the seed's bond frame (the link axis turned
    # onto +x, voxel 1's orientation removed); rotations back to the world
    # go through voxel 1's rotation matrix. A robot's links are sorted by
    # axis (x, then y, then z); the passes below run over one chunk's rows of
    # link scratch, b.chunk_link (profiled: the square roots and divisions of the
    # large-angle frames dominated the step; one branch-free vector loop does them
    # for many links at once, the same IEEE operations as the seed's scalar code):
    #   softgym_seed_geom    rows 0-9: relative position p, orientation (qw, n),
    #                        nominal length, chord length, transverse ratio
    #                        (once per axis: each run gets a copy with the axis
    #                        constant)
    #   softgym_seed_modes   (both by softgym_seed_geom_modes, which in AVX-512
    #                        builds decides the modes of each vector block of the
    #                        geometry from its values in registers, the
    #                        nominal length and the transverse ratio stored only
    #                        where the double-precision frames read row 7)
    #                        the mode (link_sa; row 9 becomes 1.0 small / 0.0
    #                        large angle), row 10 the axial displacement P0 in
    #                        that mode (the single-precision frames read it),
    #                        row 22 1.0 on a mode-change step,
    #                        row 23 1.0 where voxel 2 takes -F1, the strain
    #                        check (stops at the first strained link)
    #   softgym_seed_frames  rows 10-20: displacement P, rotation vectors a1
    #                        (y, z) and a2, the large-angle frame rq; row 21
    #                        marks links whose rotation needs the acos branch
    #                        (in single precision: turned past 120 degrees)
    #   _seed_frame_one      redoes those links with the seed's branches
    #   softgym_seed_forces  forces and moments in the bond frame (stiffness, the
    #                        seed's damping from the link's memory; rq^-1 for
    #                        large angles, not computed where a chunk's links are
    #                        all in small-angle mode; voxel 2's own force left out
    #                        where they all give it -F1) into the 12 rows of
    #                        b.chunk_out (in single precision: 12 float rows of
    #                        b.chunk_f32 from SOFTGYM_CHUNK_FOUT)
    #   softgym_seed_scatter back to the world, scattered in link order (once
    #                        per axis; with AVX-512, 8 links at a time turned in
    #                        the lanes with voxel 1's rotation, which the geometry
    #                        leaves in rows 12-20 of b.chunk_out: rr); in single
    #                        precision softgym_seed_push32 instead: the turn in
    #                        float (voxel 1's rotation rounded: the geometry's
    #                        float rows SOFTGYM_CHUNK_FR of b.chunk_f32, rf), the
    #                        sums in the thread's float rows b.link_f, blocks of
    #                        16 links in the lanes, voxel 1's side then voxel 2's
    #                        (include/softgym_seed.h)
    # The passes run over one chunk of SOFTGYM_CHUNK_LINKS links at a time (64; 128
    # before the scatter took voxel 1's rotation from 9 more rows of the chunk),
    # all of them before the next chunk: a chunk's scratch rows stay in the L1
    # cache from the geometry to the scatter, and they are the same rows for every
    # chunk, a compile-time stride apart (b.chunk_link, b.chunk_out, b.chunk_f32:
    # one register addresses all of a pass's rows; the robot's rows of scratch, a
    # run-time stride apart, took a register each and 108 KB for the reference
    # robot, walked each step). The geometry and the scatter split a chunk at the
    # axis runs; the modes, frames and forces passes need no axis. Each link's
    # quantities are its own and the links are scattered in the same order, so the
    # result is the one of running each pass over all the links, bit for bit (a
    # strained link stops the step after the links before it, as the seed's scalar
    # loop does; 3.0 % on an Intel Xeon, benchmarks/RESULTS.md). With link_precision "single" the
    # frames and forces run in float (_seed_frames_forces32), and the push's float sums
    # take each voxel's forces in the order its chunks and blocks of 16 fix (the same in
    # every build, alone or in a batch: a robot's chunks start at its first link).
    # The bond frame is voxel 1's frame turned by the proper rotation P that
    # takes the link axis onto +x (the seed's ToXDirBond): (x, y, z) ->
    # (x, y, z), (y, -x, z), (z, y, -x) for ax 0, 1, 2.
    cdef:
        intp_t lo = b.link_start[r]
        intp_t hi = b.link_start[r + 1]
        intp_t run[4]  # the x, y and z links are run[ax] .. run[ax + 1]
        # the chunk's rows of link scratch (b.chunk_link, indexed by link), a compile-time
        # stride apart
        intp_t n = SOFTGYM_CHUNK_STRIDE
        intp_t c0, c1, a0, a1, end
        int ax
        float64_t inv_dt = 1.0 / b.dt[r]
        float64_t* o
        # the geometry's rotation rows for the scatter (the chunk's)
        float64_t* rr = b.chunk_out + SOFTGYM_SEED_R_ROWS * SOFTGYM_CHUNK_STRIDE
        # the scatter's forces and moments: the float forces pass's rows of the chunk's
        # float scratch, indexed by link (NULL: the double pass's rows 0-11 of chunk_out)
        const float* of = NULL
        # the geometry's float rows of voxel 1's rotation (single-precision links; NULL with
        # double links)
        float* rf = NULL
        softgym_modes_args m
        unsigned long long t0
    if hi <= lo:
        return STATUS_OK
    _modes_args(b, &m)
    if b.link_f32:
        rf = b.chunk_f32 + SOFTGYM_CHUNK_FR * SOFTGYM_CHUNK_FSTRIDE
    run[0] = lo
    for ax in range(3):
        run[ax + 1] = run[ax] + b.link_axis_count[3 * r + ax] if ax < 2 else hi
    c0 = lo
    while c0 < hi:
        c1 = min(c0 + SOFTGYM_CHUNK_LINKS, hi)
        o = b.chunk_link - c0
        end = c1
        for ax in range(3):
            a0 = max(c0, run[ax])
            a1 = min(c1, run[ax + 1])
            if a0 < a1:
                end = _seed_geom_modes(b, ax, a0, a1, n, o, b.vox_start[r + 1], rr - c0,
                                       rf - c0 if rf != NULL else NULL, &m)
                if end < a1:
                    break  # a strained link: the links after it stay as they were
                end = c1
        if b.link_f32:
            _seed_frames_forces32(b, c0, end, o, n, inv_dt)
            of = b.chunk_f32 + SOFTGYM_CHUNK_FOUT * SOFTGYM_CHUNK_FSTRIDE - c0
        else:
            _seed_frames_forces(b, c0, end, o, n, inv_dt)
        t0 = softgym_prof_tsc()
        for ax in range(3):
            a0 = max(c0, run[ax])
            a1 = min(end, run[ax + 1])
            if a0 < a1 and b.link_f32:
                softgym_seed_push32(ax, a0, a1, b.v1, b.v2, rf - c0, of, o + 23 * n,
                                    b.link_f, b.link_fs)
            elif a0 < a1:
                softgym_seed_scatter(ax, a0, a1, b.v1, b.v2, b.rot, b.chunk_out - c0,
                                     o + 23 * n, b.force, b.moment)
        softgym_prof_add(5, t0)
        if end < c1:
            return STATUS_STRAIN
        c0 = c1
    return STATUS_OK


# ---------------------------------------------------------------------------
# Python entry point (re-exported by _core)

def seed_frames(float64_t[:, ::1] geom, bint scalar=False, bint single=False):
    """The seed model's bond-frame pass on given link geometry (for tests).

    ``geom`` is (10, n): rows 0-9 of the link scratch as ``_seed_geom`` and
    ``softgym_seed_modes`` leave them (relative position p0, p1, p2; relative
    orientation qw, n1, n2, n3; nominal length; chord length; the mode, 1.0
    small / 0.0 large angle). Returns (11, n): the displacement P, voxel 1's
    rotation vector (y, z), voxel 2's, the large-angle frame (rw, ry, rz),
    from the vectorised kernel with its scalar fix-ups, or (``scalar``) from
    the seed's branchy scalar code for every link. The two are equal bit
    for bit in a build that does not fuse multiply-adds, and within the
    fusing's rounding (~1e-12 relative) in one that does (setup.py).
    ``single``: the single-precision pass (SimConfig.link_precision
    "single") with its fix-ups in double, its float results as doubles.
    """
    cdef:
        intp_t n = geom.shape[1], li, k
        cnp.ndarray[float64_t, ndim=2] o = np.zeros((N_LINK_OUT, max(n, 1)))
        float64_t* op = <float64_t*> cnp.PyArray_DATA(o)
        intp_t stride = o.shape[1], c0, c1
        # the float rows of one chunk, as links_seed has them
        cnp.ndarray[cnp.float32_t, ndim=1] fbuf = np.zeros(
            SOFTGYM_CHUNK_FROWS * SOFTGYM_CHUNK_FSTRIDE, dtype=np.float32)
        float* f
    if geom.shape[0] != 10:
        raise ValueError("geom must have 10 rows")
    for k in range(10):
        for li in range(n):
            op[k * stride + li] = geom[k, li]
    for li in range(n):  # row 10 as softgym_seed_modes leaves it: P0 in the link's mode
        op[10 * stride + li] = (op[li] if op[9 * stride + li] != 0.0
                                else op[8 * stride + li]) - op[7 * stride + li]
    with nogil:
        if single:
            c0 = 0
            while c0 < n:  # chunk by chunk
                c1 = min(c0 + SOFTGYM_CHUNK_LINKS, n)
                f = <float*> cnp.PyArray_DATA(fbuf) - c0
                softgym_seed_frames32(c0, c1, stride, <float> SMALL_ANGLE_RAD,
                                      <float> ACOS2SQRT_W, op, f)
                for li in range(c0, c1):
                    if f[11 * SOFTGYM_CHUNK_FSTRIDE + li] != 0.0:
                        _seed_frame_one(li, op, stride, f)
                for k in range(11):
                    for li in range(c0, c1):
                        op[(10 + k) * stride + li] = f[k * SOFTGYM_CHUNK_FSTRIDE + li]
                c0 = c1
        elif scalar:
            for li in range(n):
                _seed_frame_one(li, op, stride, NULL)
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
                    _seed_frame_one(li, op, stride, NULL)
    return o[10:21, :n].copy()
