/* The all-pairs test of the self-collision candidate lists (softgym/engine/
   _contact.pyx, _voxel_pairs): for a small robot, every pair of its surface
   voxels is tested in one vector loop instead of walking a spatial hash (the
   hash's 27 cells of edge `horizon` hold most of a small robot, so its walk
   tests nearly every pair anyway, one at a time). Py_ssize_t comes from
   Python.h, which Cython includes first. */
#ifndef SOFTGYM_PAIRS_H
#define SOFTGYM_PAIRS_H

#include "softgym_simd.h"

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
        double dx = x[k] - xa;
        double dy = y[k] - ya;
        double dz = z[k] - za;
        double d2 = dx * dx + dy * dy + dz * dz;
        long long out = d2 >= lim2;
        if (seed_rule) {
            double act = 2.0 * (ra < rank[k] ? sa : s[k]);
            out |= d2 >= act * act;
        }
        hit[k] = out == 0;
        last = out == 0 ? k : last;
    }
    return last;
}
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
