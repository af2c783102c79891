/* The seed model's single-precision frames pass alone (a probe; benchmarks/frames_probe.py
   builds and runs it).

   The engine's frames pass (softgym_seed_frames32, include/softgym_seed.h) turns each
   link's geometry into its bond-frame quantities. A chunk whose links are all in
   small-angle mode runs a copy of its loop without the large-angle candidates; a chunk
   that mixes the modes computes both candidates for every link and selects one. This
   probe times the engine's own function (the header included as it is) on given link
   geometry, chunk by chunk as links_seed calls it, so the pass's cost per mode mix can be
   measured in a second instead of a profiled run of the whole engine.

   usage: frames_probe IN OUT REPS
   IN: the geometry as links_seed's rows 0-9 leave it for the frames pass (p0, p1, p2, qw,
   n1, n2, n3, nominal length, chord length, mode 1.0 small / 0.0 large), a little-endian
   int64 link count n (a multiple of SOFTGYM_CHUNK_LINKS) then 10 rows of n doubles.
   The probe adds row 10 as the modes pass leaves it (the axial displacement in the link's
   mode). OUT: the pass's 12 float rows (P0, P1, P2, a1y, a1z, a2x, a2y, a2z, rw, ry, rz, fix), 12
   rows of n floats. Prints the quickest of REPS sweeps over the links in time-stamp
   counter cycles per 16 links. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <x86intrin.h>
typedef long Py_ssize_t;
#include "softgym_seed.h"

/* the rows of a chunk's scratch the pass reads: the geometry's 0-9 and the modes pass's 10 */
#define SOFTGYM_PROBE_ROWS 11
/* the engine's constants (_seed.pyx: SMALL_ANGLE_RAD, ACOS2SQRT_W) */
#define PROBE_SMALL_ANGLE_RAD 1.732e-2f
#define PROBE_ACOS2SQRT_W 0.9988f

int main(int argc, char **argv)
{
    if (argc != 4) {
        fprintf(stderr, "usage: frames_probe IN OUT REPS\n");
        return 2;
    }
    const Py_ssize_t cl = SOFTGYM_CHUNK_LINKS, cs = SOFTGYM_CHUNK_STRIDE;
    const Py_ssize_t fs = SOFTGYM_CHUNK_FSTRIDE;
    FILE *fin = fopen(argv[1], "rb");
    int64_t n = 0;
    if (fin == NULL || fread(&n, sizeof n, 1, fin) != 1 || n <= 0 || n % cl != 0
        || n > 1 << 22) {
        fprintf(stderr, "frames_probe: bad input %s\n", argv[1]);
        return 2;
    }
    long reps = atol(argv[3]);
    if (reps < 1)
        reps = 1;
    const Py_ssize_t nchunks = n / cl;
    /* each chunk's 10 rows of geometry, cs apart, as links_seed's scratch holds them */
    double *geo = aligned_alloc(64, sizeof(double) * SOFTGYM_PROBE_ROWS * cs * nchunks);
    float *out = aligned_alloc(64, sizeof(float) * SOFTGYM_CHUNK_FROWS * fs);
    float *res = malloc(sizeof(float) * 12 * n);
    double *row = malloc(sizeof(double) * n);
    if (geo == NULL || out == NULL || res == NULL || row == NULL)
        return 2;
    memset(geo, 0, sizeof(double) * SOFTGYM_PROBE_ROWS * cs * nchunks);
    for (int k = 0; k < 10; k++) {
        if (fread(row, sizeof(double), n, fin) != (size_t)n) {
            fprintf(stderr, "frames_probe: short input\n");
            return 2;
        }
        for (Py_ssize_t c = 0; c < nchunks; c++)
            memcpy(geo + (c * SOFTGYM_PROBE_ROWS + k) * cs, row + c * cl, sizeof(double) * cl);
    }
    fclose(fin);
    /* row 10 as the modes pass leaves it: the axial displacement in the link's mode */
    for (Py_ssize_t c = 0; c < nchunks; c++) {
        double *g = geo + c * SOFTGYM_PROBE_ROWS * cs;
        for (Py_ssize_t li = 0; li < cl; li++)
            g[10 * cs + li] = (g[9 * cs + li] != 0.0 ? g[li] : g[8 * cs + li]) - g[7 * cs + li];
    }
    unsigned long long best = ~0ULL;
    int fixes = 0;
    for (long r = 0; r < reps; r++) {
        unsigned long long t0 = __rdtsc();
        for (Py_ssize_t c = 0; c < nchunks; c++)
            fixes += softgym_seed_frames32(0, cl, cs, PROBE_SMALL_ANGLE_RAD, PROBE_ACOS2SQRT_W,
                                           geo + c * SOFTGYM_PROBE_ROWS * cs, out);
        unsigned long long t = __rdtsc() - t0;
        if (t < best)
            best = t;
    }
    /* the results of one more sweep, chunk by chunk */
    for (Py_ssize_t c = 0; c < nchunks; c++) {
        softgym_seed_frames32(0, cl, cs, PROBE_SMALL_ANGLE_RAD, PROBE_ACOS2SQRT_W,
                              geo + c * SOFTGYM_PROBE_ROWS * cs, out);
        for (int k = 0; k < 12; k++)
            memcpy(res + k * n + c * cl, out + k * fs, sizeof(float) * cl);
    }
    FILE *fout = fopen(argv[2], "wb");
    if (fout == NULL || fwrite(res, sizeof(float), 12 * n, fout) != (size_t)(12 * n)) {
        fprintf(stderr, "frames_probe: cannot write %s\n", argv[2]);
        return 2;
    }
    fclose(fout);
    printf("%.1f\n", (double)best / ((double)n / 16.0));
    (void)fixes;
    return 0;
}
