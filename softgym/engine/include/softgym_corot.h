/* The corotational model's link kernel (softgym/engine/_corotational.pyx calls it; the
   physics is described there and in docs/PHYSICS.md). Per link, branch-free: the axial
   extension and force, the bending and twist of the two voxels relative to the link's
   frame, their damping, and the force on voxel 2 (voxel 1 takes minus it) and the two
   voxels' moments, into rows of the scratch. Py_ssize_t comes from Python.h, which
   Cython includes first. */
#ifndef SOFTGYM_COROT_H
#define SOFTGYM_COROT_H

#include <math.h>
#include "softgym_restrict.h"
#include "softgym_simd.h"
/* the 4-lane gathers and scatter of AVX builds; the portable builds' 4 lanes (GCC's vectors
   on SSE2 registers) were slower here than the compiler's loop (2.8x against 4.4x the seed's
   engine, baseline build) and keep it */
#if defined(SOFTGYM_VLANES) && !defined(SOFTGYM_PORTABLE_LANES)
#define SOFTGYM_COROT_V4 1
#else
#define SOFTGYM_COROT_V4 0
#endif

/* One link's kernel in type T (double, or softgym_vd for SOFTGYM_VLANES links at once:
   SQRT, FABS T's square root and absolute value, PUT(row, li, v) storing v at row + li,
   RD(R, k) element k of a rotation matrix R: SOFTGYM_COROT_IDX where R is an array, a
   load from the k-th row where it is the voxels' rows, which lets the compiler load each
   where it is used instead of holding 18 in registers),
   from voxel 2's position and velocity relative to voxel 1's (d, dv), the voxels' sizes
   si, sj, rotation matrices R1, R2 (row-major: R1[3 r + c]), angular velocities w1, w2
   and the link's constants. (ax, p, q) is a cyclic permutation of (0, 1, 2), ax the
   link's lattice axis; inv_L = 1 / the nominal voxel size. Rows out: ext |axial
   extension|, f the force on voxel 2, m1, m2 the moments on voxels 1 and 2. */
#define SOFTGYM_COROT_LINK_T(T, SQRT, FABS, PUT, RD, li, ax, p, q, inv_L, dx, dy, dz, dvx, dvy, \
                             dvz, si, sj, R1, R2, w1x_, w1y_, w1z_, w2x_, w2y_, w2z_, k_ax, \
                             c_ax, k_b, c_b, k_t, c_t) do { \
        T ell = SQRT((((dx) * (dx)) + ((dy) * (dy))) + ((dz) * (dz))); \
        T e = ell - (0.5 * ((si) + (sj))); \
        PUT(o_ext, li, FABS(e));  /* NaN stays NaN: the caller's check catches it */ \
        /* axial force on voxel 2 along the chord u = d / |d| (elastic + damping) */ \
        T inv_l = 1.0 / ell; \
        T edot = ((((dx) * (dvx)) + ((dy) * (dvy))) + ((dz) * (dvz))) * inv_l; \
        T fa = (((k_ax) * e) + ((c_ax) * edot)) * inv_l; \
        T ax_x = (-fa) * (dx), ax_y = (-fa) * (dy), ax_z = (-fa) * (dz); \
        /* the link's lattice axis in each voxel (column ax of its rotation) and the \
           link's frame axis r, their bisector */ \
        T a1x = RD(R1, ax), a1y = RD(R1, 3 + (ax)), a1z = RD(R1, 6 + (ax)); \
        T a2x = RD(R2, ax), a2y = RD(R2, 3 + (ax)), a2z = RD(R2, 6 + (ax)); \
        T rx = a1x + a2x, ry = a1y + a2y, rz = a1z + a2z; \
        /* 1 / |a1 + a2| by one Newton step from 1/2 (|a1 + a2|^2 = 4 - |a1 - a2|^2 is \
           near 4): relative error 0.14 % at 0.5 rad of relative bending */ \
        T inv_r = 0.5 * (1.5 - (0.125 * (((rx * rx) + (ry * ry)) + (rz * rz)))); \
        rx = rx * inv_r; \
        ry = ry * inv_r; \
        rz = rz * inv_r; \
        /* transverse offset of voxel 2 as an angle on the nominal length, c = r x d / L \
           (the seed's Pos2.y / L: stiffness does not grow when actuated voxels shrink) */ \
        T cx = ((ry * (dz)) - (rz * (dy))) * (inv_L); \
        T cy = ((rz * (dx)) - (rx * (dz))) * (inv_L); \
        T cz = ((rx * (dy)) - (ry * (dx))) * (inv_L); \
        /* bending of each voxel relative to the link, b_i = r x a_i - c; as r bisects a1 \
           and a2, r x a2 = -(r x a1) = h = inv_r (a1 x a2), so b1 = -h - c, b2 = h - c */ \
        T hx = ((a1y * a2z) - (a1z * a2y)) * inv_r; \
        T hy = ((a1z * a2x) - (a1x * a2z)) * inv_r; \
        T hz = ((a1x * a2y) - (a1y * a2x)) * inv_r; \
        /* twist of voxel 2 relative to voxel 1 about the link: with y, z the voxels' \
           two other lattice axes, sin(twist) = (z1 . y2 - y1 . z2) / 2 */ \
        T tw = 0.5 * ((((((RD(R1, q) * RD(R2, p)) + (RD(R1, 3 + (q)) * RD(R2, 3 + (p)))) \
                         + (RD(R1, 6 + (q)) * RD(R2, 6 + (p)))) - (RD(R1, p) * RD(R2, q))) \
                       - (RD(R1, 3 + (p)) * RD(R2, 3 + (q)))) - (RD(R1, 6 + (p)) * RD(R2, 6 + (q)))); \
        /* rates: transverse angle (wc = r x dv / L), the voxels' angular velocities \
           across the link (w_i minus its part along r) and twist */ \
        T wcx = ((ry * (dvz)) - (rz * (dvy))) * (inv_L); \
        T wcy = ((rz * (dvx)) - (rx * (dvz))) * (inv_L); \
        T wcz = ((rx * (dvy)) - (ry * (dvx))) * (inv_L); \
        T w1x = (w1x_), w1y = (w1y_), w1z = (w1z_); \
        T uw = ((rx * w1x) + (ry * w1y)) + (rz * w1z); \
        w1x = w1x - (uw * rx); \
        w1y = w1y - (uw * ry); \
        w1z = w1z - (uw * rz); \
        T twdot = -uw; \
        T w2x = (w2x_), w2y = (w2y_), w2z = (w2z_); \
        uw = ((rx * w2x) + (ry * w2y)) + (rz * w2z); \
        w2x = w2x - (uw * rx); \
        w2y = w2y - (uw * ry); \
        w2z = w2z - (uw * rz); \
        twdot = twdot + uw; \
        /* bending moments: elastic -k_b (2 b1 + b2) = k_b (h + 3 c) on voxel 1, \
           -k_b (b1 + 2 b2) = k_b (3 c - h) on voxel 2; damping the same form with the \
           bending rates (w_i - wc) */ \
        T kb_ = (k_b), cb_ = (c_b); \
        T n1x = (kb_ * (hx + (3.0 * cx))) - (cb_ * (((2.0 * w1x) + w2x) - (3.0 * wcx))); \
        T n1y = (kb_ * (hy + (3.0 * cy))) - (cb_ * (((2.0 * w1y) + w2y) - (3.0 * wcy))); \
        T n1z = (kb_ * (hz + (3.0 * cz))) - (cb_ * (((2.0 * w1z) + w2z) - (3.0 * wcz))); \
        T n2x = (kb_ * ((3.0 * cx) - hx)) - (cb_ * ((w1x + (2.0 * w2x)) - (3.0 * wcx))); \
        T n2y = (kb_ * ((3.0 * cy) - hy)) - (cb_ * ((w1y + (2.0 * w2y)) - (3.0 * wcy))); \
        T n2z = (kb_ * ((3.0 * cz) - hz)) - (cb_ * ((w1z + (2.0 * w2z)) - (3.0 * wcz))); \
        /* force on voxel 2: axial plus the shear that balances the bending moments \
           over the nominal length */ \
        T sx = n1x + n2x, sy = n1y + n2y, sz = n1z + n2z; \
        PUT(o_fx, li, ax_x + (((ry * sz) - (rz * sy)) * (inv_L))); \
        PUT(o_fy, li, ax_y + (((rz * sx) - (rx * sz)) * (inv_L))); \
        PUT(o_fz, li, ax_z + (((rx * sy) - (ry * sx)) * (inv_L))); \
        /* torsion, equal and opposite along r */ \
        T tor = ((k_t) * tw) + ((c_t) * twdot); \
        PUT(o_m1x, li, n1x + (tor * rx)); \
        PUT(o_m1y, li, n1y + (tor * ry)); \
        PUT(o_m1z, li, n1z + (tor * rz)); \
        PUT(o_m2x, li, n2x - (tor * rx)); \
        PUT(o_m2y, li, n2y - (tor * ry)); \
        PUT(o_m2z, li, n2z - (tor * rz)); \
    } while (0)

#if SOFTGYM_COROT_V4
/* voxels idx[0..3] as rows of 4: position 0-2, velocity 3-5, angular velocity 6-8,
   rotation matrix 9-17 (row-major), size 18. GCC's vectoriser loaded these 19 numbers a
   voxel one by one; here pairs of 16-byte loads and unpacks, and the matrix as two
   32-byte loads a voxel turned into rows by a 4 x 4 transpose */
static inline void softgym_corot_gather4(const Py_ssize_t *idx, const double *pos,
                                         const double *vel, const double *av,
                                         const double *rot, const double *scale, softgym_m4 *r)
{
    const double *a = pos + 3 * idx[0], *b = pos + 3 * idx[1];
    const double *c = pos + 3 * idx[2], *d = pos + 3 * idx[3];
    SOFTGYM_GATHER_PAIRS(a, b, c, d, 0, r[0], r[1]);
    r[2] = SOFTGYM_M4SET(a[2], b[2], c[2], d[2]);
    a = vel + 3 * idx[0], b = vel + 3 * idx[1], c = vel + 3 * idx[2], d = vel + 3 * idx[3];
    SOFTGYM_GATHER_PAIRS(a, b, c, d, 0, r[3], r[4]);
    r[5] = SOFTGYM_M4SET(a[2], b[2], c[2], d[2]);
    a = av + 3 * idx[0], b = av + 3 * idx[1], c = av + 3 * idx[2], d = av + 3 * idx[3];
    SOFTGYM_GATHER_PAIRS(a, b, c, d, 0, r[6], r[7]);
    r[8] = SOFTGYM_M4SET(a[2], b[2], c[2], d[2]);
    a = rot + 9 * idx[0], b = rot + 9 * idx[1], c = rot + 9 * idx[2], d = rot + 9 * idx[3];
    SOFTGYM_TRANSPOSE4(SOFTGYM_M4LOADU(a), SOFTGYM_M4LOADU(b), SOFTGYM_M4LOADU(c),
                       SOFTGYM_M4LOADU(d), r[9], r[10], r[11], r[12]);
    SOFTGYM_TRANSPOSE4(SOFTGYM_M4LOADU(a + 4), SOFTGYM_M4LOADU(b + 4), SOFTGYM_M4LOADU(c + 4),
                       SOFTGYM_M4LOADU(d + 4), r[13], r[14], r[15], r[16]);
    r[17] = SOFTGYM_M4SET(a[8], b[8], c[8], d[8]);
    r[18] = SOFTGYM_M4SET(scale[idx[0]], scale[idx[1]], scale[idx[2]], scale[idx[3]]);
}
#endif

/* element k of a rotation matrix held as an array (SOFTGYM_COROT_LINK_T's RD) */
#define SOFTGYM_COROT_IDX(R, k) ((R)[k])
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
#define SOFTGYM_COROT_ROWS 18
/* the voxels' rotation matrices as rows SOFTGYM_ROW_ROT .. + 8 (9-17) of the voxel rows (n apart, indexed by
   voxel; row-major), computed from their quaternions in rows SOFTGYM_ROW_QUAT (the
   formula that stores rot, softgym_quat_matrix: the same bits in the lanes as one by one),
   once a step, so that the links' 8-lane paths load a voxel's 18 numbers (position,
   velocity, angular velocity in rows 0-8, the step loop's state: include/softgym_simd.h)
   as 18 rows of 8 voxels (no transposes a link). The step does not read rot, which
   advance_robot refreshes when it returns (SOFTGYM_ROT_DEFERRED) */
static void softgym_corot_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double *rows)
{
    Py_ssize_t i = lo;
    const double *q = rows + SOFTGYM_ROW_QUAT * n;
    for (; i + 8 <= hi; i += 8) {
        softgym_v8 R[9];
        softgym_v8 w = softgym_v8_load(q + i), x = softgym_v8_load(q + n + i);
        softgym_v8 y = softgym_v8_load(q + 2 * n + i), z = softgym_v8_load(q + 3 * n + i);
        SOFTGYM_QUAT_MATRIX(w, x, y, z, R);
        for (int k = 0; k < 9; k++)
            memcpy(rows + (SOFTGYM_ROW_ROT + k) * n + i, &R[k], sizeof R[k]);
    }
    for (; i < hi; i++) {
        double R[9];
        softgym_quat_matrix_wxyz(q[i], q[n + i], q[2 * n + i], q[3 * n + i], R);
        for (int k = 0; k < 9; k++)
            rows[(SOFTGYM_ROW_ROT + k) * n + i] = R[k];
    }
}
#endif


/* links lo..hi, all along axis ax (a compile-time constant in each copy), into the
   rows of the scratch o (stride n): 0 |axial extension|, 1-3 the force on voxel 2,
   4-6 voxel 1's moment, 7-9 voxel 2's. vr: the voxels' rows (the step loop's state and
   the matrices of softgym_corot_rows: vn
   apart; NULL: none), vend the robot's end of voxels */
SOFTGYM_ALWAYS_INLINE void softgym_corot_links_ax(
    const int ax, Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double inv_L,
    const Py_ssize_t *SOFTGYM_RESTRICT v1, const Py_ssize_t *SOFTGYM_RESTRICT v2,
    const double *SOFTGYM_RESTRICT pos, const double *SOFTGYM_RESTRICT vel,
    const double *SOFTGYM_RESTRICT av, const double *SOFTGYM_RESTRICT rot,
    const double *SOFTGYM_RESTRICT scale, const double *SOFTGYM_RESTRICT k_axial,
    const double *SOFTGYM_RESTRICT c_axial, const double *SOFTGYM_RESTRICT k_bend,
    const double *SOFTGYM_RESTRICT c_bend, const double *SOFTGYM_RESTRICT k_torsion,
    const double *SOFTGYM_RESTRICT c_torsion, const double *SOFTGYM_RESTRICT vr, Py_ssize_t vn,
    Py_ssize_t vend, double *o)
{
    const int p = (ax + 1) % 3, q = (ax + 2) % 3;
    double *SOFTGYM_RESTRICT o_ext = o, *SOFTGYM_RESTRICT o_fx = o + n, *SOFTGYM_RESTRICT o_fy = o + 2 * n;
    double *SOFTGYM_RESTRICT o_fz = o + 3 * n, *SOFTGYM_RESTRICT o_m1x = o + 4 * n;
    double *SOFTGYM_RESTRICT o_m1y = o + 5 * n, *SOFTGYM_RESTRICT o_m1z = o + 6 * n;
    double *SOFTGYM_RESTRICT o_m2x = o + 7 * n, *SOFTGYM_RESTRICT o_m2y = o + 8 * n;
    double *SOFTGYM_RESTRICT o_m2z = o + 9 * n;
    Py_ssize_t li = lo;
#if defined(SOFTGYM_COROT_ROWS)
    /* with AVX-512, 8 links a vector from the voxels' rows: runs of consecutive voxels
       (the links along a lattice's slower axes) by plain loads, a window of 16 voxels (its
       fastest axis) by two-source permutes, any others by gathers; the last links one by
       one; the arithmetic is the macro's, lane by lane: the same bits */
    if (vr != NULL) {
        /* every number a link reads through an accessor of its voxel's handle h (the first
           voxel of a run, or a vector of voxel indices): ROW(k, h) row k, RD(h, k) element
           k of the rotation matrix; loaded where the kernel uses it (held all at once, the
           38 spilled) */
#define SOFTGYM_COROT_LINK_ROWS(T, PUT, ROW, RD, SCALE, h1, h2) do { \
            T dx = ROW(0, h2) - ROW(0, h1), dy = ROW(1, h2) - ROW(1, h1); \
            T dz = ROW(2, h2) - ROW(2, h1), dvx = ROW(3, h2) - ROW(3, h1); \
            T dvy = ROW(4, h2) - ROW(4, h1), dvz = ROW(5, h2) - ROW(5, h1); \
            SOFTGYM_COROT_LINK_T(T, SQRT_, FABS_, PUT, RD, li, ax, p, q, inv_L, dx, dy, dz, dvx, \
                                 dvy, dvz, SCALE(h1), SCALE(h2), h1, h2, ROW(6, h1), ROW(7, h1), \
                                 ROW(8, h1), ROW(6, h2), ROW(7, h2), ROW(8, h2), LD_(k_axial), \
                                 LD_(c_axial), LD_(k_bend), LD_(c_bend), LD_(k_torsion), \
                                 LD_(c_torsion)); \
        } while (0)
#define SQRT_ SOFTGYM_VSQRT
#define FABS_ softgym_vabs
#define LD_(a) softgym_v8_load((a) + li)
        /* runs of 8 consecutive voxels (h: the first) */
#define SOFTGYM_COROT_RUN(k, h) softgym_v8_load(vr + (k) * vn + (h))
#define SOFTGYM_COROT_RUN_RD(h, k) SOFTGYM_COROT_RUN(SOFTGYM_ROW_ROT + (k), h)
#define SOFTGYM_COROT_RUN_S(h) softgym_v8_load(scale + (h))
        /* a window of 16 voxels from base (h: the links' places in it), each number picked
           from the window's two vectors of its row */
#define SOFTGYM_COROT_WIN(k, h) ((softgym_vd)_mm512_permutex2var_pd( \
            _mm512_loadu_pd(vr + (k) * vn + base), (h), _mm512_loadu_pd(vr + (k) * vn + base + 8)))
#define SOFTGYM_COROT_WIN_RD(h, k) SOFTGYM_COROT_WIN(SOFTGYM_ROW_ROT + (k), h)
#define SOFTGYM_COROT_WIN_S(h) ((softgym_vd)_mm512_permutex2var_pd( \
            _mm512_loadu_pd(scale + base), (h), _mm512_loadu_pd(scale + base + 8)))
        /* any 8 voxels (h: their indices), gathered */
#define SOFTGYM_COROT_GAT(k, h) ((softgym_vd)_mm512_i64gather_pd((h), vr + (k) * vn, 8))
#define SOFTGYM_COROT_GAT_RD(h, k) SOFTGYM_COROT_GAT(SOFTGYM_ROW_ROT + (k), h)
#define SOFTGYM_COROT_GAT_S(h) ((softgym_vd)_mm512_i64gather_pd((h), scale, 8))
        for (; li + 8 <= hi; li += 8) {
            const Py_ssize_t base = v1[li];
            __m512i ia, ib;
            if (softgym_run8(v1 + li) & softgym_run8(v2 + li)) {
                const Py_ssize_t i1 = base, i2 = v2[li];
                SOFTGYM_COROT_LINK_ROWS(softgym_vd, SOFTGYM_VPUT, SOFTGYM_COROT_RUN,
                                        SOFTGYM_COROT_RUN_RD, SOFTGYM_COROT_RUN_S, i1, i2);
            } else if (softgym_window8_index(v1 + li, v2 + li, vend, &ia, &ib)) {
                SOFTGYM_COROT_LINK_ROWS(softgym_vd, SOFTGYM_VPUT, SOFTGYM_COROT_WIN,
                                        SOFTGYM_COROT_WIN_RD, SOFTGYM_COROT_WIN_S, ia, ib);
            } else {
                ia = _mm512_loadu_si512((const void *)(v1 + li));
                ib = _mm512_loadu_si512((const void *)(v2 + li));
                SOFTGYM_COROT_LINK_ROWS(softgym_vd, SOFTGYM_VPUT, SOFTGYM_COROT_GAT,
                                        SOFTGYM_COROT_GAT_RD, SOFTGYM_COROT_GAT_S, ia, ib);
            }
        }
#undef SQRT_
#undef FABS_
#undef LD_
        /* the rest, one link at a time from the rows */
#define SQRT_ sqrt
#define FABS_ fabs
#define LD_(a) ((a)[li])
#define SOFTGYM_COROT_ONE(k, h) (vr[(k) * vn + (h)])
#define SOFTGYM_COROT_ONE_RD(h, k) SOFTGYM_COROT_ONE(SOFTGYM_ROW_ROT + (k), h)
#define SOFTGYM_COROT_ONE_S(h) (scale[h])
        for (; li < hi; li++) {
            const Py_ssize_t i1 = v1[li], i2 = v2[li];
            SOFTGYM_COROT_LINK_ROWS(double, SOFTGYM_PUT1, SOFTGYM_COROT_ONE,
                                    SOFTGYM_COROT_ONE_RD, SOFTGYM_COROT_ONE_S, i1, i2);
        }
#undef SQRT_
#undef FABS_
#undef LD_
#undef SOFTGYM_COROT_ONE
#undef SOFTGYM_COROT_ONE_RD
#undef SOFTGYM_COROT_ONE_S
#undef SOFTGYM_COROT_GAT
#undef SOFTGYM_COROT_GAT_RD
#undef SOFTGYM_COROT_GAT_S
#undef SOFTGYM_COROT_WIN
#undef SOFTGYM_COROT_WIN_RD
#undef SOFTGYM_COROT_WIN_S
#undef SOFTGYM_COROT_RUN
#undef SOFTGYM_COROT_RUN_RD
#undef SOFTGYM_COROT_RUN_S
#undef SOFTGYM_COROT_LINK_ROWS
        return;  /* (rot is not read: the rows' matrices come from the quaternions) */
    }
#else
    (void)vr;
    (void)vn;
    (void)vend;
#endif
#if SOFTGYM_COROT_V4
    /* with AVX2 (and where no rows are given), 4 links a vector from gathered records
       (8 lanes from gathered records spilled: 38 rows live, measured 5 % slower) */
    for (; li + 4 <= hi; li += 4) {
        softgym_m4 gi[19], gj[19];
        softgym_corot_gather4(v1 + li, pos, vel, av, rot, scale, gi);
        softgym_corot_gather4(v2 + li, pos, vel, av, rot, scale, gj);
        softgym_v4 dx = gj[0] - gi[0], dy = gj[1] - gi[1], dz = gj[2] - gi[2];
        softgym_v4 dvx = gj[3] - gi[3], dvy = gj[4] - gi[4], dvz = gj[5] - gi[5];
        SOFTGYM_COROT_LINK_T(softgym_v4, SOFTGYM_V4SQRT, softgym_v4abs, SOFTGYM_V4PUT,
                             SOFTGYM_COROT_IDX, li, ax, p, q, inv_L, dx, dy, dz, dvx, dvy, dvz,
                             (softgym_v4)gi[18], (softgym_v4)gj[18], ((softgym_v4 *)gi + 9),
                             ((softgym_v4 *)gj + 9), (softgym_v4)gi[6], (softgym_v4)gi[7],
                             (softgym_v4)gi[8], (softgym_v4)gj[6], (softgym_v4)gj[7],
                             (softgym_v4)gj[8], softgym_v4load(k_axial, li),
                             softgym_v4load(c_axial, li), softgym_v4load(k_bend, li),
                             softgym_v4load(c_bend, li), softgym_v4load(k_torsion, li),
                             softgym_v4load(c_torsion, li));
    }
#endif
    /* the rest (and every link without AVX): the compiler's vectoriser */
    SOFTGYM_IVDEP
    for (; li < hi; li++) {
        Py_ssize_t i = v1[li], j = v2[li];
        SOFTGYM_DIFF3(pos, i, j, dx, dy, dz);
        SOFTGYM_DIFF3(vel, i, j, dvx, dvy, dvz);
        SOFTGYM_COROT_LINK_T(double, sqrt, fabs, SOFTGYM_PUT1, SOFTGYM_COROT_IDX, li, ax, p, q,
                             inv_L, dx, dy, dz,
                             dvx, dvy, dvz, scale[i], scale[j], (rot + 9 * i), (rot + 9 * j),
                             av[3 * i], av[3 * i + 1], av[3 * i + 2], av[3 * j], av[3 * j + 1],
                             av[3 * j + 2], k_axial[li], c_axial[li], k_bend[li], c_bend[li],
                             k_torsion[li], c_torsion[li]);
    }
}
static void softgym_corot_links(int ax, Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                double inv_L, const Py_ssize_t *v1, const Py_ssize_t *v2,
                                const double *pos, const double *vel, const double *av,
                                const double *rot, const double *scale, const double *k_axial,
                                const double *c_axial, const double *k_bend,
                                const double *c_bend, const double *k_torsion,
                                const double *c_torsion, const double *vr, Py_ssize_t vn,
                                Py_ssize_t vend, double *o)
{
    SOFTGYM_BY_AXIS(ax, softgym_corot_links_ax, lo, hi, n, inv_L, v1, v2, pos, vel, av, rot,
                    scale, k_axial, c_axial, k_bend, c_bend, k_torsion, c_torsion, vr, vn, vend,
                    o);
}

/* The strain check and the scatter of links lo..hi in link order, from the kernel's rows
   of o (stride n): voxel 2 takes the force f and voxel 1 minus it, each voxel its moment.
   Returns hi, or the first link whose |axial extension| is beyond max_ext (NaN
   included); the links before it are scattered. With AVX each link's three components
   are added to the voxel's whole row of 4 (lane 3 is padding, never read): the same
   additions, in the same order, per component. Where a link's voxel 1 is the last link's
   voxel 2 (runs along the lattice's fastest axis) its rows come from registers instead
   of a load that would wait on the store just made. */
static Py_ssize_t softgym_corot_scatter(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                        double max_ext, const Py_ssize_t *v1,
                                        const Py_ssize_t *v2, const double *o, double *force,
                                        double *moment)
{
    Py_ssize_t li = lo;
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
    /* 8 links at a time with AVX-512 while none of them is strained: their rows turned
       into each link's rows of 4 in registers (softgym_v8_rows4), paired into the rows of
       8 each voxel takes (force and moment: SOFTGYM_ROW8), then added link after link, as
       below (the first strained link's block goes link by link) */
    for (; li + 8 <= hi; li += 8) {
        __m512d e = _mm512_loadu_pd(o + li);
        if (_mm512_cmp_pd_mask(e, _mm512_set1_pd(max_ext), _CMP_LE_OQ) != 0xFF)
            break;
        __m512d wf[4], w1[4], w2[4];
        softgym_v8_rows4(softgym_v8_load(o + n + li), softgym_v8_load(o + 2 * n + li),
                         softgym_v8_load(o + 3 * n + li), wf);
        softgym_v8_rows4(softgym_v8_load(o + 4 * n + li), softgym_v8_load(o + 5 * n + li),
                         softgym_v8_load(o + 6 * n + li), w1);
        softgym_v8_rows4(softgym_v8_load(o + 7 * n + li), softgym_v8_load(o + 8 * n + li),
                         softgym_v8_load(o + 9 * n + li), w2);
        /* voxel 1's row takes [-f | m1]: fmadd of [-1 .. | 1 ..] times [f | m1] is its sum
           with f negated (exactly: the product by -1 is exact and the sum rounds once) */
        const __m512d sg = _mm512_set_pd(1.0, 1.0, 1.0, 1.0, -1.0, -1.0, -1.0, -1.0);
        __m512d c = _mm512_setzero_pd();
        Py_ssize_t pb = -1;
#define SOFTGYM_COROT_ADD1(k) do { \
            Py_ssize_t i_ = SOFTGYM_FM_STRIDE * v1[li + (k)]; \
            Py_ssize_t j_ = SOFTGYM_FM_STRIDE * v2[li + (k)]; \
            __m512d a_; \
            SOFTGYM_ROW_OR_CARRIED(i_ == pb, a_, c, force, i_); \
            c = _mm512_add_pd(_mm512_load_pd(force + j_), SOFTGYM_ROW8(wf, w2, k)); \
            _mm512_store_pd(force + j_, c); \
            _mm512_store_pd(force + i_, _mm512_fmadd_pd(sg, SOFTGYM_ROW8(wf, w1, k), a_)); \
            pb = j_; \
        } while (0)
        SOFTGYM_EACH8(SOFTGYM_COROT_ADD1);
#undef SOFTGYM_COROT_ADD1
    }
#endif
#if SOFTGYM_COROT_V4
    softgym_v4 cf = {0.0, 0.0, 0.0, 0.0}, cm = cf;
    Py_ssize_t pj = -1;
#endif
    for (; li < hi; li++) {
        if (!(o[li] <= max_ext))
            return li;
        Py_ssize_t i = v1[li], j = v2[li];
        double fx = o[n + li], fy = o[2 * n + li], fz = o[3 * n + li];
#if SOFTGYM_COROT_V4
        softgym_v4 f = {fx, fy, fz, 0.0};
        softgym_v4 m1 = {o[4 * n + li], o[5 * n + li], o[6 * n + li], 0.0};
        softgym_v4 m2 = {o[7 * n + li], o[8 * n + li], o[9 * n + li], 0.0};
        softgym_v4 fi, mi, fj, mj;
        if (i == pj) {
            fi = cf;
            mi = cm;
        } else {
            memcpy(&fi, force + SOFTGYM_FM_STRIDE * i, sizeof fi);
            memcpy(&mi, moment + SOFTGYM_FM_STRIDE * i, sizeof mi);
        }
        memcpy(&fj, force + SOFTGYM_FM_STRIDE * j, sizeof fj);
        memcpy(&mj, moment + SOFTGYM_FM_STRIDE * j, sizeof mj);
        fj += f;
        fi -= f;
        mi += m1;
        mj += m2;
        memcpy(force + SOFTGYM_FM_STRIDE * j, &fj, sizeof fj);
        memcpy(force + SOFTGYM_FM_STRIDE * i, &fi, sizeof fi);
        memcpy(moment + SOFTGYM_FM_STRIDE * i, &mi, sizeof mi);
        memcpy(moment + SOFTGYM_FM_STRIDE * j, &mj, sizeof mj);
        cf = fj;
        cm = mj;
        pj = j;
#else
        force[SOFTGYM_FM_STRIDE * j] += fx;
        force[SOFTGYM_FM_STRIDE * j + 1] += fy;
        force[SOFTGYM_FM_STRIDE * j + 2] += fz;
        force[SOFTGYM_FM_STRIDE * i] -= fx;
        force[SOFTGYM_FM_STRIDE * i + 1] -= fy;
        force[SOFTGYM_FM_STRIDE * i + 2] -= fz;
        moment[SOFTGYM_FM_STRIDE * i] += o[4 * n + li];
        moment[SOFTGYM_FM_STRIDE * i + 1] += o[5 * n + li];
        moment[SOFTGYM_FM_STRIDE * i + 2] += o[6 * n + li];
        moment[SOFTGYM_FM_STRIDE * j] += o[7 * n + li];
        moment[SOFTGYM_FM_STRIDE * j + 1] += o[8 * n + li];
        moment[SOFTGYM_FM_STRIDE * j + 2] += o[9 * n + li];
#endif
    }
    return hi;
}

/* whether the build has the rows path (the Cython side's COROT_ROWS_USED) */
#if defined(SOFTGYM_COROT_ROWS)
#define COROT_ROWS_USED 1
#else
#define COROT_ROWS_USED 0
static void softgym_corot_rows(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, double *rows)
{
    (void)lo; (void)hi; (void)n; (void)rows;
}
#endif

#endif  /* SOFTGYM_COROT_H */
