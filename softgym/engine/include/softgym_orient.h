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

/* q + (w dt / 2) x q for voxel i, declaring qw, qx, qy, qz (and q0..q3, its old value) */
#define SOFTGYM_QUAT_STEP(av, quat, i, dt) \
    double wx = av[3 * i] * 0.5 * dt; \
    double wy = av[3 * i + 1] * 0.5 * dt; \
    double wz = av[3 * i + 2] * 0.5 * dt; \
    double q0 = quat[4 * i], q1 = quat[4 * i + 1], q2 = quat[4 * i + 2], q3 = quat[4 * i + 3]; \
    double qw = q0 - wx * q1 - wy * q2 - wz * q3; \
    double qx = q1 + wx * q0 + wy * q3 - wz * q2; \
    double qy = q2 + wy * q0 + wz * q1 - wx * q3; \
    double qz = q3 + wz * q0 + wx * q2 - wy * q1

/* model 0 (the seed's): renormalised exactly (the seed's square root and division),
   snapped to the identity at w >= 1 */
static void softgym_seed_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                               const double *av, const double *quat, double *q_out)
{
    Py_ssize_t i;
    SOFTGYM_IVDEP
    for (i = lo; i < hi; i++) {
        SOFTGYM_QUAT_STEP(av, quat, i, dt);
        double nq = sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
        double inv = 1.0 / nq;
        double nw = nq != 0.0 ? qw * inv : qw;
        double nx = nq != 0.0 ? qx * inv : qx;
        double ny = nq != 0.0 ? qy * inv : qy;
        double nz = nq != 0.0 ? qz * inv : qz;
        long long one = nw >= 1.0;
        q_out[i] = one ? 1.0 : nw;
        q_out[n + i] = one ? 0.0 : nx;
        q_out[2 * n + i] = one ? 0.0 : ny;
        q_out[3 * n + i] = one ? 0.0 : nz;
    }
}

/* model 1 (corotational): renormalised by one Newton step of 1 / sqrt from 1 (|q|^2 is
   1 + O((w dt)^2), so the step is exact to rounding) */
static void softgym_corot_quats(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double dt,
                                const double *av, const double *quat, double *q_out)
{
    Py_ssize_t i;
    SOFTGYM_IVDEP
    for (i = lo; i < hi; i++) {
        SOFTGYM_QUAT_STEP(av, quat, i, dt);
        double nq = 1.5 - 0.5 * (qw * qw + qx * qx + qy * qy + qz * qz);
        q_out[i] = qw * nq;
        q_out[n + i] = qx * nq;
        q_out[2 * n + i] = qy * nq;
        q_out[3 * n + i] = qz * nq;
    }
}

#endif  /* SOFTGYM_ORIENT_H */
