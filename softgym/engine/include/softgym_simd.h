/* Portable helpers of the engine's vectorised C loops (included by the
   seed kernels, softgym_seed.h). */
#ifndef SOFTGYM_SIMD_H
#define SOFTGYM_SIMD_H

/* SOFTGYM_IVDEP before a loop: its iterations touch distinct elements,
   vectorise without alias checks */
#if defined(__clang__)
#define SOFTGYM_IVDEP _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#define SOFTGYM_IVDEP _Pragma("GCC ivdep")
#else
#define SOFTGYM_IVDEP
#endif
#include <string.h>
/* c ? a : b on the bits: compilers keep it a blend (a select before a
   store may otherwise become a masked store, slow on some cores) */
static inline double softgym_pick(long long c, double a, double b)
{
    unsigned long long ua, ub, m = (unsigned long long)0 - (unsigned long long)(c != 0);
    double r;
    memcpy(&ua, &a, sizeof ua);
    memcpy(&ub, &b, sizeof ub);
    ua = (ua & m) | (ub & ~m);
    memcpy(&r, &ua, sizeof r);
    return r;
}
/* R = the rotation matrix of the unit quaternion q = (w, x, y, z), row-major: the
   one formula of the engine (the voxel update stores it, the seed geometry
   recomputes it in its vector lanes from the same quaternion, bit for bit).
   The geometry passes the values it has loaded: given the pointer form inside
   its loop, GCC 12 found the loads "not suitable for gather" and ran the loop
   scalar (twice the cycles; check with -fopt-info-vec-missed) */
/* the formula itself, for any arithmetic type of w, x, y, z and the elements of R
   (doubles, or the seed geometry's vectors of doubles: the same operations lane by lane) */
#define SOFTGYM_QUAT_MATRIX(w, x, y, z, R) do { \
        (R)[0] = 1.0 - 2.0 * ((y) * (y) + (z) * (z)); \
        (R)[1] = 2.0 * ((x) * (y) - (w) * (z)); \
        (R)[2] = 2.0 * ((x) * (z) + (w) * (y)); \
        (R)[3] = 2.0 * ((x) * (y) + (w) * (z)); \
        (R)[4] = 1.0 - 2.0 * ((x) * (x) + (z) * (z)); \
        (R)[5] = 2.0 * ((y) * (z) - (w) * (x)); \
        (R)[6] = 2.0 * ((x) * (z) - (w) * (y)); \
        (R)[7] = 2.0 * ((y) * (z) + (w) * (x)); \
        (R)[8] = 1.0 - 2.0 * ((x) * (x) + (y) * (y)); \
    } while (0)
static inline void softgym_quat_matrix_wxyz(double w, double x, double y, double z, double *R)
{
    SOFTGYM_QUAT_MATRIX(w, x, y, z, R);
}
static inline void softgym_quat_matrix(const double *q, double *R)
{
    softgym_quat_matrix_wxyz(q[0], q[1], q[2], q[3], R);
}
#if defined(_MSC_VER)
#define SOFTGYM_ALWAYS_INLINE static __forceinline
#else
#define SOFTGYM_ALWAYS_INLINE static inline __attribute__((always_inline))
#endif
#endif  /* SOFTGYM_SIMD_H */
