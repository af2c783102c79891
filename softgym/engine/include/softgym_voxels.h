/* Both models' voxel updates (softgym/engine/_integrate.pyx, integrate_seed and
   integrate_corotational) for 8 voxels at once, in the lanes of AVX-512 (and for 4 in
   the lanes of AVX2 and 2 in SSE2's, on the records: below, softgym_voxels_block.h): the
   same IEEE operations as the scalar loop, lane by lane, each expression written in the scalar
   code's shape (so the build fuses the same multiply-adds), the seed's floor with every
   branch computed and one selected. The positions, velocities, angular velocities and
   external forces come from the voxel rows (the step loops' state in these builds), the
   force and moment (halves of one row of SOFTGYM_FM_STRIDE a voxel) are turned into rows
   of 8 lanes by two-source permutes. Only for the common block: no fixed voxel, no fluid,
   no terrain box; a block where a voxel runs away is left to the scalar loop untouched
   (nothing is stored before the check), which then stops where the seed's loop stops.
   Py_ssize_t comes from Python.h, which Cython includes first. */
#ifndef SOFTGYM_VOXELS_H
#define SOFTGYM_VOXELS_H

#include <math.h>
#include <string.h>
#include "softgym_simd.h"

/* the arguments of softgym_seed_voxels8 and softgym_corot_voxels8: voxels i..i+7 of a
   robot whose first voxel is vs, the robot's time step, gravity and floor flag, the state
   and per-voxel constants (the Batch's arrays), the drift reference (ref and the first
   voxel's displacement c, which the block from vs sets; ref NULL: none), whether to
   track the fastest speed, the runaway bound, the running maxima of drift and speed
   squared (raised), and the voxel rows (rn apart), where both models keep the voxels'
   positions, velocities and angular velocities during their step loops in AVX-512 builds
   (rows SOFTGYM_ROW_POS, SOFTGYM_ROW_VEL, SOFTGYM_ROW_AV; a copy of the external forces in
   SOFTGYM_ROW_EXT): their blocks read and write those, not the records; the AVX2 build's
   blocks read and write the records (pos, vel, av: 3 doubles a voxel; ext, the external
   forces) */
#define SOFTGYM_VOXELS8_PARAMS \
    Py_ssize_t i, Py_ssize_t vs, double dt, double g, int has_floor, double *force, \
    double *moment, const double *c_global, const double *mass, const double *inv_mass, \
    const double *inv_inertia, const double *rot_damp, const double *scale, \
    const double *k_floor, const double *c_floor, const double *mu_s, const double *mu_k, \
    const signed char *fixed, const double *ref, double *c, int track_speed, \
    double runaway, double *dmax, double *vmax2, double *rows, Py_ssize_t rn, float *lf, \
    Py_ssize_t lfs, double *pos, double *vel, double *av, const double *ext

#define SOFTGYM_VOXELS8_ARGS i, vs, dt, g, has_floor, force, moment, c_global, mass, \
    inv_mass, inv_inertia, rot_damp, scale, k_floor, c_floor, mu_s, mu_k, fixed, ref, c, \
    track_speed, runaway, dmax, vmax2, rows, rn, lf, lfs, pos, vel, av, ext

#if defined(__AVX512F__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_VOXELS8 1
/* the lanes of a block, and whether the corotational model has blocks */
#define SOFTGYM_VOXEL_BLOCK 8
#define SOFTGYM_VOXEL_BLOCK_COROT 1

#define SOFTGYM_V8_PICK(m, a, b) ((softgym_v8)_mm512_mask_blend_pd((m), (__m512d)(b), (__m512d)(a)))
#define SOFTGYM_V8_LT(a, b) _mm512_cmp_pd_mask((__m512d)(a), (__m512d)(b), _CMP_LT_OQ)
#define SOFTGYM_V8_LE(a, b) _mm512_cmp_pd_mask((__m512d)(a), (__m512d)(b), _CMP_LE_OQ)
#define SOFTGYM_V8_GT(a, b) _mm512_cmp_pd_mask((__m512d)(a), (__m512d)(b), _CMP_GT_OQ)
#define SOFTGYM_V8_EQ(a, b) _mm512_cmp_pd_mask((__m512d)(a), (__m512d)(b), _CMP_EQ_OQ)


/* the force (a = force + SOFTGYM_FM_STRIDE i) or moment columns of voxels i..i+7 as rows
   x, y, z (softgym_v8_load4_fm), or with lf (single-precision links: Batch.link_f, its
   force's or moment's three rows lfs apart) those rows' floats widened (exactly) */
SOFTGYM_ALWAYS_INLINE void softgym_v8_forces(const double *a, const float *lf, Py_ssize_t lfs,
                                             Py_ssize_t i, softgym_v8 *x, softgym_v8 *y,
                                             softgym_v8 *z)
{
    if (lf) {
        *x = (softgym_v8)_mm512_cvtps_pd(_mm256_loadu_ps(lf + i));
        *y = (softgym_v8)_mm512_cvtps_pd(_mm256_loadu_ps(lf + lfs + i));
        *z = (softgym_v8)_mm512_cvtps_pd(_mm256_loadu_ps(lf + 2 * lfs + i));
    } else {
        softgym_v8_load4_fm(a, x, y, z);
    }
}
/* rows k, k + 1, k + 2 of the voxel rows (rn apart) at voxel i, as three vectors */
#define SOFTGYM_V8_ROWS3(k, a, b, c) do { \
        a = softgym_v8_load(rows + (k) * rn + i); \
        b = softgym_v8_load(rows + ((k) + 1) * rn + i); \
        c = softgym_v8_load(rows + ((k) + 2) * rn + i); \
    } while (0)
#define SOFTGYM_V8_STORE_ROWS3(k, a, b, c) do { \
        _mm512_storeu_pd(rows + (k) * rn + i, (__m512d)(a)); \
        _mm512_storeu_pd(rows + ((k) + 1) * rn + i, (__m512d)(b)); \
        _mm512_storeu_pd(rows + ((k) + 2) * rn + i, (__m512d)(c)); \
    } while (0)
/* the block's velocity, position and external force from the voxel rows (the step's
   state), its force as rows from the records; 0 when a voxel of the block is fixed (the
   scalar loop's case). The moment is loaded by softgym_v8_finish, where it is used (its
   rows' registers free for the floor's arithmetic before) */
#define SOFTGYM_VOXELS8_LOAD \
    if (!softgym_none8(fixed + i)) \
        return 0; \
    softgym_v8 v0, v1, v2, p0, p1, p2, F0, F1, F2, E0, E1, E2; \
    SOFTGYM_V8_ROWS3(SOFTGYM_ROW_VEL, v0, v1, v2); \
    SOFTGYM_V8_ROWS3(SOFTGYM_ROW_EXT, E0, E1, E2); \
    SOFTGYM_V8_ROWS3(SOFTGYM_ROW_POS, p0, p1, p2); \
    softgym_v8_forces(force + SOFTGYM_FM_STRIDE * i, lf, lfs, i, &F0, &F1, &F2); \
    softgym_v8 cg = softgym_v8_load(c_global + i), m = softgym_v8_load(mass + i)

/* the largest lane of v above *best, as the scalar loop's "if v > best": the lanes'
   maximum by a vector reduction (the same value; its callers' lanes are squares of
   finite numbers, past the runaway check, never NaN, where the reduction and the
   scalar loop could differ) */
static inline void softgym_v8_raise_max(softgym_v8 v, double *best)
{
    double m = _mm512_reduce_max_pd((__m512d)v);
    if (m > *best)
        *best = m;
}

/* both models' step after the forces (f) and the floor (v possibly stopped): the
   translation, the runaway check (0 and nothing stored when a voxel ran away), the
   stores, the drift and speed maxima, the angular velocity (positions, velocities and
   angular velocities in the voxel rows); returns 1 */
SOFTGYM_ALWAYS_INLINE int softgym_v8_finish(SOFTGYM_VOXELS8_PARAMS,
                                    softgym_v8 v0, softgym_v8 v1,
                                    softgym_v8 v2, softgym_v8 p0, softgym_v8 p1, softgym_v8 p2,
                                    softgym_v8 f0, softgym_v8 f1, softgym_v8 f2)
{
    softgym_v8 M0, M1, M2;
    softgym_v8_forces(moment + SOFTGYM_FM_STRIDE * i, lf ? lf + 3 * lfs : lf, lfs, i, &M0, &M1,
                      &M2);
    softgym_v8 h = dt * softgym_v8_load(inv_mass + i);
    softgym_v8 vx = v0 + (f0 * h), vy = v1 + (f1 * h), vz = v2 + (f2 * h);
    softgym_v8 px = p0 + (vx * dt), py = p1 + (vy * dt), pz = p2 + (vz * dt);
    softgym_v8 run = (softgym_vabs(px) + softgym_vabs(py)) + softgym_vabs(pz);
    if ((SOFTGYM_V8_LT(run, _mm512_set1_pd(runaway)) & 0xFF) != 0xFF)
        return 0;
    /* the block is stepped: from here on, stores */
    SOFTGYM_V8_STORE_ROWS3(SOFTGYM_ROW_VEL, vx, vy, vz);
    SOFTGYM_V8_STORE_ROWS3(SOFTGYM_ROW_POS, px, py, pz);
    /* the 8 voxels' force and moment rows, padding included: one aligned 64-byte store a
       row (a memset of the 512 bytes compiled to `rep stos`, whose start-up took a sixth
       of the voxel update on an Intel Xeon) */
    if (lf) {
        for (int k = 0; k < 6; k++)
            _mm256_storeu_ps(lf + k * lfs + i, _mm256_setzero_ps());
    } else {
        for (int k = 0; k < 8; k++)
            _mm512_store_pd(force + SOFTGYM_FM_STRIDE * (i + k), _mm512_setzero_pd());
    }
    if (ref != NULL) {
        softgym_v8 r0, r1, r2;
        softgym_v8_load3(ref + 3 * (i - vs), &r0, &r1, &r2);
        softgym_v8 e0 = px - r0, e1 = py - r1, e2 = pz - r2;
        if (i == vs) {
            /* the robot's first voxel's displacement, lane 0 (the scalar loop's c) */
            c[0] = e0[0];
            c[1] = e1[0];
            c[2] = e2[0];
        }
        softgym_v8 d0 = e0 - c[0], d1 = e1 - c[1], d2 = e2 - c[2];
        softgym_v8_raise_max(((d0 * d0) + (d1 * d1)) + (d2 * d2), dmax);
    }
    if (track_speed) {
#if defined(__FMA__)
        /* softgym_speed2's fused form */
        softgym_v8 s2 = (softgym_v8)_mm512_fmadd_pd(
            (__m512d)vz, (__m512d)vz,
            _mm512_fmadd_pd((__m512d)vx, (__m512d)vx, _mm512_mul_pd((__m512d)vy, (__m512d)vy)));
#else
        softgym_v8 s2 = vx * vx + vy * vy + vz * vz;
#endif
        softgym_v8_raise_max(s2, vmax2);
    }
    softgym_v8 w0, w1, w2;
    SOFTGYM_V8_ROWS3(SOFTGYM_ROW_AV, w0, w1, w2);
    softgym_v8 hi = dt * softgym_v8_load(inv_inertia + i), rd = softgym_v8_load(rot_damp + i);
    w0 = (w0 + (M0 * hi)) * rd;
    w1 = (w1 + (M1 * hi)) * rd;
    w2 = (w2 + (M2 * hi)) * rd;
    SOFTGYM_V8_STORE_ROWS3(SOFTGYM_ROW_AV, w0, w1, w2);
    return 1;
}
#define SOFTGYM_VOXELS8_FINISH \
    return softgym_v8_finish(SOFTGYM_VOXELS8_ARGS, v0, v1, v2, p0, p1, p2, f0, f1, f2)

/* model 0 (integrate_seed): 1 when voxels i..i+7 were stepped, 0 when nothing was
   written (a fixed voxel in the block, or a runaway one) */
static int softgym_seed_voxels8(SOFTGYM_VOXELS8_PARAMS)
{
    SOFTGYM_VOXELS8_LOAD;
    softgym_v8 f0 = (((-cg) * v0) + F0) + E0;
    softgym_v8 f1 = (((-cg) * v1) + F1) + E1;
    softgym_v8 f2 = ((((-cg) * v2) + F2) + (m * g)) + E2;
    if (has_floor) {
        softgym_v8 sc = softgym_v8_load(scale + i);
        softgym_v8 pen = (0.5 * sc) - p2;
        __mmask8 contact = ~SOFTGYM_V8_LE(pen, _mm512_setzero_pd()) & 0xFF;
        if (contact) {
            softgym_v8 n = softgym_v8_load(k_floor + i) * pen;
            softgym_v8 fd = softgym_v8_load(mu_k + i) * n;
            __mmask8 still = SOFTGYM_V8_EQ(v0, _mm512_setzero_pd()) & SOFTGYM_V8_EQ(v1, _mm512_setzero_pd());
            __mmask8 stat = 0;
            if (contact & still) {  /* (the square root and the divisions only where needed) */
                softgym_v8 sf = (softgym_v8)_mm512_sqrt_pd((__m512d)((f0 * f0) + (f1 * f1)));
                stat = SOFTGYM_V8_LT(sf, (softgym_v8_load(mu_s + i) * n));
            }
            __mmask8 moving = contact & ~still, slide = 0, stop = 0;
            if (moving) {
                softgym_v8 vsp = (softgym_v8)_mm512_sqrt_pd((__m512d)((v0 * v0) + (v1 * v1)));
                __mmask8 kin = SOFTGYM_V8_LT((fd * dt), (m * vsp));
                slide = moving & kin;          /* kinetic friction */
                stop = moving & ~kin;          /* friction stops it: v_xy = 0 */
                if (slide) {
                    softgym_v8 f0k = f0 - ((fd * v0) / vsp);
                    softgym_v8 f1k = f1 - ((fd * v1) / vsp);
                    f0 = SOFTGYM_V8_PICK(slide, f0k, f0);
                    f1 = SOFTGYM_V8_PICK(slide, f1k, f1);
                }
            }
            __mmask8 stick = (contact & still & stat) | stop;
            v0 = SOFTGYM_V8_PICK(stop, (softgym_v8){0}, v0);
            v1 = SOFTGYM_V8_PICK(stop, (softgym_v8){0}, v1);
            softgym_v8 f2c = f2 + (n - (softgym_v8_load(c_floor + i) * v2));
            f2 = SOFTGYM_V8_PICK(contact, f2c, f2);
            f0 = SOFTGYM_V8_PICK(stick, (softgym_v8){0}, f0);
            f1 = SOFTGYM_V8_PICK(stick, (softgym_v8){0}, f1);
        }
    }
    SOFTGYM_VOXELS8_FINISH;
}

/* model 1 (integrate_corotational: its floor is the common surface contact with the
   normal (0, 0, 1), applied before any box), as softgym_seed_voxels8 */
static int softgym_corot_voxels8(SOFTGYM_VOXELS8_PARAMS)
{
    SOFTGYM_VOXELS8_LOAD;
    softgym_v8 f0 = (F0 + E0) - (cg * v0);
    softgym_v8 f1 = (F1 + E1) - (cg * v1);
    softgym_v8 f2 = ((F2 + E2) - (cg * v2)) + (m * g);
    if (has_floor) {
        softgym_v8 pen = (0.5 * softgym_v8_load(scale + i)) - p2;
        __mmask8 contact = SOFTGYM_V8_GT(pen, _mm512_setzero_pd());
        if (contact) {
            /* surface_contact with n = (0, 0, 1), every product as the scalar code's */
            const softgym_v8 nx = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            const softgym_v8 ny = nx;
            const softgym_v8 nz = {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
            softgym_v8 vn = ((v0 * nx) + (v1 * ny)) + (v2 * nz);
            softgym_v8 fn = (softgym_v8_load(k_floor + i) * pen) - (softgym_v8_load(c_floor + i) * vn);
            contact &= ~SOFTGYM_V8_LE(fn, _mm512_setzero_pd());
            if (contact) {
                softgym_v8 g0 = f0 + (fn * nx), g1 = f1 + (fn * ny), g2 = f2 + (fn * nz);
                softgym_v8 vtx = v0 - (vn * nx), vty = v1 - (vn * ny), vtz = v2 - (vn * nz);
                softgym_v8 ftn = ((g0 * nx) + (g1 * ny)) + (g2 * nz);
                softgym_v8 ftx = g0 - (ftn * nx), fty = g1 - (ftn * ny), ftz = g2 - (ftn * nz);
                __mmask8 rest = SOFTGYM_V8_EQ(vtx, _mm512_setzero_pd())
                                & SOFTGYM_V8_EQ(vty, _mm512_setzero_pd())
                                & SOFTGYM_V8_EQ(vtz, _mm512_setzero_pd());
                softgym_v8 ms = softgym_v8_load(mu_s + i) * fn;
                __mmask8 hold = rest & SOFTGYM_V8_LE(((ftx * ftx) + (fty * fty)) + (ftz * ftz),
                                                     (ms * ms));
                __mmask8 moving = ~rest & 0xFF, stop = 0, slide = 0;
                softgym_v8 s0 = g0, s1 = g1, s2 = g2;
                if (moving & contact) {
                    softgym_v8 vt = (softgym_v8)_mm512_sqrt_pd(
                        (__m512d)(((vtx * vtx) + (vty * vty)) + (vtz * vtz)));
                    softgym_v8 fk = softgym_v8_load(mu_k + i) * fn;
                    __mmask8 ge = _mm512_cmp_pd_mask((__m512d)(fk * dt), (__m512d)(m * vt),
                                                     _CMP_GE_OQ);
                    stop = moving & ge;
                    slide = moving & ~ge;
                    if (slide & contact) {
                        softgym_v8 fkv = fk / vt;
                        s0 = g0 - (fkv * vtx);
                        s1 = g1 - (fkv * vty);
                        s2 = g2 - (fkv * vtz);
                    }
                }
                /* hold, stop: f - ft; slide: f - fk vt / |vt|; rest without hold: f */
                __mmask8 minus_ft = contact & (hold | stop);
                __mmask8 sl = contact & slide;
                softgym_v8 h0 = SOFTGYM_V8_PICK(minus_ft, g0 - ftx, SOFTGYM_V8_PICK(sl, s0, g0));
                softgym_v8 h1 = SOFTGYM_V8_PICK(minus_ft, g1 - fty, SOFTGYM_V8_PICK(sl, s1, g1));
                softgym_v8 h2 = SOFTGYM_V8_PICK(minus_ft, g2 - ftz, SOFTGYM_V8_PICK(sl, s2, g2));
                f0 = SOFTGYM_V8_PICK(contact, h0, f0);
                f1 = SOFTGYM_V8_PICK(contact, h1, f1);
                f2 = SOFTGYM_V8_PICK(contact, h2, f2);
                __mmask8 st = contact & stop;
                v0 = SOFTGYM_V8_PICK(st, v0 - vtx, v0);
                v1 = SOFTGYM_V8_PICK(st, v1 - vty, v1);
                v2 = SOFTGYM_V8_PICK(st, v2 - vtz, v2);
            }
        }
    }
    SOFTGYM_VOXELS8_FINISH;
}
#elif defined(__AVX2__) && defined(__FMA__) && (defined(__GNUC__) || defined(__clang__))
/* The AVX2 build (x86-64-v3), whose step loops keep the voxels' state in their records:
   both models' voxel updates for 4 voxels in the lanes of AVX2
   (softgym_voxels_block.h), the records turned into rows of 4 lanes and back by shuffles,
   the force and moment as the float rows of the single-precision links (Batch.link_f)
   widened, or the double rows transposed; both models */
#define SOFTGYM_VOXELS8 1
#define SOFTGYM_VOXEL_BLOCK 4
#define SOFTGYM_VOXEL_BLOCK_COROT 1

/* the force (a = force + SOFTGYM_FM_STRIDE i) or moment columns of voxels i..i+3 as rows,
   or with lf their float rows (lfs apart) widened (exactly) */
SOFTGYM_ALWAYS_INLINE void softgym_v4_forces(const double *a, const float *lf, Py_ssize_t lfs,
                                             Py_ssize_t i, softgym_v4 *x, softgym_v4 *y,
                                             softgym_v4 *z)
{
    if (lf) {
        *x = (softgym_v4)_mm256_cvtps_pd(_mm_loadu_ps(lf + i));
        *y = (softgym_v4)_mm256_cvtps_pd(_mm_loadu_ps(lf + lfs + i));
        *z = (softgym_v4)_mm256_cvtps_pd(_mm_loadu_ps(lf + 2 * lfs + i));
    } else {
        __m256d r0, r1, r2, r3;
        SOFTGYM_TRANSPOSE4(_mm256_load_pd(a), _mm256_load_pd(a + SOFTGYM_FM_STRIDE),
                           _mm256_load_pd(a + 2 * SOFTGYM_FM_STRIDE),
                           _mm256_load_pd(a + 3 * SOFTGYM_FM_STRIDE), r0, r1, r2, r3);
        (void)r3;
        *x = (softgym_v4)r0;
        *y = (softgym_v4)r1;
        *z = (softgym_v4)r2;
    }
}
/* the 4 voxels' force and moment: their float rows, or their rows of SOFTGYM_FM_STRIDE */
static inline void softgym_v4_clear(double *a, float *lf, Py_ssize_t lfs, Py_ssize_t i)
{
    if (lf) {
        for (int k = 0; k < 6; k++)
            _mm_storeu_ps(lf + k * lfs + i, _mm_setzero_ps());
    } else {
        for (int k = 0; k < 8; k++)
            _mm256_store_pd(a + 4 * k, _mm256_setzero_pd());
    }
}
/* the largest lane of v above *best (as softgym_v8_raise_max) */
static inline void softgym_v4_raise_max(softgym_v4 v, double *best)
{
    __m256d a = (__m256d)v;
    __m128d m = _mm_max_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));
    m = _mm_max_sd(m, _mm_unpackhi_pd(m, m));
    double x = _mm_cvtsd_f64(m);
    if (x > *best)
        *best = x;
}
static inline int softgym_none4(const signed char *f)
{
    unsigned int w;
    memcpy(&w, f, sizeof w);
    return w == 0;
}
#define SOFTGYM_VB_NAME softgym_voxels4
#define SOFTGYM_VB_T softgym_v4
#define SOFTGYM_VB_LANES 4
#define SOFTGYM_VB_LOAD3 softgym_v4_load3
#define SOFTGYM_VB_STORE3 softgym_v4_store3
#define SOFTGYM_VB_AT(p) ((softgym_v4)_mm256_loadu_pd(p))
#define SOFTGYM_VB_FORCES softgym_v4_forces
#define SOFTGYM_VB_CLEAR softgym_v4_clear
#define SOFTGYM_VB_CMP_(a, b, op) ((softgym_v4)_mm256_cmp_pd((__m256d)(a), (__m256d)(b), (op)))
#define SOFTGYM_VB_NLE(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_NLE_UQ)
#define SOFTGYM_VB_EQ(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_EQ_OQ)
#define SOFTGYM_VB_LT(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_LT_OQ)
#define SOFTGYM_VB_GT(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_GT_OQ)
#define SOFTGYM_VB_LE(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_LE_OQ)
#define SOFTGYM_VB_GE(a, b) SOFTGYM_VB_CMP_(a, b, _CMP_GE_OQ)
#define SOFTGYM_VB_AND(a, b) ((softgym_v4)_mm256_and_pd((__m256d)(a), (__m256d)(b)))
#define SOFTGYM_VB_OR(a, b) ((softgym_v4)_mm256_or_pd((__m256d)(a), (__m256d)(b)))
#define SOFTGYM_VB_ANDNOT(a, b) ((softgym_v4)_mm256_andnot_pd((__m256d)(a), (__m256d)(b)))
#define SOFTGYM_VB_BITS(m) _mm256_movemask_pd((__m256d)(m))
#define SOFTGYM_VB_PICK(m, a, b) \
    ((softgym_v4)_mm256_blendv_pd((__m256d)(b), (__m256d)(a), (__m256d)(m)))
#define SOFTGYM_VB_SQRT SOFTGYM_V4SQRT
#define SOFTGYM_VB_ABS softgym_v4abs
#define SOFTGYM_VB_RAISE softgym_v4_raise_max
/* softgym_speed2's fused form */
#define SOFTGYM_VB_SPEED2(vx, vy, vz) ((softgym_v4)_mm256_fmadd_pd( \
        (__m256d)(vz), (__m256d)(vz), \
        _mm256_fmadd_pd((__m256d)(vx), (__m256d)(vx), _mm256_mul_pd((__m256d)(vy), (__m256d)(vy)))))
#define SOFTGYM_VB_NONE_FIXED softgym_none4
#include "softgym_voxels_block.h"
#elif defined(__SSE2__) && !defined(__AVX__) && !defined(__FMA__) && \
    (defined(__GNUC__) || defined(__clang__))
/* The portable x86-64 build (SSE2, no fused multiply-adds: neither here nor in the scalar
   loop): both models' voxel updates for 2 voxels in the lanes of SSE2
   (softgym_voxels_block.h), both models */
#define SOFTGYM_VOXELS8 1
#define SOFTGYM_VOXEL_BLOCK 2
#define SOFTGYM_VOXEL_BLOCK_COROT 1
/* the force (a = force + SOFTGYM_FM_STRIDE i) or moment columns of voxels i, i+1 as rows,
   or with lf their float rows (lfs apart) widened (exactly) */
static inline __m128d softgym_v2_floats(const float *p)
{
    return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)p)));
}
SOFTGYM_ALWAYS_INLINE void softgym_v2_forces(const double *a, const float *lf, Py_ssize_t lfs,
                                             Py_ssize_t i, softgym_v2 *x, softgym_v2 *y,
                                             softgym_v2 *z)
{
    if (lf) {
        *x = (softgym_v2)softgym_v2_floats(lf + i);
        *y = (softgym_v2)softgym_v2_floats(lf + lfs + i);
        *z = (softgym_v2)softgym_v2_floats(lf + 2 * lfs + i);
    } else {
        __m128d a01 = _mm_load_pd(a), b01 = _mm_load_pd(a + SOFTGYM_FM_STRIDE);
        *x = (softgym_v2)_mm_unpacklo_pd(a01, b01);
        *y = (softgym_v2)_mm_unpackhi_pd(a01, b01);
        *z = (softgym_v2)_mm_unpacklo_pd(_mm_load_pd(a + 2), _mm_load_pd(a + SOFTGYM_FM_STRIDE + 2));
    }
}
static inline void softgym_v2_clear(double *a, float *lf, Py_ssize_t lfs, Py_ssize_t i)
{
    if (lf) {
        for (int k = 0; k < 6; k++)
            _mm_storel_epi64((__m128i *)(lf + k * lfs + i), _mm_setzero_si128());
    } else {
        for (int k = 0; k < 8; k++)
            _mm_store_pd(a + 2 * k, _mm_setzero_pd());
    }
}
static inline void softgym_v2_raise_max(softgym_v2 v, double *best)
{
    __m128d a = (__m128d)v;
    double x = _mm_cvtsd_f64(_mm_max_sd(a, _mm_unpackhi_pd(a, a)));
    if (x > *best)
        *best = x;
}
static inline int softgym_none2(const signed char *f)
{
    unsigned short w;
    memcpy(&w, f, sizeof w);
    return w == 0;
}
#define SOFTGYM_VB_NAME softgym_voxels2
#define SOFTGYM_VB_T softgym_v2
#define SOFTGYM_VB_LANES 2
#define SOFTGYM_VB_LOAD3 softgym_v2_load3
#define SOFTGYM_VB_STORE3 softgym_v2_store3
#define SOFTGYM_VB_AT(p) ((softgym_v2)_mm_loadu_pd(p))
#define SOFTGYM_VB_FORCES softgym_v2_forces
#define SOFTGYM_VB_CLEAR softgym_v2_clear
#define SOFTGYM_VB_NLE(a, b) ((softgym_v2)_mm_cmpnle_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_EQ(a, b) ((softgym_v2)_mm_cmpeq_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_LT(a, b) ((softgym_v2)_mm_cmplt_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_GT(a, b) ((softgym_v2)_mm_cmpgt_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_LE(a, b) ((softgym_v2)_mm_cmple_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_GE(a, b) ((softgym_v2)_mm_cmpge_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_AND(a, b) ((softgym_v2)_mm_and_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_OR(a, b) ((softgym_v2)_mm_or_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_ANDNOT(a, b) ((softgym_v2)_mm_andnot_pd((__m128d)(a), (__m128d)(b)))
#define SOFTGYM_VB_BITS(m) _mm_movemask_pd((__m128d)(m))
#define SOFTGYM_VB_PICK(m, a, b) SOFTGYM_VB_OR(SOFTGYM_VB_AND(m, a), SOFTGYM_VB_ANDNOT(m, b))
#define SOFTGYM_VB_SQRT(v) ((softgym_v2)_mm_sqrt_pd((__m128d)(v)))
#define SOFTGYM_VB_ABS softgym_v2abs
#define SOFTGYM_VB_RAISE softgym_v2_raise_max
/* softgym_speed2's unfused form */
#define SOFTGYM_VB_SPEED2(vx, vy, vz) ((vx) * (vx) + (vy) * (vy) + (vz) * (vz))
#define SOFTGYM_VB_NONE_FIXED softgym_none2
#include "softgym_voxels_block.h"
#else
#define SOFTGYM_VOXELS8 0
#define SOFTGYM_VOXEL_BLOCK 8
#define SOFTGYM_VOXEL_BLOCK_COROT 0
#endif

/* the entry _integrate.pyx calls: model 0 (seed = 1) or 1's block of SOFTGYM_VOXEL_BLOCK
   voxels from i (the corotational model's where SOFTGYM_VOXEL_BLOCK_COROT); without
   vector blocks the scalar loops step every voxel (0) */
static inline int softgym_voxels8(int seed, SOFTGYM_VOXELS8_PARAMS)
{
#if SOFTGYM_VOXELS8 && SOFTGYM_VOXEL_BLOCK == 8
    return seed ? softgym_seed_voxels8(SOFTGYM_VOXELS8_ARGS)
                : softgym_corot_voxels8(SOFTGYM_VOXELS8_ARGS);
#elif SOFTGYM_VOXELS8
    return seed ? SOFTGYM_VB_NAME(1, SOFTGYM_VOXELS8_ARGS)
                : SOFTGYM_VB_NAME(0, SOFTGYM_VOXELS8_ARGS);
#else
    (void)seed;
    return 0;
#endif
}

#endif  /* SOFTGYM_VOXELS_H */
