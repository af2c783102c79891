/* The single-precision forces pass (softgym_seed_forces.h) for the SOFTGYM_FB_LANES links
   li.. in vector lanes, written in intrinsics: softgym_seed.h includes this file for the
   16 lanes of AVX-512 and the 8 of AVX2, with SOFTGYM_FB_NAME (the function), SOFTGYM_FB_V
   (the floats' vector type), SOFTGYM_FB_M (the lanes' conditions) and the operations
   defined: SOFTGYM_FB_ROW (a row's lanes from li), SOFTGYM_FB_PUT, SOFTGYM_FB_SET,
   SOFTGYM_FB_FMA, _FMS, _FNMA, _FNMS (the fused multiply-adds), SOFTGYM_FB_PICK (m ? a : b),
   SOFTGYM_FB_DAMP (x + s d where m, else x), SOFTGYM_FB_NOT_NONZERO (the lanes whose double
   row holds 0.0) and SOFTGYM_FB_KEEP (p's lanes set to x where m, else left as last, the
   value loaded from them). No include guard, on purpose.

   The compiler's loop of the same pass took 343 instructions a 16-lane block, 82 of them
   loads and stores of spilled registers (with its conditions as vectors of ints); here the
   conditions are masks (AVX-512's mask registers), the damping's selects masked
   multiply-adds or blends, and the memory's masked stores or blends of the loaded row
   (about 1.2x fewer cycles in the pass with AVX-512: benchmarks/RESULTS.md). Every
   multiply-add is written out as the compiler fused the loop it replaces (its widening_mul
   dump of the x86-64-v4 build): the same IEEE operations lane by lane, bit for bit
   (benchmarks/check_bitident.py; tests/engine/test_kernel_variants.py holds the builds to
   one another). The large-angle turn RQ^T v takes its products in two orders, as that loop
   did: f1 rounds its x product, the moments and f2 their y product; where every link is in
   small-angle mode the loop had folded the moments' x output's negation into their
   damping (a zero's sign differs from negating after), and so does this. Two blocks side
   by side, as the frames pass's, were no faster (their registers spill). all_small,
   all_neg2 as softgym_seed_forces32_impl's. */
/* the rate of the quantity x in memory row r, (x - last) inv_dt, and the row set to x where
   the mode did not change */
#define SOFTGYM_FB_MEMORY(r, x, rate) do { \
        SOFTGYM_FB_V last_ = SOFTGYM_FB_ROW(SOFTGYM_MEM(r), li); \
        rate = vdt * ((x) - last_); \
        SOFTGYM_FB_KEEP(SOFTGYM_MEM(r) + li, keep, x, last_); \
    } while (0)
SOFTGYM_ALWAYS_INLINE void SOFTGYM_FB_NAME(
    const int all_small, const int all_neg2, Py_ssize_t li, Py_ssize_t n, float L, float bz,
    float bzh, float inv_dt, const float *in, const double *sa_, const double *chg_,
    const float *ka_, const float *kt_, const float *kb_, const float *cs_,
    float *link_last, float *out)
{
    const Py_ssize_t is = SOFTGYM_CHUNK_FSTRIDE, os = SOFTGYM_CHUNK_FSTRIDE;
    SOFTGYM_FB_V P0, P1, P2, a1y, a1z, a2x, a2y, a2z;
    SOFTGYM_FB_V ka, b2, f1x, f1y, f1z, m1x, m1y, m1z;
    SOFTGYM_FB_V m2x, m2y, m2z, f2x, f2y, f2z;
    SOFTGYM_FB_V vx, vy, vz, ra1x, ra1y, ra1z, ra2y, ra2z;
    SOFTGYM_FB_V s1z, s1y, dax, c0, c1, c2, c3, d1, d2, nm1x, nm2x;
    SOFTGYM_FB_M keep, large;
    const SOFTGYM_FB_V two = SOFTGYM_FB_SET(2.0f), nil = SOFTGYM_FB_SET(0.0f);
    const SOFTGYM_FB_V vdt = SOFTGYM_FB_SET(inv_dt), vbz = SOFTGYM_FB_SET(bz);
    const SOFTGYM_FB_V vbzh = SOFTGYM_FB_SET(bzh);
#define SOFTGYM_IN(r) SOFTGYM_FB_ROW(in + (r) * is, li)
#define SOFTGYM_MEM(r) (link_last + (r) * n)
    P0 = SOFTGYM_IN(0);
    P1 = SOFTGYM_IN(1);
    P2 = SOFTGYM_IN(2);
    a1y = SOFTGYM_IN(3);
    a1z = SOFTGYM_IN(4);
    a2x = SOFTGYM_IN(5);
    a2y = SOFTGYM_IN(6);
    a2z = SOFTGYM_IN(7);
    keep = SOFTGYM_FB_NOT_NONZERO(chg_, li);
    ka = SOFTGYM_FB_ROW(ka_, li);
    /* stiffness */
    b2 = (ka * 0.5f) * L;
    f1x = P0 * ka;
    f1y = SOFTGYM_FB_FMS(P1, ka, b2 * (a1z + a2z));
    f1z = SOFTGYM_FB_FMA(P2, ka, b2 * (a1y + a2y));
    m1x = SOFTGYM_FB_ROW(kt_, li) * (nil - a2x);
    c0 = SOFTGYM_FB_ROW(kb_, li);
    m1y = SOFTGYM_FB_FMA(P2, b2, c0 * SOFTGYM_FB_FMA(a1y, two, a2y));
    m1z = SOFTGYM_FB_FNMA(P1, b2, c0 * SOFTGYM_FB_FMA(a1z, two, a2z));
    m2y = SOFTGYM_FB_FMA(P2, b2, c0 * SOFTGYM_FB_FMA(a2y, two, a1y));
    m2z = SOFTGYM_FB_FNMA(P1, b2, c0 * SOFTGYM_FB_FMA(a2z, two, a1z));
    m2x = -m1x;
    /* damping: rates from the memory of the last step, which is updated where the mode did
       not change */
    SOFTGYM_FB_MEMORY(0, P0, vx);
    SOFTGYM_FB_MEMORY(1, P1, vy);
    SOFTGYM_FB_MEMORY(2, P2, vz);
    SOFTGYM_FB_MEMORY(3, nil, ra1x);
    SOFTGYM_FB_MEMORY(4, a1y, ra1y);
    SOFTGYM_FB_MEMORY(5, a1z, ra1z);
    /* ra2x - ra1x, ra2x = inv_dt (a2x - l6) fused into the difference */
    c0 = SOFTGYM_FB_ROW(SOFTGYM_MEM(6), li);
    dax = SOFTGYM_FB_FMS(vdt, a2x - c0, ra1x);
    SOFTGYM_FB_KEEP(SOFTGYM_MEM(6) + li, keep, a2x, c0);
    SOFTGYM_FB_MEMORY(7, a2y, ra2y);
    SOFTGYM_FB_MEMORY(8, a2z, ra2z);
    s1z = ra1z + ra2z;
    s1y = ra1y + ra2y;
    /* voxel 2's damped force (c_seed rows 4-7), where it is its own */
    if (!all_neg2) {
        c0 = SOFTGYM_FB_ROW(cs_ + 4 * n, li);
        c1 = SOFTGYM_FB_ROW(cs_ + 5 * n, li);
        f2x = SOFTGYM_FB_FMS(vx * -c0, vbz, f1x);
        f2y = SOFTGYM_FB_FMS(vbz, SOFTGYM_FB_FNMA(vy, c0, s1z * c1), f1y);
        f2z = SOFTGYM_FB_FMS(vbz, SOFTGYM_FB_FNMS(vz, c0, s1y * c1), f1z);
    }
    /* voxel 1's damping (c_seed rows 0-3) */
    c0 = SOFTGYM_FB_ROW(cs_, li);
    c1 = SOFTGYM_FB_ROW(cs_ + n, li);
    c2 = SOFTGYM_FB_ROW(cs_ + 2 * n, li);
    c3 = SOFTGYM_FB_ROW(cs_ + 3 * n, li);
    f1x = SOFTGYM_FB_DAMP(keep, f1x, vbz, vx * c0);
    f1y = SOFTGYM_FB_DAMP(keep, f1y, vbz, SOFTGYM_FB_FNMA(c1, s1z, vy * c0));
    f1z = SOFTGYM_FB_DAMP(keep, f1z, vbz, SOFTGYM_FB_FMA(c1, s1y, vz * c0));
    /* m1x's damping: with all links in small-angle mode the compiler's loop fused its
       output's negation into the damping's multiply-add (-(d bzh) - m1x, which differs
       from -(d bzh + m1x) in the sign of a zero), elsewhere it negated the turned sum */
    d1 = dax * -c2;
    if (all_small)
        nm1x = SOFTGYM_FB_PICK(keep, SOFTGYM_FB_FNMS(d1, vbzh, m1x), m2x);
    d2 = SOFTGYM_FB_ROW(cs_ + 6 * n, li) * dax;
    /* voxel 2's: m2x + bzh ca2 (ra2x - ra1x) = bzh ca2 (...) - m1x, fused, from m1x
       before its damping (negated: m1x - bzh ca2 (...), where all links are small) */
    if (all_small)
        nm2x = SOFTGYM_FB_PICK(keep, SOFTGYM_FB_FNMA(vbzh, d2, m1x), m1x);
    else
        m2x = SOFTGYM_FB_PICK(keep, SOFTGYM_FB_FMS(vbzh, d2, m1x), m2x);
    m1x = SOFTGYM_FB_DAMP(keep, m1x, vbzh, d1);
    m1y = SOFTGYM_FB_DAMP(keep, m1y, vbzh,
                           SOFTGYM_FB_FMA(c3, SOFTGYM_FB_FMA(ra1y, two, ra2y), vz * c1));
    m1z = SOFTGYM_FB_DAMP(keep, m1z, vbzh,
                           SOFTGYM_FB_FMA(c3, SOFTGYM_FB_FMA(ra1z, two, ra2z), vy * -c1));
    /* voxel 2's moment's damping (c_seed rows 5 and 7) */
    c1 = SOFTGYM_FB_ROW(cs_ + 5 * n, li);
    c3 = SOFTGYM_FB_ROW(cs_ + 7 * n, li);
    m2y = SOFTGYM_FB_DAMP(keep, m2y, vbzh,
                           SOFTGYM_FB_FMA(c3, SOFTGYM_FB_FMA(ra2y, two, ra1y), vz * c1));
    m2z = SOFTGYM_FB_DAMP(keep, m2z, vbzh,
                           SOFTGYM_FB_FMA(c3, SOFTGYM_FB_FMA(ra2z, two, ra1z), vy * -c1));
    if (!all_small) {
        /* large angle: G = RQ^T v (RQ the matrix of rq over |rq|^2) */
        SOFTGYM_FB_V r0, r1, r2, r4, r5, r8, yy, zz, g;
        large = SOFTGYM_FB_NOT_NONZERO(sa_, li);
        c0 = SOFTGYM_IN(8);   /* rw */
        c1 = SOFTGYM_IN(9);   /* ry */
        c2 = SOFTGYM_IN(10);  /* rz */
        yy = c1 * c1;
        zz = c2 * c2;
        c3 = zz + SOFTGYM_FB_FMA(c0, c0, yy);  /* |rq|^2 */
        r0 = SOFTGYM_FB_FNMA(yy + zz, two, c3);
        r1 = (c0 * c2) * 2.0f;
        r2 = (c0 * c1) * 2.0f;
        r4 = SOFTGYM_FB_FNMA(zz, two, c3);
        r5 = (c1 * c2) * 2.0f;
        r8 = SOFTGYM_FB_FNMA(yy, two, c3);
/* (x, y, z) turned where the link is in large-angle mode; X: the x product rounded */
#define SOFTGYM_FB_UNTURN_X(x, y, z) do { \
            g = SOFTGYM_FB_FMA(r1, y, r0 * x); \
            yy = SOFTGYM_FB_FMA(r4, y, -r1 * x); \
            zz = SOFTGYM_FB_FMA(r5, y, r2 * x); \
            SOFTGYM_FB_UNTURN_Z(x, y, z); \
        } while (0)
/* Y: the y product rounded */
#define SOFTGYM_FB_UNTURN_Y(x, y, z) do { \
            g = SOFTGYM_FB_FMA(r0, x, r1 * y); \
            yy = SOFTGYM_FB_FNMA(r1, x, r4 * y); \
            zz = SOFTGYM_FB_FMA(r2, x, r5 * y); \
            SOFTGYM_FB_UNTURN_Z(x, y, z); \
        } while (0)
#define SOFTGYM_FB_UNTURN_Z(x, y, z) do { \
            x = SOFTGYM_FB_PICK(large, SOFTGYM_FB_FNMA(r2, z, g), x); \
            y = SOFTGYM_FB_PICK(large, SOFTGYM_FB_FMA(r5, z, yy), y); \
            z = SOFTGYM_FB_PICK(large, SOFTGYM_FB_FMA(r8, z, zz), z); \
        } while (0)
        SOFTGYM_FB_UNTURN_X(f1x, f1y, f1z);
        SOFTGYM_FB_UNTURN_Y(m1x, m1y, m1z);
        SOFTGYM_FB_UNTURN_Y(m2x, m2y, m2z);
        if (!all_neg2)
            SOFTGYM_FB_UNTURN_Y(f2x, f2y, f2z);
#undef SOFTGYM_FB_UNTURN_X
#undef SOFTGYM_FB_UNTURN_Y
#undef SOFTGYM_FB_UNTURN_Z
    }
    SOFTGYM_FB_PUT(out, li, f1x);
    SOFTGYM_FB_PUT(out + os, li, f1y);
    SOFTGYM_FB_PUT(out + 2 * os, li, f1z);
    if (!all_neg2) {
        SOFTGYM_FB_PUT(out + 3 * os, li, f2x);
        SOFTGYM_FB_PUT(out + 4 * os, li, f2y);
        SOFTGYM_FB_PUT(out + 5 * os, li, f2z);
    }
    if (all_small)
        SOFTGYM_FB_PUT(out + 6 * os, li, nm1x);
    else
        SOFTGYM_FB_PUT(out + 6 * os, li, -m1x);
    SOFTGYM_FB_PUT(out + 7 * os, li, -m1y);
    SOFTGYM_FB_PUT(out + 8 * os, li, -m1z);
    if (all_small)
        SOFTGYM_FB_PUT(out + 9 * os, li, nm2x);
    else
        SOFTGYM_FB_PUT(out + 9 * os, li, -m2x);
    SOFTGYM_FB_PUT(out + 10 * os, li, -m2y);
    SOFTGYM_FB_PUT(out + 11 * os, li, -m2z);
#undef SOFTGYM_FB_MEMORY
#undef SOFTGYM_MEM
#undef SOFTGYM_IN
}
