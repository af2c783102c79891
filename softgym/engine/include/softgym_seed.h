/* The seed model's vectorised link and voxel passes (softgym/engine/_seed.pyx
   calls them; declared for Cython in _seed.pyx's `cdef extern from`).
   The same operations as the seed's scalar code; compiled with
   -ffp-contract=fast, so builds with FMA instructions fuse a * b + c (setup.py).
   Py_ssize_t comes from Python.h, which Cython
   includes first. */
#ifndef SOFTGYM_SEED_H
#define SOFTGYM_SEED_H

#include <math.h>
#include <stdint.h>
#include "softgym_restrict.h"
#include "softgym_simd.h"

/* links_seed (_seed.pyx) runs its passes over chunks of SOFTGYM_CHUNK_LINKS links (a
   multiple of 16: a chunk's rows of the scratch start on cache lines), and the forces
   pass leaves a chunk's forces and moments in 12 rows of their own, SOFTGYM_CHUNK_STRIDE
   doubles apart (a compile-time constant: the scatter addresses all 12 from one pointer,
   where a run-time stride took a register per row and spilled; 8 more than the chunk, so
   that consecutive rows start on different cache sets). 64 links: with the rotation rows
   below, chunks of 128 overflowed the L1 cache (1.6 % slower on an Intel Xeon) */
#define SOFTGYM_CHUNK_LINKS 64
#define SOFTGYM_CHUNK_STRIDE (SOFTGYM_CHUNK_LINKS + 8)
#define SOFTGYM_CHUNK_ROWS 21
/* rows 12-20 of those: voxel 1's rotation matrix, row-major, from the geometry (AVX-512
   builds: softgym_seed_scatter8 turns the forces with it) */
#define SOFTGYM_SEED_R_ROWS 12
/* the single-precision frames pass leaves a chunk's 12 float rows (P0, P1, P2, a1y, a1z,
   a2x, a2y, a2z, rw, ry, rz, fix) SOFTGYM_CHUNK_FSTRIDE floats apart (each row on a cache
   line of its own, consecutive rows on different sets), so the frames and forces passes
   address them from one pointer: with a pointer per row, the forces pass's 40-odd rows
   outnumbered the general registers and spilled; rows 12-23 (from SOFTGYM_CHUNK_FOUT) are
   the single-precision forces pass's forces and moments, in the order of the double rows
   0-11 of SOFTGYM_CHUNK_STRIDE (the scatter widens them to doubles as it loads them: a
   float is exactly a double, and the forces pass, which had widened its 16 lanes a row
   into two stores of 8 doubles, now stores them as they are) */
#define SOFTGYM_CHUNK_FSTRIDE (SOFTGYM_CHUNK_LINKS + 16)
#define SOFTGYM_CHUNK_FROWS 33
#define SOFTGYM_CHUNK_FOUT 12
/* rows 24-32 of the float rows: voxel 1's rotation matrix, row-major, rounded to float by
   the geometry (single-precision links: softgym_seed_push32 turns the forces with it) */
#define SOFTGYM_CHUNK_FR 24

/* The first pass of links_seed (_seed.pyx): links lo..hi (all along axis ax, a
   compile-time constant in each copy) measured in the bond frame, without
   branches so the loop vectorises; rows of o (stride n): 0-2 the relative
   position p, 3-6 voxel 2's orientation relative to voxel 1 (q1* q2 = (qw,
   n)), both in the bond frame (voxel 1's frame turned by the proper
   rotation P that takes the link axis onto +x, the seed's ToXDirBond:
   (x, y, z) -> (x, y, z), (y, -x, z), (z, y, -x) for ax 0, 1, 2); 7 the
   nominal length, 8 the chord length, 9 the transverse ratio. Component c
   of a bond-frame vector is s_c times local component a_c (s = +-1: exact).
   Voxel 1's rotation matrix is computed in the lanes from its quaternion
   (softgym_quat_matrix, as the voxel update stores it): the same bits as
   the stored matrix, and 9 fewer gathered loads a link. */
/* the axis constants of the geometry of links along ax: the components a0, a1, a2 of
   the bond frame's axes in voxel 1's frame and their signs s1, s2 (the bond-frame
   vector part of a relative quaternion is (q[a0], s1 q[a1], s2 q[a2]): a permutation
   and exact sign changes) */
#define SOFTGYM_SEED_GEOM_AXIS(ax) \
    const int a0 = (ax), a1 = (ax) == 1 ? 0 : 1, a2 = (ax) == 2 ? 0 : 2; \
    const double s1 = (ax) == 1 ? -1.0 : 1.0, s2 = (ax) == 2 ? -1.0 : 1.0
/* the geometry's output rows 0-9 of the scratch o (row stride n) */
#define SOFTGYM_SEED_GEOM_OUT(o, n) \
    double *SOFTGYM_RESTRICT o_p0 = (o), *SOFTGYM_RESTRICT o_p1 = (o) + (n); \
    double *SOFTGYM_RESTRICT o_p2 = (o) + 2 * (n), *SOFTGYM_RESTRICT o_qw = (o) + 3 * (n); \
    double *SOFTGYM_RESTRICT o_n1 = (o) + 4 * (n), *SOFTGYM_RESTRICT o_n2 = (o) + 5 * (n); \
    double *SOFTGYM_RESTRICT o_n3 = (o) + 6 * (n), *SOFTGYM_RESTRICT o_nom = (o) + 7 * (n); \
    double *SOFTGYM_RESTRICT o_len = (o) + 8 * (n), *SOFTGYM_RESTRICT o_st = (o) + 9 * (n)
/* v (a double, or a vector of them) rounded to float and stored at row[li] (the geometry's
   float rows of voxel 1's rotation) */
#define SOFTGYM_PUTF1(row, li, v) ((row)[li] = (float)(v))
/* (SOFTGYM_VPUTF, the same for vectors: softgym_simd.h) */
/* one link's geometry into column li of those rows, from voxel 2's position relative
   to voxel 1's (dx, dy, dz), their orientations (w, x, y, z), (wj, xj, yj, zj) and
   sizes si, sj (the axis constants and output rows in scope); the engine's pass
   below and benchmarks/dense_links_probe.c share it */
#define SOFTGYM_SEED_GEOM_LINK(li, dx, dy, dz, w, x, y, z, wj, xj, yj, zj, si, sj) \
    SOFTGYM_SEED_GEOM_LINK_T(double, sqrt, fabs, SOFTGYM_PUT1, SOFTGYM_PUTF1, li, dx, dy, dz, w, \
                             x, y, z, wj, xj, yj, zj, si, sj, (double *)0, (float *)0, 7, (void)0)
/* the same for any arithmetic type T (double, or a vector of doubles: then links li ..
   li + lanes - 1 at once, SQRT and FABS T's square root and absolute value, PUT(row,
   li, v) storing v at row + li); in builds whose scatter reads them (SOFTGYM_SEED_R_USED)
   and rr not NULL, also voxel 1's rotation matrix, element k in row rr + k
   SOFTGYM_CHUNK_STRIDE (the chunk's rows that softgym_seed_scatter8 turns the forces
   with). KEEPLS: bit 0 stores the chord length (row 8), bit 1 the transverse ratio (row
   9), bit 2 the nominal length (row 7), which only the modes pass and the double-precision
   frames pass (rows 7 and 8) read; AFTER: a statement run with the link's values in scope
   (geo_p0, geo_qw, geo_nom, geo_len, geo_st), where the geometry's vector loop decides
   their modes (softgym_seed_modes8v) */
#define SOFTGYM_SEED_GEOM_LINK_T(T, SQRT, FABS, PUT, PUTF, li, dx, dy, dz, w, x, y, z, wj, xj, \
                                 yj, zj, si, sj, rr, rf, KEEPLS, AFTER) do { \
        T geo_R[9]; \
        SOFTGYM_QUAT_MATRIX(w, x, y, z, geo_R); \
        if ((rf) != 0) { \
            for (int geo_k = 0; geo_k < 9; geo_k++) \
                PUTF((rf) + geo_k * SOFTGYM_CHUNK_FSTRIDE, li, geo_R[geo_k]); \
        } else if (SOFTGYM_SEED_R_USED && (rr) != 0) { \
            for (int geo_k = 0; geo_k < 9; geo_k++) \
                PUT((rr) + geo_k * SOFTGYM_CHUNK_STRIDE, li, geo_R[geo_k]); \
        } \
        /* relative position in voxel 1's frame (column a of its rotation . d) */ \
        T geo_p0 = (((geo_R[a0] * (dx)) + (geo_R[3 + a0] * (dy))) + (geo_R[6 + a0] * (dz))); \
        T geo_p1 = (s1 * (((geo_R[a1] * (dx)) + (geo_R[3 + a1] * (dy))) + (geo_R[6 + a1] * (dz)))); \
        T geo_p2 = (s2 * (((geo_R[a2] * (dx)) + (geo_R[3 + a2] * (dy))) + (geo_R[6 + a2] * (dz)))); \
        T geo_qw = (((((w) * (wj)) + ((x) * (xj))) + ((y) * (yj))) + ((z) * (zj))); \
        T geo_qx = (((((w) * (xj)) - ((x) * (wj))) - ((y) * (zj))) + ((z) * (yj))); \
        T geo_qy = (((((w) * (yj)) + ((x) * (zj))) - ((y) * (wj))) - ((z) * (xj))); \
        T geo_qz = (((((w) * (zj)) - ((x) * (yj))) + ((y) * (xj))) - ((z) * (wj))); \
        PUT(o_p0, li, geo_p0); \
        PUT(o_p1, li, geo_p1); \
        PUT(o_p2, li, geo_p2); \
        PUT(o_qw, li, geo_qw); \
        T geo_qv[3] = {geo_qx, geo_qy, geo_qz}; \
        PUT(o_n1, li, geo_qv[a0]); \
        PUT(o_n2, li, (s1 * geo_qv[a1])); \
        PUT(o_n3, li, (s2 * geo_qv[a2])); \
        T geo_nom = (0.5 * ((si) + (sj))); \
        T geo_len = SQRT(((((dx) * (dx)) + ((dy) * (dy))) + ((dz) * (dz)))); \
        T geo_st = ((FABS(geo_p2) + FABS(geo_p1)) / geo_p0); \
        if ((KEEPLS) & 4) \
            PUT(o_nom, li, geo_nom); \
        if ((KEEPLS) & 1) \
            PUT(o_len, li, geo_len); \
        if ((KEEPLS) & 2) \
            PUT(o_st, li, geo_st); \
        AFTER; \
    } while (0)
#if defined(SOFTGYM_VLANES)
/* The geometry's loads in vector code of our own. GCC's vectoriser loaded the 16
   numbers a link reads from its two voxels one by one, and with 16 indices per 8 links
   it parked them in vector registers and spilled (objdump: about 34 instructions a link
   before any arithmetic). Here each voxel's quaternion is two 16-byte loads and its
   position one (x, y) load and z, turned into rows of 4 links by unpacks
   (SOFTGYM_GATHER_PAIRS), 8 links with AVX-512; the arithmetic is
   SOFTGYM_SEED_GEOM_LINK_T's, lane by lane: the same bits. */
/* voxels idx[0..3]: position (x, y, z), quaternion (w, qx, qy, qz) and size as rows of 4 */
static inline void softgym_seed_gather4(const Py_ssize_t *idx, const double *pos,
                                        const double *quat, const double *scale, softgym_m4 *r)
{
    const double *pa = pos + 3 * idx[0], *pb = pos + 3 * idx[1];
    const double *pc = pos + 3 * idx[2], *pd = pos + 3 * idx[3];
    const double *qa = quat + 4 * idx[0], *qb = quat + 4 * idx[1];
    const double *qc = quat + 4 * idx[2], *qd = quat + 4 * idx[3];
    SOFTGYM_GATHER_PAIRS(pa, pb, pc, pd, 0, r[0], r[1]);
    r[2] = SOFTGYM_M4SET(pa[2], pb[2], pc[2], pd[2]);
    SOFTGYM_GATHER_PAIRS(qa, qb, qc, qd, 0, r[3], r[4]);
    SOFTGYM_GATHER_PAIRS(qa, qb, qc, qd, 2, r[5], r[6]);
    r[7] = SOFTGYM_M4SET(scale[idx[0]], scale[idx[1]], scale[idx[2]], scale[idx[3]]);
}
/* the same for SOFTGYM_VLANES voxels, as vectors */
static inline void softgym_seed_gather(const Py_ssize_t *idx, const double *pos,
                                       const double *quat, const double *scale, softgym_vd *r)
{
    softgym_m4 a[8];
    softgym_seed_gather4(idx, pos, quat, scale, a);
#if SOFTGYM_VLANES == 8
    softgym_m4 b[8];
    softgym_seed_gather4(idx + 4, pos, quat, scale, b);
    SOFTGYM_VJOIN(r, a, b, 8);
#else
    SOFTGYM_VJOIN(r, a, a, 8);
#endif
}
#if SOFTGYM_VLANES == 8
/* the same for the 8 consecutive voxels v .. v + 7, from the voxels' rows vr (no gather,
   no transpose: SOFTGYM_VOXEL_ROWS, vn apart) */
static inline void softgym_seed_rows8(Py_ssize_t v, const double *vr, Py_ssize_t vn,
                                      const double *scale, softgym_vd *r)
{
    for (int k = 0; k < 3; k++)
        r[k] = softgym_v8_load(vr + (SOFTGYM_ROW_POS + k) * vn + v);
    for (int k = 0; k < 4; k++)
        r[3 + k] = softgym_v8_load(vr + (SOFTGYM_ROW_QUAT + k) * vn + v);
    memcpy(&r[7], scale + v, sizeof r[7]);
}
/* the same for any 8 voxels idx[0..7], gathered from the voxels' rows (the seed step's
   state in SOFTGYM_STATE_ROWS builds: the records are not up to date during it) */
static inline void softgym_seed_gather_rows(const Py_ssize_t *idx, const double *vr,
                                            Py_ssize_t vn, const double *scale, softgym_vd *r)
{
    __m512i ix = _mm512_loadu_si512((const void *)idx);
    for (int k = 0; k < 3; k++)
        r[k] = (softgym_vd)_mm512_i64gather_pd(ix, vr + (SOFTGYM_ROW_POS + k) * vn, 8);
    for (int k = 0; k < 4; k++)
        r[3 + k] = (softgym_vd)_mm512_i64gather_pd(ix, vr + (SOFTGYM_ROW_QUAT + k) * vn, 8);
    r[7] = (softgym_vd)_mm512_i64gather_pd(ix, scale, 8);
}
/* links whose voxels all lie in the 16 voxels from voxel 1 of the first (a[0]:
   softgym_window8_index): those 16 voxels' records as rows, each link's voxels picked
   from them by a two-source permute. 0 when they do not fit. */
static inline int softgym_seed_window8(const Py_ssize_t *a, const Py_ssize_t *b,
                                       Py_ssize_t vend, const double *vr, Py_ssize_t vn,
                                       const double *scale, softgym_vd *gi, softgym_vd *gj)
{
    Py_ssize_t base = a[0];
    __m512i ia, ib;
    if (!softgym_window8_index(a, b, vend, &ia, &ib))
        return 0;
    softgym_vd lo[8], hi[8];
    softgym_seed_rows8(base, vr, vn, scale, lo);
    softgym_seed_rows8(base + 8, vr, vn, scale, hi);
    for (int k = 0; k < 8; k++) {
        gi[k] = (softgym_vd)_mm512_permutex2var_pd((__m512d)lo[k], ia, (__m512d)hi[k]);
        gj[k] = (softgym_vd)_mm512_permutex2var_pd((__m512d)lo[k], ib, (__m512d)hi[k]);
    }
    return 1;
}
#endif
#endif
/* The modes pass's parts (softgym_seed_modes, below, which documents it), here so that
   the geometry's vector loop can decide its blocks' modes while their rows are in
   registers (softgym_seed_geom_modes) */
/* the modes pass's thresholds and per-link state (softgym_seed_modes's arguments) */
typedef struct {
    double max_ext, sa_w, sah_w, st_in, ex_in, st_out, ex_out;
    long long *link_sa;
    const long long *homog;
    int keep_len;  /* rows 7 and 8 (nominal and chord length) are read after the modes (the
                      double-precision frames) */
} softgym_modes_args;
/* the loop of softgym_seed_modes without the strain check's stop: links lo..hi's modes and
   rows; whether any of them is strained (or NaN) */
static inline long long softgym_seed_modes_loop(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                                const softgym_modes_args *m, double *o)
{
    const double max_ext = m->max_ext, sa_w = m->sa_w, sah_w = m->sah_w, st_in = m->st_in;
    const double ex_in = m->ex_in, st_out = m->st_out, ex_out = m->ex_out;
    long long *link_sa = m->link_sa;
    const long long *homog = m->homog;
    Py_ssize_t li;
    long long bad = 0;
    SOFTGYM_IVDEP
    for (li = lo; li < hi; li++) {
        double p0 = o[li], qw = o[3 * n + li], nom = o[7 * n + li];
        double len = o[8 * n + li], st = o[9 * n + li];
        double ex = p0 / nom;
        long long sa = link_sa[li] != 0;
        long long enter = (sa == 0) & (qw > sa_w) & (st < st_in) & (ex < ex_in);
        long long leave = sa & (!(qw > sah_w) | (st > st_out) | (ex > ex_out));
        long long ch = enter | leave;
        long long s2 = sa ^ ch;
        double P0 = softgym_pick(s2, p0 - nom, len - nom);
        o[10 * n + li] = P0;
        link_sa[li] = s2;
        o[9 * n + li] = softgym_pick(s2, 1.0, 0.0);
        o[22 * n + li] = softgym_pick(ch, 1.0, 0.0);
        o[23 * n + li] = softgym_pick(ch | (homog[li] != 0), 1.0, 0.0);
        bad |= !(fabs(P0) <= max_ext);
    }
    return bad;
}
/* the strain check after the loop (bad: its result): hi, or the first strained link, the
   links after it given back their old mode (old = new xor changed), as in the seed's
   scalar loop, which stops there; row 10 holds each link's displacement P0 */
static inline Py_ssize_t softgym_seed_modes_end(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                                double max_ext, long long bad,
                                                long long *link_sa, const double *o)
{
    Py_ssize_t li;
    if (!bad)
        return hi;
    for (li = lo; li < hi; li++)
        if (!(fabs(o[10 * n + li]) <= max_ext))
            break;
    for (Py_ssize_t k = li + 1; k < hi; k++)
        link_sa[k] = link_sa[k] ^ (o[22 * n + k] != 0.0);
    return li;
}
#if defined(__AVX512F__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_MODES8 1
/* softgym_seed_modes_loop for the 8 links li..li + 7 in the lanes of AVX-512 (o + li on a
   cache line, but for a run too short for its peel: unaligned stores), from the
   geometry's values of their rows 0, 3, 7, 8 and 9 (p0, qw, nom, len, st) in registers:
   the same IEEE operations (a division, subtractions, ordered compares); returns the
   lanes that are strained (or NaN) */
SOFTGYM_ALWAYS_INLINE __mmask8 softgym_seed_modes8v(Py_ssize_t li, Py_ssize_t n, __m512d p0,
                                                    __m512d qw, __m512d nom, __m512d len,
                                                    __m512d st, const softgym_modes_args *m,
                                                    double *o)
{
    const double max_ext = m->max_ext, sa_w = m->sa_w, sah_w = m->sah_w, st_in = m->st_in;
    const double ex_in = m->ex_in, st_out = m->st_out, ex_out = m->ex_out;
    long long *link_sa = m->link_sa;
    const long long *homog = m->homog;
    const __m512d ex = _mm512_div_pd(p0, nom);
    const __m512i zero = _mm512_setzero_si512();
    const __mmask8 sa = _mm512_cmpneq_epi64_mask(_mm512_loadu_si512((const void *)(link_sa + li)),
                                                 zero);
    const __mmask8 enter = (__mmask8)~sa
                           & _mm512_cmp_pd_mask(qw, _mm512_set1_pd(sa_w), _CMP_GT_OQ)
                           & _mm512_cmp_pd_mask(st, _mm512_set1_pd(st_in), _CMP_LT_OQ)
                           & _mm512_cmp_pd_mask(ex, _mm512_set1_pd(ex_in), _CMP_LT_OQ);
    const __mmask8 leave = sa
                           & ((__mmask8)~_mm512_cmp_pd_mask(qw, _mm512_set1_pd(sah_w), _CMP_GT_OQ)
                              | _mm512_cmp_pd_mask(st, _mm512_set1_pd(st_out), _CMP_GT_OQ)
                              | _mm512_cmp_pd_mask(ex, _mm512_set1_pd(ex_out), _CMP_GT_OQ));
    const __mmask8 ch = enter | leave, s2 = sa ^ ch;
    const __mmask8 hg = _mm512_cmpneq_epi64_mask(_mm512_loadu_si512((const void *)(homog + li)),
                                                 zero);
    const __m512d P0 = _mm512_mask_blend_pd(s2, _mm512_sub_pd(len, nom), _mm512_sub_pd(p0, nom));
    const __m512d one = _mm512_set1_pd(1.0);
    _mm512_storeu_pd(o + 10 * n + li, P0);
    _mm512_storeu_si512((void *)(link_sa + li), _mm512_maskz_mov_epi64(s2, _mm512_set1_epi64(1)));
    _mm512_storeu_pd(o + 9 * n + li, _mm512_maskz_mov_pd(s2, one));
    _mm512_storeu_pd(o + 22 * n + li, _mm512_maskz_mov_pd(ch, one));
    _mm512_storeu_pd(o + 23 * n + li, _mm512_maskz_mov_pd(ch | hg, one));
    return (__mmask8)~_mm512_cmp_pd_mask(_mm512_abs_pd(P0), _mm512_set1_pd(max_ext), _CMP_LE_OQ);
}
#else
#define SOFTGYM_MODES8 0
#endif
/* links lo..hi by the formula on doubles, in a loop the compiler vectorises; the voxels'
   positions and quaternions from their records, or in the builds whose seed step keeps
   them in the voxel rows (SOFTGYM_STATE_ROWS: its state there) from the rows vr */
#if SOFTGYM_STATE_ROWS
#define SOFTGYM_GEOM_POS(i, k) vr[(SOFTGYM_ROW_POS + (k)) * vn + (i)]
#define SOFTGYM_GEOM_QUAT(i, k) vr[(SOFTGYM_ROW_QUAT + (k)) * vn + (i)]
#else
#define SOFTGYM_GEOM_POS(i, k) pos[3 * (i) + (k)]
#define SOFTGYM_GEOM_QUAT(i, k) quat[4 * (i) + (k)]
#endif
SOFTGYM_ALWAYS_INLINE void softgym_seed_geom_scalar(const int ax, Py_ssize_t lo, Py_ssize_t hi,
                                                    Py_ssize_t n, const Py_ssize_t *v1,
                                                    const Py_ssize_t *v2, const double *pos,
                                                    const double *quat, const double *vr,
                                                    Py_ssize_t vn, const double *scale,
                                                    double *o, double *rr, float *rf)
{
    SOFTGYM_SEED_GEOM_AXIS(ax);
    SOFTGYM_SEED_GEOM_OUT(o, n);
    Py_ssize_t li;
    (void)pos;
    (void)quat;
    (void)vr;
    (void)vn;
    SOFTGYM_IVDEP
    for (li = lo; li < hi; li++) {
        Py_ssize_t i = v1[li], j = v2[li];
        double dx = SOFTGYM_GEOM_POS(j, 0) - SOFTGYM_GEOM_POS(i, 0);
        double dy = SOFTGYM_GEOM_POS(j, 1) - SOFTGYM_GEOM_POS(i, 1);
        double dz = SOFTGYM_GEOM_POS(j, 2) - SOFTGYM_GEOM_POS(i, 2);
        double w = SOFTGYM_GEOM_QUAT(i, 0), x = SOFTGYM_GEOM_QUAT(i, 1);
        double y = SOFTGYM_GEOM_QUAT(i, 2), z = SOFTGYM_GEOM_QUAT(i, 3);
        double wj = SOFTGYM_GEOM_QUAT(j, 0), xj = SOFTGYM_GEOM_QUAT(j, 1);
        double yj = SOFTGYM_GEOM_QUAT(j, 2), zj = SOFTGYM_GEOM_QUAT(j, 3);
        SOFTGYM_SEED_GEOM_LINK_T(double, sqrt, fabs, SOFTGYM_PUT1, SOFTGYM_PUTF1, li, dx, dy, dz,
                                 w, x, y, z, wj, xj, yj, zj, scale[i], scale[j], rr, rf, 7,
                                 (void)0);
    }
}
/* m not NULL (a compile-time constant where inlined; only in SOFTGYM_MODES8 builds, from
   softgym_seed_geom_modes): the modes of links lo..hi too, as
   softgym_seed_modes_loop leaves them (whether any is strained or-ed into *bad), those of
   the vector loop's blocks by softgym_seed_modes8 after each block's geometry */
SOFTGYM_ALWAYS_INLINE void softgym_seed_geom_ax(const int ax, Py_ssize_t lo, Py_ssize_t hi,
                                                Py_ssize_t n, const Py_ssize_t *v1,
                                                const Py_ssize_t *v2, Py_ssize_t vend,
                                                const double *pos, const double *quat,
                                                const double *vr, Py_ssize_t vn,
                                                const double *scale, double *o, double *rr,
                                                float *rf, const softgym_modes_args *m,
                                                long long *bad)
{
    Py_ssize_t li = lo;
#define SOFTGYM_GEOM_MODES(a, b) do { \
        if (m) \
            *bad |= softgym_seed_modes_loop((a), (b), n, m, o); \
    } while (0)
#if defined(SOFTGYM_VLANES)
    SOFTGYM_SEED_GEOM_AXIS(ax);
    SOFTGYM_SEED_GEOM_OUT(o, n);
    /* the links before the first whose output rows start a cache line go through
       softgym_seed_geom_scalar, so that no vector store spans two lines: the rows start
       on lines, but a run of links along y starts mid-line (after 180 x links in the
       reference robot), and its stores that spanned lines cost 3.5 % of the step on an
       Intel Xeon */
    Py_ssize_t al = lo;
    while (al < hi && ((uintptr_t)(o + al) & 63) != 0)
        al++;
    if (al + SOFTGYM_VLANES <= hi) {
        softgym_seed_geom_scalar(ax, lo, al, n, v1, v2, pos, quat, vr, vn, scale, o, rr, rf);
        SOFTGYM_GEOM_MODES(lo, al);
        li = al;
    }
    for (; li + SOFTGYM_VLANES <= hi; li += SOFTGYM_VLANES) {
        softgym_vd gi[8], gj[8];
#if SOFTGYM_VLANES == 8
        /* links whose voxels 1 and 2 are runs of consecutive voxels (a filled lattice's
           links along its slower axes): each voxel's records as rows at unit stride */
        if (softgym_run8(v1 + li) & softgym_run8(v2 + li)) {
            softgym_seed_rows8(v1[li], vr, vn, scale, gi);
            softgym_seed_rows8(v2[li], vr, vn, scale, gj);
        } else if (!softgym_seed_window8(v1 + li, v2 + li, vend, vr, vn, scale, gi, gj))
#endif
        {
#if SOFTGYM_STATE_ROWS
            softgym_seed_gather_rows(v1 + li, vr, vn, scale, gi);
            softgym_seed_gather_rows(v2 + li, vr, vn, scale, gj);
#else
            softgym_seed_gather(v1 + li, pos, quat, scale, gi);
            softgym_seed_gather(v2 + li, pos, quat, scale, gj);
#endif
        }
        softgym_vd dx = gj[0] - gi[0], dy = gj[1] - gi[1], dz = gj[2] - gi[2];
#if SOFTGYM_MODES8
#define SOFTGYM_GEOM_AFTER do { \
            if (m) \
                *bad |= softgym_seed_modes8v(li, n, (__m512d)geo_p0, (__m512d)geo_qw, \
                                             (__m512d)geo_nom, (__m512d)geo_len, \
                                             (__m512d)geo_st, m, o); \
        } while (0)
#else  /* (m is passed only where SOFTGYM_MODES8: softgym_seed_geom_modes) */
#define SOFTGYM_GEOM_AFTER (void)0
#endif
        SOFTGYM_SEED_GEOM_LINK_T(softgym_vd, SOFTGYM_VSQRT, softgym_vabs, SOFTGYM_VPUT,
                                 SOFTGYM_VPUTF, li, dx, dy, dz, gi[3], gi[4], gi[5], gi[6],
                                 gj[3], gj[4], gj[5], gj[6], gi[7], gj[7], rr, rf,
                                 SOFTGYM_MODES8 && m ? (m->keep_len ? 5 : 1) : 7,
                                 SOFTGYM_GEOM_AFTER);
#undef SOFTGYM_GEOM_AFTER
    }
#endif
    /* the rest (and every link without AVX): the compiler's vectoriser */
    softgym_seed_geom_scalar(ax, li, hi, n, v1, v2, pos, quat, vr, vn, scale, o, rr, rf);
    SOFTGYM_GEOM_MODES(li, hi);
#undef SOFTGYM_GEOM_MODES
}
/* vend: the end of the voxel records (voxel indices below it may be read); vr: the
   voxels' rows (SOFTGYM_VOXEL_ROWS: the same quaternions and positions as quat and pos,
   rows vn apart, indexed by voxel; read by the AVX-512 builds' rows and window paths);
   rr: the chunk's rotation rows (SOFTGYM_SEED_R_ROWS), indexed by link, or NULL
   (written only where SOFTGYM_SEED_R_USED) */
static void softgym_seed_geom(int ax, Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                              const Py_ssize_t *v1, const Py_ssize_t *v2, Py_ssize_t vend,
                              const double *pos, const double *quat, const double *vr,
                              Py_ssize_t vn, const double *scale, double *o, double *rr,
                              float *rf)
{
    SOFTGYM_BY_AXIS(ax, softgym_seed_geom_ax, lo, hi, n, v1, v2, vend, pos, quat, vr, vn, scale,
                    o, rr, rf, (const softgym_modes_args *)0, (long long *)0);
}

/* The frames pass of links_seed, in C for one pragma: the bond-frame
   quantities of links lo..hi in the mode the first pass gave them, without
   branches so the loop vectorises (the outputs are distinct rows of the
   scratch: no two iterations touch the same element). Every candidate
   value is computed and one is selected: the branchy scalar code's result
   (_seed_frame_one), bit for bit where multiply-adds are not fused, else
   to within the fusing's rounding (~1e-12 relative). Outputs: the displacement P, voxel 1's rotation vector
   (y, z; its x is 0), voxel 2's, the large-angle frame rq = (rw, 0, ry,
   rz). A link whose rotation vector needs the seed's acos branch (angles
   beyond ~5.6 degrees), or whose chord points backwards, gets fix = 1 and
   is redone by _seed_frame_one. */
/* _rotvec_k(w) where the seed takes its square-root branch (0 < sl <
   thr), and whether it takes the acos branch instead */
static inline double softgym_rotvec_k_sqrt(double w)
{
    double sl = 1.0 - w * w;
    double ks = 2.0 * sqrt((2.0 - 2.0 * w) / sl);
    return sl <= 0.0 ? 0.0 : ks;
}
static inline long long softgym_rotvec_needs_acos(double w, double thr)
{
    double sl = 1.0 - w * w;
    return (sl > 0.0) & (sl >= thr);
}
/* The large-angle frame rq = (rw, 0, ry, rz) of a link onto its chord p = (p0,
   p1, p2) (the seed's ToXDirBond of the relative position), in type T (M:
   the type of its conditions; SQRT: T's square root), every branch computed
   and one selected, declaring zero (p = 0: the identity), small (transverse
   ratios under sa_rad: the seed's small-ratio rq, exactly along the chord
   to first order), back (the chord points backwards, p0 < -|p| / 2, where
   the seed's discard test may apply: the scalar code redoes the link), rw,
   ry, rz. Otherwise the half-angle quaternion onto the chord n = p / |p|:
   (1 + nx, 0, nz, -ny) / sqrt(2 (1 + nx)), i.e. (|p| + p0, 0, p2, -p1) / s
   with s = sqrt(2 |p| (|p| + p0)): two square roots and one division (the
   seed's cos(th / 2), sin(th / 2) and 1 / |n_yz| took four and four). */
#define SOFTGYM_CHORD_FRAME(T, M, SQRT, p0, p1, p2, sa_rad, LN) \
    M zero = (p0 == (T)0.0) & (p1 == (T)0.0) & (p2 == (T)0.0); \
    T inv_p0_ = (T)1.0 / p0; \
    T yx_ = p1 * inv_p0_, zx_ = p2 * inv_p0_; \
    M small = (yx_ < sa_rad) & (yx_ > -sa_rad) & (zx_ < sa_rad) & (zx_ > -sa_rad); \
    T ry_s_ = (T)0.5 * zx_, rz_s_ = (T)-0.5 * yx_; \
    T rw_s_ = (T)1.0 + (T)0.5 * (-ry_s_ * ry_s_ - rz_s_ * rz_s_); \
    T ln_ = (LN); \
    T lp_ = ln_ + p0; \
    T inv_s_ = (T)1.0 / SQRT((T)2.0 * ln_ * lp_); \
    T ch_ = lp_ * inv_s_; \
    T ry_l_ = p2 * inv_s_, rz_l_ = -p1 * inv_s_; \
    M back = (1 - small) & (p0 < (T)-0.5 * ln_); \
    T rw = zero ? (T)1.0 : (small ? rw_s_ : ch_); \
    T ry = zero ? (T)0.0 : (small ? ry_s_ : ry_l_); \
    T rz = zero ? (T)0.0 : (small ? rz_s_ : rz_l_)
/* tq = rq nq in type T, declaring tw, tx, ty, tz: voxel 2's orientation
   relative to voxel 1 (qw, n1, n2, n3) turned into the large-angle frame rq
   = (rw, 0, ry, rz) (rq's x part is zero) */
#define SOFTGYM_TQ(T) \
    T tw = rw * qw - ry * n2 - rz * n3; \
    T tx = rw * n1 + ry * n3 - rz * n2; \
    T ty = rw * n2 + ry * qw + rz * n1; \
    T tz = rw * n3 - ry * n1 + rz * qw
/* whether every value of the row lo..hi is nonzero: with the mode row (sa_, 1.0 small
   angle), whether a chunk's links (SOFTGYM_CHUNK_LINKS at most) are all in small-angle
   mode, where the frames and forces passes run copies of their loops without the
   large-angle candidates (a settled or gently actuated body: most chunks); with row 23,
   whether voxel 2 takes -F1 at every link, where the forces pass leaves out voxel 2's own
   force. One test a chunk: with a loop of blocks around the copies, the forces pass's
   mixed loop spilled twice as many registers (benchmarks/RESULTS.md) */
static inline int softgym_all_nonzero(const double *row, Py_ssize_t lo, Py_ssize_t hi)
{
    Py_ssize_t li = lo;
#if defined(__AVX512F__)
    /* 8 at a time into a mask, out at the first zero (the compiler's loop took the flags
       through vectors of ints and a reduction, three times a chunk: about 1 % of the
       step); a NaN is not zero here either */
    for (; li + 8 <= hi; li += 8)
        if (_mm512_cmp_pd_mask(_mm512_loadu_pd(row + li), _mm512_setzero_pd(), _CMP_EQ_OQ))
            return 0;
#elif defined(__AVX__)
    /* the same, 8 at a time in two compares (the scalar loop, a load and two branches a
       link, took about 3 % of the AVX2 build's step) */
    const __m256d zero = _mm256_setzero_pd();
    for (; li + 8 <= hi; li += 8)
        if (_mm256_movemask_pd(_mm256_or_pd(
                _mm256_cmp_pd(_mm256_loadu_pd(row + li), zero, _CMP_EQ_OQ),
                _mm256_cmp_pd(_mm256_loadu_pd(row + li + 4), zero, _CMP_EQ_OQ))))
            return 0;
#elif defined(__SSE2__)
    const __m128d zero = _mm_setzero_pd();
    for (; li + 4 <= hi; li += 4)
        if (_mm_movemask_pd(_mm_or_pd(_mm_cmpeq_pd(_mm_loadu_pd(row + li), zero),
                                      _mm_cmpeq_pd(_mm_loadu_pd(row + li + 2), zero))))
            return 0;
#endif
    for (; li < hi; li++)
        if (!(row[li] != 0.0))
            return 0;
    return 1;
}
/* the frames pass's rows: geometry and mode in, frame quantities out */
#define SOFTGYM_FRAME_ROWS \
    const double *p0_, const double *p1_, const double *p2_, const double *qw_, \
    const double *n1_, const double *n2_, const double *n3_, const double *nom_, \
    const double *len_, const double *sa_, \
    double *o_P0, double *o_P1, double *o_P2, double *o_a1y, double *o_a1z, \
    double *o_a2x, double *o_a2y, double *o_a2z, double *o_rw, double *o_ry, \
    double *o_rz, double *o_fix
#define SOFTGYM_FRAME_ROW_NAMES p0_, p1_, p2_, qw_, n1_, n2_, n3_, nom_, len_, sa_, o_P0, \
    o_P1, o_P2, o_a1y, o_a1z, o_a2x, o_a2y, o_a2z, o_rw, o_ry, o_rz, o_fix
SOFTGYM_ALWAYS_INLINE long long softgym_seed_frames_impl(
    const int all_small, Py_ssize_t lo, Py_ssize_t hi, double sa_rad, double thr,
    SOFTGYM_FRAME_ROWS)
{
    Py_ssize_t li;
    long long any_fix = 0;
    SOFTGYM_IVDEP
    for (li = lo; li < hi; li++) {
        double p0 = p0_[li], p1 = p1_[li], p2 = p2_[li], qw = qw_[li];
        double n1 = n1_[li], n2 = n2_[li], n3 = n3_[li], nom = nom_[li], cl = len_[li];
        long long is_sa = all_small ? 1 : sa_[li] != 0.0;
        long long fix = 0;
        SOFTGYM_CHORD_FRAME(double, long long, sqrt, p0, p1, p2, sa_rad,
                            sqrt(p0 * p0 + p1 * p1 + p2 * p2));
        fix |= (1 - is_sa) & (1 - zero) & back;
        double k1 = softgym_rotvec_k_sqrt(rw);
        fix |= (1 - is_sa) & (1 - zero) & softgym_rotvec_needs_acos(rw, thr);
        double a1y = ry * k1, a1z = rz * k1;
        SOFTGYM_TQ(double);
        /* voxel 2's rotation vector: k of qw (small angle) or of tw (large),
           one square root and one division for either */
        double w2 = softgym_pick(is_sa, qw, tw);
        double k2 = softgym_rotvec_k_sqrt(w2);
        fix |= softgym_rotvec_needs_acos(w2, thr);
        double P0_s = p0 - nom, P0_l = cl - nom;
        double a2x_s = n1 * k2, a2y_s = n2 * k2, a2z_s = n3 * k2;
        double a2x_l = tx * k2, a2y_l = ty * k2, a2z_l = tz * k2;
        o_P0[li] = softgym_pick(is_sa, P0_s, P0_l);
        o_P1[li] = softgym_pick(is_sa, p1, 0.0);
        o_P2[li] = softgym_pick(is_sa, p2, 0.0);
        o_a1y[li] = softgym_pick(is_sa | zero, 0.0, a1y);
        o_a1z[li] = softgym_pick(is_sa | zero, 0.0, a1z);
        o_a2x[li] = softgym_pick(is_sa, a2x_s, a2x_l);
        o_a2y[li] = softgym_pick(is_sa, a2y_s, a2y_l);
        o_a2z[li] = softgym_pick(is_sa, a2z_s, a2z_l);
        o_rw[li] = softgym_pick(is_sa, 1.0, rw);  /* unused in small-angle mode */
        o_ry[li] = softgym_pick(is_sa, 0.0, ry);
        o_rz[li] = softgym_pick(is_sa, 0.0, rz);
        o_fix[li] = softgym_pick(fix, 1.0, 0.0);
        any_fix |= fix;
    }
    return any_fix;
}
/* returns whether any link got fix = 1 (else the caller need not look) */
static int softgym_seed_frames(
    Py_ssize_t lo, Py_ssize_t hi, double sa_rad, double thr, SOFTGYM_FRAME_ROWS)
{
    long long any_fix;
    if (softgym_all_nonzero(sa_, lo, hi))
        any_fix = softgym_seed_frames_impl(1, lo, hi, sa_rad, thr, SOFTGYM_FRAME_ROW_NAMES);
    else
        any_fix = softgym_seed_frames_impl(0, lo, hi, sa_rad, thr, SOFTGYM_FRAME_ROW_NAMES);
    return any_fix != 0;
}

/* Single-precision link math (the seed model's default link precision): the
   frames and forces passes in float, 16 lanes of AVX-512 instead of 8 and
   the divider's float rate, on quantities relative to voxel 1 (positions
   stay double; the geometry and mode passes stay double). The frames' float rows
   are a chunk's float scratch (SOFTGYM_CHUNK_FROWS rows); the forces pass
   leaves floats (rows SOFTGYM_CHUNK_FOUT on), which softgym_seed_push32 turns to
   the world and adds to the voxels' float rows.
   Reformulated where float would cancel:
   - the displacements p0 - nom and |p| - nom are taken in double (the modes pass
     leaves the link's mode's one in row 10), then rounded; the chord length |p|
     of the large-angle frame is the geometry's (row 8, double), rounded (one
     square root fewer on the pass's longest chain of operations);
   - the rotation vector of a unit quaternion (w, v) is k v with the seed's
     k = 2 sqrt((2 - 2w) / (1 - w^2)), which is 2 sqrt(2 / (1 + w)) exactly:
     that form, with no cancellation near w = 1 (the seed's own form loses
     up to half its digits there in double);
   - its acos branch (1 - w^2 >= 1 - 0.9988^2) is w <= 0.9988, computed in the
     lanes for w >= 0.5 (softgym_rotvec_k32_acos).
   Links turned past 120 degrees (w < 0.5) or with a backward chord are redone
   in double by _seed_frame_one, as in double precision. */
/* k = 2 sqrt(2 / (1 + w)) without the division unit (which bound the pass: each 512-bit
   float division or square root holds it about 10-12 cycles): for w >= 0.5 (the links the
   pass keeps) the minimax cubic in w of k itself (relative error 1.5e-5; SOFTGYM_RSQ_D0..D3,
   fitted by benchmarks/rotvec_fit.py) and one Newton step for 1 / sqrt, e + e (1/2 -
   ((1 + w) / 16) e^2) (k^2 (1 + w) = 8), the cubic in Estrin's form: the chain from w to k is
   4 multiply-adds and a product deep (the frames' longest chain runs through it), the
   multiply-adds fused where the build has FMA instructions (written out, so that the
   compiler's loop and the AVX-512 blocks round alike): k within 1.7 float roundings (the
   square root and division: 1.5). The lanes with w < 0.5 are redone in double (the
   fix-up) */
#define SOFTGYM_RSQ_D3 (-0.12716345489025116f)
#define SOFTGYM_RSQ_D2 0.5518827438354492f
#define SOFTGYM_RSQ_D1 (-1.2240811586380005f)
#define SOFTGYM_RSQ_D0 2.799332857131958f
#if defined(__FMA__)
#define SOFTGYM_FMAF(a, b, c) fmaf((a), (b), (c))
#else
#define SOFTGYM_FMAF(a, b, c) ((a) * (b) + (c))
#endif
static inline float softgym_rotvec_k32(float w)
{
    float w2 = w * w, x16 = SOFTGYM_FMAF(w, 0.0625f, 0.0625f);
    float e = SOFTGYM_FMAF(SOFTGYM_FMAF(SOFTGYM_RSQ_D3, w, SOFTGYM_RSQ_D2), w2,
                           SOFTGYM_FMAF(SOFTGYM_RSQ_D1, w, SOFTGYM_RSQ_D0));
    float u = SOFTGYM_FMAF(-x16, e * e, 0.5f);
    return SOFTGYM_FMAF(e, u, e);
}
/* k(w) in float for every w >= 0.5: past the seed's acos cut (w <= w_acos)
   its k = 2 acos(w) / sqrt(1 - w^2) is, with z = (1 - w) / 2 and u = sqrt(z),
   (2 / sqrt(1 - z)) (asin(u) / u): the square-root branch's k times asin(u) / u,
   which for z <= 1/4 (w >= 0.5) is single-precision asin's polynomial 1 + z
   P(z) (Cephes' asinf, good to float rounding; P in Estrin's form, its chain two
   multiply-adds shorter than Horner's). z = 0.5 - 0.5 w is exact there. Below
   w = 0.5 (rotations past 120 degrees) the link is redone in double. */
#define SOFTGYM_ASIN_P4 4.2163199048e-2f
#define SOFTGYM_ASIN_P3 2.4181311049e-2f
#define SOFTGYM_ASIN_P2 4.5470025998e-2f
#define SOFTGYM_ASIN_P1 7.4953002686e-2f
#define SOFTGYM_ASIN_P0 1.6666752422e-1f
static inline float softgym_rotvec_k32_acos(float w, float w_acos)
{
    float z = SOFTGYM_FMAF(-0.5f, w, 0.5f), z2 = z * z;
    float p = SOFTGYM_FMAF(SOFTGYM_FMAF(SOFTGYM_ASIN_P4, z2, SOFTGYM_FMAF(SOFTGYM_ASIN_P3, z,
                                                                        SOFTGYM_ASIN_P2)),
                           z2, SOFTGYM_FMAF(SOFTGYM_ASIN_P1, z, SOFTGYM_ASIN_P0));
    float r = w <= w_acos ? SOFTGYM_FMAF(z, p, 1.0f) : 1.0f;
    return softgym_rotvec_k32(w) * r;
}
/* whether row[li] (a double row's flag, 1.0 or 0.0) is set, as a condition of the float
   passes' lanes: without AVX compared in float, so that the condition is as wide as the
   lanes (a double compare's 64-bit mask among 32-bit lanes kept the SSE2 loop scalar:
   -fopt-info-vec-missed, control flow in loop); a NaN is set either way */
#if defined(__AVX__)
#define SOFTGYM_FLAG32(row, li) ((row)[li] != 0.0)
#else
#define SOFTGYM_FLAG32(row, li) ((float)(row)[li] != 0.0f)
#endif
/* c ? a : b in the float passes: without AVX (SSE2 on x86-64, NEON) a bitwise select (a
   select before a store became a conditional store, which SSE2 has no instruction for,
   and the loop stayed scalar) */
#if defined(__AVX__)
#define SOFTGYM_PICK32(c, a, b) ((c) ? (a) : (b))
#else
#define SOFTGYM_PICK32 softgym_pickf
#endif
SOFTGYM_ALWAYS_INLINE int softgym_seed_frames32_impl(
    const int all_small, Py_ssize_t lo, Py_ssize_t hi, float sa_rad, float w_acos,
    const double *p0_, const double *p1_, const double *p2_, const double *qw_,
    const double *n1_, const double *n2_, const double *n3_, const double *P0_,
    const double *len_, const double *sa_, float *o_P0, float *o_P1, float *o_P2,
    float *o_a1y, float *o_a1z, float *o_a2x, float *o_a2y, float *o_a2z, float *o_rw,
    float *o_ry, float *o_rz, float *o_fix)
{
    Py_ssize_t li;
    int any_fix = 0;
    SOFTGYM_IVDEP
    for (li = lo; li < hi; li++) {
        float p0 = (float)p0_[li], p1 = (float)p1_[li], p2 = (float)p2_[li];
        float qw = (float)qw_[li], n1 = (float)n1_[li], n2 = (float)n2_[li];
        float n3 = (float)n3_[li];
        int is_sa = all_small ? 1 : SOFTGYM_FLAG32(sa_, li);
        int fix = 0;
        SOFTGYM_CHORD_FRAME(float, int, sqrtf, p0, p1, p2, sa_rad, (float)len_[li]);
        fix |= (1 - is_sa) & (1 - zero) & back;
        float k1 = softgym_rotvec_k32_acos(rw, w_acos);
        fix |= (1 - is_sa) & (1 - zero) & (rw < 0.5f);
        float a1y = ry * k1, a1z = rz * k1;
        SOFTGYM_TQ(float);
        float w2 = is_sa ? qw : tw;
        float k2 = softgym_rotvec_k32_acos(w2, w_acos);
        fix |= w2 < 0.5f;
        o_P0[li] = (float)P0_[li];
        o_P1[li] = is_sa ? p1 : 0.0f;
        o_P2[li] = is_sa ? p2 : 0.0f;
        o_a1y[li] = (is_sa | zero) ? 0.0f : a1y;
        o_a1z[li] = (is_sa | zero) ? 0.0f : a1z;
        o_a2x[li] = (is_sa ? n1 : tx) * k2;
        o_a2y[li] = (is_sa ? n2 : ty) * k2;
        o_a2z[li] = (is_sa ? n3 : tz) * k2;
        o_rw[li] = is_sa ? 1.0f : rw;
        o_ry[li] = is_sa ? 0.0f : ry;
        o_rz[li] = is_sa ? 0.0f : rz;
        o_fix[li] = fix ? 1.0f : 0.0f;
        any_fix |= fix;
    }
    return any_fix;
}
#if defined(__AVX512F__) && (defined(__GNUC__) || defined(__clang__))
/* the float passes' code of 16 lanes in intrinsics (the frames pairs, the forces blocks) */
#define SOFTGYM_F16_LANES 1
/* The mixed loop of softgym_seed_frames32_impl for 32 links li..li + 31 (two blocks of 16
   lanes, li on a row's cache line), written in the lanes of AVX-512 with every statement
   made for both blocks before the next (SOFTGYM_X2): the same IEEE operations, lane by
   lane, as the compiler's vectorised loop, which does one block's statements after the
   other. The loop's chain of square roots and divisions (the chord, the frame, the two
   rotation vectors' k) is about as long as the block's work on the ports, so with one
   block in flight the core's scheduler fills with operations waiting on it; two blocks
   side by side give it independent work (benchmarks/frames_probe.py, Intel Xeon: 113 ->
   88 TSC cycles per 16 links of a mixed chunk). Its multiply-adds with two products are
   written out as the compiler fused the loop's (its widening_mul dump of the x86-64-v4
   build: |p|^2, the small-ratio rw, tw, tx, ty, tz), the rest (one product and an add)
   left to its contraction, which fuses those alike; checked bit for bit against that loop
   by tests/engine/test_seed_frames.py, frames_probe.py and benchmarks/check_bitident.py. */
typedef float softgym_v16f __attribute__((vector_size(64)));
#define SOFTGYM_X2(stmt) do { \
        for (int k_ = 0; k_ < 2; k_++) { \
            stmt; \
        } \
    } while (0)
/* 16 doubles at a, rounded to 16 floats */
#define SOFTGYM_F16_LOAD(a) ((softgym_v16f)_mm512_insertf32x8( \
        _mm512_castps256_ps512(_mm512_cvtpd_ps(_mm512_loadu_pd(a))), \
        _mm512_cvtpd_ps(_mm512_loadu_pd((a) + 8)), 1))
/* 16 doubles of a row that holds 1.0 or 0.0 (or any value): the lanes that are not 0.0 */
#define SOFTGYM_F16_NONZERO(row, li) _mm512_kunpackb( \
        _mm512_cmp_pd_mask(_mm512_loadu_pd((row) + (li) + 8), _mm512_setzero_pd(), \
                           _CMP_NEQ_UQ), \
        _mm512_cmp_pd_mask(_mm512_loadu_pd((row) + (li)), _mm512_setzero_pd(), _CMP_NEQ_UQ))
/* m ? a : b, lane by lane */
#define SOFTGYM_F16_PICK(m, a, b) \
    ((softgym_v16f)_mm512_mask_blend_ps((m), (__m512)(b), (__m512)(a)))
#define SOFTGYM_F16_CMP(a, b, op) _mm512_cmp_ps_mask((__m512)(a), (__m512)(b), (op))
#define SOFTGYM_F16_SET(c) ((softgym_v16f)_mm512_set1_ps(c))
#define SOFTGYM_F16_FMA(a, b, c) \
    ((softgym_v16f)_mm512_fmadd_ps((__m512)(a), (__m512)(b), (__m512)(c)))
#define SOFTGYM_F16_FNMA(a, b, c) \
    ((softgym_v16f)_mm512_fnmadd_ps((__m512)(a), (__m512)(b), (__m512)(c)))
#define SOFTGYM_FP_LANES 16
#define SOFTGYM_FP_NAME softgym_seed_frames32_x2
#define SOFTGYM_FP_V softgym_v16f
#define SOFTGYM_FP_M __mmask16
#define SOFTGYM_FP_LOAD SOFTGYM_F16_LOAD
#define SOFTGYM_FP_NONZERO SOFTGYM_F16_NONZERO
#define SOFTGYM_FP_PICK SOFTGYM_F16_PICK
#define SOFTGYM_FP_CMP SOFTGYM_F16_CMP
#define SOFTGYM_FP_SET SOFTGYM_F16_SET
#define SOFTGYM_FP_FMA SOFTGYM_F16_FMA
#define SOFTGYM_FP_FNMA SOFTGYM_F16_FNMA
#define SOFTGYM_FP_SQRT(v) ((softgym_v16f)_mm512_sqrt_ps((__m512)(v)))
#define SOFTGYM_FP_STORE(p, v) _mm512_storeu_ps((p), (__m512)(v))
#define SOFTGYM_FP_ANY(m) ((m) != 0)
#include "softgym_frames_pair.h"
#elif defined(__AVX2__) && defined(__FMA__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_F16_LANES 0
/* the same two blocks in the 8 lanes of AVX2 (conditions: vectors of ints) */
typedef float softgym_v8f __attribute__((vector_size(32)));
typedef int softgym_v8m __attribute__((vector_size(32)));  /* all ones where set */
#define SOFTGYM_X2(stmt) do { \
        for (int k_ = 0; k_ < 2; k_++) { \
            stmt; \
        } \
    } while (0)
#define SOFTGYM_FP_LANES 8
#define SOFTGYM_FP_NAME softgym_seed_frames32_x2
#define SOFTGYM_FP_V softgym_v8f
#define SOFTGYM_FP_M softgym_v8m
#define SOFTGYM_FP_LOAD(a) ((softgym_v8f)_mm256_set_m128(_mm256_cvtpd_ps(_mm256_loadu_pd((a) + 4)), \
                                                          _mm256_cvtpd_ps(_mm256_loadu_pd(a))))
/* a double row's 8 conditions as 32-bit lanes: lanes 0-3's from the even halves of the
   first compare, 4-7's from the odd halves of the second, put in order */
#define SOFTGYM_FP_NONZERO(row, li) ((softgym_v8m)_mm256_permutevar8x32_ps( \
        _mm256_blend_ps(_mm256_castpd_ps(_mm256_cmp_pd(_mm256_loadu_pd((row) + (li)), \
                                                       _mm256_setzero_pd(), _CMP_NEQ_UQ)), \
                        _mm256_castpd_ps(_mm256_cmp_pd(_mm256_loadu_pd((row) + (li) + 4), \
                                                       _mm256_setzero_pd(), _CMP_NEQ_UQ)), \
                        0xAA), \
        _mm256_set_epi32(7, 5, 3, 1, 6, 4, 2, 0)))
#define SOFTGYM_FP_PICK(m, a, b) \
    ((softgym_v8f)_mm256_blendv_ps((__m256)(b), (__m256)(a), (__m256)(m)))
#define SOFTGYM_FP_CMP(a, b, op) ((softgym_v8m)_mm256_cmp_ps((__m256)(a), (__m256)(b), (op)))
#define SOFTGYM_FP_SET(c) ((softgym_v8f)_mm256_set1_ps(c))
#define SOFTGYM_FP_FMA(a, b, c) \
    ((softgym_v8f)_mm256_fmadd_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FP_FNMA(a, b, c) \
    ((softgym_v8f)_mm256_fnmadd_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FP_SQRT(v) ((softgym_v8f)_mm256_sqrt_ps((__m256)(v)))
#define SOFTGYM_FP_STORE(p, v) _mm256_storeu_ps((p), (__m256)(v))
#define SOFTGYM_FP_ANY(m) (!_mm256_testz_si256((__m256i)(m), (__m256i)(m)))
#include "softgym_frames_pair.h"
#else
#define SOFTGYM_F16_LANES 0
#define SOFTGYM_FP_LANES 0
#endif
/* the frames pass in float: rows in as softgym_seed_frames, but the axial displacement P0
   from row 10 (softgym_seed_modes leaves it) instead of row 7, float rows out (row k at f +
   k SOFTGYM_CHUNK_FSTRIDE, indexed by link); returns whether any link got fix = 1 */
static int softgym_seed_frames32(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n, float sa_rad,
                                 float w_acos, const double *o, float *f)
{
    const Py_ssize_t fs = SOFTGYM_CHUNK_FSTRIDE;
    const double *sa_ = o + 9 * n;
    const int all_small = softgym_all_nonzero(sa_, lo, hi);
#define SOFTGYM_FRAMES32(s) softgym_seed_frames32_impl( \
            s, lo, hi, sa_rad, w_acos, o, o + n, o + 2 * n, o + 3 * n, o + 4 * n, o + 5 * n, \
            o + 6 * n, o + 10 * n, o + 8 * n, sa_, f, f + fs, f + 2 * fs, f + 3 * fs, \
            f + 4 * fs, f + 5 * fs, f + 6 * fs, f + 7 * fs, f + 8 * fs, f + 9 * fs, \
            f + 10 * fs, f + 11 * fs)
    int any_fix = 0;
    if (all_small) {
        any_fix = SOFTGYM_FRAMES32(1);
    } else {
#if SOFTGYM_FP_LANES
        /* two blocks at a time where they make whole pairs from lo (a chunk's rows start on
           cache lines) */
        for (; lo + 2 * SOFTGYM_FP_LANES <= hi; lo += 2 * SOFTGYM_FP_LANES)
            any_fix |= softgym_seed_frames32_x2(
                lo, sa_rad, w_acos, o, o + n, o + 2 * n, o + 3 * n, o + 4 * n, o + 5 * n,
                o + 6 * n, o + 10 * n, o + 8 * n, sa_, f, f + fs, f + 2 * fs, f + 3 * fs, f + 4 * fs,
                f + 5 * fs, f + 6 * fs, f + 7 * fs, f + 8 * fs, f + 9 * fs, f + 10 * fs,
                f + 11 * fs);
#endif
        if (lo < hi)
            any_fix |= SOFTGYM_FRAMES32(0);
    }
#undef SOFTGYM_FRAMES32
    return any_fix != 0;
}

/* The forces pass of links_seed (softgym_seed_forces.h, one definition
   for both precisions): softgym_seed_forces in double, the seed's operations
   (softgym_pick keeps its selects blends: a select before a store may
   otherwise become a masked store), softgym_seed_forces32 in float for
   link_precision "single" (its lanes' conditions 32 bits wide) */
#define SOFTGYM_FT double
#define SOFTGYM_FNAME softgym_seed_forces
#define SOFTGYM_FIN_STRIDE in_stride
#define SOFTGYM_FOUT_T double
#define SOFTGYM_FOUT_STRIDE SOFTGYM_CHUNK_STRIDE
#define SOFTGYM_FPICK softgym_pick
#define SOFTGYM_FMASK long long
#define SOFTGYM_FCOND(row, li) ((row)[li] != 0.0)
#include "softgym_seed_forces.h"
#undef SOFTGYM_FOUT_T
#undef SOFTGYM_FOUT_STRIDE
#undef SOFTGYM_FT
#undef SOFTGYM_FNAME
#undef SOFTGYM_FIN_STRIDE
#undef SOFTGYM_FPICK
#undef SOFTGYM_FMASK
#undef SOFTGYM_FCOND
/* The single-precision forces pass in vector lanes of intrinsics
   (softgym_seed_forces_block.h, which documents it): blocks of 16 links with AVX-512, of 8
   with AVX2 and FMA, the rest of a chunk by the compiler's loop */
#if SOFTGYM_F16_LANES
#define SOFTGYM_FB_LANES 16
#define SOFTGYM_FB_NAME softgym_seed_forces32_block16
#define SOFTGYM_FB_V softgym_v16f
#define SOFTGYM_FB_M __mmask16
#define SOFTGYM_FB_ROW(row, li) ((softgym_v16f)_mm512_loadu_ps((row) + (li)))
/* 16 floats v at out + li (the scatter widens them to doubles as it loads them) */
#define SOFTGYM_FB_PUT(out, li, v) _mm512_storeu_ps((out) + (li), (__m512)(v))
#define SOFTGYM_FB_SET SOFTGYM_F16_SET
#define SOFTGYM_FB_FMA SOFTGYM_F16_FMA
#define SOFTGYM_FB_FNMA SOFTGYM_F16_FNMA
#define SOFTGYM_FB_FMS(a, b, c) \
    ((softgym_v16f)_mm512_fmsub_ps((__m512)(a), (__m512)(b), (__m512)(c)))
#define SOFTGYM_FB_FNMS(a, b, c) \
    ((softgym_v16f)_mm512_fnmsub_ps((__m512)(a), (__m512)(b), (__m512)(c)))
#define SOFTGYM_FB_PICK SOFTGYM_F16_PICK
/* x + s d where m (else x): a masked multiply-add */
#define SOFTGYM_FB_DAMP(m, x, s, d) \
    ((softgym_v16f)_mm512_mask3_fmadd_ps((__m512)(s), (__m512)(d), (__m512)(x), (m)))
#define SOFTGYM_FB_NOT_NONZERO(row, li) ((__mmask16)~SOFTGYM_F16_NONZERO(row, li))
/* a masked store (last, the row's loaded lanes, is not needed) */
#define SOFTGYM_FB_KEEP(p, m, x, last) _mm512_mask_storeu_ps((p), (m), (__m512)(x))
#elif defined(__AVX2__) && defined(__FMA__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_FB_LANES 8
/* (softgym_v8f, softgym_v8m: the frames pairs' types, above) */
#define SOFTGYM_FB_NAME softgym_seed_forces32_block8
#define SOFTGYM_FB_V softgym_v8f
#define SOFTGYM_FB_M softgym_v8m
#define SOFTGYM_FB_ROW(row, li) ((softgym_v8f)_mm256_loadu_ps((row) + (li)))
#define SOFTGYM_FB_PUT(out, li, v) _mm256_storeu_ps((out) + (li), (__m256)(v))
#define SOFTGYM_FB_SET(c) ((softgym_v8f)_mm256_set1_ps(c))
#define SOFTGYM_FB_FMA(a, b, c) \
    ((softgym_v8f)_mm256_fmadd_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FB_FNMA(a, b, c) \
    ((softgym_v8f)_mm256_fnmadd_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FB_FMS(a, b, c) \
    ((softgym_v8f)_mm256_fmsub_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FB_FNMS(a, b, c) \
    ((softgym_v8f)_mm256_fnmsub_ps((__m256)(a), (__m256)(b), (__m256)(c)))
#define SOFTGYM_FB_PICK(m, a, b) \
    ((softgym_v8f)_mm256_blendv_ps((__m256)(b), (__m256)(a), (__m256)(m)))
/* x + s d where m (else x): the multiply-add in every lane, then a blend */
#define SOFTGYM_FB_DAMP(m, x, s, d) SOFTGYM_FB_PICK(m, SOFTGYM_FB_FMA(s, d, x), x)
/* the lanes whose double row holds 0.0: its 8 doubles rounded to floats (the rows hold 1.0
   or 0.0, exact in float; a NaN stays one, not equal) and compared */
#define SOFTGYM_FB_NOT_NONZERO(row, li) ((softgym_v8m)_mm256_cmp_ps( \
        _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(_mm256_loadu_pd((row) + (li)))), \
                             _mm256_cvtpd_ps(_mm256_loadu_pd((row) + (li) + 4)), 1), \
        _mm256_setzero_ps(), _CMP_EQ_OQ))
/* the row's lanes at p set to x where m, else left as last (what was loaded from them) */
#define SOFTGYM_FB_KEEP(p, m, x, last) \
    _mm256_storeu_ps((p), (__m256)SOFTGYM_FB_PICK(m, x, last))
#endif
#if defined(SOFTGYM_FB_LANES)
#include "softgym_seed_forces_block.h"
#undef SOFTGYM_FB_NAME
#undef SOFTGYM_FB_V
#undef SOFTGYM_FB_M
#undef SOFTGYM_FB_ROW
#undef SOFTGYM_FB_PUT
#undef SOFTGYM_FB_SET
#undef SOFTGYM_FB_FMA
#undef SOFTGYM_FB_FNMA
#undef SOFTGYM_FB_FMS
#undef SOFTGYM_FB_FNMS
#undef SOFTGYM_FB_PICK
#undef SOFTGYM_FB_DAMP
#undef SOFTGYM_FB_NOT_NONZERO
#undef SOFTGYM_FB_KEEP
#endif
#define SOFTGYM_FT float
#define SOFTGYM_FNAME softgym_seed_forces32
#if SOFTGYM_FB_LANES == 16
#define SOFTGYM_FBLOCK softgym_seed_forces32_block16
#elif SOFTGYM_FB_LANES == 8
#define SOFTGYM_FBLOCK softgym_seed_forces32_block8
#endif
#define SOFTGYM_FIN_STRIDE SOFTGYM_CHUNK_FSTRIDE
#define SOFTGYM_FOUT_T float
#define SOFTGYM_FOUT_STRIDE SOFTGYM_CHUNK_FSTRIDE
#define SOFTGYM_FPICK SOFTGYM_PICK32
#define SOFTGYM_FCOND SOFTGYM_FLAG32
#define SOFTGYM_FMASK int
#include "softgym_seed_forces.h"
#undef SOFTGYM_FOUT_T
#undef SOFTGYM_FOUT_STRIDE
#undef SOFTGYM_FBLOCK
#undef SOFTGYM_FT
#undef SOFTGYM_FNAME
#undef SOFTGYM_FIN_STRIDE
#undef SOFTGYM_FPICK
#undef SOFTGYM_FMASK
#undef SOFTGYM_FCOND

/* The pass of links_seed after the geometry, without branches
   so the loop vectorises: each link's mode, small or large angle, with the
   seed's hysteresis (updates link_sa), from the rows the geometry left
   (p0: row 0, qw: 3, nominal length: 7, chord length: 8, transverse ratio:
   9). Row 9 becomes the mode as 1.0 / 0.0, row 10 the axial displacement P0
   (p0 - nominal length in small-angle mode, chord - nominal length in large:
   the strain check's, which the single-precision frames pass rounds to float
   instead of taking both differences and selecting one), row 22 1.0 on a
   mode-change step, row 23 1.0 where voxel 2 takes -F1 (then or for a single
   material).
   Then the strain check: returns hi, or the first link whose extension is
   beyond max_ext (NaN included); the links after it keep their old mode
   (old = new xor changed), as in the seed's scalar loop, which stops there.
   With AVX only (4 lanes, 64-bit compares); else that scalar loop. link_sa and
   homog are 64-bit: with 8-bit flags the loop took 64 links a vector iteration
   and left up to 63 of each run to its scalar remainder (profiled: 12.3 against
   5.5 cycles per voxel-step). The loop and the check are softgym_seed_modes_loop and
   softgym_seed_modes_end (above); links_seed runs the pass through
   softgym_seed_geom_modes (below), which with AVX-512 decides the geometry's vector
   blocks' modes in its loop. */
static Py_ssize_t softgym_seed_modes(Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                     double max_ext, double sa_w, double sah_w,
                                     double st_in, double ex_in, double st_out,
                                     double ex_out, long long *link_sa,
                                     const long long *homog, double *o)
{
#if defined(__AVX__)
    const softgym_modes_args m = {max_ext, sa_w, sah_w, st_in, ex_in, st_out, ex_out,
                                  link_sa, homog, 0};
    long long bad = softgym_seed_modes_loop(lo, hi, n, &m, o);
    return softgym_seed_modes_end(lo, hi, n, max_ext, bad, link_sa, o);
#else
    /* 2 lanes and no 64-bit compare (SSE2): the branchy scalar loop is
       faster (profiled: 75 against 168 instructions per voxel-step) */
    Py_ssize_t li;
    for (li = lo; li < hi; li++) {
        double p0 = o[li], qw = o[3 * n + li], nom = o[7 * n + li];
        double st = o[9 * n + li];
        double ex = p0 / nom, P0;
        int sa = link_sa[li], changed = 0;
        if (!sa && qw > sa_w && st < st_in && ex < ex_in) {
            sa = 1;
            changed = 1;
        } else if (sa && (!(qw > sah_w) || st > st_out || ex > ex_out)) {
            sa = 0;
            changed = 1;
        }
        link_sa[li] = sa;
        o[9 * n + li] = sa ? 1.0 : 0.0;
        o[22 * n + li] = changed ? 1.0 : 0.0;
        o[23 * n + li] = (changed || homog[li]) ? 1.0 : 0.0;
        P0 = sa ? p0 - nom : o[8 * n + li] - nom;
        o[10 * n + li] = P0;
        if (!(fabs(P0) <= max_ext))
            return li;  /* also catches NaN */
    }
    return hi;
#endif
}

/* softgym_seed_geom then softgym_seed_modes on links lo..hi along ax (the same results),
   the modes of the geometry's vector blocks (AVX-512: softgym_seed_modes8) decided in
   its loop while their rows are in the cache and its store buffer, without the modes
   pass's own loop over them */
static Py_ssize_t softgym_seed_geom_modes(int ax, Py_ssize_t lo, Py_ssize_t hi, Py_ssize_t n,
                                          const Py_ssize_t *v1, const Py_ssize_t *v2,
                                          Py_ssize_t vend, const double *pos,
                                          const double *quat, const double *vr, Py_ssize_t vn,
                                          const double *scale, double *o, double *rr,
                                          float *rf, const softgym_modes_args *m)
{
#if SOFTGYM_MODES8
    long long bad = 0;
    SOFTGYM_BY_AXIS(ax, softgym_seed_geom_ax, lo, hi, n, v1, v2, vend, pos, quat, vr, vn, scale,
                    o, rr, rf, m, &bad);
    return softgym_seed_modes_end(lo, hi, n, m->max_ext, bad, m->link_sa, o);
#else
    softgym_seed_geom(ax, lo, hi, n, v1, v2, vend, pos, quat, vr, vn, scale, o, rr, rf);
    return softgym_seed_modes(lo, hi, n, m->max_ext, m->sa_w, m->sah_w, m->st_in, m->ex_in,
                              m->st_out, m->ex_out, m->link_sa, m->homog, o);
#endif
}

/* The last pass of links_seed: links lo..hi (all along axis ax, in one chunk) back
   to the world and scattered, in link order (the seed's summation order).
   Row k of a link's bond-frame output o (the chunk's rows, SOFTGYM_CHUNK_STRIDE apart:
   f1: 0-2, f2: 3-5, m1: 6-8, m2: 9-11) becomes R1 P^T v (P^T the inverse axis turn: (x, y, z) =
   (v0, v1, v2), (-v1, v0, v2), (-v2, v1, v0) for ax 0, 1, 2; R1 voxel 1's
   rotation, row-major) and is added to force / moment of voxel 1 or 2.
   Component c of R1 P^T v is R[3c] x + R[3c+1] y + R[3c+2] z, evaluated in
   that order: here as lane c of C0 x + C1 y + C2 z with the columns C_k of
   R1 in lanes 0-2 (lane 3 holds whatever the shuffles leave), so one link's four turns are 12
   multiplies and 8 adds of 4 lanes instead of 36 and 24 scalar ones, and
   each turned vector is added to the voxel's whole row of force / moment
   (4 lanes; lane 3 is the row's padding, never read): the same IEEE
   operations, bit for bit. Without AVX (2 lanes) the scalar turn, with R1
   in locals (the stores to force may alias rot for the compiler). */
#if defined(__AVX__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_SCATTER_V4 1
typedef double softgym_v4d __attribute__((vector_size(32)));
typedef long long softgym_v4i __attribute__((vector_size(32)));
#if defined(__clang__)
#define SOFTGYM_SHUFFLE4(a, b, i, j, k, l) __builtin_shufflevector(a, b, i, j, k, l)
#else
#define SOFTGYM_SHUFFLE4(a, b, i, j, k, l) __builtin_shuffle(a, b, (softgym_v4i){i, j, k, l})
#endif
/* the first input of a y or z link's turn, negated in the portable build;
   the vector build negates the first column instead (SOFTGYM_SCATTER_V4) */
#define SOFTGYM_NEG1(x) (x)
#define SOFTGYM_SCATTER_W(x, y, z) do { \
        double x_ = (x), y_ = (y), z_ = (z); \
        w = c0 * x_ + c1 * y_ + c2 * z_; \
    } while (0)
/* acc op= w on the voxel's whole row (op: += or -=), held in the register
   acc_v (loaded before the link's turns, stored after them) */
#define SOFTGYM_SCATTER_ACC(acc, op) do { \
        acc##_v op w; \
    } while (0)
#else
#define SOFTGYM_NEG1(x) (-(x))
#define SOFTGYM_SCATTER_W(x, y, z) do { \
        double x_ = (x), y_ = (y), z_ = (z); \
        w[0] = R[0] * x_ + R[1] * y_ + R[2] * z_; \
        w[1] = R[3] * x_ + R[4] * y_ + R[5] * z_; \
        w[2] = R[6] * x_ + R[7] * y_ + R[8] * z_; \
    } while (0)
#define SOFTGYM_SCATTER_ACC(acc, op) do { \
        (acc)[0] op w[0]; \
        (acc)[1] op w[1]; \
        (acc)[2] op w[2]; \
    } while (0)
#endif
/* row k of the link's forces and moments: the forces pass's doubles (o, SOFTGYM_CHUNK_STRIDE
   apart) */
#define SOFTGYM_SQ(k) (q[(k) * n])
#define SOFTGYM_SCATTER_TURN(acc, x, y, z) do { \
        SOFTGYM_SCATTER_W(x, y, z); \
        SOFTGYM_SCATTER_ACC(acc, +=); \
    } while (0)
/* voxel 2's force where it is minus voxel 1's (row 23: a single material or
   a mode change): the turn of -f1 is exactly minus the turn of f1 (negation
   is exact and rounding symmetric, fused or not), and a + (-b) is a - b, so
   voxel 1's turned force is subtracted, one turn fewer, the same bits */
#define SOFTGYM_SCATTER_F2(x, y, z) do { \
        if (neg2) { \
            SOFTGYM_SCATTER_ACC(fj, -=); \
        } else { \
            SOFTGYM_SCATTER_TURN(fj, x, y, z); \
        } \
    } while (0)
SOFTGYM_ALWAYS_INLINE void softgym_seed_scatter_links(const int ax, Py_ssize_t lo,
                                                      Py_ssize_t hi, const Py_ssize_t *v1,
                                                      const Py_ssize_t *v2, const double *rot,
                                                      const double *o,
                                                      const double *neg2_row, double *force,
                                                      double *moment)
{
    const Py_ssize_t n = SOFTGYM_CHUNK_STRIDE;
    Py_ssize_t li;
#if defined(SOFTGYM_SCATTER_V4)
    /* voxel 2's rows after the last link, kept in registers: where a link's
       voxel 1 is the last link's voxel 2 (runs along the lattice's fastest
       axis) its rows come from them instead of a load that would wait on
       the store just made (the same values, added in the same order) */
    softgym_v4d cf = {0.0, 0.0, 0.0, 0.0}, cm = cf;
    Py_ssize_t pj = -1;
#endif
    for (li = lo; li < hi; li++) {
        Py_ssize_t i = v1[li], j = v2[li];
#if SOFTGYM_SEED_R_USED
        /* the columns from the geometry's rotation rows of the chunk (rot is not kept up
           to date during a step in these builds) */
        const double *Rq = o + li + SOFTGYM_SEED_R_ROWS * n;
        (void)rot;
        softgym_v4d c0 = {Rq[0], Rq[3 * n], Rq[6 * n], Rq[6 * n]};
        softgym_v4d c1 = {Rq[n], Rq[4 * n], Rq[7 * n], Rq[7 * n]};
        softgym_v4d c2 = {Rq[2 * n], Rq[5 * n], Rq[8 * n], Rq[8 * n]};
        if (ax != 0)
            c0 = -c0;
        softgym_v4d w;
#elif defined(SOFTGYM_SCATTER_V4)
        const double *Rp = rot + 9 * i;
        /* the columns from two row loads and R[8] (lane 3 is padding: the
           rows' padding lane takes what it gets); for the y and z links the
           first column negated instead of the first input, (-c0) a =
           c0 (-a) exactly, so the inputs stay loads */
        softgym_v4d r03, r47;
        memcpy(&r03, Rp, sizeof r03);
        memcpy(&r47, Rp + 4, sizeof r47);
        softgym_v4d r8 = {Rp[8], Rp[8], Rp[8], Rp[8]};
        softgym_v4d c0 = SOFTGYM_SHUFFLE4(r03, r47, 0, 3, 6, 7);
        softgym_v4d c1 = SOFTGYM_SHUFFLE4(r03, r47, 1, 4, 7, 7);
        softgym_v4d c2 = SOFTGYM_SHUFFLE4(SOFTGYM_SHUFFLE4(r03, r47, 2, 5, 2, 5), r8, 0, 1, 4, 4);
        if (ax != 0)
            c0 = -c0;
        softgym_v4d w;
#else
        double R[9];
        memcpy(R, rot + 9 * i, sizeof R);
        double w[3];
#endif
        const double *q = o + li;
        /* neg2_row (row 23 of the scratch) holds exactly 1.0 or 0.0 (the modes pass): its
           bits, one integer test (a double's != 0.0 is two branches, for NaN) */
        unsigned long long neg2_bits;
        memcpy(&neg2_bits, neg2_row + li, sizeof neg2_bits);
        int neg2 = neg2_bits != 0;
        double *fi = force + SOFTGYM_FM_STRIDE * i, *fj = force + SOFTGYM_FM_STRIDE * j;
        double *mi = moment + SOFTGYM_FM_STRIDE * i, *mj = moment + SOFTGYM_FM_STRIDE * j;
#if defined(SOFTGYM_SCATTER_V4)
        softgym_v4d fi_v, fj_v, mi_v, mj_v;
        if (i == pj) {
            fi_v = cf;
            mi_v = cm;
        } else {
            memcpy(&fi_v, fi, sizeof fi_v);
            memcpy(&mi_v, mi, sizeof mi_v);
        }
        memcpy(&fj_v, fj, sizeof fj_v);
        memcpy(&mj_v, mj, sizeof mj_v);
#endif
        if (ax == 0) {
            SOFTGYM_SCATTER_TURN(fi, SOFTGYM_SQ(0), SOFTGYM_SQ(1), SOFTGYM_SQ(2));
            SOFTGYM_SCATTER_F2(SOFTGYM_SQ(3), SOFTGYM_SQ(4), SOFTGYM_SQ(5));
            SOFTGYM_SCATTER_TURN(mi, SOFTGYM_SQ(6), SOFTGYM_SQ(7), SOFTGYM_SQ(8));
            SOFTGYM_SCATTER_TURN(mj, SOFTGYM_SQ(9), SOFTGYM_SQ(10), SOFTGYM_SQ(11));
        } else if (ax == 1) {
            SOFTGYM_SCATTER_TURN(fi, SOFTGYM_NEG1(SOFTGYM_SQ(1)), SOFTGYM_SQ(0), SOFTGYM_SQ(2));
            SOFTGYM_SCATTER_F2(SOFTGYM_NEG1(SOFTGYM_SQ(4)), SOFTGYM_SQ(3), SOFTGYM_SQ(5));
            SOFTGYM_SCATTER_TURN(mi, SOFTGYM_NEG1(SOFTGYM_SQ(7)), SOFTGYM_SQ(6), SOFTGYM_SQ(8));
            SOFTGYM_SCATTER_TURN(mj, SOFTGYM_NEG1(SOFTGYM_SQ(10)), SOFTGYM_SQ(9), SOFTGYM_SQ(11));
        } else {
            SOFTGYM_SCATTER_TURN(fi, SOFTGYM_NEG1(SOFTGYM_SQ(2)), SOFTGYM_SQ(1), SOFTGYM_SQ(0));
            SOFTGYM_SCATTER_F2(SOFTGYM_NEG1(SOFTGYM_SQ(5)), SOFTGYM_SQ(4), SOFTGYM_SQ(3));
            SOFTGYM_SCATTER_TURN(mi, SOFTGYM_NEG1(SOFTGYM_SQ(8)), SOFTGYM_SQ(7), SOFTGYM_SQ(6));
            SOFTGYM_SCATTER_TURN(mj, SOFTGYM_NEG1(SOFTGYM_SQ(11)), SOFTGYM_SQ(10), SOFTGYM_SQ(9));
        }
#if defined(SOFTGYM_SCATTER_V4)
        memcpy(fi, &fi_v, sizeof fi_v);
        memcpy(fj, &fj_v, sizeof fj_v);
        memcpy(mi, &mi_v, sizeof mi_v);
        memcpy(mj, &mj_v, sizeof mj_v);
        cf = fj_v;
        cm = mj_v;
        pj = j;
#endif
    }
}
#undef SOFTGYM_SQ
#undef SOFTGYM_SCATTER_F2
#undef SOFTGYM_SCATTER_TURN
#undef SOFTGYM_SCATTER_ACC
#undef SOFTGYM_SCATTER_W
#undef SOFTGYM_SCATTER_V4
#undef SOFTGYM_NEG1

#if SOFTGYM_SEED_R_USED
#define SOFTGYM_SCATTER8 1
/* R1 P^T v of the 8 links in the lanes, v's bond-frame components in v[0..2] (P^T and
   the first column's sign as in softgym_seed_scatter_links: component c is R[3c] x +
   R[3c+1] y + R[3c+2] z in that order, with R[3c] negated for the y and z links), as the
   links' rows of 4 */
SOFTGYM_ALWAYS_INLINE void softgym_turn8(const int ax, const softgym_v8 *R, const softgym_v8 *v,
                                         __m512d *out)
{
    softgym_v8 x = ax == 0 ? v[0] : (ax == 1 ? v[1] : v[2]);
    softgym_v8 y = ax == 1 ? v[0] : v[1];
    softgym_v8 z = ax == 2 ? v[0] : v[2];
    softgym_v8 wx = R[0] * x + R[1] * y + R[2] * z;
    softgym_v8 wy = R[3] * x + R[4] * y + R[5] * z;
    softgym_v8 wz = R[6] * x + R[7] * y + R[8] * z;
    softgym_v8_rows4(wx, wy, wz, out);
}
/* link k's turned vectors w added to its voxels' rows: voxel 1's force f1 and moment m1
   in one 8-lane read-add-write of its row (SOFTGYM_FM_STRIDE), voxel 2's f2 and m2 in
   another; along x, where a link's voxel 1 is the last link's voxel 2, its row comes from
   the register just stored rather than a load that would wait on that store */
#define SOFTGYM_ADD1(k) do { \
        Py_ssize_t i_ = SOFTGYM_FM_STRIDE * v1[li + (k)], j_ = SOFTGYM_FM_STRIDE * v2[li + (k)]; \
        __m512d a_; \
        SOFTGYM_ROW_OR_CARRIED(ax == 0 && (k) > 0 && i_ == pj, a_, c, force, i_); \
        _mm512_store_pd(force + i_, _mm512_add_pd(a_, SOFTGYM_ROW8(wf1, wm1, k))); \
        c = _mm512_add_pd(_mm512_load_pd(force + j_), SOFTGYM_ROW8(wf2, wm2, k)); \
        _mm512_store_pd(force + j_, c); \
        pj = j_; \
    } while (0)
/* softgym_seed_scatter_links for the 8 links li..li + 7 (q = o + li on a cache line):
   the turns in the lanes of AVX-512 with voxel 1's rotation from the geometry's rows
   (SOFTGYM_SEED_R_ROWS), the same IEEE operations as the per-link turns, then each link's
   4 turned vectors added to its voxels' rows (one 8-lane add a voxel: its force and
   moment, force being the rows' start), link after link: each voxel's sum in the same
   order. Where voxel 2 takes -F1 (neg2_row), its force is the turn of -F1: exactly minus
   F1's, and adding it is subtracting F1's */
SOFTGYM_ALWAYS_INLINE void softgym_seed_scatter8(const int ax, Py_ssize_t li,
                                                 const Py_ssize_t *v1, const Py_ssize_t *v2,
                                                 const double *o, const double *neg2_row,
                                                 double *force)
{
    const Py_ssize_t n = SOFTGYM_CHUNK_STRIDE;
    const double *q = o + li;
    /* row k of the 8 links' forces and moments (softgym_seed_scatter_links's SOFTGYM_SQ) */
#define SOFTGYM_SQ8(k) (softgym_v8_load(q + (k) * n))
    softgym_v8 R[9], a[3], b[3];
    for (int k = 0; k < 9; k++)
        R[k] = softgym_v8_load(q + (SOFTGYM_SEED_R_ROWS + k) * n);
    if (ax != 0) {
        R[0] = -R[0];
        R[3] = -R[3];
        R[6] = -R[6];
    }
    __mmask8 neg2 = _mm512_cmpneq_epi64_mask(_mm512_loadu_si512((const void *)(neg2_row + li)),
                                             _mm512_setzero_si512());
    __m512d wf1[4], wf2[4], wm1[4], wm2[4];
    for (int c = 0; c < 3; c++)
        a[c] = SOFTGYM_SQ8(c);
    softgym_turn8(ax, R, a, wf1);
    if (neg2 == 0xFF) {
        /* every voxel 2 takes -F1 (one material, or two with the same damping ends, or a
           mode change: every block of a body of one tissue): the turn of -F1 is exactly
           minus F1's, so its rows are F1's negated (a voxel's sum starts at +0.0 and is
           never -0.0, the one case where the two could differ: the sign of a zero) */
        for (int k = 0; k < 4; k++)
            wf2[k] = (__m512d)(-(softgym_v8)wf1[k]);
    } else {
        for (int c = 0; c < 3; c++)
            b[c] = (softgym_v8)_mm512_mask_blend_pd(
                neg2, (__m512d)SOFTGYM_SQ8(3 + c), (__m512d)(-a[c]));
        softgym_turn8(ax, R, b, wf2);
    }
    for (int c = 0; c < 3; c++) {
        a[c] = SOFTGYM_SQ8(6 + c);
        b[c] = SOFTGYM_SQ8(9 + c);
    }
#undef SOFTGYM_SQ8
    softgym_turn8(ax, R, a, wm1);
    softgym_turn8(ax, R, b, wm2);
    __m512d c = _mm512_setzero_pd();
    Py_ssize_t pj = -1;
    SOFTGYM_EACH8(SOFTGYM_ADD1);
}
#endif
/* links lo..hi along ax: blocks of 8 whose rows start on a cache line through
   softgym_seed_scatter8 (with AVX-512), the others link by link */
SOFTGYM_ALWAYS_INLINE void softgym_seed_scatter_ax(const int ax, Py_ssize_t lo, Py_ssize_t hi,
                                                   const Py_ssize_t *v1, const Py_ssize_t *v2,
                                                   const double *rot, const double *o,
                                                   const double *neg2_row, double *force,
                                                   double *moment)
{
#if defined(SOFTGYM_SCATTER8)
    Py_ssize_t al = lo;
    while (al < hi && ((uintptr_t)(o + al) & 63) != 0)
        al++;
    if (al + 8 <= hi) {
        softgym_seed_scatter_links(ax, lo, al, v1, v2, rot, o, neg2_row, force, moment);
        for (lo = al; lo + 8 <= hi; lo += 8)
            softgym_seed_scatter8(ax, lo, v1, v2, o, neg2_row, force);
    }
#endif
    softgym_seed_scatter_links(ax, lo, hi, v1, v2, rot, o, neg2_row, force, moment);
}

/* the double-precision links' forces and moments (the double rows 0-11 of o, indexed by
   link) back to the world and into the voxels' rows of force and moment (the
   single-precision links' go through softgym_seed_push32) */
static void softgym_seed_scatter(int ax, Py_ssize_t lo, Py_ssize_t hi, const Py_ssize_t *v1,
                                 const Py_ssize_t *v2, const double *rot, const double *o,
                                 const double *neg2_row, double *force, double *moment)
{
    SOFTGYM_BY_AXIS(ax, softgym_seed_scatter_ax, lo, hi, v1, v2, rot, o, neg2_row, force, moment);
}

/* The single-precision links' last pass (link_precision "single"): the forces pass's float
   forces and moments turned to the world in float and added to the voxels' float rows
   (Batch.link_f: row k at lf + k lfs, k = 0-5 the force's x, y, z and the moment's, indexed
   by voxel), which the voxel update widens to doubles. The links of a chunk's axis run go
   in blocks of 16 from its start, and in each block every link's voxel 1 takes its f1 and
   m1, then every link's voxel 2 its f2 (or -f1 where neg2_row) and m2: within one block's
   side a voxel takes at most one link (a link joins a voxel to its neighbour along the
   axis), so the order of the links inside it does not matter and any grouping of them into
   vector lanes gives the same sums, bit for bit; the blocks, the sides' order and the
   chunks (SOFTGYM_CHUNK_LINKS from the robot's first link) fix the order of each voxel's
   additions in every build. The turn R1 P^T v (P^T and the first column's sign as in
   softgym_seed_scatter_links) with its multiply-adds written out (component c is
   fma(R[3c+2], z, fma(R[3c+1], y, R[3c] x))), so the scalar loop and the AVX-512 blocks
   round alike; R1 is voxel 1's rotation matrix rounded to float: the geometry's float rows
   (rf, SOFTGYM_CHUNK_FR, indexed by link). Where the double
   scatter transposed each link's turned vectors into its voxels' rows of 8 (a third of its
   operations shuffles) and widened the forces to doubles, a block here turns 16 links in
   the lanes and adds them to the voxels' rows in windows of 16 voxels (softgym_push16). */
#define SOFTGYM_TURN32(R, x, y, z, c) \
    SOFTGYM_FMAF((R)[3 * (c) + 2], (z), SOFTGYM_FMAF((R)[3 * (c) + 1], (y), (R)[3 * (c)] * (x)))
/* one side (1: voxel 1's f1 and m1; 2: voxel 2's f2 or -f1, and m2) of links lo..hi (at
   most 16, one block): the turn of every link into w (row k of link li at w[k][li - lo], a
   loop the compiler vectorises: the rows are contiguous by link), then each link's six
   components added to its voxel's float rows in link order, in one vector loop a row
   where the voxels are consecutive (the portable builds' path, and the AVX-512 blocks'
   fall-back) */
SOFTGYM_ALWAYS_INLINE void softgym_seed_push32_links(const int ax, const int side, Py_ssize_t lo,
                                                     Py_ssize_t hi, const Py_ssize_t *v1,
                                                     const Py_ssize_t *v2, const float *rf,
                                                     const float *of, const double *neg2_row,
                                                     float *lf, Py_ssize_t lfs)
{
    float w[6][16];
    const Py_ssize_t fs = SOFTGYM_CHUNK_FSTRIDE;
    SOFTGYM_IVDEP
    for (Py_ssize_t li = lo; li < hi; li++) {
        float R[9];
        for (int k = 0; k < 9; k++)
            R[k] = rf[k * fs + li];
        if (ax != 0) {
            R[0] = -R[0];
            R[3] = -R[3];
            R[6] = -R[6];
        }
        /* row k of the link's float forces and moments (SOFTGYM_CHUNK_FSTRIDE apart) */
        const float *q = of + li;
        float a[3], m[3];
        for (int c = 0; c < 3; c++) {
            if (side == 1) {
                a[c] = q[c * fs];
            } else {
                /* both loaded, then a select (a conditional load kept SSE2's loop scalar) */
                float minus_f1 = -q[c * fs], f2 = q[(3 + c) * fs];
                a[c] = SOFTGYM_PICK32(SOFTGYM_FLAG32(neg2_row, li), minus_f1, f2);
            }
            m[c] = q[((side == 1 ? 6 : 9) + c) * fs];
        }
        float x = a[ax], y = ax == 1 ? a[0] : a[1], z = ax == 2 ? a[0] : a[2];
        float mx = m[ax], my = ax == 1 ? m[0] : m[1], mz = ax == 2 ? m[0] : m[2];
        for (int c = 0; c < 3; c++) {
            w[c][li - lo] = SOFTGYM_TURN32(R, x, y, z, c);
            w[3 + c][li - lo] = SOFTGYM_TURN32(R, mx, my, mz, c);
        }
    }
    const Py_ssize_t *v = side == 1 ? v1 : v2;
    int run = 1;
    for (Py_ssize_t li = lo + 1; li < hi; li++)
        run &= v[li] == v[lo] + (li - lo);
    if (run) {
        /* consecutive voxels (a lattice's links along its slower axes): a loop the compiler
           vectorises, the same additions */
        for (int k = 0; k < 6; k++) {
            float *row = lf + k * lfs + v[lo];
            SOFTGYM_IVDEP
            for (Py_ssize_t t = 0; t < hi - lo; t++)
                row[t] += w[k][t];
        }
        return;
    }
    for (Py_ssize_t li = lo; li < hi; li++) {
        Py_ssize_t j = v[li];
        for (int k = 0; k < 6; k++)
            lf[k * lfs + j] += w[k][li - lo];
    }
}
#if defined(__AVX512F__) && SOFTGYM_SEED_R_USED && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_PUSH16 1
/* w[0..5] (the turned force and moment components of the links in the lanes `lanes`, the
   first n = popcount(lanes) of 16) added to the float rows of their voxels idx[0..n-1]
   (distinct, ascending): 16 consecutive voxels in one read-add-write a row; else in
   windows of 16 voxels that start on a row's cache line (lf's rows start on lines, lfs a
   multiple of 16): a window's lanes are the links' lanes permuted to their voxels (the
   inverse of the links' places, by an expand of their lane numbers), zero where no link of
   the block has its voxel, and the window's row takes one aligned read-add-write (a sum of
   floats that starts at +0.0 is never -0.0, so adding +0.0 leaves it as it is). A window's
   read meets the stores before it whole or not at all (a read that overlaps part of a
   store in flight waits for it to reach the cache: adding each run of voxels through
   masked unaligned stores took twice as long). Returns 0 (nothing added) where the voxels
   span more than 3 windows or are not strictly ascending (the layout's links along an
   axis are, by voxel; a guard, never taken by a lattice's links) */
SOFTGYM_ALWAYS_INLINE int softgym_push16(const softgym_v16f *w, const Py_ssize_t *idx,
                                         __mmask16 lanes, float *lf, Py_ssize_t lfs)
{
    const int n = __builtin_popcount((unsigned int)lanes);
    if (n == 16 && idx[15] - idx[0] == 15) {
        float *p = lf + idx[0];
        for (int k = 0; k < 6; k++)
            _mm512_storeu_ps(p + k * lfs,
                             _mm512_add_ps(_mm512_loadu_ps(p + k * lfs), (__m512)w[k]));
        return 1;
    }
    Py_ssize_t base = idx[0] - (Py_ssize_t)(((uintptr_t)(lf + idx[0]) & 63) / sizeof(float));
    if (idx[n - 1] - base >= 48)
        return 0;
    const __m512i vb = _mm512_set1_epi64((long long)base), one = _mm512_set1_epi64(1);
    const __mmask8 la = (__mmask8)lanes, lb = (__mmask8)(lanes >> 8);
    __m512i a = _mm512_sub_epi64(_mm512_maskz_loadu_epi64(la, (const void *)idx), vb);
    __m512i b = _mm512_sub_epi64(_mm512_maskz_loadu_epi64(lb, (const void *)(idx + 8)), vb);
    /* each lane above its left neighbour (lane 0 against itself: left out) */
    unsigned int up = ((unsigned int)_mm512_cmpgt_epi64_mask(b, _mm512_alignr_epi64(b, a, 7)) << 8)
                      | (unsigned int)_mm512_cmpgt_epi64_mask(a, _mm512_alignr_epi64(a, a, 7));
    if (((up | 1u) & (unsigned int)lanes) != (unsigned int)lanes)
        return 0;
    unsigned long long mask = (unsigned long long)_mm512_reduce_or_epi64(_mm512_or_si512(
        _mm512_maskz_sllv_epi64(la, one, a), _mm512_maskz_sllv_epi64(lb, one, b)));
    const __m512i iota = _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
    int before = 0;
    for (int win = 0; win < 3; win++) {
        __mmask16 m = (__mmask16)(mask >> (16 * win));
        if (m == 0)
            break;
        __m512i inv = _mm512_maskz_expand_epi32(
            m, _mm512_add_epi32(iota, _mm512_set1_epi32(before)));
        before += __builtin_popcount((unsigned int)m);
        float *p = lf + base + 16 * win;
        for (int k = 0; k < 6; k++)
            _mm512_store_ps(p + k * lfs,
                            _mm512_add_ps(_mm512_load_ps(p + k * lfs),
                                          _mm512_maskz_permutexvar_ps(m, inv, (__m512)w[k])));
    }
    return 1;
}
/* (x, y, z) of the bond frame turned to the world: w[c] for c = 0..2 (softgym_turn8's
   order, in float) */
#define SOFTGYM_TURN16(R, x, y, z, w) do { \
        for (int c_ = 0; c_ < 3; c_++) \
            (w)[c_] = SOFTGYM_F16_FMA((R)[3 * c_ + 2], (z), \
                                      SOFTGYM_F16_FMA((R)[3 * c_ + 1], (y), (R)[3 * c_] * (x))); \
    } while (0)
/* the block of links li..li + 15 in the lanes `lanes` (all 16, or the first few: a run's
   last block: full 0, the other lanes' loads masked off), both sides, in the lanes of
   AVX-512 (rf: the geometry's float rows); a side whose voxels softgym_push16 leaves goes
   link by link */
SOFTGYM_ALWAYS_INLINE void softgym_seed_push32_16(const int ax, const int full, Py_ssize_t li,
                                                  __mmask16 lanes,
                                                  const Py_ssize_t *v1, const Py_ssize_t *v2,
                                                  const float *rf, const float *of,
                                                  const double *neg2_row, float *lf,
                                                  Py_ssize_t lfs)
{
    const float *q = of + li;
    softgym_v16f R[9], a[3], m[3], w[6];
#define SOFTGYM_LOAD16(p) \
    ((softgym_v16f)(full ? _mm512_loadu_ps(p) : _mm512_maskz_loadu_ps(lanes, (p))))
    for (int k = 0; k < 9; k++)
        R[k] = SOFTGYM_LOAD16(rf + k * SOFTGYM_CHUNK_FSTRIDE + li);
    if (ax != 0) {
        R[0] = -R[0];
        R[3] = -R[3];
        R[6] = -R[6];
    }
    const Py_ssize_t hi = li + __builtin_popcount((unsigned int)lanes);
    for (int c = 0; c < 3; c++) {
        a[c] = SOFTGYM_LOAD16(q + c * SOFTGYM_CHUNK_FSTRIDE);
        m[c] = SOFTGYM_LOAD16(q + (6 + c) * SOFTGYM_CHUNK_FSTRIDE);
    }
    SOFTGYM_TURN16(R, a[ax], ax == 1 ? a[0] : a[1], ax == 2 ? a[0] : a[2], w);
    SOFTGYM_TURN16(R, m[ax], ax == 1 ? m[0] : m[1], ax == 2 ? m[0] : m[2], w + 3);
    if (!softgym_push16(w, v1 + li, lanes, lf, lfs))
        softgym_seed_push32_links(ax, 1, li, hi, v1, v2, rf, of, neg2_row, lf, lfs);
    /* voxel 2: -F1 in the lanes whose row 23 is not 0.0 (1.0: it takes -F1) */
    __mmask16 neg2 = _mm512_kunpackb(
        _mm512_cmp_pd_mask(full ? _mm512_loadu_pd(neg2_row + li + 8)
                                : _mm512_maskz_loadu_pd((__mmask8)(lanes >> 8), neg2_row + li + 8),
                           _mm512_setzero_pd(), _CMP_NEQ_UQ),
        _mm512_cmp_pd_mask(full ? _mm512_loadu_pd(neg2_row + li)
                                : _mm512_maskz_loadu_pd((__mmask8)lanes, neg2_row + li),
                           _mm512_setzero_pd(), _CMP_NEQ_UQ));
    for (int c = 0; c < 3; c++) {
        a[c] = SOFTGYM_F16_PICK(neg2, -a[c], SOFTGYM_LOAD16(q + (3 + c) * SOFTGYM_CHUNK_FSTRIDE));
        m[c] = SOFTGYM_LOAD16(q + (9 + c) * SOFTGYM_CHUNK_FSTRIDE);
    }
#undef SOFTGYM_LOAD16
    SOFTGYM_TURN16(R, a[ax], ax == 1 ? a[0] : a[1], ax == 2 ? a[0] : a[2], w);
    SOFTGYM_TURN16(R, m[ax], ax == 1 ? m[0] : m[1], ax == 2 ? m[0] : m[2], w + 3);
    if (!softgym_push16(w, v2 + li, lanes, lf, lfs))
        softgym_seed_push32_links(ax, 2, li, hi, v1, v2, rf, of, neg2_row, lf, lfs);
}
#undef SOFTGYM_TURN16
#elif defined(__AVX2__) && defined(__FMA__) && (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_PUSH8 1
/* The AVX2 builds' push: a block of 16 links as two halves of 8 float lanes (AVX2 has no
   expand or masked permute; its permute takes one register of 8). */
/* entry m, byte k: the number of set bits of m below bit k (a window's voxel k takes the
   link in lane `before` + that, where bit k of m is set) */
#define SOFTGYM_RANK1(m, k) ((unsigned char)__builtin_popcount((unsigned)(m) & ((1u << (k)) - 1u)))
#define SOFTGYM_RANK8(m) {SOFTGYM_RANK1(m, 0), SOFTGYM_RANK1(m, 1), SOFTGYM_RANK1(m, 2), \
                          SOFTGYM_RANK1(m, 3), SOFTGYM_RANK1(m, 4), SOFTGYM_RANK1(m, 5), \
                          SOFTGYM_RANK1(m, 6), SOFTGYM_RANK1(m, 7)}
#define SOFTGYM_RANK32(m) SOFTGYM_RANK8(m), SOFTGYM_RANK8((m) + 1), SOFTGYM_RANK8((m) + 2), \
    SOFTGYM_RANK8((m) + 3), SOFTGYM_RANK8((m) + 4), SOFTGYM_RANK8((m) + 5), \
    SOFTGYM_RANK8((m) + 6), SOFTGYM_RANK8((m) + 7)
static const unsigned char softgym_rank8[256][8] __attribute__((aligned(64))) = {
    SOFTGYM_RANK32(0), SOFTGYM_RANK32(8), SOFTGYM_RANK32(16), SOFTGYM_RANK32(24),
    SOFTGYM_RANK32(32), SOFTGYM_RANK32(40), SOFTGYM_RANK32(48), SOFTGYM_RANK32(56),
    SOFTGYM_RANK32(64), SOFTGYM_RANK32(72), SOFTGYM_RANK32(80), SOFTGYM_RANK32(88),
    SOFTGYM_RANK32(96), SOFTGYM_RANK32(104), SOFTGYM_RANK32(112), SOFTGYM_RANK32(120),
    SOFTGYM_RANK32(128), SOFTGYM_RANK32(136), SOFTGYM_RANK32(144), SOFTGYM_RANK32(152),
    SOFTGYM_RANK32(160), SOFTGYM_RANK32(168), SOFTGYM_RANK32(176), SOFTGYM_RANK32(184),
    SOFTGYM_RANK32(192), SOFTGYM_RANK32(200), SOFTGYM_RANK32(208), SOFTGYM_RANK32(216),
    SOFTGYM_RANK32(224), SOFTGYM_RANK32(232), SOFTGYM_RANK32(240), SOFTGYM_RANK32(248)};
#undef SOFTGYM_RANK32
#undef SOFTGYM_RANK8
#undef SOFTGYM_RANK1
/* (x, y, z) of the bond frame turned to the world in 8 lanes: w[c] for c = 0..2, the
   multiply-adds of softgym_seed_push32_links's SOFTGYM_TURN32 (fmaf: the same roundings) */
#define SOFTGYM_TURN8(R, x, y, z, w) do { \
        for (int c_ = 0; c_ < 3; c_++) \
            (w)[c_] = _mm256_fmadd_ps((R)[3 * c_ + 2], (z), \
                                      _mm256_fmadd_ps((R)[3 * c_ + 1], (y), \
                                                      _mm256_mul_ps((R)[3 * c_], (x)))); \
    } while (0)
/* both sides of the 8 links li..li + 7 turned: w1[0..5] voxel 1's (force x, y, z, moment
   x, y, z), w2[0..5] voxel 2's; the lanes from nl on (nl < 8: a run's last block) taken
   from the rows' padding (never added: softgym_push8x2). For the y and z links the bond
   frame's x input is negated instead of the rotation's first column ((-R) x = R (-x),
   exactly) */
SOFTGYM_ALWAYS_INLINE void softgym_seed_turn8(const int ax, Py_ssize_t li, int nl,
                                              const float *rf, const float *of,
                                              const double *neg2_row, __m256 *w1, __m256 *w2)
{
    const Py_ssize_t fs = SOFTGYM_CHUNK_FSTRIDE;
    const float *q = of + li;
    const __m256 sign = _mm256_set1_ps(-0.0f);
    __m256 R[9], a[3], m[3];
    for (int k = 0; k < 9; k++)
        R[k] = _mm256_loadu_ps(rf + k * fs + li);
    /* -f1 in the lanes whose row 23 is not 0.0 (1.0: voxel 2 takes -F1), else f2 */
    __m256d n_lo, n_hi;
    if (nl == 8) {
        n_lo = _mm256_loadu_pd(neg2_row + li);
        n_hi = _mm256_loadu_pd(neg2_row + li + 4);
    } else {
        const __m256i lane = _mm256_set_epi64x(3, 2, 1, 0);
        n_lo = _mm256_maskload_pd(neg2_row + li, _mm256_cmpgt_epi64(_mm256_set1_epi64x(nl), lane));
        n_hi = _mm256_maskload_pd(neg2_row + li + 4,
                                  _mm256_cmpgt_epi64(_mm256_set1_epi64x(nl - 4), lane));
    }
    /* the two halves' 64-bit conditions as 32-bit lanes: lanes 0-3's from the even halves
       of the first, 4-7's from the odd halves of the second, put in order */
    const __m256d zero = _mm256_setzero_pd();
    __m256 neg2 = _mm256_permutevar8x32_ps(
        _mm256_blend_ps(_mm256_castpd_ps(_mm256_cmp_pd(n_lo, zero, _CMP_NEQ_UQ)),
                        _mm256_castpd_ps(_mm256_cmp_pd(n_hi, zero, _CMP_NEQ_UQ)), 0xAA),
        _mm256_set_epi32(7, 5, 3, 1, 6, 4, 2, 0));
    for (int side = 1; side <= 2; side++) {
        for (int c = 0; c < 3; c++) {
            if (side == 1) {
                a[c] = _mm256_loadu_ps(q + c * fs);
                m[c] = _mm256_loadu_ps(q + (6 + c) * fs);
            } else {
                a[c] = _mm256_blendv_ps(_mm256_loadu_ps(q + (3 + c) * fs),
                                        _mm256_xor_ps(_mm256_loadu_ps(q + c * fs), sign), neg2);
                m[c] = _mm256_loadu_ps(q + (9 + c) * fs);
            }
        }
        __m256 x = a[ax], mx = m[ax];
        if (ax != 0) {
            x = _mm256_xor_ps(x, sign);
            mx = _mm256_xor_ps(mx, sign);
        }
        __m256 *w = side == 1 ? w1 : w2;
        SOFTGYM_TURN8(R, x, ax == 1 ? a[0] : a[1], ax == 2 ? a[0] : a[2], w);
        SOFTGYM_TURN8(R, mx, ax == 1 ? m[0] : m[1], ax == 2 ? m[0] : m[2], w + 3);
    }
}
#undef SOFTGYM_TURN8
/* the voxels idx[0..nl) of a block's side (1 <= nl <= 16) placed: 2 where they are
   consecutive (a run from idx[0]); else 1 where they rise strictly and lie within the 4
   windows of 8 from base, with bit idx[k] - base of *mask set for each; else 0 (the layout's
   links along an axis rise, by voxel: a guard, never 0 for a lattice's links). In four
   groups of 4 lanes of 64 bits (the lanes from nl on masked off) */
SOFTGYM_ALWAYS_INLINE int softgym_place16(const Py_ssize_t *idx, int nl, Py_ssize_t base,
                                          unsigned int *mask)
{
    const __m256i four = _mm256_set1_epi64x(4), one = _mm256_set1_epi64x(1);
    const __m256i vnl = _mm256_set1_epi64x(nl), first = _mm256_set1_epi64x(idx[0]);
    __m256i lane = _mm256_set_epi64x(3, 2, 1, 0), x[5], valid[4];
    __m256i off = _mm256_setzero_si256();
    for (int g = 0; g < 4; g++) {
        valid[g] = _mm256_cmpgt_epi64(vnl, lane);
        x[g] = _mm256_maskload_epi64((const long long *)(idx + 4 * g), valid[g]);
        off = _mm256_or_si256(off, _mm256_andnot_si256(
                                       _mm256_cmpeq_epi64(x[g], _mm256_add_epi64(first, lane)),
                                       valid[g]));
        lane = _mm256_add_epi64(lane, four);
    }
    if (_mm256_testz_si256(off, off))
        return 2;
    if (idx[nl - 1] - base >= 32)
        return 0;
    /* lane k below lane k + 1 where k + 1 < nl, and each lane's bit */
    const __m256i vbase = _mm256_set1_epi64x(base);
    __m256i down = _mm256_setzero_si256(), bits = _mm256_setzero_si256();
    x[4] = x[3];
    lane = _mm256_set_epi64x(4, 3, 2, 1);
    for (int g = 0; g < 4; g++) {
        __m256i next = _mm256_blend_epi32(_mm256_permute4x64_epi64(x[g], _MM_SHUFFLE(3, 3, 2, 1)),
                                          _mm256_permute4x64_epi64(x[g + 1], 0), 0xC0);
        down = _mm256_or_si256(down, _mm256_andnot_si256(_mm256_cmpgt_epi64(next, x[g]),
                                                         _mm256_cmpgt_epi64(vnl, lane)));
        bits = _mm256_or_si256(bits, _mm256_and_si256(
                                         _mm256_sllv_epi64(one, _mm256_sub_epi64(x[g], vbase)),
                                         valid[g]));
        lane = _mm256_add_epi64(lane, four);
    }
    if (!_mm256_testz_si256(down, down))
        return 0;
    __m128i b2 = _mm_or_si128(_mm256_castsi256_si128(bits), _mm256_extracti128_si256(bits, 1));
    *mask = (unsigned int)(_mm_cvtsi128_si64(b2) | _mm_extract_epi64(b2, 1));
    return 1;
}
/* w (the turned rows of the links in lanes 0..nl - 1: lanes 0-7 in wl, 8-15 in wh) added
   to the float rows of their voxels idx[0..nl - 1]: a run of consecutive voxels in one
   unaligned read-add-write a half and a row (lanes past nl add +0.0: a sum of floats that
   starts at +0.0 is never -0.0, so adding +0.0 leaves it as it is); else voxels that rise
   in aligned windows of 8 (lf's rows start on lines, lfs a multiple of 16): a window's
   lanes are the links' lanes permuted to their voxels (the ranks of its voxels among the
   block's, softgym_rank8), +0.0 where no link of the block has its voxel, and one
   read-add-write a row. Every voxel of a side takes one link at most, so each voxel's sum
   is the one of softgym_seed_push32_links, bit for bit. Returns 0 (nothing added) where
   softgym_place16 does */
SOFTGYM_ALWAYS_INLINE int softgym_push8x2(const __m256 *wl, const __m256 *wh,
                                          const Py_ssize_t *idx, int nl, float *lf,
                                          Py_ssize_t lfs)
{
    Py_ssize_t base = idx[0] - (Py_ssize_t)(((uintptr_t)(lf + idx[0]) & 31) / sizeof(float));
    unsigned int mask = 0;
    int place = softgym_place16(idx, nl, base, &mask);
    if (place == 0)
        return 0;
    if (place == 2) {
        float *p = lf + idx[0];
        const __m256i lane = _mm256_set_epi32(7, 6, 5, 4, 3, 2, 1, 0);
        if (nl >= 8) {
            for (int k = 0; k < 6; k++)
                _mm256_storeu_ps(p + k * lfs, _mm256_add_ps(_mm256_loadu_ps(p + k * lfs), wl[k]));
            if (nl > 8) {
                __m256 keep = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(nl - 8), lane));
                for (int k = 0; k < 6; k++)
                    _mm256_storeu_ps(p + 8 + k * lfs,
                                     _mm256_add_ps(_mm256_loadu_ps(p + 8 + k * lfs),
                                                   _mm256_and_ps(wh[k], keep)));
            }
        } else {
            __m256 keep = _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(nl), lane));
            for (int k = 0; k < 6; k++)
                _mm256_storeu_ps(p + k * lfs, _mm256_add_ps(_mm256_loadu_ps(p + k * lfs),
                                                            _mm256_and_ps(wl[k], keep)));
        }
        return 1;
    }
    const __m256i bit = _mm256_set_epi32(128, 64, 32, 16, 8, 4, 2, 1);
    __m256i before = _mm256_setzero_si256();
    /* the windows up to the last voxel's (counted from the indices, not from the mask: the
       loop's branch then does not wait on the mask's chain; a window without a voxel of
       the block adds +0.0) */
    const int nwin = (int)((idx[nl - 1] - base) >> 3) + 1;
    for (int win = 0; win < nwin; win++) {
        unsigned int m = (mask >> (8 * win)) & 0xFFu;
        __m128i r8 = _mm_loadl_epi64((const __m128i *)softgym_rank8[m]);
        __m256i rank = _mm256_add_epi32(_mm256_cvtepu8_epi32(r8), before);
        before = _mm256_add_epi32(before, _mm256_set1_epi32(__builtin_popcount(m)));
        /* lanes 8-15 (bit 3 of the rank) from wh: the sign bit for blendv */
        __m256 hi = _mm256_castsi256_ps(_mm256_slli_epi32(rank, 28));
        __m256 has = _mm256_castsi256_ps(
            _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)m), bit), bit));
        float *p = lf + base + 8 * win;
        for (int k = 0; k < 6; k++) {
            __m256 v = _mm256_blendv_ps(_mm256_permutevar8x32_ps(wl[k], rank),
                                        _mm256_permutevar8x32_ps(wh[k], rank), hi);
            _mm256_store_ps(p + k * lfs, _mm256_add_ps(_mm256_load_ps(p + k * lfs),
                                                       _mm256_and_ps(v, has)));
        }
    }
    return 1;
}
/* the block of links li..hi (at most 16: all a block's, or a run's last few), both sides,
   in two halves of 8 lanes (rf: the geometry's float rows); a side whose voxels
   softgym_push8x2 leaves goes link by link */
SOFTGYM_ALWAYS_INLINE void softgym_seed_push32_8x2(const int ax, Py_ssize_t li, Py_ssize_t hi,
                                                   const Py_ssize_t *v1, const Py_ssize_t *v2,
                                                   const float *rf, const float *of,
                                                   const double *neg2_row, float *lf,
                                                   Py_ssize_t lfs)
{
    const int nl = (int)(hi - li);
    /* side s's turned rows: w[s - 1][0..5] lanes 0-7, w[s - 1][6..11] lanes 8-15 */
    __m256 w[2][12];
    softgym_seed_turn8(ax, li, nl < 8 ? nl : 8, rf, of, neg2_row, w[0], w[1]);
    if (nl > 8) {
        softgym_seed_turn8(ax, li + 8, nl - 8, rf, of, neg2_row, w[0] + 6, w[1] + 6);
    } else {
        for (int k = 6; k < 12; k++)
            w[0][k] = w[1][k] = _mm256_setzero_ps();
    }
    for (int side = 1; side <= 2; side++)
        if (!softgym_push8x2(w[side - 1], w[side - 1] + 6, (side == 1 ? v1 : v2) + li, nl, lf,
                             lfs))
            softgym_seed_push32_links(ax, side, li, hi, v1, v2, rf, of, neg2_row, lf, lfs);
}
#endif
SOFTGYM_ALWAYS_INLINE void softgym_seed_push32_ax(const int ax, Py_ssize_t lo, Py_ssize_t hi,
                                                  const Py_ssize_t *v1, const Py_ssize_t *v2,
                                                  const float *rf, const float *of,
                                                  const double *neg2_row, float *lf,
                                                  Py_ssize_t lfs)
{
    for (Py_ssize_t li = lo; li < hi; li += 16) {
        Py_ssize_t e = hi - li < 16 ? hi : li + 16;
#if defined(SOFTGYM_PUSH16)
        if (e - li == 16)
            softgym_seed_push32_16(ax, 1, li, (__mmask16)0xFFFF, v1, v2, rf, of, neg2_row, lf,
                                   lfs);
        else
            softgym_seed_push32_16(ax, 0, li, (__mmask16)((1u << (e - li)) - 1u), v1, v2, rf,
                                   of, neg2_row, lf, lfs);
#elif defined(SOFTGYM_PUSH8)
        softgym_seed_push32_8x2(ax, li, e, v1, v2, rf, of, neg2_row, lf, lfs);
#else
        softgym_seed_push32_links(ax, 1, li, e, v1, v2, rf, of, neg2_row, lf, lfs);
        softgym_seed_push32_links(ax, 2, li, e, v1, v2, rf, of, neg2_row, lf, lfs);
#endif
    }
}
/* links lo..hi along ax (one chunk's run): of, the float forces pass's rows, and rf, the
   geometry's float rows of voxel 1's rotation (both indexed by link) */
static void softgym_seed_push32(int ax, Py_ssize_t lo, Py_ssize_t hi, const Py_ssize_t *v1,
                                const Py_ssize_t *v2, const float *rf, const float *of,
                                const double *neg2_row, float *lf, Py_ssize_t lfs)
{
    SOFTGYM_BY_AXIS(ax, softgym_seed_push32_ax, lo, hi, v1, v2, rf, of, neg2_row, lf, lfs);
}
#undef SOFTGYM_TURN32
#if defined(SOFTGYM_F16_NONZERO)
#undef SOFTGYM_F16_NONZERO
#endif

#endif  /* SOFTGYM_SEED_H */
