/* The all-pairs test of the self-collision candidate lists (softgym/engine/
   _contact.pyx, _voxel_pairs): for a small robot, every pair of its surface
   voxels is tested in one vector loop instead of walking a spatial hash (the
   hash's 27 cells of edge `horizon` hold most of a small robot, so its walk
   tests nearly every pair anyway, one at a time). Py_ssize_t comes from
   Python.h, which Cython includes first. */
#ifndef SOFTGYM_PAIRS_H
#define SOFTGYM_PAIRS_H

#include "softgym_simd.h"

/* out = 1 where the all-pairs test drops the pair of surface voxels a (its centre xa, ya,
   za, size sa, rank ra) and k (x[k], ..., rank[k]) */
#define SOFTGYM_PAIR_OUT(seed_rule, xa, ya, za, sa, ra, x, y, z, s, rank, k, lim2, out) do { \
        double dx_ = (x)[k] - (xa); \
        double dy_ = (y)[k] - (ya); \
        double dz_ = (z)[k] - (za); \
        double d2_ = dx_ * dx_ + dy_ * dy_ + dz_ * dz_; \
        out = d2_ >= (lim2); \
        if (seed_rule) { \
            double act_ = 2.0 * ((ra) < (rank)[k] ? (sa) : (s)[k]); \
            out |= d2_ >= act_ * act_; \
        } \
    } while (0)

/* hit[b] = 1 where the surface voxels a < b (b in a + 1 .. n - 1) are
   candidates, else 0. Their centres: x, y, z; sizes s and ranks in the seed's
   voxel order rank (used with seed_rule). seed_rule (a compile-time constant
   in each copy): the pair is kept unless d2 >= lim2 (9 L^2) or d2 >= act^2,
   act twice the size of the pair's first voxel in the seed's order; else
   unless d2 >= lim2 (the horizon squared). The same expressions and
   comparisons as the hash's scalar test (a NaN distance is kept, as there).
   hit is 64-bit: with 8-bit flags the loop took 64 voxels a vector iteration,
   and the rows of a small robot (shorter than 64) ran in its scalar remainder.
   Returns the last b with hit[b] = 1 (a if none): the caller's walk over the flags
   stops there. */
SOFTGYM_ALWAYS_INLINE Py_ssize_t softgym_pair_hits_impl(const int seed_rule, Py_ssize_t a,
                                                        Py_ssize_t n, const double *x,
                                                        const double *y, const double *z,
                                                        const double *s,
                                                        const Py_ssize_t *rank, double lim2,
                                                        long long *hit)
{
    const double xa = x[a], ya = y[a], za = z[a], sa = s[a];
    const Py_ssize_t ra = rank[a];
    Py_ssize_t k;
    long long last = a;
    SOFTGYM_IVDEP
    for (k = a + 1; k < n; k++) {
        long long out;
        SOFTGYM_PAIR_OUT(seed_rule, xa, ya, za, sa, ra, x, y, z, s, rank, k, lim2, out);
        hit[k] = out == 0;
        last = out == 0 ? k : last;
    }
    return last;
}
#if defined(SOFTGYM_VLANES) && (SOFTGYM_VLANES == 8 || defined(__AVX2__)) && \
    (defined(__GNUC__) || defined(__clang__))
#define SOFTGYM_PAIR_IDX 1
/* bits k .. k + 63 of the exclusion row xb (the next word's low bits past its end) */
SOFTGYM_ALWAYS_INLINE unsigned long long softgym_xbits_at(const unsigned long long *xb,
                                                          Py_ssize_t k)
{
    const int sh = (int)(k & 63);
    const unsigned long long w0 = xb[k >> 6], w1 = xb[(k >> 6) + 1];
    return (w0 >> sh) | (sh ? w1 << (64 - sh) : 0);
}
/* the vector loops' last voxels b = k .. n - 1, one at a time (SOFTGYM_PAIR_OUT and the
   exclusion bit), their kept indices stored from idx[m]; returns the count */
SOFTGYM_ALWAYS_INLINE Py_ssize_t softgym_pair_idx_tail(const int seed_rule, Py_ssize_t a,
                                                       Py_ssize_t k, Py_ssize_t m,
                                                       Py_ssize_t n, const double *x,
                                                       const double *y, const double *z,
                                                       const double *s,
                                                       const Py_ssize_t *rank, double lim2,
                                                       const unsigned long long *xb,
                                                       long long *idx)
{
    const double xa = x[a], ya = y[a], za = z[a], sa = s[a];
    const Py_ssize_t ra = rank[a];
    for (; k < n; k++) {
        long long out;
        SOFTGYM_PAIR_OUT(seed_rule, xa, ya, za, sa, ra, x, y, z, s, rank, k, lim2, out);
        out |= (long long)((xb[k >> 6] >> (k & 63)) & 1);
        idx[m] = k;
        m += out == 0;
    }
    return m;
}
#endif
#if defined(SOFTGYM_VLANES) && SOFTGYM_VLANES == 8
/* the same test with AVX-512, 8 voxels b a vector, its candidates' indices b compressed
   into idx[0..] in increasing order (a two-uop compress a vector where the caller walked
   every flag up to the last hit, a branch each: on an Intel Xeon a third of the list's
   rebuilds); returns how many. Each lane's decision is SOFTGYM_PAIR_OUT's, written in its
   shape (so that the build fuses the same multiply-adds). xb: voxel a's row of exclusion
   bits (bit b set: a and b are within the exclusion hops; at least n / 64 + 2 words),
   whose pairs are dropped with the others: the caller no longer walks a's exclusion list
   candidate by candidate (that walk was a third of the list's rebuilds) */
SOFTGYM_ALWAYS_INLINE Py_ssize_t softgym_pair_idx_impl(const int seed_rule, Py_ssize_t a,
                                                       Py_ssize_t n, const double *x,
                                                       const double *y, const double *z,
                                                       const double *s,
                                                       const Py_ssize_t *rank, double lim2,
                                                       const unsigned long long *xb,
                                                       long long *idx)
{
    const double xa = x[a], ya = y[a], za = z[a], sa = s[a];
    const Py_ssize_t ra = rank[a];
    Py_ssize_t k = a + 1, m = 0;
    __m512i kv = _mm512_add_epi64(_mm512_set1_epi64(k), _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0));
    const __m512i eight = _mm512_set1_epi64(8);
    for (; k + 8 <= n; k += 8) {
        softgym_v8 dx = softgym_v8_load(x + k) - xa;
        softgym_v8 dy = softgym_v8_load(y + k) - ya;
        softgym_v8 dz = softgym_v8_load(z + k) - za;
        softgym_v8 d2 = dx * dx + dy * dy + dz * dz;
        __mmask8 out = _mm512_cmp_pd_mask((__m512d)d2, _mm512_set1_pd(lim2), _CMP_GE_OQ);
        if (seed_rule) {
            __mmask8 first = _mm512_cmpgt_epi64_mask(_mm512_loadu_si512((const void *)(rank + k)),
                                                     _mm512_set1_epi64(ra));
            softgym_v8 act = 2.0 * (softgym_v8)_mm512_mask_blend_pd(
                first, _mm512_loadu_pd(s + k), _mm512_set1_pd(sa));
            out |= _mm512_cmp_pd_mask((__m512d)d2, (__m512d)(act * act), _CMP_GE_OQ);
        }
        /* bits k .. k + 7 of the exclusion row */
        out |= (__mmask8)softgym_xbits_at(xb, k);
        __mmask8 keep = ~out;
        /* most vectors keep no pair (the exclusions dropped): no store, and no step of the
           chain through m (mask, count, add: its latency was the loop's bound) */
        if (keep) {
            _mm512_storeu_si512((void *)(idx + m), _mm512_maskz_compress_epi64(keep, kv));
            m += __builtin_popcount((unsigned)keep);
        }
        kv = _mm512_add_epi64(kv, eight);
    }
    return softgym_pair_idx_tail(seed_rule, a, k, m, n, x, y, z, s, rank, lim2, xb, idx);
}
#elif defined(__AVX2__) && defined(SOFTGYM_VLANES) && (defined(__GNUC__) || defined(__clang__))
/* the same with AVX2, 4 voxels b a vector (softgym_v4: GCC's vector of 4 doubles, the
   decision written in SOFTGYM_PAIR_OUT's shape, as the AVX-512 loop's), each kept voxel's
   index stored at idx[m] and m advanced by its bit (no branch a lane) */
SOFTGYM_ALWAYS_INLINE Py_ssize_t softgym_pair_idx_impl(const int seed_rule, Py_ssize_t a,
                                                       Py_ssize_t n, const double *x,
                                                       const double *y, const double *z,
                                                       const double *s,
                                                       const Py_ssize_t *rank, double lim2,
                                                       const unsigned long long *xb,
                                                       long long *idx)
{
    const double xa = x[a], ya = y[a], za = z[a], sa = s[a];
    const Py_ssize_t ra = rank[a];
    Py_ssize_t k = a + 1, m = 0;
    for (; k + 4 <= n; k += 4) {
        softgym_v4 dx, dy, dz;
        memcpy(&dx, x + k, sizeof dx);
        memcpy(&dy, y + k, sizeof dy);
        memcpy(&dz, z + k, sizeof dz);
        dx = dx - xa;
        dy = dy - ya;
        dz = dz - za;
        softgym_v4 d2 = dx * dx + dy * dy + dz * dz;
        int out = _mm256_movemask_pd(_mm256_cmp_pd((__m256d)d2, _mm256_set1_pd(lim2), _CMP_GE_OQ));
        if (seed_rule) {
            __m256d first = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
                _mm256_loadu_si256((const __m256i *)(rank + k)), _mm256_set1_epi64x(ra)));
            softgym_v4 act = 2.0 * (softgym_v4)_mm256_blendv_pd(_mm256_loadu_pd(s + k),
                                                                 _mm256_set1_pd(sa), first);
            out |= _mm256_movemask_pd(_mm256_cmp_pd((__m256d)d2, (__m256d)(act * act),
                                                    _CMP_GE_OQ));
        }
        /* bits k .. k + 3 of the exclusion row */
        out |= (int)(softgym_xbits_at(xb, k) & 15);
        const int keep = ~out & 15;
        if (keep) {
            for (int l = 0; l < 4; l++) {
                idx[m] = k + l;
                m += (keep >> l) & 1;
            }
        }
    }
    return softgym_pair_idx_tail(seed_rule, a, k, m, n, x, y, z, s, rank, lim2, xb, idx);
}
#endif
#if SOFTGYM_PAIR_IDX
static Py_ssize_t softgym_pair_idx(int seed_rule, Py_ssize_t a, Py_ssize_t n, const double *x,
                                   const double *y, const double *z, const double *s,
                                   const Py_ssize_t *rank, double lim2,
                                   const unsigned long long *xb, long long *idx)
{
    if (seed_rule)
        return softgym_pair_idx_impl(1, a, n, x, y, z, s, rank, lim2, xb, idx);
    return softgym_pair_idx_impl(0, a, n, x, y, z, s, rank, lim2, xb, idx);
}
#else
#define SOFTGYM_PAIR_IDX 0
static Py_ssize_t softgym_pair_idx(int seed_rule, Py_ssize_t a, Py_ssize_t n, const double *x,
                                   const double *y, const double *z, const double *s,
                                   const Py_ssize_t *rank, double lim2,
                                   const unsigned long long *xb, long long *idx)
{
    (void)seed_rule; (void)a; (void)n; (void)x; (void)y; (void)z; (void)s; (void)rank;
    (void)lim2; (void)xb; (void)idx;
    return 0;
}
#endif
static Py_ssize_t softgym_pair_hits(int seed_rule, Py_ssize_t a, Py_ssize_t n,
                                    const double *x, const double *y, const double *z,
                                    const double *s, const Py_ssize_t *rank, double lim2,
                                    long long *hit)
{
    if (seed_rule)
        return softgym_pair_hits_impl(1, a, n, x, y, z, s, rank, lim2, hit);
    return softgym_pair_hits_impl(0, a, n, x, y, z, s, rank, lim2, hit);
}

#endif  /* SOFTGYM_PAIRS_H */
