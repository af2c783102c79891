/* The voxels' orientation step of both models (softgym/engine/_integrate.pyx), in C for
   the vectorising pragma: q + (w dt / 2) x q (w the new angular velocity), renormalised,
   into the scratch rows q_out (4, n), which softgym_orient_store copies back (deriving the
   rotation matrices where the build's steps read them); in AVX-512 builds, whose step
   loops keep the voxels' state in the voxel rows (SOFTGYM_STATE_ROWS), in place there
   (softgym_seed_quats_rows, softgym_corot_quats_rows), with the helpers that move that
   state between the records and the rows. The same IEEE operations as the scalar code
   they replaced (but for the seed model's renormalisation with single-precision links,
   by Newton steps near unit length since issue 29's tenth session: softgym_quats_impl);
   one voxel's no longer waits on the previous voxel's. Py_ssize_t comes from Python.h,
   which Cython includes first. */
#ifndef SOFTGYM_ORIENT_H
#define SOFTGYM_ORIENT_H

#include <math.h>
#include "softgym_simd.h"

/* the seed's renormalisation by two Newton steps of 1 / sqrt from 1 where |q|^2 - 1 is
   within +-SOFTGYM_QUAT_NEWTON_TOL (2^-14): the steps' relative error is then under
   0.21 (|q|^2 - 1)^4 < 3e-18, below the rounding of the seed's square root and division,
   which cost a 512-bit division unit two long operations per 8 voxels (the orientation
   step's whole time). Further from 1 (a voxel turning faster than about 24 rad/s at the
   seed's time step) the seed's exact square root and division, voxel by voxel */
#define SOFTGYM_QUAT_NEWTON_TOL 6.103515625e-05
/* the seed's exact renormalisation of (qw, qx, qy, qz) (its square root and division; a
   zero quaternion left as it is) snapped to the identity at w >= 1, into nv[0..3]: selects,
   so that the orientation loop vectorises with it */
SOFTGYM_ALWAYS_INLINE void softgym_quat_seed_norm(double qw, double qx, double qy, double qz,
                                                  double *nv)
{
    double nq = sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    double inv = 1.0 / nq;
    double nw = nq != 0.0 ? qw * inv : qw;
    double nx = nq != 0.0 ? qx * inv : qx;
    double ny = nq != 0.0 ? qy * inv : qy;
    double nz = nq != 0.0 ? qz * inv : qz;
    long long one = nw >= 1.0;
    nv[0] = one ? 1.0 : nw;
    nv[1] = one ? 0.0 : nx;
    nv[2] = one ? 0.0 : ny;
    nv[3] = one ? 0.0 : nz;
}
/* that renormalisation of voxel i's unnormalised quaternion in rows q_out[k n + i] */
static inline void softgym_quat_exact(Py_ssize_t i, Py_ssize_t n, double *q_out)
{
    double nv[4];
    softgym_quat_seed_norm(q_out[i], q_out[n + i], q_out[2 * n + i], q_out[3 * n + i], nv);
    for (int k = 0; k < 4; k++)
        q_out[k * n + i] = nv[k];
}
/* The orientation step's formulas for any arithmetic type T (doubles, or GCC's vectors of
   doubles, lane by lane: softgym_orient_block.h), so that the loop below and the blocks
   run the same operations. SOFTGYM_QUAT_TURN declares qw, qx, qy, qz: the quaternion
   (q0, q1, q2, q3) plus (w dt / 2) x q for the angular velocity (a0, a1, a2);
   SOFTGYM_QUAT_NEWTON declares s = |q|^2 and y, two Newton steps of 1 / sqrt(s) from 1;
   SOFTGYM_QUAT_COROT declares nq, the corotational model's one step */
#define SOFTGYM_QUAT_TURN(T, a0, a1, a2, q0, q1, q2, q3, dt) \
    T wx = (a0) * 0.5 * (dt); \
    T wy = (a1) * 0.5 * (dt); \
    T wz = (a2) * 0.5 * (dt); \
    T qw = (q0) - wx * (q1) - wy * (q2) - wz * (q3); \
    T qx = (q1) + wx * (q0) + wy * (q3) - wz * (q2); \
    T qy = (q2) + wy * (q0) + wz * (q1) - wx * (q3); \
    T qz = (q3) + wz * (q0) + wx * (q2) - wy * (q1)
#define SOFTGYM_QUAT_NEWTON(T) \
    T s = qw * qw + qx * qx + qy * qy + qz * qz; \
    T y = 1.5 - 0.5 * s; \
    y = y * (1.5 - (0.5 * s) * (y * y))
#define SOFTGYM_QUAT_COROT(T) T nq = 1.5 - 0.5 * (qw * qw + qx * qx + qy * qy + qz * qz)
/* voxels lo..hi: q + (w dt / 2) x q, then (seed, a compile-time constant in each copy)
   the seed's renormalisation snapped to the identity at w >= 1: 1, its square root and
   division (the seed's own operations: the seed model with double-precision links); 2,
   two Newton steps near 1 (above; its square root and division further out, by
   softgym_quat_exact on the unnormalised quaternion the loop leaves: the seed model with
   single-precision links, its default); or 0, the corotational model's one Newton step
   of 1 / sqrt from 1 (|q|^2 is 1 + O((w dt)^2), so the step is exact to rounding) */
SOFTGYM_ALWAYS_INLINE void softgym_quats_impl(const int seed, Py_ssize_t lo, Py_ssize_t hi,
                                              Py_ssize_t n, double dt, const double *ax,
                                              const double *ay, const double *az,
                                              const Py_ssize_t as, const double *quat,
                                              const Py_ssize_t qs, const Py_ssize_t qc,
                                              double *q_out)
{
    /* angular velocity component c of voxel i at (ax, ay, az)[as i], quaternion component k
       at quat[qs i + qc k] (q_out may be quat's rows: each voxel's is read, then written) */
    Py_ssize_t i;
    long far = 0;
    SOFTGYM_IVDEP
    for (i = lo; i < hi; i++) {
        double q0 = quat[qs * i], q1 = quat[qs * i + qc], q2 = quat[qs * i + 2 * qc];
        double q3 = quat[qs * i + 3 * qc];
        SOFTGYM_QUAT_TURN(double, ax[as * i], ay[as * i], az[as * i], q0, q1, q2, q3, dt);
        double nw, nx, ny, nz;
        if (seed == 2) {
            SOFTGYM_QUAT_NEWTON(double);
            long long out = fabs(s - 1.0) > SOFTGYM_QUAT_NEWTON_TOL || s != s;
            long long one;
            far += out;
            y = out ? 1.0 : y;  /* left unnormalised for softgym_quat_exact */
            nw = qw * y;
            nx = qx * y;
            ny = qy * y;
            nz = qz * y;
            one = !out && nw >= 1.0;
            nw = one ? 1.0 : nw;
            nx = one ? 0.0 : nx;
            ny = one ? 0.0 : ny;
            nz = one ? 0.0 : nz;
        } else if (seed == 1) {
            double nv[4];
            softgym_quat_seed_norm(qw, qx, qy, qz, nv);
            nw = nv[0];
            nx = nv[1];
            ny = nv[2];
            nz = nv[3];
        } else {
            SOFTGYM_QUAT_COROT(double);
            nw = qw * nq;
            nx = qx * nq;
            ny = qy * nq;
            nz = qz * nq;
        }
        q_out[i] = nw;
        q_out[n + i] = nx;
        q_out[2 * n + i] = ny;
        q_out[3 * n + i] = nz;
    }
    if (seed == 2 && far)
        for (i = lo; i < hi; i++) {
            double qw = q_out[i], qx = q_out[n + i], qy = q_out[2 * n + i];
            double qz = q_out[3 * n + i];
            double s = qw * qw + qx * qx + qy * qy + qz * qz;
            /* the loop's unnormalised ones (half the tolerance: the loop's |q|^2 may be
               rounded otherwise; a renormalised one is within 1e-15 of 1) */
            if (fabs(s - 1.0) > 0.5 * SOFTGYM_QUAT_NEWTON_TOL || s != s)
                softgym_quat_exact(i, n, q_out);
        }
}
/* model 0 (the seed's; newton: its single-precision links' renormalisation, above) */
static void softgym_seed_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                               const double *av, const double *quat, double *q_out,
                               int newton)
{
    if (newton)
        softgym_quats_impl(2, lo, hi, n, dt, av, av + 1, av + 2, 3, quat, 4, 1, q_out);
    else
        softgym_quats_impl(1, lo, hi, n, dt, av, av + 1, av + 2, 3, quat, 4, 1, q_out);
}
/* the same on the voxel rows, the step loop's state in SOFTGYM_STATE_ROWS builds (seed: a
   compile-time constant, as softgym_quats_impl's): the angular velocities from rows
   SOFTGYM_ROW_AV, the quaternions of rows SOFTGYM_ROW_QUAT updated in place, then the
   fixed voxels' put back from their records quat (a fixed voxel's quaternion never
   changes, so its record is its row; selecting them in the loop made it 1.6 times
   slower) */
SOFTGYM_ALWAYS_INLINE void softgym_quats_rows_impl(const int seed, Py_ssize_t lo, Py_ssize_t hi,
                                                   Py_ssize_t n, double dt,
                                                   const signed char *fixed, const double *quat,
                                                   double *rows)
{
    const double *r = rows + SOFTGYM_ROW_AV * n;
    double *q = rows + SOFTGYM_ROW_QUAT * n;
    softgym_quats_impl(seed, lo, hi, n, dt, r, r + n, r + 2 * n, 1, q, 1, n, q);
    /* the fixed voxels: 8 flags at a time where none is set (a robot without fixed voxels
       is one test every 8 voxels, where a test a voxel took about a cycle each) */
    Py_ssize_t i = lo;
    while (i < hi) {
        if (i + 8 <= hi && softgym_none8(fixed + i)) {
            i += 8;
            continue;
        }
        if (fixed[i])
            for (int k = 0; k < 4; k++)
                q[k * n + i] = quat[4 * i + k];
        i++;
    }
}
static void softgym_seed_quats_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                    const signed char *fixed, const double *quat, double *rows,
                                    int newton)
{
    if (newton)
        softgym_quats_rows_impl(2, lo, hi, n, dt, fixed, quat, rows);
    else
        softgym_quats_rows_impl(1, lo, hi, n, dt, fixed, quat, rows);
}
/* model 1 (corotational) */
static void softgym_corot_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                const double *av, const double *quat, double *q_out)
{
    softgym_quats_impl(0, lo, hi, n, dt, av, av + 1, av + 2, 3, quat, 4, 1, q_out);
}
static void softgym_corot_quats_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                     const signed char *fixed, const double *quat, double *rows)
{
    softgym_quats_rows_impl(0, lo, hi, n, dt, fixed, quat, rows);
}

/* The step loops' state in the voxel rows (SOFTGYM_STATE_ROWS builds; rows
   SOFTGYM_ROW_QUAT, SOFTGYM_ROW_POS, SOFTGYM_ROW_VEL, SOFTGYM_ROW_AV, SOFTGYM_ROW_EXT of
   softgym_simd.h, n apart, indexed by voxel): voxels lo..hi from their records (ext NULL:
   not the external forces), and back (the external forces are constant) */
static void softgym_state_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, const double *pos,
                               const double *quat, const double *vel, const double *av,
                               const double *ext, double *rows)
{
    /* (vel and av NULL: the positions and quaternions only) */
    Py_ssize_t i = lo;
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
    /* 8 voxels at a time, their records turned into rows of 8 lanes */
    for (; i + 8 <= hi; i += 8) {
        softgym_v8 r[4];
        const double *rec[4] = {pos, vel, av, ext};
        const int row[4] = {SOFTGYM_ROW_POS, SOFTGYM_ROW_VEL, SOFTGYM_ROW_AV, SOFTGYM_ROW_EXT};
        for (int m = 0; m < 4; m++) {
            if (rec[m] == NULL)
                continue;
            softgym_v8_load3(rec[m] + 3 * i, &r[0], &r[1], &r[2]);
            for (int c = 0; c < 3; c++)
                memcpy(rows + (row[m] + c) * n + i, &r[c], sizeof r[c]);
        }
        softgym_v8_load4x4(quat + 4 * i, r);
        for (int k = 0; k < 4; k++)
            memcpy(rows + (SOFTGYM_ROW_QUAT + k) * n + i, &r[k], sizeof r[k]);
    }
#endif
    for (; i < hi; i++) {
        for (int k = 0; k < 4; k++)
            rows[(SOFTGYM_ROW_QUAT + k) * n + i] = quat[4 * i + k];
        for (int k = 0; k < 3; k++) {
            rows[(SOFTGYM_ROW_POS + k) * n + i] = pos[3 * i + k];
            if (vel != NULL) {
                rows[(SOFTGYM_ROW_VEL + k) * n + i] = vel[3 * i + k];
                rows[(SOFTGYM_ROW_AV + k) * n + i] = av[3 * i + k];
            }
            if (ext != NULL)
                rows[(SOFTGYM_ROW_EXT + k) * n + i] = ext[3 * i + k];
        }
    }
}
static void softgym_state_back(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, const double *rows,
                                    double *pos, double *quat, double *vel, double *av)
{
    for (int k = 0; k < 4; k++) {
        const double *rq = rows + (SOFTGYM_ROW_QUAT + k) * n;
        for (Py_ssize_t i = lo; i < hi; i++)
            quat[4 * i + k] = rq[i];
    }
    for (int k = 0; k < 3; k++) {
        const double *rp = rows + (SOFTGYM_ROW_POS + k) * n;
        const double *rv = rows + (SOFTGYM_ROW_VEL + k) * n;
        const double *ra = rows + (SOFTGYM_ROW_AV + k) * n;
        for (Py_ssize_t i = lo; i < hi; i++) {
            pos[3 * i + k] = rp[i];
            vel[3 * i + k] = rv[i];
            av[3 * i + k] = ra[i];
        }
    }
}

/* voxel i's (not fixed), its matrix into R unless R is NULL */
#define SOFTGYM_ORIENT_STORE1(i, R) do { \
        double w_ = q_out[i], x_ = q_out[n + (i)], y_ = q_out[2 * n + (i)]; \
        double z_ = q_out[3 * n + (i)]; \
        double *qq_ = quat + 4 * (i); \
        qq_[0] = w_; \
        qq_[1] = x_; \
        qq_[2] = y_; \
        qq_[3] = z_; \
        if ((R) != NULL) \
            softgym_quat_matrix_wxyz(w_, x_, y_, z_, (R) + 9 * (i)); \
    } while (0)
/* voxels lo..hi but the fixed: the new quaternions from the rows q_out into quat, and their
   rotation matrices into rot (softgym_quat_matrix_wxyz, from registers; rot NULL: none).
   Scalar stores: GCC packed each matrix into a 512-bit register with seven shuffles and
   stored it across two cache lines (a voxel's matrix is 72 bytes), and on an Intel Xeon
   the loop waited on that (perf annotate) */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-slp-vectorize")))
#endif
static void softgym_orient_store(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double *q_out,
                                 const signed char *fixed, double *quat, double *rot)
{
    Py_ssize_t i = lo;
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
    /* without matrices (the corotational step, which does not read them), 8 voxels at a
       time: their rows turned back into records where none of them is fixed (2.4 cycles a
       voxel-step one by one on an Intel Xeon) */
    if (rot == NULL) {
        for (; i + 8 <= hi; i += 8) {
            long long fx;
            memcpy(&fx, fixed + i, sizeof fx);
            if (fx != 0) {
                for (Py_ssize_t k = i; k < i + 8; k++)
                    if (!fixed[k])
                        SOFTGYM_ORIENT_STORE1(k, (double *)0);
                continue;
            }
            softgym_v8 r[4];
            for (int k = 0; k < 4; k++)
                r[k] = softgym_v8_load(q_out + k * n + i);
            softgym_v8_store4x4(quat + 4 * i, r);
        }
    }
#endif
    for (; i < hi; i++)
        if (!fixed[i])
            SOFTGYM_ORIENT_STORE1(i, rot);
}
#undef SOFTGYM_ORIENT_STORE1

/* The builds whose step loops keep the voxels' state in their records, with AVX (4 lanes)
   or SSE2 (2 lanes, the portable x86-64 build): the orientation step of a block of voxels
   in one pass, from the records to the records (softgym_orient_block.h), instead of the
   loop above and softgym_orient_store (the loop's strided loads of the records, and the
   store's 13 scalar stores a voxel with its branch, took 17 cycles a voxel-step on an AMD
   Zen 4 with AVX2, 29 with SSE2). SOFTGYM_ORIENT_BLOCK: its lanes (0: none) */
#if defined(__AVX__) && !defined(__AVX512F__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_ORIENT_BLOCK 4
#define SOFTGYM_OB_NAME softgym_orient4
#define SOFTGYM_OB_T softgym_v4
#define SOFTGYM_OB_TI softgym_v4i
#define SOFTGYM_OB_ANY(m) (_mm256_movemask_pd((__m256d)(m)) != 0)
#define SOFTGYM_OB_SQRT SOFTGYM_V4SQRT
#define SOFTGYM_OB_ABS softgym_v4abs
/* 4 voxels' quaternions (records of 4 at q) as rows w, x, y, z, and back */
#define SOFTGYM_OB_LOADQ(q, w, x, y, z) do { \
        __m256d w_, x_, y_, z_; \
        SOFTGYM_TRANSPOSE4(_mm256_loadu_pd(q), _mm256_loadu_pd((q) + 4), \
                           _mm256_loadu_pd((q) + 8), _mm256_loadu_pd((q) + 12), w_, x_, y_, z_); \
        w = (softgym_v4)w_; \
        x = (softgym_v4)x_; \
        y = (softgym_v4)y_; \
        z = (softgym_v4)z_; \
    } while (0)
#define SOFTGYM_OB_STOREQ(q, w, x, y, z) do { \
        __m256d r0_, r1_, r2_, r3_; \
        SOFTGYM_TRANSPOSE4((__m256d)(w), (__m256d)(x), (__m256d)(y), (__m256d)(z), r0_, r1_, \
                           r2_, r3_); \
        _mm256_storeu_pd((q), r0_); \
        _mm256_storeu_pd((q) + 4, r1_); \
        _mm256_storeu_pd((q) + 8, r2_); \
        _mm256_storeu_pd((q) + 12, r3_); \
    } while (0)
/* the 4 voxels' matrices R[0..8] (rows of lanes) as their records of 9 at ro: elements
   0-3 and 4-7 by two transposes, element 8 lane by lane */
#define SOFTGYM_OB_STOREROT(ro, R) do { \
        __m256d a0_, a1_, a2_, a3_, b0_, b1_, b2_, b3_; \
        SOFTGYM_TRANSPOSE4((__m256d)(R)[0], (__m256d)(R)[1], (__m256d)(R)[2], (__m256d)(R)[3], \
                           a0_, a1_, a2_, a3_); \
        SOFTGYM_TRANSPOSE4((__m256d)(R)[4], (__m256d)(R)[5], (__m256d)(R)[6], (__m256d)(R)[7], \
                           b0_, b1_, b2_, b3_); \
        _mm256_storeu_pd((ro), a0_); \
        _mm256_storeu_pd((ro) + 4, b0_); \
        _mm256_storeu_pd((ro) + 9, a1_); \
        _mm256_storeu_pd((ro) + 13, b1_); \
        _mm256_storeu_pd((ro) + 18, a2_); \
        _mm256_storeu_pd((ro) + 22, b2_); \
        _mm256_storeu_pd((ro) + 27, a3_); \
        _mm256_storeu_pd((ro) + 31, b3_); \
        for (int k_ = 0; k_ < 4; k_++) \
            (ro)[9 * k_ + 8] = (R)[8][k_]; \
    } while (0)
#define SOFTGYM_OB_LOAD3 softgym_v4_load3
#include "softgym_orient_block.h"
#elif defined(__SSE2__) && !defined(__AVX__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_ORIENT_BLOCK 2
#define SOFTGYM_OB_NAME softgym_orient2
#define SOFTGYM_OB_T softgym_v2
#define SOFTGYM_OB_TI softgym_v2i
#define SOFTGYM_OB_ANY(m) (_mm_movemask_pd((__m128d)(m)) != 0)
#define SOFTGYM_OB_SQRT(v) ((softgym_v2)_mm_sqrt_pd((__m128d)(v)))
#define SOFTGYM_OB_ABS softgym_v2abs
/* 2 voxels' quaternions (records of 4 at q) as rows w, x, y, z, and back */
#define SOFTGYM_OB_LOADQ(q, w, x, y, z) do { \
        __m128d a_ = _mm_loadu_pd(q), b_ = _mm_loadu_pd((q) + 2); \
        __m128d c_ = _mm_loadu_pd((q) + 4), d_ = _mm_loadu_pd((q) + 6); \
        w = (softgym_v2)_mm_unpacklo_pd(a_, c_); \
        x = (softgym_v2)_mm_unpackhi_pd(a_, c_); \
        y = (softgym_v2)_mm_unpacklo_pd(b_, d_); \
        z = (softgym_v2)_mm_unpackhi_pd(b_, d_); \
    } while (0)
#define SOFTGYM_OB_STOREQ(q, w, x, y, z) do { \
        __m128d w_ = (__m128d)(w), x_ = (__m128d)(x), y_ = (__m128d)(y), z_ = (__m128d)(z); \
        _mm_storeu_pd((q), _mm_unpacklo_pd(w_, x_)); \
        _mm_storeu_pd((q) + 2, _mm_unpacklo_pd(y_, z_)); \
        _mm_storeu_pd((q) + 4, _mm_unpackhi_pd(w_, x_)); \
        _mm_storeu_pd((q) + 6, _mm_unpackhi_pd(y_, z_)); \
    } while (0)
/* the 2 voxels' matrices R[0..8] (rows of lanes) as their records of 9 at ro */
#define SOFTGYM_OB_STOREROT(ro, R) do { \
        for (int k_ = 0; k_ < 8; k_ += 2) { \
            __m128d e_ = (__m128d)(R)[k_], f_ = (__m128d)(R)[k_ + 1]; \
            _mm_storeu_pd((ro) + k_, _mm_unpacklo_pd(e_, f_)); \
            _mm_storeu_pd((ro) + 9 + k_, _mm_unpackhi_pd(e_, f_)); \
        } \
        (ro)[8] = (R)[8][0]; \
        (ro)[17] = (R)[8][1]; \
    } while (0)
#define SOFTGYM_OB_LOAD3 softgym_v2_load3
#include "softgym_orient_block.h"
#else
#define SOFTGYM_ORIENT_BLOCK 0
#endif
/* the orientation step of voxels lo..hi but the fixed, from the records (av, quat) to
   the records (quat, and rot unless NULL) for model 2 (the seed's with single-precision
   links: Newton steps), 1 (the seed's exact renormalisation) or 0 (corotational): blocks
   of SOFTGYM_ORIENT_BLOCK where the build has them, blocks is not 0 and none of the
   block is fixed, the
   rest by softgym_quats_impl into the scratch rows q_out (n apart) and
   softgym_orient_store */
SOFTGYM_ALWAYS_INLINE void softgym_orient_records_impl(const int seed, Py_ssize_t lo,
                                                       Py_ssize_t hi, Py_ssize_t n, double dt,
                                                       const signed char *fixed,
                                                       const double *av, double *quat,
                                                       double *q_out, double *rot,
                                                       int blocks)
{
    Py_ssize_t i = lo;
#if SOFTGYM_ORIENT_BLOCK
    const int B = SOFTGYM_ORIENT_BLOCK;
    for (; blocks && i + B <= hi; i += B) {
        int any_fixed = 0;
        for (int k = 0; k < B; k++)
            any_fixed |= fixed[i + k];
        if (!any_fixed && SOFTGYM_OB_NAME(seed, i, dt, av, quat, rot))
            continue;
        softgym_quats_impl(seed, i, i + B, n, dt, av, av + 1, av + 2, 3, quat, 4, 1, q_out);
        softgym_orient_store(i, i + B, n, q_out, fixed, quat, rot);
    }
#endif
    if (i < hi) {
        softgym_quats_impl(seed, i, hi, n, dt, av, av + 1, av + 2, 3, quat, 4, 1, q_out);
        softgym_orient_store(i, hi, n, q_out, fixed, quat, rot);
    }
}
static void softgym_orient_records(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                   const signed char *fixed, const double *av, double *quat,
                                   double *q_out, double *rot, int model, int blocks)
{
    if (model == 2)
        softgym_orient_records_impl(2, lo, hi, n, dt, fixed, av, quat, q_out, rot, blocks);
    else if (model == 1)
        softgym_orient_records_impl(1, lo, hi, n, dt, fixed, av, quat, q_out, rot, blocks);
    else
        softgym_orient_records_impl(0, lo, hi, n, dt, fixed, av, quat, q_out, rot, blocks);
}

#endif  /* SOFTGYM_ORIENT_H */
