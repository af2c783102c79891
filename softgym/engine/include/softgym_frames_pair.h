/* The frames pass in float (softgym_seed_frames32_impl's mixed loop, softgym_seed.h) for
   two blocks of SOFTGYM_FP_LANES links li.. side by side, written in intrinsics:
   softgym_seed.h includes this file for the 16 lanes of AVX-512 and the 8 of AVX2, with
   SOFTGYM_FP_NAME (the function), SOFTGYM_FP_V (the floats' vector type, GCC's, whose
   arithmetic operators act lane by lane), SOFTGYM_FP_M (the lanes' conditions: AVX-512's
   mask registers, or vectors of ints with every bit of a lane set) and the operations
   defined: SOFTGYM_FP_LOAD (SOFTGYM_FP_LANES doubles rounded to floats),
   SOFTGYM_FP_NONZERO (the lanes whose double row is not 0.0), SOFTGYM_FP_PICK (m ? a : b),
   SOFTGYM_FP_CMP, SOFTGYM_FP_SET, SOFTGYM_FP_FMA, SOFTGYM_FP_FNMA, SOFTGYM_FP_SQRT,
   SOFTGYM_FP_STORE and SOFTGYM_FP_ANY (any lane set). Every statement is made for both
   blocks before the next (SOFTGYM_X2): the loop's chain of square roots and divisions is
   about as long as a block's work on the ports, and a second block gives the scheduler
   independent work. The same IEEE operations lane by lane as the compiler's loop, its
   multiply-adds with two products written out as that loop fused them (softgym_seed.h).
   No include guard, on purpose. */
/* softgym_rotvec_k32_acos(w, w_acos) in the lanes (softgym_rotvec_k32's operations lane by lane) */
#define SOFTGYM_FP_ROTVEC_K(w, w_acos, k) do { \
        SOFTGYM_FP_V w2_ = (w) * (w); \
        SOFTGYM_FP_V x16_ = SOFTGYM_FP_FMA((w), SOFTGYM_FP_SET(0.0625f), SOFTGYM_FP_SET(0.0625f)); \
        SOFTGYM_FP_V e_ = SOFTGYM_FP_FMA( \
            SOFTGYM_FP_FMA(SOFTGYM_FP_SET(SOFTGYM_RSQ_D3), (w), SOFTGYM_FP_SET(SOFTGYM_RSQ_D2)), \
            w2_, SOFTGYM_FP_FMA(SOFTGYM_FP_SET(SOFTGYM_RSQ_D1), (w), SOFTGYM_FP_SET(SOFTGYM_RSQ_D0))); \
        SOFTGYM_FP_V u_ = SOFTGYM_FP_FNMA(x16_, e_ * e_, SOFTGYM_FP_SET(0.5f)); \
        SOFTGYM_FP_V z_ = SOFTGYM_FP_FNMA(SOFTGYM_FP_SET(0.5f), (w), SOFTGYM_FP_SET(0.5f)); \
        SOFTGYM_FP_V z2_ = z_ * z_; \
        SOFTGYM_FP_V p_ = SOFTGYM_FP_FMA( \
            SOFTGYM_FP_FMA(SOFTGYM_FP_SET(SOFTGYM_ASIN_P4), z2_, SOFTGYM_FP_FMA( \
                SOFTGYM_FP_SET(SOFTGYM_ASIN_P3), z_, SOFTGYM_FP_SET(SOFTGYM_ASIN_P2))), \
            z2_, SOFTGYM_FP_FMA(SOFTGYM_FP_SET(SOFTGYM_ASIN_P1), z_, SOFTGYM_FP_SET(SOFTGYM_ASIN_P0))); \
        SOFTGYM_FP_V r_ = SOFTGYM_FP_PICK( \
            SOFTGYM_FP_CMP((w), SOFTGYM_FP_SET(w_acos), _CMP_LE_OQ), \
            SOFTGYM_FP_FMA(z_, p_, SOFTGYM_FP_SET(1.0f)), SOFTGYM_FP_SET(1.0f)); \
        k = SOFTGYM_FP_FMA(e_, u_, e_) * r_; \
    } while (0)
SOFTGYM_ALWAYS_INLINE int SOFTGYM_FP_NAME(
    Py_ssize_t li, float sa_rad, float w_acos, const double *p0_, const double *p1_,
    const double *p2_, const double *qw_, const double *n1_, const double *n2_,
    const double *n3_, const double *P0_, const double *len_, const double *sa_, float *o_P0,
    float *o_P1, float *o_P2, float *o_a1y, float *o_a1z, float *o_a2x, float *o_a2y, float *o_a2z,
    float *o_rw, float *o_ry, float *o_rz, float *o_fix)
{
    SOFTGYM_FP_V p0[2], p1[2], p2[2], qw[2], n1[2], n2[2], n3[2];
    SOFTGYM_FP_V inv_p0[2], yx[2], zx[2], ry_s[2], rz_s[2], rw_s[2], ln[2], lp[2];
    SOFTGYM_FP_V inv_s[2], ch[2], ry_l[2], rz_l[2], rw[2], ry[2], rz[2], k1[2], k2[2];
    SOFTGYM_FP_V tw[2], tx[2], ty[2], tz[2], w2[2];
    SOFTGYM_FP_M is_sa[2], zero[2], small[2], fix[2];
    const SOFTGYM_FP_V one = SOFTGYM_FP_SET(1.0f), nil = SOFTGYM_FP_SET(0.0f);
#define SOFTGYM_L (li + SOFTGYM_FP_LANES * k_)
    SOFTGYM_X2(p0[k_] = SOFTGYM_FP_LOAD(p0_ + SOFTGYM_L));
    SOFTGYM_X2(p1[k_] = SOFTGYM_FP_LOAD(p1_ + SOFTGYM_L));
    SOFTGYM_X2(p2[k_] = SOFTGYM_FP_LOAD(p2_ + SOFTGYM_L));
    SOFTGYM_X2(is_sa[k_] = SOFTGYM_FP_NONZERO(sa_, SOFTGYM_L));
    /* SOFTGYM_CHORD_FRAME */
    SOFTGYM_X2(zero[k_] = SOFTGYM_FP_CMP(p0[k_], nil, _CMP_EQ_OQ)
                          & SOFTGYM_FP_CMP(p1[k_], nil, _CMP_EQ_OQ)
                          & SOFTGYM_FP_CMP(p2[k_], nil, _CMP_EQ_OQ));
    SOFTGYM_X2(inv_p0[k_] = 1.0f / p0[k_]);
    SOFTGYM_X2(ln[k_] = SOFTGYM_FP_LOAD(len_ + SOFTGYM_L));
    SOFTGYM_X2(yx[k_] = p1[k_] * inv_p0[k_]);
    SOFTGYM_X2(zx[k_] = p2[k_] * inv_p0[k_]);
    SOFTGYM_X2(lp[k_] = ln[k_] + p0[k_]);
    SOFTGYM_X2(small[k_] = SOFTGYM_FP_CMP(yx[k_], SOFTGYM_FP_SET(sa_rad), _CMP_LT_OQ)
                           & SOFTGYM_FP_CMP(yx[k_], SOFTGYM_FP_SET(-sa_rad), _CMP_GT_OQ)
                           & SOFTGYM_FP_CMP(zx[k_], SOFTGYM_FP_SET(sa_rad), _CMP_LT_OQ)
                           & SOFTGYM_FP_CMP(zx[k_], SOFTGYM_FP_SET(-sa_rad), _CMP_GT_OQ));
    SOFTGYM_X2(inv_s[k_] = 1.0f / SOFTGYM_FP_SQRT(2.0f * ln[k_] * lp[k_]));
    SOFTGYM_X2(ry_s[k_] = 0.5f * zx[k_]);
    SOFTGYM_X2(rz_s[k_] = -0.5f * yx[k_]);
    SOFTGYM_X2(rw_s[k_] = SOFTGYM_FP_FMA(
                   SOFTGYM_FP_SET(0.5f),
                   SOFTGYM_FP_FNMA(rz_s[k_], rz_s[k_], -ry_s[k_] * ry_s[k_]), one));
    SOFTGYM_X2(qw[k_] = SOFTGYM_FP_LOAD(qw_ + SOFTGYM_L));
    SOFTGYM_X2(n1[k_] = SOFTGYM_FP_LOAD(n1_ + SOFTGYM_L));
    SOFTGYM_X2(ch[k_] = lp[k_] * inv_s[k_]);
    SOFTGYM_X2(ry_l[k_] = p2[k_] * inv_s[k_]);
    SOFTGYM_X2(rz_l[k_] = -p1[k_] * inv_s[k_]);
    /* fix: a large-angle link (not zero) whose chord points backwards */
    SOFTGYM_X2(fix[k_] = ~is_sa[k_] & ~zero[k_] & ~small[k_]
                         & SOFTGYM_FP_CMP(p0[k_], -0.5f * ln[k_], _CMP_LT_OQ));
    SOFTGYM_X2(rw[k_] = SOFTGYM_FP_PICK(zero[k_], one,
                                         SOFTGYM_FP_PICK(small[k_], rw_s[k_], ch[k_])));
    SOFTGYM_X2(ry[k_] = SOFTGYM_FP_PICK(zero[k_], nil,
                                         SOFTGYM_FP_PICK(small[k_], ry_s[k_], ry_l[k_])));
    SOFTGYM_X2(rz[k_] = SOFTGYM_FP_PICK(zero[k_], nil,
                                         SOFTGYM_FP_PICK(small[k_], rz_s[k_], rz_l[k_])));
    SOFTGYM_X2(n2[k_] = SOFTGYM_FP_LOAD(n2_ + SOFTGYM_L));
    SOFTGYM_X2(n3[k_] = SOFTGYM_FP_LOAD(n3_ + SOFTGYM_L));
    SOFTGYM_X2(SOFTGYM_FP_ROTVEC_K(rw[k_], w_acos, k1[k_]));
    SOFTGYM_X2(fix[k_] |= ~is_sa[k_] & ~zero[k_]
                          & SOFTGYM_FP_CMP(rw[k_], SOFTGYM_FP_SET(0.5f), _CMP_LT_OQ));
    /* SOFTGYM_TQ */
    SOFTGYM_X2(tw[k_] = SOFTGYM_FP_FNMA(rz[k_], n3[k_],
                                         SOFTGYM_FP_FNMA(ry[k_], n2[k_], rw[k_] * qw[k_])));
    SOFTGYM_X2(tx[k_] = SOFTGYM_FP_FNMA(rz[k_], n2[k_],
                                         SOFTGYM_FP_FMA(ry[k_], n3[k_], rw[k_] * n1[k_])));
    SOFTGYM_X2(ty[k_] = SOFTGYM_FP_FMA(rz[k_], n1[k_],
                                        SOFTGYM_FP_FMA(ry[k_], qw[k_], rw[k_] * n2[k_])));
    SOFTGYM_X2(tz[k_] = SOFTGYM_FP_FMA(rz[k_], qw[k_],
                                        SOFTGYM_FP_FNMA(ry[k_], n1[k_], rw[k_] * n3[k_])));
    SOFTGYM_X2(w2[k_] = SOFTGYM_FP_PICK(is_sa[k_], qw[k_], tw[k_]));
    SOFTGYM_X2(SOFTGYM_FP_ROTVEC_K(w2[k_], w_acos, k2[k_]));
    SOFTGYM_X2(fix[k_] |= SOFTGYM_FP_CMP(w2[k_], SOFTGYM_FP_SET(0.5f), _CMP_LT_OQ));
    /* the outputs, as softgym_seed_frames32_impl's */
#define SOFTGYM_FP_OUT(row, v) SOFTGYM_X2(SOFTGYM_FP_STORE((row) + SOFTGYM_L, (v)))
    SOFTGYM_FP_OUT(o_P0, SOFTGYM_FP_LOAD(P0_ + SOFTGYM_L));
    SOFTGYM_FP_OUT(o_P1, SOFTGYM_FP_PICK(is_sa[k_], p1[k_], nil));
    SOFTGYM_FP_OUT(o_P2, SOFTGYM_FP_PICK(is_sa[k_], p2[k_], nil));
    SOFTGYM_FP_OUT(o_a1y, SOFTGYM_FP_PICK(is_sa[k_] | zero[k_], nil, ry[k_] * k1[k_]));
    SOFTGYM_FP_OUT(o_a1z, SOFTGYM_FP_PICK(is_sa[k_] | zero[k_], nil, rz[k_] * k1[k_]));
    SOFTGYM_FP_OUT(o_a2x, SOFTGYM_FP_PICK(is_sa[k_], n1[k_], tx[k_]) * k2[k_]);
    SOFTGYM_FP_OUT(o_a2y, SOFTGYM_FP_PICK(is_sa[k_], n2[k_], ty[k_]) * k2[k_]);
    SOFTGYM_FP_OUT(o_a2z, SOFTGYM_FP_PICK(is_sa[k_], n3[k_], tz[k_]) * k2[k_]);
    SOFTGYM_FP_OUT(o_rw, SOFTGYM_FP_PICK(is_sa[k_], one, rw[k_]));
    SOFTGYM_FP_OUT(o_ry, SOFTGYM_FP_PICK(is_sa[k_], nil, ry[k_]));
    SOFTGYM_FP_OUT(o_rz, SOFTGYM_FP_PICK(is_sa[k_], nil, rz[k_]));
    SOFTGYM_FP_OUT(o_fix, SOFTGYM_FP_PICK(fix[k_], one, nil));
#undef SOFTGYM_FP_OUT
#undef SOFTGYM_L
    return SOFTGYM_FP_ANY(fix[0] | fix[1]);
}
#undef SOFTGYM_FP_ROTVEC_K
