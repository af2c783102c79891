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
#include <math.h>
#include <string.h>
/* Each voxel's accumulated force and moment share one row of SOFTGYM_FM_STRIDE doubles
   (Batch.force: force in columns 0-2, moment in 4-6, columns 3 and 7 padding, never
   read; Batch.moment points at column 4): 64 bytes, one cache line, so that a link's
   vector scatter adds its force and moment to a voxel in one 8-lane read-add-write */
#define SOFTGYM_FM_STRIDE 8
/* Rows of the per-thread voxel scratch (Batch.vox_out: row k of voxel i at k vox_stride +
   i): the voxel update's new quaternions (w, x, y, z) in rows 0-3 (the corotational
   model, and the seed model without AVX-512); in the seed model's AVX-512 builds the
   voxels' state (below); in the corotational model's AVX-512 builds, rows 0-17 hold the
   voxels' positions, velocities, angular velocities and rotation matrices during its
   links pass (include/softgym_corot.h: softgym_corot_rows) */
#define SOFTGYM_VOXEL_ROWS 25
/* In AVX-512 builds the rows are the voxels' state throughout both models' step loops
   (_core._advance_seed, _advance_corotational; written back to the records when they
   return, include/softgym_orient.h: softgym_state_rows, softgym_state_back),
   which the 8-voxel blocks, the orientation step and the link kernels load and store
   without transposing records: positions (x, y, z) in rows 0-2, velocities 3-5, angular
   velocities 6-8 (the order the corotational link kernel reads them in, with the rotation
   matrices it computes from the quaternions each step in rows 9-17), quaternions (w, x,
   y, z) 18-21, and a copy of the external forces in 22-24 */
#define SOFTGYM_ROW_POS 0
#define SOFTGYM_ROW_VEL 3
#define SOFTGYM_ROW_AV 6
#define SOFTGYM_ROW_ROT 9  /* the corotational step's rotation matrices, 9 rows */
#define SOFTGYM_ROW_QUAT 18
#define SOFTGYM_ROW_EXT 22
/* whether none of the 8 one-byte flags f[0..7] is set (one 64-bit test) */
static inline int softgym_none8(const signed char *f)
{
    unsigned long long w;
    memcpy(&w, f, sizeof w);
    return w == 0;
}
/* name(c, a, b): c ? a : b on the bits of the floating type T (U: its unsigned integer
   twin, C: the condition's type) */
#define SOFTGYM_DEFINE_PICK(name, T, U, C) \
    static inline T name(C c, T a, T b) \
    { \
        U ua, ub, m = (U)0 - (U)(c != 0); \
        T r; \
        memcpy(&ua, &a, sizeof ua); \
        memcpy(&ub, &b, sizeof ub); \
        ua = (ua & m) | (ub & ~m); \
        memcpy(&r, &ua, sizeof r); \
        return r; \
    }
/* c ? a : b on the bits: compilers keep it a blend (a select before a
   store may otherwise become a masked store, slow on some cores) */
SOFTGYM_DEFINE_PICK(softgym_pick, double, unsigned long long, long long)
/* the same for floats (the float passes' selects in the builds without AVX, which have no
   conditional store) */
SOFTGYM_DEFINE_PICK(softgym_pickf, float, unsigned int, int)
/* |v|^2 of a voxel's velocity, for the seed's collision schedule (the fastest voxel's
   speed). Where the build fuses multiply-adds, the fusion is written out: the value
   is the same wherever the expression is inlined, (vy vy, then + vx vx and + vz vz
   fused), the form GCC chose in the separate loop over the velocities that this
   replaced, so the schedule keeps its bits */
static inline double softgym_speed2(double vx, double vy, double vz)
{
#if defined(__FMA__)
    return fma(vz, vz, fma(vx, vx, vy * vy));
#else
    return vx * vx + vy * vy + vz * vz;
#endif
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
/* Vector code of our own for the link passes' loads (softgym_seed.h, softgym_corot.h):
   GCC's vectoriser loads a gathered number at a time, and with two voxels' indices per
   lane it parks them in vector registers and spills. softgym_vd is a vector of
   SOFTGYM_VLANES doubles (8 with AVX-512, 4 with AVX, and 4 in the portable builds, below)
   that GCC's arithmetic operators act on lane by lane, so a pass's formula, written once
   as a macro over its type, runs on doubles and on these vectors with the same
   operations. */
#if defined(__AVX__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#if defined(__AVX512F__)
#define SOFTGYM_VLANES 8
typedef double softgym_vd __attribute__((vector_size(64)));
#define SOFTGYM_VSQRT(v) ((softgym_vd)_mm512_sqrt_pd((__m512d)(v)))
/* 8 doubles as GCC's vector (the same type as softgym_vd here): the transposes between
   8 voxels' records (3 or 4 doubles each, consecutive) and rows of 8 lanes, for the voxel
   updates (softgym_voxels.h) and the link geometry of a run of voxels (softgym_seed.h) */
typedef double softgym_v8 __attribute__((vector_size(64)));
/* 8 consecutive doubles from a */
static inline softgym_v8 softgym_v8_load(const double *a)
{
    softgym_v8 v;
    memcpy(&v, a, sizeof v);
    return v;
}
/* 8 voxels' records of 3 (a[0..23]) as rows x, y, z */
static inline void softgym_v8_load3(const double *a, softgym_v8 *x, softgym_v8 *y,
                                    softgym_v8 *z)
{
    __m512d p0 = _mm512_loadu_pd(a), p1 = _mm512_loadu_pd(a + 8), p2 = _mm512_loadu_pd(a + 16);
    /* element e of the 24 is voxel e / 3, component e % 3 */
    const __m512i ix0 = _mm512_set_epi64(0, 0, 15, 12, 9, 6, 3, 0);
    const __m512i iy0 = _mm512_set_epi64(0, 0, 8 + 8, 13, 10, 7, 4, 1);
    const __m512i iz0 = _mm512_set_epi64(0, 0, 8 + 9, 14, 11, 8, 5, 2);
    const __m512i ix1 = _mm512_set_epi64(8 + 5, 8 + 2, 5, 4, 3, 2, 1, 0);
    const __m512i iy1 = _mm512_set_epi64(8 + 6, 8 + 3, 8 + 0, 4, 3, 2, 1, 0);
    const __m512i iz1 = _mm512_set_epi64(8 + 7, 8 + 4, 8 + 1, 4, 3, 2, 1, 0);
    /* x: 0 3 6 9 12 15 | 18 21; y: 1 4 7 10 13 | 16 19 22; z: 2 5 8 11 14 | 17 20 23 */
    *x = (softgym_v8)_mm512_permutex2var_pd(_mm512_permutex2var_pd(p0, ix0, p1), ix1, p2);
    *y = (softgym_v8)_mm512_permutex2var_pd(_mm512_permutex2var_pd(p0, iy0, p1), iy1, p2);
    *z = (softgym_v8)_mm512_permutex2var_pd(_mm512_permutex2var_pd(p0, iz0, p1), iz1, p2);
}
/* rows x, y, z back into 8 records of 3 at a[0..23] */
static inline void softgym_v8_store3(double *a, softgym_v8 x, softgym_v8 y, softgym_v8 z)
{
    /* out0 = x0 y0 z0 x1 y1 z1 x2 y2; out1 = z2 x3 y3 z3 x4 y4 z4 x5;
       out2 = y5 z5 x6 y6 z6 x7 y7 z7 */
    /* t0 = x0 y0 _ x1 y1 _ x2 y2, then z0, z1 into its gaps; the same for out1, out2 */
    __m512d t0 = _mm512_permutex2var_pd(
        (__m512d)x, _mm512_set_epi64(8 + 2, 2, 0, 8 + 1, 1, 0, 8 + 0, 0), (__m512d)y);
    __m512d o0 = _mm512_permutex2var_pd(t0, _mm512_set_epi64(7, 6, 8 + 1, 4, 3, 8 + 0, 1, 0),
                                        (__m512d)z);
    __m512d t1 = _mm512_permutex2var_pd((__m512d)x, _mm512_set_epi64(5, 0, 8 + 4, 4, 0, 8 + 3, 3, 0),
                                        (__m512d)y);
    __m512d o1 = _mm512_permutex2var_pd(t1, _mm512_set_epi64(7, 8 + 4, 5, 4, 8 + 3, 2, 1, 8 + 2),
                                        (__m512d)z);
    __m512d t2 = _mm512_permutex2var_pd((__m512d)x, _mm512_set_epi64(0, 8 + 7, 7, 0, 8 + 6, 6, 0, 8 + 5),
                                        (__m512d)y);
    __m512d o2 = _mm512_permutex2var_pd(t2, _mm512_set_epi64(8 + 7, 6, 5, 8 + 6, 3, 2, 8 + 5, 0),
                                        (__m512d)z);
    _mm512_storeu_pd(a, o0);
    _mm512_storeu_pd(a + 8, o1);
    _mm512_storeu_pd(a + 16, o2);
}
/* 8 records of 4, two to a register (p0: records 0 and 1, ..., p3: 6 and 7), as the 4 rows
   r[0..3] (element 0 .. 3 of each record) */
static inline void softgym_v8_rows_of4(__m512d p0, __m512d p1, __m512d p2, __m512d p3,
                                       softgym_v8 *r)
{
    /* from p0, p1: elements 0 and 1 of records 0-3; elements 2 and 3 of them */
    const __m512i i01 = _mm512_set_epi64(8 + 5, 8 + 1, 5, 1, 8 + 4, 8 + 0, 4, 0);
    const __m512i i23 = _mm512_set_epi64(8 + 7, 8 + 3, 7, 3, 8 + 6, 8 + 2, 6, 2);
    __m512d a01 = _mm512_permutex2var_pd(p0, i01, p1), b01 = _mm512_permutex2var_pd(p2, i01, p3);
    __m512d a23 = _mm512_permutex2var_pd(p0, i23, p1), b23 = _mm512_permutex2var_pd(p2, i23, p3);
    const __m512i lo = _mm512_set_epi64(8 + 3, 8 + 2, 8 + 1, 8 + 0, 3, 2, 1, 0);
    const __m512i hi = _mm512_set_epi64(8 + 7, 8 + 6, 8 + 5, 8 + 4, 7, 6, 5, 4);
    r[0] = (softgym_v8)_mm512_permutex2var_pd(a01, lo, b01);
    r[1] = (softgym_v8)_mm512_permutex2var_pd(a01, hi, b01);
    r[2] = (softgym_v8)_mm512_permutex2var_pd(a23, lo, b23);
    r[3] = (softgym_v8)_mm512_permutex2var_pd(a23, hi, b23);
}
/* 8 voxels' records of 4 (a[0..31]) as its 4 rows r[0..3] (element 0 .. 3 of each) */
static inline void softgym_v8_load4x4(const double *a, softgym_v8 *r)
{
    softgym_v8_rows_of4(_mm512_loadu_pd(a), _mm512_loadu_pd(a + 8), _mm512_loadu_pd(a + 16),
                        _mm512_loadu_pd(a + 24), r);
}
/* two records of 4 that start SOFTGYM_FM_STRIDE doubles apart, at a, in one register */
#define SOFTGYM_FM_PAIR(a) \
    _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_load_pd(a)), \
                       _mm256_load_pd((a) + SOFTGYM_FM_STRIDE), 1)
/* the same for 8 records of 4 that start SOFTGYM_FM_STRIDE doubles apart (a[0..3],
   a[8..11], ...: the force or the moment columns of the voxels' rows) */
static inline void softgym_v8_load4x4_fm(const double *a, softgym_v8 *r)
{
    const int s = SOFTGYM_FM_STRIDE;
    softgym_v8_rows_of4(SOFTGYM_FM_PAIR(a), SOFTGYM_FM_PAIR(a + 2 * s),
                        SOFTGYM_FM_PAIR(a + 4 * s), SOFTGYM_FM_PAIR(a + 6 * s), r);
}
/* rows r[0..3] (element 0 .. 3 of 8 records) back into the 8 records of 4 at a[0..31] */
static inline void softgym_v8_store4x4(double *a, const softgym_v8 *r)
{
    __m512d l01 = _mm512_unpacklo_pd((__m512d)r[0], (__m512d)r[1]);  /* records 0 2 4 6 */
    __m512d h01 = _mm512_unpackhi_pd((__m512d)r[0], (__m512d)r[1]);  /* records 1 3 5 7 */
    __m512d l23 = _mm512_unpacklo_pd((__m512d)r[2], (__m512d)r[3]);
    __m512d h23 = _mm512_unpackhi_pd((__m512d)r[2], (__m512d)r[3]);
    const __m512i i02 = _mm512_set_epi64(8 + 3, 8 + 2, 3, 2, 8 + 1, 8 + 0, 1, 0);
    const __m512i i46 = _mm512_set_epi64(8 + 7, 8 + 6, 7, 6, 8 + 5, 8 + 4, 5, 4);
    __m512d r02 = _mm512_permutex2var_pd(l01, i02, l23), r13 = _mm512_permutex2var_pd(h01, i02, h23);
    __m512d r46 = _mm512_permutex2var_pd(l01, i46, l23), r57 = _mm512_permutex2var_pd(h01, i46, h23);
    _mm512_storeu_pd(a, _mm512_shuffle_f64x2(r02, r13, 0x44));       /* records 0, 1 */
    _mm512_storeu_pd(a + 8, _mm512_shuffle_f64x2(r02, r13, 0xEE));   /* records 2, 3 */
    _mm512_storeu_pd(a + 16, _mm512_shuffle_f64x2(r46, r57, 0x44));  /* records 4, 5 */
    _mm512_storeu_pd(a + 24, _mm512_shuffle_f64x2(r46, r57, 0xEE));  /* records 6, 7 */
}
/* the force (a = force + SOFTGYM_FM_STRIDE i) or moment columns of 8 voxels' rows as rows
   x, y, z (element 3 of each record dropped: the compiler drops its permute) */
static inline void softgym_v8_load4_fm(const double *a, softgym_v8 *x, softgym_v8 *y,
                                       softgym_v8 *z)
{
    softgym_v8 r[4];
    softgym_v8_load4x4_fm(a, r);
    *x = r[0];
    *y = r[1];
    *z = r[2];
}
/* 8 links' (or voxels') vectors (x, y, z) in the lanes of x, y, z as their rows of 4 (x,
   y, z, z: lane 3 lands in a force or moment row's padding), two to a register: link k's
   in half k / 4 of out[k % 4] (SOFTGYM_ROW8 pairs a force's with a moment's, the link
   scatters add them to the voxels' rows) */
static inline void softgym_v8_rows4(softgym_v8 x, softgym_v8 y, softgym_v8 z, __m512d *out)
{
    __m512d t0 = _mm512_unpacklo_pd((__m512d)x, (__m512d)y);  /* x0 y0 x2 y2 x4 y4 x6 y6 */
    __m512d t1 = _mm512_unpackhi_pd((__m512d)x, (__m512d)y);  /* x1 y1 x3 y3 x5 y5 x7 y7 */
    out[0] = _mm512_permutex2var_pd(t0, _mm512_set_epi64(12, 12, 5, 4, 8, 8, 1, 0), (__m512d)z);
    out[1] = _mm512_permutex2var_pd(t1, _mm512_set_epi64(13, 13, 5, 4, 9, 9, 1, 0), (__m512d)z);
    out[2] = _mm512_permutex2var_pd(t0, _mm512_set_epi64(14, 14, 7, 6, 10, 10, 3, 2),
                                    (__m512d)z);
    out[3] = _mm512_permutex2var_pd(t1, _mm512_set_epi64(15, 15, 7, 6, 11, 11, 3, 2),
                                    (__m512d)z);
}
/* the 8 lanes of a voxel's force and moment row (double fm + i: SOFTGYM_FM_STRIDE) into
   a: the register c where carried (the row a store has just made: a link's voxel 1 that
   is the last link's voxel 2), else a load that would wait on such a store */
#define SOFTGYM_ROW_OR_CARRIED(carried, a, c, fm, i) do { \
        if (carried) \
            a = c; \
        else \
            a = _mm512_load_pd((fm) + (i)); \
    } while (0)
/* link k's rows of 4 in two of softgym_v8_rows4's outputs (w for the force, u for the
   moment) as one row of 8: the voxel's force and moment lanes */
#define SOFTGYM_ROW8(w, u, k) \
    ((k) < 4 ? _mm512_shuffle_f64x2((w)[(k) % 4], (u)[(k) % 4], 0x44) \
             : _mm512_shuffle_f64x2((w)[(k) % 4], (u)[(k) % 4], 0xEE))
/* M(0); M(1); ... M(7): a block's 8 links in order, each index a compile-time constant */
#define SOFTGYM_EACH8(M) do { \
        M(0); M(1); M(2); M(3); M(4); M(5); M(6); M(7); \
    } while (0)
/* whether the 8 indices v[0..7] are v[0], v[0] + 1, ..., v[0] + 7 (a run of records) */
static inline int softgym_run8(const Py_ssize_t *v)
{
    __m512i a = _mm512_loadu_si512((const void *)v);
    __m512i e = _mm512_add_epi64(_mm512_set1_epi64((long long)v[0]),
                                 _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0));
    return _mm512_cmpeq_epi64_mask(a, e) == 0xFF;
}
/* 8 links whose voxels all lie in the 16 voxels from the first link's voxel 1 a[0] (a
   lattice's links along its fastest axis, and most blocks of a sparse body): 1 and each
   link's voxels' places in that window (ia: voxel 1's a[k], ib: voxel 2's b[k]; indices
   below vend, the end of the voxels' records), else 0; both models' link passes then
   pick each link's numbers from the window's two vectors of a row (a two-source permute) */
static inline int softgym_window8_index(const Py_ssize_t *a, const Py_ssize_t *b,
                                        Py_ssize_t vend, __m512i *ia, __m512i *ib)
{
    Py_ssize_t base = a[0];
    if (base + 16 > vend)
        return 0;
    __m512i vbase = _mm512_set1_epi64((long long)base), sixteen = _mm512_set1_epi64(16);
    *ia = _mm512_sub_epi64(_mm512_loadu_si512((const void *)a), vbase);
    *ib = _mm512_sub_epi64(_mm512_loadu_si512((const void *)b), vbase);
    return (_mm512_cmplt_epu64_mask(*ia, sixteen) & _mm512_cmplt_epu64_mask(*ib, sixteen))
           == 0xFF;
}

#else
#define SOFTGYM_VLANES 4
typedef double softgym_vd __attribute__((vector_size(32)));
#define SOFTGYM_VSQRT(v) ((softgym_vd)_mm256_sqrt_pd((__m256d)(v)))
#endif
/* 4 doubles in a register (the 4-lane gathers' rows): AVX's own type here, GCC's vector
   of 4 doubles in the portable builds (below) */
typedef __m256d softgym_m4;
#define SOFTGYM_V4SQRT(v) ((softgym_v4)_mm256_sqrt_pd((__m256d)(v)))
/* (a, b, c, d) as 4 lanes; 4 doubles from p (unaligned) */
#define SOFTGYM_M4SET(a, b, c, d) _mm256_set_pd((d), (c), (b), (a))
#define SOFTGYM_M4LOADU(p) _mm256_loadu_pd(p)
#define SOFTGYM_M4STOREU(p, v) _mm256_storeu_pd((p), (v))
/* elements k and k + 1 of 4 voxels' rows at pa..pd as two rows of 4 lanes (lo_: k, hi_: k + 1) */
#define SOFTGYM_GATHER_PAIRS(pa, pb, pc, pd, k, lo_, hi_) do { \
        __m256d ac_ = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd((pa) + (k))), \
                                           _mm_loadu_pd((pc) + (k)), 1); \
        __m256d bd_ = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd((pb) + (k))), \
                                           _mm_loadu_pd((pd) + (k)), 1); \
        lo_ = _mm256_unpacklo_pd(ac_, bd_); \
        hi_ = _mm256_unpackhi_pd(ac_, bd_); \
    } while (0)
/* rows a..d (4 doubles each) transposed: r0 = the a..d's element 0, ..., r3 element 3 */
#define SOFTGYM_TRANSPOSE4(a, b, c, d, r0, r1, r2, r3) do { \
        __m256d t0_ = _mm256_unpacklo_pd(a, b), t1_ = _mm256_unpackhi_pd(a, b); \
        __m256d t2_ = _mm256_unpacklo_pd(c, d), t3_ = _mm256_unpackhi_pd(c, d); \
        r0 = _mm256_permute2f128_pd(t0_, t2_, 0x20); \
        r1 = _mm256_permute2f128_pd(t1_, t3_, 0x20); \
        r2 = _mm256_permute2f128_pd(t0_, t2_, 0x31); \
        r3 = _mm256_permute2f128_pd(t1_, t3_, 0x31); \
    } while (0)
/* v (4 or 8 lanes of softgym_vd) rounded to floats at row + li */
#if SOFTGYM_VLANES == 8
#define SOFTGYM_VPUTF(row, li, v) _mm256_storeu_ps((row) + (li), _mm512_cvtpd_ps((__m512d)(v)))
#else
#define SOFTGYM_VPUTF(row, li, v) _mm_storeu_ps((row) + (li), _mm256_cvtpd_ps((__m256d)(v)))
#endif
#elif defined(__GNUC__) || defined(__clang__)
/* The portable builds (x86-64 without AVX: SSE2; aarch64: NEON; any target GCC or clang
   knows): the same 4-lane link passes on GCC's vectors of 4 doubles, which the compiler
   lowers to the target's registers (two SSE2 or NEON registers a vector), with the
   loads and permutes written as element reads instead of AVX intrinsics. The arithmetic
   is the formulas' own, lane by lane: the same bits as the scalar loops they replace. */
#define SOFTGYM_VLANES 4
#define SOFTGYM_PORTABLE_LANES 1
#if defined(__GNUC__) && !defined(__clang__)
/* GCC notes that a 32-byte vector passed or returned without AVX would change the
   calling convention: these are static inline helpers, no call crosses a boundary */
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
typedef double softgym_vd __attribute__((vector_size(32)));
typedef softgym_vd softgym_m4;
#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__aarch64__) && defined(__ARM_NEON)
#include <arm_neon.h>
#endif
/* v's two halves as registers of type T, each replaced by SQRT of it */
#define SOFTGYM_M4SQRT_HALVES(T, SQRT) do { \
        T lo_, hi_; \
        memcpy(&lo_, &v, sizeof lo_); \
        memcpy(&hi_, (const char *)&v + sizeof lo_, sizeof hi_); \
        lo_ = SQRT(lo_); \
        hi_ = SQRT(hi_); \
        memcpy(&v, &lo_, sizeof lo_); \
        memcpy((char *)&v + sizeof lo_, &hi_, sizeof hi_); \
    } while (0)
/* the square root of each lane (IEEE, as sqrt) */
static inline softgym_vd softgym_m4sqrt(softgym_vd v)
{
#if defined(__SSE2__)
    SOFTGYM_M4SQRT_HALVES(__m128d, _mm_sqrt_pd);
#elif defined(__aarch64__) && defined(__ARM_NEON)
    SOFTGYM_M4SQRT_HALVES(float64x2_t, vsqrtq_f64);
#else
    for (int k = 0; k < 4; k++)
        v[k] = sqrt(v[k]);
#endif
    return v;
}
#undef SOFTGYM_M4SQRT_HALVES
#define SOFTGYM_VSQRT(v) softgym_m4sqrt(v)
#define SOFTGYM_V4SQRT(v) softgym_m4sqrt(v)
#define SOFTGYM_M4SET(a, b, c, d) ((softgym_vd){(a), (b), (c), (d)})
static inline softgym_vd softgym_m4loadu(const double *p)
{
    softgym_vd v;
    memcpy(&v, p, sizeof v);
    return v;
}
#define SOFTGYM_M4LOADU(p) softgym_m4loadu(p)
#define SOFTGYM_M4STOREU(p, v) do { \
        softgym_vd v_ = (v); \
        memcpy((p), &v_, sizeof v_); \
    } while (0)
#define SOFTGYM_GATHER_PAIRS(pa, pb, pc, pd, k, lo_, hi_) do { \
        lo_ = SOFTGYM_M4SET((pa)[k], (pb)[k], (pc)[k], (pd)[k]); \
        hi_ = SOFTGYM_M4SET((pa)[(k) + 1], (pb)[(k) + 1], (pc)[(k) + 1], (pd)[(k) + 1]); \
    } while (0)
#define SOFTGYM_TRANSPOSE4(a, b, c, d, r0, r1, r2, r3) do { \
        softgym_vd a_ = (a), b_ = (b), c_ = (c), d_ = (d); \
        r0 = SOFTGYM_M4SET(a_[0], b_[0], c_[0], d_[0]); \
        r1 = SOFTGYM_M4SET(a_[1], b_[1], c_[1], d_[1]); \
        r2 = SOFTGYM_M4SET(a_[2], b_[2], c_[2], d_[2]); \
        r3 = SOFTGYM_M4SET(a_[3], b_[3], c_[3], d_[3]); \
    } while (0)
typedef float softgym_v4f __attribute__((vector_size(16)));
#define SOFTGYM_VPUTF(row, li, v) do { \
        softgym_v4f f_ = __builtin_convertvector((v), softgym_v4f); \
        memcpy((row) + (li), &f_, sizeof f_); \
    } while (0)
#endif
#if defined(SOFTGYM_VLANES)
typedef long long softgym_vi __attribute__((vector_size(sizeof(softgym_vd))));
/* 4 lanes whatever the build (a pass with many rows live at once: with AVX-512 these
   take the 32 vector registers at half width, where 8 lanes spilled) */
typedef double softgym_v4 __attribute__((vector_size(32)));
typedef long long softgym_v4i __attribute__((vector_size(32)));
/* name(v): |v| lane by lane for the vector type VT (its integer twin VI): the sign bit
   cleared, as fabs */
#define SOFTGYM_DEFINE_VABS(name, VT, VI) \
    static inline VT name(VT v) \
    { \
        VI bits; \
        memcpy(&bits, &v, sizeof bits); \
        bits &= 0x7fffffffffffffffLL; \
        memcpy(&v, &bits, sizeof v); \
        return v; \
    }
SOFTGYM_DEFINE_VABS(softgym_vabs, softgym_vd, softgym_vi)
SOFTGYM_DEFINE_VABS(softgym_v4abs, softgym_v4, softgym_v4i)
/* v (of type VT) stored at row + li (lanes li ..) */
#define SOFTGYM_VTPUT(VT, row, li, v) do { \
        VT v_ = (v); \
        memcpy((row) + (li), &v_, sizeof v_); \
    } while (0)
#define SOFTGYM_VPUT(row, li, v) SOFTGYM_VTPUT(softgym_vd, row, li, v)
#define SOFTGYM_V4PUT(row, li, v) SOFTGYM_VTPUT(softgym_v4, row, li, v)
/* records of 3 doubles a voxel and rows of lanes, both ways: softgym_v4_load3 turns 4
   voxels' records (a[0..11]) into rows x, y, z and softgym_v4_store3 back (AVX shuffles);
   softgym_v2_load3, softgym_v2_store3 the same for 2 voxels in the SSE2 registers of the
   portable x86-64 build (the voxel updates and orientation steps of the builds whose step
   loops keep the voxels' state in their records: softgym_voxels.h, softgym_orient.h) */
#if defined(__AVX__) && (defined(__GNUC__) || defined(__clang__))
/* 4 voxels' records of 3 (a[0..11]) as rows x, y, z */
static inline void softgym_v4_load3(const double *a, softgym_v4 *x, softgym_v4 *y,
                                    softgym_v4 *z)
{
    __m256d A = _mm256_loadu_pd(a), B = _mm256_loadu_pd(a + 4), C = _mm256_loadu_pd(a + 8);
    __m256d xy = _mm256_blend_pd(A, B, 0xC);          /* x0 y0 x2 y2 */
    __m256d zx = _mm256_permute2f128_pd(A, C, 0x21);  /* z0 x1 z2 x3 */
    __m256d yz = _mm256_blend_pd(B, C, 0xC);          /* y1 z1 y3 z3 */
    *x = (softgym_v4)_mm256_blend_pd(xy, zx, 0xA);
    *y = (softgym_v4)_mm256_shuffle_pd(xy, yz, 0x5);
    *z = (softgym_v4)_mm256_blend_pd(zx, yz, 0xA);
}
/* rows x, y, z of 4 voxels as their records of 3 at a[0..11] */
static inline void softgym_v4_store3(double *a, softgym_v4 x, softgym_v4 y, softgym_v4 z)
{
    __m256d X = (__m256d)x, Y = (__m256d)y, Z = (__m256d)z;
    __m256d xy = _mm256_unpacklo_pd(X, Y);   /* x0 y0 x2 y2 */
    __m256d xyh = _mm256_unpackhi_pd(X, Y);  /* x1 y1 x3 y3 */
    __m256d zx = _mm256_unpacklo_pd(Z, xyh); /* z0 x1 z2 x3 */
    __m256d yz = _mm256_unpackhi_pd(xyh, Z); /* y1 z1 y3 z3 */
    _mm256_storeu_pd(a, _mm256_permute2f128_pd(xy, zx, 0x20));
    _mm256_storeu_pd(a + 4, _mm256_blend_pd(yz, xy, 0xC));
    _mm256_storeu_pd(a + 8, _mm256_permute2f128_pd(zx, yz, 0x31));
}
#elif defined(__SSE2__) && (defined(__GNUC__) || defined(__clang__))
#include <emmintrin.h>
typedef double softgym_v2 __attribute__((vector_size(16)));
typedef long long softgym_v2i __attribute__((vector_size(16)));
SOFTGYM_DEFINE_VABS(softgym_v2abs, softgym_v2, softgym_v2i)
/* 2 voxels' records of 3 (a[0..5]: x0 y0 z0 x1 y1 z1) as rows x, y, z, and back */
static inline void softgym_v2_load3(const double *a, softgym_v2 *x, softgym_v2 *y,
                                    softgym_v2 *z)
{
    __m128d A = _mm_loadu_pd(a), B = _mm_loadu_pd(a + 2), C = _mm_loadu_pd(a + 4);
    *x = (softgym_v2)_mm_shuffle_pd(A, B, 0x2);
    *y = (softgym_v2)_mm_shuffle_pd(A, C, 0x1);
    *z = (softgym_v2)_mm_shuffle_pd(B, C, 0x2);
}
static inline void softgym_v2_store3(double *a, softgym_v2 x, softgym_v2 y, softgym_v2 z)
{
    __m128d X = (__m128d)x, Y = (__m128d)y, Z = (__m128d)z;
    _mm_storeu_pd(a, _mm_unpacklo_pd(X, Y));
    _mm_storeu_pd(a + 2, _mm_shuffle_pd(Z, X, 0x2));
    _mm_storeu_pd(a + 4, _mm_unpackhi_pd(Y, Z));
}
#endif
/* 4 consecutive values of a row from li, as 4 lanes */
static inline softgym_v4 softgym_v4load(const double *row, Py_ssize_t li)
{
    softgym_v4 v;
    memcpy(&v, row + li, sizeof v);
    return v;
}
/* rows of 4 lanes a[0..m) (links 0-3) and b[0..m) (links 4-7) as m rows of softgym_vd (with
   4 lanes, b is not read) */
#if SOFTGYM_VLANES == 8
#define SOFTGYM_VJOIN(r, a, b, m) do { \
        for (int k_ = 0; k_ < (m); k_++) \
            (r)[k_] = (softgym_vd)_mm512_insertf64x4(_mm512_castpd256_pd512((a)[k_]), (b)[k_], 1); \
    } while (0)
#else
#define SOFTGYM_VJOIN(r, a, b, m) do { \
        for (int k_ = 0; k_ < (m); k_++) \
            (r)[k_] = (softgym_vd)(a)[k_]; \
    } while (0)
#endif
#endif

/* f(a, ...) with the link axis a = ax as a compile-time constant: one copy of an
   always-inline pass per axis */
#define SOFTGYM_BY_AXIS(ax, f, ...) do { \
        if ((ax) == 0) \
            f(0, __VA_ARGS__); \
        else if ((ax) == 1) \
            f(1, __VA_ARGS__); \
        else \
            f(2, __VA_ARGS__); \
    } while (0)
/* voxel j's row of 3 in a (rows of 3 doubles) minus voxel i's, declared as doubles dx, dy, dz */
#define SOFTGYM_DIFF3(a, i, j, dx, dy, dz) \
    double dx = (a)[3 * (j)] - (a)[3 * (i)], dy = (a)[3 * (j) + 1] - (a)[3 * (i) + 1]; \
    double dz = (a)[3 * (j) + 2] - (a)[3 * (i) + 2]
/* v stored at row[li] (a pass's formula macro on doubles; SOFTGYM_VPUT on vectors) */
#define SOFTGYM_PUT1(row, li, v) ((row)[li] = (v))

/* 1 where the seed model's step takes each link's rotation of voxel 1 from the geometry's
   rows (softgym_seed.h: the AVX-512 builds' scatter) and does not read the voxels'
   rotation matrices: the seed voxel update then leaves them to advance_robot's end */
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
#define SOFTGYM_SEED_R_USED 1
#else
#define SOFTGYM_SEED_R_USED 0
#endif
/* 1 where neither model's step loop reads the voxels' rotation matrices (Batch.rot): the
   seed's (SOFTGYM_SEED_R_USED) and the corotational links', which read rows of matrices
   computed from the quaternions (softgym_corot.h: softgym_corot_rows); the voxel updates
   then do not store them, and advance_robot refreshes them when it returns */
#define SOFTGYM_ROT_DEFERRED SOFTGYM_SEED_R_USED
/* 1 where both models' step loops keep the voxels' state in the voxel rows
   (SOFTGYM_ROW_POS ...: the AVX-512 builds) */
#define SOFTGYM_STATE_ROWS SOFTGYM_SEED_R_USED

#if defined(_MSC_VER)
#define SOFTGYM_ALWAYS_INLINE static __forceinline
#define SOFTGYM_NOINLINE static __declspec(noinline)
#else
#define SOFTGYM_ALWAYS_INLINE static inline __attribute__((always_inline))
#define SOFTGYM_NOINLINE static __attribute__((noinline))
#endif
#endif  /* SOFTGYM_SIMD_H */
