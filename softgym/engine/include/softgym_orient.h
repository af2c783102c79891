/* The voxels' orientation step of both models (softgym/engine/_integrate.pyx), in C for
   the vectorising pragma: q + (w dt / 2) x q (w the new angular velocity), renormalised,
   into the scratch rows q_out (4, n); the voxel update copies them back and derives the
   rotation matrices. The same IEEE operations as the scalar code they replaced; one
   voxel's no longer waits on the previous voxel's. Py_ssize_t comes from Python.h,
   which Cython includes first. */
#ifndef SOFTGYM_ORIENT_H
#define SOFTGYM_ORIENT_H

#include <math.h>
#include "softgym_simd.h"

/* voxels lo..hi: q + (w dt / 2) x q, then (seed, a compile-time constant in each copy)
   the seed's exact renormalisation (its square root and division) snapped to the
   identity at w >= 1, or the corotational model's one Newton step of 1 / sqrt from 1
   (|q|^2 is 1 + O((w dt)^2), so the step is exact to rounding) */
SOFTGYM_ALWAYS_INLINE void softgym_quats_impl(const int seed, Py_ssize_t lo, Py_ssize_t hi,
                                              Py_ssize_t n, double dt, const double *av,
                                              const double *quat, double *q_out)
{
    Py_ssize_t i;
    SOFTGYM_IVDEP
    for (i = lo; i < hi; i++) {
        double wx = av[3 * i] * 0.5 * dt;
        double wy = av[3 * i + 1] * 0.5 * dt;
        double wz = av[3 * i + 2] * 0.5 * dt;
        double q0 = quat[4 * i], q1 = quat[4 * i + 1], q2 = quat[4 * i + 2], q3 = quat[4 * i + 3];
        double qw = q0 - wx * q1 - wy * q2 - wz * q3;
        double qx = q1 + wx * q0 + wy * q3 - wz * q2;
        double qy = q2 + wy * q0 + wz * q1 - wx * q3;
        double qz = q3 + wz * q0 + wx * q2 - wy * q1;
        double nw, nx, ny, nz;
        if (seed) {
            double nq = sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
            double inv = 1.0 / nq;
            long long one;
            nw = nq != 0.0 ? qw * inv : qw;
            nx = nq != 0.0 ? qx * inv : qx;
            ny = nq != 0.0 ? qy * inv : qy;
            nz = nq != 0.0 ? qz * inv : qz;
            one = nw >= 1.0;
            nw = one ? 1.0 : nw;
            nx = one ? 0.0 : nx;
            ny = one ? 0.0 : ny;
            nz = one ? 0.0 : nz;
        } else {
            double nq = 1.5 - 0.5 * (qw * qw + qx * qx + qy * qy + qz * qz);
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
}
/* model 0 (the seed's) */
static void softgym_seed_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                               const double *av, const double *quat, double *q_out)
{
    softgym_quats_impl(1, lo, hi, n, dt, av, quat, q_out);
}
/* model 1 (corotational) */
static void softgym_corot_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                const double *av, const double *quat, double *q_out)
{
    softgym_quats_impl(0, lo, hi, n, dt, av, quat, q_out);
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
/* voxels lo..hi: their quaternions and positions into rows 0-6 of the voxel scratch rows
   (SOFTGYM_VOXEL_ROWS, n apart, indexed by voxel), as the seed step's geometry reads them */
static void softgym_voxel_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, const double *pos,
                               const double *quat, double *rows)
{
    Py_ssize_t i;
    for (int k = 0; k < 4; k++)
        for (i = lo; i < hi; i++)
            rows[k * n + i] = quat[4 * i + k];
    for (int k = 0; k < 3; k++)
        for (i = lo; i < hi; i++)
            rows[(4 + k) * n + i] = pos[3 * i + k];
}
/* voxels lo..hi but the fixed: the new quaternions from the rows q_out into quat, and their
   rotation matrices into rot (softgym_quat_matrix_wxyz, from registers; rot NULL: none).
   With pos not NULL, the rows are kept as softgym_voxel_rows leaves them: 8 voxels'
   positions turned into rows 4-6 with the quaternions' transpose, softgym_voxel_rows for
   the voxels the transpose does not take (a block with a fixed voxel, whose quaternion
   stays as it was, and the voxels after the last block).
   Scalar stores: GCC packed each matrix into a 512-bit register with seven shuffles and
   stored it across two cache lines (a voxel's matrix is 72 bytes), and on an Intel Xeon
   the loop waited on that (perf annotate) */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-slp-vectorize")))
#endif
static void softgym_orient_store(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double *q_out,
                                 const signed char *fixed, double *quat, double *rot,
                                 const double *pos)
{
    Py_ssize_t i = lo;
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
    /* without matrices (the seed step that does not read them), 8 voxels at a time: their
       rows turned back into records where none of them is fixed (2.4 cycles a voxel-step
       one by one on an Intel Xeon), their positions' records into rows */
    if (rot == NULL) {
        for (; i + 8 <= hi; i += 8) {
            if (pos != NULL) {
                softgym_v8 x, y, z;
                softgym_v8_load3(pos + 3 * i, &x, &y, &z);
                memcpy(q_out + 4 * n + i, &x, sizeof x);
                memcpy(q_out + 5 * n + i, &y, sizeof y);
                memcpy(q_out + 6 * n + i, &z, sizeof z);
            }
            long long fx;
            memcpy(&fx, fixed + i, sizeof fx);
            if (fx != 0) {
                for (Py_ssize_t k = i; k < i + 8; k++)
                    if (!fixed[k])
                        SOFTGYM_ORIENT_STORE1(k, (double *)0);
                if (pos != NULL)
                    softgym_voxel_rows(i, i + 8, n, pos, quat, q_out);
                continue;
            }
            softgym_v8 r[4];
            for (int k = 0; k < 4; k++)
                r[k] = softgym_v8_load(q_out + k * n + i);
            softgym_v8_store4x4(quat + 4 * i, r);
        }
    }
#endif
    Py_ssize_t rest = i;
    for (; i < hi; i++)
        if (!fixed[i])
            SOFTGYM_ORIENT_STORE1(i, rot);
    if (pos != NULL)
        softgym_voxel_rows(rest, hi, n, pos, quat, q_out);
}
#undef SOFTGYM_ORIENT_STORE1

#endif  /* SOFTGYM_ORIENT_H */
