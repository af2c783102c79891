/* A measurement, not part of the engine: what the seed model's link geometry and force
   scatter would cost on a dense lattice, against the engine's own passes.

   The engine (softgym/engine/include/softgym_seed.h) keeps a robot's links in a list,
   sorted by axis and then by voxel 1's lattice cell: its geometry pass gathers both
   voxels' positions, orientations and sizes link by link, and its scatter turns each
   link's bond-frame forces and moments to the world and adds them to its two voxels'
   rows, in link order. On a dense lattice (voxel data packed into rows indexed by cell;
   a link slot for every cell, voxel 2 a constant number of cells away along each axis)
   the same passes read unit-stride rows instead:
     pack      voxel positions, orientations and sizes into eight rows by cell;
     geometry  softgym_seed_geom_ax's arithmetic on slots, loads at c and c + s;
     turn      each slot's four bond-frame vectors to the world in vector lanes (voxel
               1's rotation from the packed quaternion, the scatter's turn formula);
     pull      each cell's force and moment: its six links' world vectors added in the
               engine's order (along x as voxel 2, as voxel 1, then y, then z), a missing
               link skipped by a select (adding +0.0 could turn a -0.0 sum into +0.0).
   Both sides run on the same state; the program checks that the dense results equal
   the engine's bit for bit and prints time-stamp-counter cycles per voxel-step of each
   part (the quickest of REPS repeats), and the slots the dense form computes for
   nothing (the modes, frames and forces passes would run on every slot).

   Usage: dense_links_probe [N [FILL [SEED]]]: an N^3 lattice (default 6), each cell
   occupied with probability FILL (default 1.0). Built and run by dense_links_probe.py
   with the kernel's compiler flags. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <x86intrin.h>
typedef long Py_ssize_t;
#include "softgym_seed.h"

#define REPS 3000
#define NROWS 25 /* rows of the engine's link scratch (N_LINK_OUT) */

static int NX, NY, NZ, NC; /* lattice and cell count; cell (x, y, z) = (x NY + y) NZ + z */

static double urand(void) { return rand() / (double)RAND_MAX - 0.5; }
static Py_ssize_t stride_of(int n) { return (n + 15) / 16 * 16 + 16; }

/* the geometry of slots [0, hi) along axis ax: voxel 1 in cell c, voxel 2 in c + s;
   the engine's arithmetic (SOFTGYM_SEED_GEOM_LINK) into rows of o as softgym_seed_geom_ax's
   (P: the packed rows, 8 of NC) */
SOFTGYM_ALWAYS_INLINE void geom_dense_ax(const int ax, Py_ssize_t s, Py_ssize_t hi,
                                         Py_ssize_t n, const double *P, double *o)
{
    SOFTGYM_SEED_GEOM_AXIS(ax);
    SOFTGYM_SEED_GEOM_OUT(o, n);
    const double *__restrict__ px = P, *__restrict__ py = P + NC, *__restrict__ pz = P + 2 * NC;
    const double *__restrict__ qw_ = P + 3 * NC, *__restrict__ qx_ = P + 4 * NC;
    const double *__restrict__ qy_ = P + 5 * NC, *__restrict__ qz_ = P + 6 * NC;
    const double *__restrict__ sc = P + 7 * NC;
    Py_ssize_t c;
    SOFTGYM_IVDEP
    for (c = 0; c < hi; c++) {
        Py_ssize_t i = c, j = c + s;
        double dx = px[j] - px[i], dy = py[j] - py[i], dz = pz[j] - pz[i];
        double w = qw_[i], x = qx_[i], y = qy_[i], z = qz_[i];
        double wj = qw_[j], xj = qx_[j], yj = qy_[j], zj = qz_[j];
        SOFTGYM_SEED_GEOM_LINK(c, dx, dy, dz, w, x, y, z, wj, xj, yj, zj, sc[i], sc[j]);
    }
}

/* the turn of slots [0, hi) along axis ax: bond-frame rows (f1: 0-2, f2: 3-5, m1: 6-8,
   m2: 9, 21, 24; row 23: voxel 2 takes -F1) of bo to the world, W rows 0-2 voxel 1's
   force, 3-5 voxel 2's, 6-8 voxel 1's moment, 9-11 voxel 2's: lane k of the scatter's
   turn, R1 P^T v (P^T the inverse axis turn; for y and z links R1's first column
   negated, as the scatter does) */
SOFTGYM_ALWAYS_INLINE void turn_dense_ax(const int ax, Py_ssize_t hi, Py_ssize_t n,
                                         const double *bo, const double *P, double *W)
{
    Py_ssize_t c;
    SOFTGYM_IVDEP
    for (c = 0; c < hi; c++) {
        double R[9], v[12], w[12];
        softgym_quat_matrix_wxyz(P[3 * NC + c], P[4 * NC + c], P[5 * NC + c], P[6 * NC + c], R);
        for (int k = 0; k < 10; k++)
            v[k] = bo[k * n + c];
        v[10] = bo[21 * n + c];
        v[11] = bo[24 * n + c];
        long long neg2 = bo[23 * n + c] != 0.0;
        const double c0s = ax == 0 ? 1.0 : -1.0;
        for (int q = 0; q < 4; q++) {
            double a = v[3 * q], b = v[3 * q + 1], d = v[3 * q + 2], x, y, z;
            if (ax == 0) {
                x = a; y = b; z = d;
            } else if (ax == 1) {
                x = b; y = a; z = d;
            } else {
                x = d; y = b; z = a;
            }
            for (int k = 0; k < 3; k++)
                w[3 * q + k] = (((c0s * R[3 * k]) * x + R[3 * k + 1] * y) + R[3 * k + 2] * z);
        }
        for (int k = 0; k < 3; k++)
            w[3 + k] = softgym_pick(neg2, -w[k], w[3 + k]);
        for (int k = 0; k < 12; k++)
            W[k * n + c] = w[k];
    }
}

/* one link's world vectors added to a cell's sums, or skipped (ok: the link exists) */
SOFTGYM_ALWAYS_INLINE void pull_term(Py_ssize_t n, const double *Wa, const double *va,
                                     Py_ssize_t d, int r, double *f, double *m)
{
    long long ok = va[d] != 0.0;
    for (int k = 0; k < 3; k++) {
        f[k] = softgym_pick(ok, f[k] + Wa[(r + k) * n + d], f[k]);
        m[k] = softgym_pick(ok, m[k] + Wa[(r + 6 + k) * n + d], m[k]);
    }
}

/* the pull: each cell's force and moment row (as the engine's: SOFTGYM_FM_STRIDE, force in
   columns 0-2, moment in 4-6) from the W rows and link flags of the three axes (padded by
   NY NZ slots before: flags 0 there) */
static void pull_dense(Py_ssize_t n, const double *Wx, const double *Wy, const double *Wz,
                       const double *vx, const double *vy, const double *vz,
                       double *__restrict__ fm)
{
    Py_ssize_t c, sx = (Py_ssize_t)NY * NZ, sy = NZ;
    SOFTGYM_IVDEP
    for (c = 0; c < NC; c++) {
        double f[3] = {0.0, 0.0, 0.0}, m[3] = {0.0, 0.0, 0.0};
        pull_term(n, Wx, vx, c - sx, 3, f, m);
        pull_term(n, Wx, vx, c, 0, f, m);
        pull_term(n, Wy, vy, c - sy, 3, f, m);
        pull_term(n, Wy, vy, c, 0, f, m);
        pull_term(n, Wz, vz, c - 1, 3, f, m);
        pull_term(n, Wz, vz, c, 0, f, m);
        for (int k = 0; k < 3; k++) {
            fm[SOFTGYM_FM_STRIDE * c + k] = f[k];
            fm[SOFTGYM_FM_STRIDE * c + 4 + k] = m[k];
        }
        fm[SOFTGYM_FM_STRIDE * c + 3] = 0.0;
        fm[SOFTGYM_FM_STRIDE * c + 7] = 0.0;
    }
}

static void *zalloc(size_t count, size_t size)
{
    void *p = calloc(count, size);
    if (p == NULL) {
        fprintf(stderr, "dense_links_probe: out of memory\n");
        exit(2);
    }
    return p;
}

int main(int argc, char **argv)
{
    int N = argc > 1 ? atoi(argv[1]) : 6;
    double fill = argc > 2 ? atof(argv[2]) : 1.0;
    unsigned seed = argc > 3 ? (unsigned)atoi(argv[3]) : 7u;
    if (N < 2 || N > 40 || !(fill > 0.0 && fill <= 1.0)) {
        fprintf(stderr, "dense_links_probe: N in [2, 40], FILL in (0, 1]\n");
        return 2;
    }
    srand(seed);
    NX = NY = NZ = N;
    NC = N * N * N;
    const Py_ssize_t S[3] = {(Py_ssize_t)N * N, N, 1};
    const double L = 0.01;
    /* the robot: occupied cells, voxels numbered in cell order (the engine's C order) */
    int *cell_of = zalloc(NC, sizeof(int)), *vox_of = zalloc(NC, sizeof(int)), nv = 0;
    for (int c = 0; c < NC; c++) {
        vox_of[c] = (rand() / (double)RAND_MAX) < fill || c == 0 ? nv : -1;
        if (vox_of[c] >= 0)
            cell_of[nv++] = c;
    }
    double *pos = zalloc(3 * nv, 8), *quat = zalloc(4 * nv, 8), *rot = zalloc(9 * nv, 8);
    double *scale = zalloc(nv, 8), *P = zalloc(8 * NC, 8);
    /* the engine's voxel rows (SOFTGYM_VOXEL_ROWS, vn apart: quaternions, then positions) */
    Py_ssize_t vn = stride_of(nv);
    double *vr = zalloc(SOFTGYM_VOXEL_ROWS * vn, 8);
    for (int i = 0; i < nv; i++) {
        int c = cell_of[i], x = c / (N * N), y = (c / N) % N, z = c % N;
        pos[3 * i] = x * L + 1e-4 * urand();
        pos[3 * i + 1] = y * L + 1e-4 * urand();
        pos[3 * i + 2] = z * L + 1e-4 * urand();
        double q[4] = {1.0, 0.05 * urand(), 0.05 * urand(), 0.05 * urand()};
        double nq = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (int k = 0; k < 4; k++)
            quat[4 * i + k] = q[k] / nq;
        softgym_quat_matrix(quat + 4 * i, rot + 9 * i);
        scale[i] = L * (1.0 + 0.01 * urand());
        for (int k = 0; k < 4; k++)
            vr[(SOFTGYM_ROW_QUAT + k) * vn + i] = quat[4 * i + k];
        for (int k = 0; k < 3; k++)
            vr[(SOFTGYM_ROW_POS + k) * vn + i] = pos[3 * i + k];
    }
    /* empty cells: the identity orientation, unit size (their slots are never used) */
    for (int c = 0; c < NC; c++) {
        P[3 * NC + c] = 1.0;
        P[7 * NC + c] = L;
    }
    /* the engine's links: by axis, then by voxel 1's cell */
    Py_ssize_t *v1 = zalloc(3 * NC, sizeof(Py_ssize_t)), *v2 = zalloc(3 * NC, sizeof(Py_ssize_t));
    Py_ssize_t nl = 0, start[4], slots = 0;
    for (int ax = 0; ax < 3; ax++) {
        start[ax] = nl;
        slots += NC - S[ax];
        for (int c = 0; c < NC; c++) {
            int co = ax == 0 ? c / (N * N) : (ax == 1 ? (c / N) % N : c % N);
            if (co < N - 1 && vox_of[c] >= 0 && vox_of[c + S[ax]] >= 0) {
                v1[nl] = vox_of[c];
                v2[nl] = vox_of[c + S[ax]];
                nl++;
            }
        }
    }
    start[3] = nl;
    /* the forces pass's bond-frame outputs (random), per link and per slot */
    Py_ssize_t ne = stride_of((int)nl), nd = stride_of(NC), pad = (Py_ssize_t)N * N;
    double *o = zalloc(NROWS * ne, 8), *bo = zalloc(NROWS * ne, 8);
    double *od[3], *bd[3], *W[3], *valid[3];
    for (int ax = 0; ax < 3; ax++) {
        od[ax] = zalloc(NROWS * nd, 8);
        bd[ax] = zalloc(NROWS * nd, 8);
        W[ax] = (double *)zalloc(12 * nd + pad, 8) + pad;
        valid[ax] = (double *)zalloc(nd + pad, 8) + pad;
    }
    static const int rows[12] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 21, 24};
    for (Py_ssize_t li = 0; li < nl; li++) {
        int ax = li < start[1] ? 0 : (li < start[2] ? 1 : 2);
        Py_ssize_t c = cell_of[v1[li]];
        for (int k = 0; k < 12; k++) {
            double val = urand();
            bo[rows[k] * ne + li] = val;
            bd[ax][rows[k] * nd + c] = val;
        }
        double neg2 = (li % 5) != 0 ? 1.0 : 0.0; /* most links: one material */
        bo[23 * ne + li] = neg2;
        bd[ax][23 * nd + c] = neg2;
        valid[ax][c] = 1.0;
    }
    /* the same rows as the engine's double-precision forces pass leaves them for its
       scatter: per chunk of SOFTGYM_CHUNK_LINKS links, 12 rows SOFTGYM_CHUNK_STRIDE apart
       (the single-precision pass's float rows hold the same values), then voxel 1's
       rotation in rows SOFTGYM_SEED_R_ROWS.. (the geometry's, in the AVX-512 builds) */
    Py_ssize_t nch = (nl + SOFTGYM_CHUNK_LINKS - 1) / SOFTGYM_CHUNK_LINKS;
    double *bc = aligned_alloc(64, nch * SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE * 8);
    for (Py_ssize_t li = 0; li < nl; li++) {
        double *col = bc + (li / SOFTGYM_CHUNK_LINKS) * SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE
                      + li % SOFTGYM_CHUNK_LINKS;
        for (int k = 0; k < 12; k++)
            col[k * SOFTGYM_CHUNK_STRIDE] = bo[rows[k] * ne + li];
        for (int k = 0; k < 9; k++)
            col[(SOFTGYM_SEED_R_ROWS + k) * SOFTGYM_CHUNK_STRIDE] = rot[9 * v1[li] + k];
    }
    /* force and moment rows, 64-byte aligned as the engine's */
    double *fa = aligned_alloc(64, SOFTGYM_FM_STRIDE * nv * 8);
    double *fb = aligned_alloc(64, SOFTGYM_FM_STRIDE * NC * 8);
    if (bc == NULL || fa == NULL || fb == NULL) {
        fprintf(stderr, "dense_links_probe: out of memory\n");
        return 2;
    }
    unsigned long long best[6];
    for (int k = 0; k < 6; k++)
        best[k] = ~0ull;
    for (int rep = 0; rep < REPS; rep++) {
        unsigned long long t0, t;
        t0 = __rdtsc();
        for (int ax = 0; ax < 3; ax++)
            softgym_seed_geom(ax, start[ax], start[ax + 1], ne, v1, v2, nv, pos, quat, vr, vn,
                              scale, o, (double *)0, (float *)0);
        t = __rdtsc() - t0;
        best[0] = t < best[0] ? t : best[0];
        memset(fa, 0, SOFTGYM_FM_STRIDE * nv * 8);
        t0 = __rdtsc();
        for (Py_ssize_t ch = 0; ch < nch; ch++) {
            Py_ssize_t c0 = ch * SOFTGYM_CHUNK_LINKS, c1 = c0 + SOFTGYM_CHUNK_LINKS;
            const double *chunk = bc + ch * SOFTGYM_CHUNK_ROWS * SOFTGYM_CHUNK_STRIDE - c0;
            for (int ax = 0; ax < 3; ax++) {
                Py_ssize_t a0 = start[ax] > c0 ? start[ax] : c0;
                Py_ssize_t a1 = start[ax + 1] < c1 ? start[ax + 1] : c1;
                if (a0 < a1)
                    softgym_seed_scatter(ax, a0, a1, v1, v2, rot, chunk, bo + 23 * ne, fa,
                                         fa + 4);
            }
        }
        t = __rdtsc() - t0;
        best[1] = t < best[1] ? t : best[1];
        t0 = __rdtsc();
        for (int i = 0; i < nv; i++) {
            int c = cell_of[i];
            P[c] = pos[3 * i];
            P[NC + c] = pos[3 * i + 1];
            P[2 * NC + c] = pos[3 * i + 2];
            P[3 * NC + c] = quat[4 * i];
            P[4 * NC + c] = quat[4 * i + 1];
            P[5 * NC + c] = quat[4 * i + 2];
            P[6 * NC + c] = quat[4 * i + 3];
            P[7 * NC + c] = scale[i];
        }
        t = __rdtsc() - t0;
        best[2] = t < best[2] ? t : best[2];
        t0 = __rdtsc();
        geom_dense_ax(0, S[0], NC - S[0], nd, P, od[0]);
        geom_dense_ax(1, S[1], NC - S[1], nd, P, od[1]);
        geom_dense_ax(2, S[2], NC - S[2], nd, P, od[2]);
        t = __rdtsc() - t0;
        best[3] = t < best[3] ? t : best[3];
        t0 = __rdtsc();
        turn_dense_ax(0, NC - S[0], nd, bd[0], P, W[0]);
        turn_dense_ax(1, NC - S[1], nd, bd[1], P, W[1]);
        turn_dense_ax(2, NC - S[2], nd, bd[2], P, W[2]);
        t = __rdtsc() - t0;
        best[4] = t < best[4] ? t : best[4];
        t0 = __rdtsc();
        pull_dense(nd, W[0], W[1], W[2], valid[0], valid[1], valid[2], fb);
        t = __rdtsc() - t0;
        best[5] = t < best[5] ? t : best[5];
    }
    long bad_geom = 0, bad_force = 0;
    for (Py_ssize_t li = 0; li < nl; li++) {
        int ax = li < start[1] ? 0 : (li < start[2] ? 1 : 2);
        for (int k = 0; k < 10; k++)
            bad_geom += memcmp(&o[k * ne + li], &od[ax][k * nd + cell_of[v1[li]]], 8) != 0;
    }
    for (int i = 0; i < nv; i++)
        for (int k = 0; k < 7; k++)  /* force 0-2, moment 4-6 */
            bad_force += k != 3 && memcmp(&fa[SOFTGYM_FM_STRIDE * i + k],
                                          &fb[SOFTGYM_FM_STRIDE * cell_of[i] + k], 8) != 0;
    double v = (double)nv;
    printf("lattice %d^3, fill %.2f: %d voxels, %ld links, %ld dense slots (%.0f %% more)\n",
           N, fill, nv, (long)nl, (long)slots, 100.0 * (slots - nl) / nl);
    printf("TSC cycles per voxel-step, the quickest of %d repeats:\n", REPS);
    printf("  engine  geometry (gathers) %6.1f  scatter (link order) %6.1f"
           "                   total %6.1f\n",
           best[0] / v, best[1] / v, (best[0] + best[1]) / v);
    printf("  dense   pack %6.1f  geometry %6.1f  turn %6.1f  pull %6.1f  total %6.1f\n",
           best[2] / v, best[3] / v, best[4] / v, best[5] / v,
           (best[2] + best[3] + best[4] + best[5]) / v);
    printf("  bit identity: geometry values differing %ld of %ld, force and moment "
           "components differing %ld of %d\n",
           bad_geom, 10 * (long)nl, bad_force, 6 * nv);
    return bad_geom || bad_force ? 1 : 0;
}
