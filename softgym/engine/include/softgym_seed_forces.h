/* The forces pass of links_seed, one definition for both precisions:
   softgym_seed.h includes this file twice, with SOFTGYM_FT (the arithmetic's
   type: double, or float for SimConfig.link_precision = "single"),
   SOFTGYM_FNAME (the function's name), SOFTGYM_FIN_STRIDE (its input rows' stride),
   SOFTGYM_FOUT_T and SOFTGYM_FOUT_STRIDE (its output rows' type and stride),
   SOFTGYM_FPICK (c ? a : b in that
   type) and SOFTGYM_FMASK (the type of the lanes' conditions: as wide as
   SOFTGYM_FT) defined. No include guard, on purpose.

   Each link's forces and moments in the bond frame from its bond-frame
   quantities (stiffness; the seed's damping from the link's memory of the
   last step, skipped on a mode-change step), turned back by rq^-1 for a
   large-angle link, without branches so the loop vectorises. Inputs: the
   frames' rows in + k SOFTGYM_FIN_STRIDE (P0, P1, P2, a1y, a1z, a2x, a2y, a2z, rw, ry,
   rz), the
   mode (sa_: 1.0 small angle), mode-change (chg_) and voxel-2-takes-minus-F1 (neg2_,
   the scratch's row 23) rows, the link
   constants (ka_, kt_, kb_; cs_: the 8 rows of c_seed, stride n) and memory
   (link_last, 9 rows of stride n). Outputs (rows of SOFTGYM_FOUT_T: the arithmetic's
   type, for the scatter, which widens floats to doubles as it loads them)
   what the scatter turns to the world and adds: voxel 1's force, voxel 2's
   damped force (read only where voxel 2 does not take -F1: two materials,
   no mode change; the scatter subtracts voxel 1's turned force otherwise),
   voxel 1's and voxel 2's moments negated (the seed subtracts them; x - y
   is x + (-y) exactly, and a rotation of -v is exactly minus the rotation
   of v). Updates the memory unless the mode changed. In double, the same
   operations as the seed's scalar code. */
#define SOFTGYM_FCAT2(a, b) a##b
#define SOFTGYM_FCAT(a, b) SOFTGYM_FCAT2(a, b)
#define SOFTGYM_FPARAMS \
    Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, SOFTGYM_FT L, SOFTGYM_FT bz, SOFTGYM_FT bzh, \
    SOFTGYM_FT inv_dt, const SOFTGYM_FT *in, Py_ssize_t in_stride, const double *sa_, \
    const double *chg_, const double *neg2_, \
    const SOFTGYM_FT *ka_, const SOFTGYM_FT *kt_, const SOFTGYM_FT *kb_, const SOFTGYM_FT *cs_, \
    SOFTGYM_FT *link_last, SOFTGYM_FOUT_T *out
/* all_small: every link of lo..hi is in small-angle mode (softgym_all_nonzero), so the
   large-angle turn by rq^-1, selected away in every lane, is not computed; all_neg2: every
   link's voxel 2 takes -F1 (row 23, neg2_), so voxel 2's own force is neither computed nor
   stored (the scatter does not read it there) */
SOFTGYM_ALWAYS_INLINE void SOFTGYM_FCAT(SOFTGYM_FNAME, _impl)(const int all_small,
                                                             const int all_neg2,
                                                             SOFTGYM_FPARAMS)
{
    typedef SOFTGYM_FT T;
    /* the input rows' stride: in_stride (the scratch's) in double, the chunk's float rows'
       (SOFTGYM_CHUNK_FSTRIDE, a compile-time constant) in float */
    const Py_ssize_t is = SOFTGYM_FIN_STRIDE;
    const T *P0_ = in, *P1_ = in + is, *P2_ = in + 2 * is, *a1y_ = in + 3 * is;
    const T *a1z_ = in + 4 * is, *a2x_ = in + 5 * is, *a2y_ = in + 6 * is;
    const T *a2z_ = in + 7 * is, *rw_ = in + 8 * is, *ry_ = in + 9 * is, *rz_ = in + 10 * is;
    /* the output rows from one pointer at a compile-time stride (one register, where 12
       row pointers spilled) */
    const Py_ssize_t os = SOFTGYM_FOUT_STRIDE;
    typedef SOFTGYM_FOUT_T OT;
    OT *o0 = out, *o1 = out + os, *o2 = out + 2 * os, *o3 = out + 3 * os;
    OT *o4 = out + 4 * os, *o5 = out + 5 * os, *o6 = out + 6 * os, *o7 = out + 7 * os;
    OT *o8 = out + 8 * os, *o9 = out + 9 * os, *o10 = out + 10 * os, *o11 = out + 11 * os;
    const T two = (T)2.0, half = (T)0.5, zero = (T)0.0;
    Py_ssize_t li;
    SOFTGYM_IVDEP
    for (li = lo; li < hi; li++) {
        SOFTGYM_FMASK sa = all_small ? 1 : SOFTGYM_FCOND(sa_, li);
        SOFTGYM_FMASK changed = SOFTGYM_FCOND(chg_, li);
        T P0 = P0_[li], P1 = P1_[li], P2 = P2_[li];
        T a1x = zero, a1y = a1y_[li], a1z = a1z_[li];
        T a2x = a2x_[li], a2y = a2y_[li], a2z = a2z_[li];
        T rw = rw_[li], ry = ry_[li], rz = rz_[li];
        T ka = ka_[li], kt = kt_[li], kb = kb_[li];
        T b2 = half * ka * L;
        T f1x = ka * P0;
        T f1y = ka * P1 - b2 * (a1z + a2z);
        T f1z = ka * P2 + b2 * (a1y + a2y);
        T m1x = kt * (a1x - a2x);
        T m1y = b2 * P2 + kb * (two * a1y + a2y);
        T m1z = -b2 * P1 + kb * (two * a1z + a2z);
        T m2x = -m1x;
        T m2y = b2 * P2 + kb * (a1y + two * a2y);
        T m2z = -b2 * P1 + kb * (a1z + two * a2z);
        /* damping: rates from the memory of the last step */
        T l0 = link_last[li], l1 = link_last[n + li], l2 = link_last[2 * n + li];
        T l3 = link_last[3 * n + li], l4 = link_last[4 * n + li];
        T l5 = link_last[5 * n + li], l6 = link_last[6 * n + li];
        T l7 = link_last[7 * n + li], l8 = link_last[8 * n + li];
        T vx = (P0 - l0) * inv_dt, vy = (P1 - l1) * inv_dt, vz = (P2 - l2) * inv_dt;
        T ra1x = (a1x - l3) * inv_dt, ra1y = (a1y - l4) * inv_dt;
        T ra1z = (a1z - l5) * inv_dt, ra2x = (a2x - l6) * inv_dt;
        T ra2y = (a2y - l7) * inv_dt, ra2z = (a2z - l8) * inv_dt;
        /* the memory updated at once (the old values' registers free for what follows) */
        link_last[li] = SOFTGYM_FPICK(changed, l0, P0);
        link_last[n + li] = SOFTGYM_FPICK(changed, l1, P1);
        link_last[2 * n + li] = SOFTGYM_FPICK(changed, l2, P2);
        link_last[3 * n + li] = SOFTGYM_FPICK(changed, l3, a1x);
        link_last[4 * n + li] = SOFTGYM_FPICK(changed, l4, a1y);
        link_last[5 * n + li] = SOFTGYM_FPICK(changed, l5, a1z);
        link_last[6 * n + li] = SOFTGYM_FPICK(changed, l6, a2x);
        link_last[7 * n + li] = SOFTGYM_FPICK(changed, l7, a2y);
        link_last[8 * n + li] = SOFTGYM_FPICK(changed, l8, a2z);
        T ca = cs_[li], cb2 = cs_[n + li];
        T ca2 = cs_[2 * n + li], cb3 = cs_[3 * n + li];
        T d1x = f1x + bz * (ca * vx);
        T d1y = f1y + bz * (ca * vy - cb2 * (ra1z + ra2z));
        T d1z = f1z + bz * (ca * vz + cb2 * (ra1y + ra2y));
        T e1x = m1x + bzh * (-ca2 * (ra2x - ra1x));
        T e1y = m1y + bzh * (cb2 * vz + cb3 * (two * ra1y + ra2y));
        T e1z = m1z + bzh * (-cb2 * vy + cb3 * (two * ra1z + ra2z));
        ca = cs_[4 * n + li];
        cb2 = cs_[5 * n + li];
        ca2 = cs_[6 * n + li];
        cb3 = cs_[7 * n + li];
        T f2x = -f1x + bz * (-ca * vx);
        T f2y = -f1y + bz * (-ca * vy + cb2 * (ra1z + ra2z));
        T f2z = -f1z + bz * (-ca * vz - cb2 * (ra1y + ra2y));
        T e2x = m2x + bzh * (ca2 * (ra2x - ra1x));
        T e2y = m2y + bzh * (cb2 * vz + cb3 * (ra1y + two * ra2y));
        T e2z = m2z + bzh * (-cb2 * vy + cb3 * (ra1z + two * ra2z));
        /* (x, y, z) stays where c holds, else becomes (dx, dy, dz) */
#define SOFTGYM_KEEP3(c, x, y, z, dx, dy, dz) do { \
            x = SOFTGYM_FPICK(c, x, dx); \
            y = SOFTGYM_FPICK(c, y, dy); \
            z = SOFTGYM_FPICK(c, z, dz); \
        } while (0)
        SOFTGYM_KEEP3(changed, f1x, f1y, f1z, d1x, d1y, d1z);
        SOFTGYM_KEEP3(changed, m1x, m1y, m1z, e1x, e1y, e1z);
        SOFTGYM_KEEP3(changed, m2x, m2y, m2z, e2x, e2y, e2z);
        /* large angle: G = RQ^T v rotates by rq^-1 (RQ the matrix of rq,
           normalised by |rq|^2: the small-ratio rq is not exactly unit) */
        T n2q = rw * rw + ry * ry + rz * rz;
        T r0 = n2q - two * (ry * ry + rz * rz);
        T r1 = two * (rw * rz);
        T r2 = two * (rw * ry);
        T r4 = n2q - two * (rz * rz);
        T r5 = two * (ry * rz);
        T r8 = n2q - two * (ry * ry);
#define SOFTGYM_UNTURN(x, y, z) do { \
            T gx_ = r0 * x + r1 * y - r2 * z; \
            T gy_ = -r1 * x + r4 * y + r5 * z; \
            T gz_ = r2 * x + r5 * y + r8 * z; \
            SOFTGYM_KEEP3(sa, x, y, z, gx_, gy_, gz_); \
        } while (0)
        SOFTGYM_UNTURN(f1x, f1y, f1z);
        SOFTGYM_UNTURN(m1x, m1y, m1z);
        SOFTGYM_UNTURN(m2x, m2y, m2z);
        if (!all_neg2)
            SOFTGYM_UNTURN(f2x, f2y, f2z);
#undef SOFTGYM_UNTURN
#undef SOFTGYM_KEEP3
        o0[li] = f1x;
        o1[li] = f1y;
        o2[li] = f1z;
        if (!all_neg2) {
            o3[li] = f2x;
            o4[li] = f2y;
            o5[li] = f2z;
        }
        o6[li] = -m1x;
        o7[li] = -m1y;
        o8[li] = -m1z;
        o9[li] = -m2x;
        o10[li] = -m2y;
        o11[li] = -m2z;
    }
}

/* the four copies, each a function of its own: inlined into one function, the mixed
   copy's loop spilled 81 registers a 16-link iteration against 35 (port_bound.py) */
#define SOFTGYM_FARGS lo, hi, n, L, bz, bzh, inv_dt, in, in_stride, sa_, chg_, neg2_, ka_, kt_, \
    kb_, cs_, link_last, out
#if defined(SOFTGYM_FBLOCK)
/* where the instantiation has one (softgym_seed.h: the float pass with AVX-512 or AVX2), the
   blocks of SOFTGYM_FB_LANES links from lo by SOFTGYM_FBLOCK, the rest by the loop */
#define SOFTGYM_FBLOCKS(s, g) \
    for (; lo + SOFTGYM_FB_LANES <= hi; lo += SOFTGYM_FB_LANES) \
        SOFTGYM_FBLOCK(s, g, lo, n, L, bz, bzh, inv_dt, in, sa_, chg_, ka_, kt_, kb_, cs_, \
                    link_last, out)
#else
#define SOFTGYM_FBLOCKS(s, g) (void)0
#endif
#define SOFTGYM_FCOPY(suffix, s, g) \
    SOFTGYM_NOINLINE void SOFTGYM_FCAT(SOFTGYM_FNAME, suffix)(SOFTGYM_FPARAMS) \
    { \
        SOFTGYM_FBLOCKS(s, g); \
        SOFTGYM_FCAT(SOFTGYM_FNAME, _impl)(s, g, SOFTGYM_FARGS); \
    }
SOFTGYM_FCOPY(_mixed, 0, 0)
SOFTGYM_FCOPY(_small, 1, 0)
SOFTGYM_FCOPY(_neg2, 0, 1)
SOFTGYM_FCOPY(_small_neg2, 1, 1)
#undef SOFTGYM_FCOPY
#undef SOFTGYM_FBLOCKS
/* links lo..hi (one chunk), without the large-angle turn where all of them are in
   small-angle mode, without voxel 2's own force where all of them give it -F1 */
static void SOFTGYM_FNAME(SOFTGYM_FPARAMS)
{
    const int all_small = softgym_all_nonzero(sa_, lo, hi);
    const int all_neg2 = softgym_all_nonzero(neg2_, lo, hi);
    if (all_small && all_neg2)
        SOFTGYM_FCAT(SOFTGYM_FNAME, _small_neg2)(SOFTGYM_FARGS);
    else if (all_small)
        SOFTGYM_FCAT(SOFTGYM_FNAME, _small)(SOFTGYM_FARGS);
    else if (all_neg2)
        SOFTGYM_FCAT(SOFTGYM_FNAME, _neg2)(SOFTGYM_FARGS);
    else
        SOFTGYM_FCAT(SOFTGYM_FNAME, _mixed)(SOFTGYM_FARGS);
}
#undef SOFTGYM_FARGS
#undef SOFTGYM_FPARAMS
#undef SOFTGYM_FCAT
#undef SOFTGYM_FCAT2
