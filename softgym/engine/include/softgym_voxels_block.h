/* Both models' voxel updates (softgym/engine/_integrate.pyx, integrate_seed and
   integrate_corotational; seed a compile-time constant where inlined) for
   SOFTGYM_VB_LANES voxels i.. in vector lanes, on their records, in the builds whose step
   loops keep the voxels' state there: softgym_voxels.h includes this file for the 4 lanes
   of AVX2 and the 2 of SSE2 (the portable x86-64 build), with SOFTGYM_VB_NAME (the
   function), SOFTGYM_VB_T (GCC's vector of the lanes' doubles, whose arithmetic operators
   act lane by lane) and the operations defined: SOFTGYM_VB_LOAD3 and SOFTGYM_VB_STORE3
   (records of 3 as rows x, y, z and back), SOFTGYM_VB_AT (consecutive doubles),
   SOFTGYM_VB_FORCES (a force or moment's rows, from the float rows of single-precision
   links widened or the double rows of SOFTGYM_FM_STRIDE transposed), SOFTGYM_VB_CLEAR
   (both zeroed), SOFTGYM_VB_NLE, _EQ, _LT (comparisons as masks: all bits of a lane),
   SOFTGYM_VB_AND, _OR, _ANDNOT (~a & b), SOFTGYM_VB_BITS (a mask's lanes as bits),
   SOFTGYM_VB_PICK (m ? a : b), SOFTGYM_VB_SQRT, SOFTGYM_VB_ABS, SOFTGYM_VB_RAISE (the
   largest lane above *best), SOFTGYM_VB_SPEED2 (softgym_speed2 in the lanes) and
   SOFTGYM_VB_NONE_FIXED. The same IEEE operations as the scalar loop lane by lane, each
   expression in softgym_seed_voxels8's and softgym_corot_voxels8's shape (so the build
   fuses the same multiply-adds, where it fuses); 1 when the voxels were stepped, 0 when nothing was written (a fixed
   voxel among them, or a runaway one: the scalar loop steps them). No include guard, on
   purpose. */
SOFTGYM_ALWAYS_INLINE int SOFTGYM_VB_NAME(const int seed, SOFTGYM_VOXELS8_PARAMS)
{
    (void)rows;
    (void)rn;
    if (!SOFTGYM_VB_NONE_FIXED(fixed + i))
        return 0;
    const SOFTGYM_VB_T zero = {0.0};
    SOFTGYM_VB_T v0, v1, v2, p0, p1, p2, F0, F1, F2, E0, E1, E2;
    SOFTGYM_VB_LOAD3(vel + 3 * i, &v0, &v1, &v2);
    SOFTGYM_VB_LOAD3(ext + 3 * i, &E0, &E1, &E2);
    SOFTGYM_VB_LOAD3(pos + 3 * i, &p0, &p1, &p2);
    SOFTGYM_VB_FORCES(force + SOFTGYM_FM_STRIDE * i, lf, lfs, i, &F0, &F1, &F2);
    SOFTGYM_VB_T cg = SOFTGYM_VB_AT(c_global + i), m = SOFTGYM_VB_AT(mass + i);
    SOFTGYM_VB_T f0, f1, f2;
    if (seed) {
        f0 = (((-cg) * v0) + F0) + E0;
        f1 = (((-cg) * v1) + F1) + E1;
        f2 = ((((-cg) * v2) + F2) + (m * g)) + E2;
        if (has_floor) {
            SOFTGYM_VB_T sc = SOFTGYM_VB_AT(scale + i);
            SOFTGYM_VB_T pen = (0.5 * sc) - p2;
            /* not pen <= 0 (a NaN is in contact, as the AVX-512 block's ~(pen <= 0)) */
            SOFTGYM_VB_T contact = SOFTGYM_VB_NLE(pen, zero);
            if (SOFTGYM_VB_BITS(contact)) {
                SOFTGYM_VB_T n = SOFTGYM_VB_AT(k_floor + i) * pen;
                SOFTGYM_VB_T fd = SOFTGYM_VB_AT(mu_k + i) * n;
                SOFTGYM_VB_T still = SOFTGYM_VB_AND(SOFTGYM_VB_EQ(v0, zero), SOFTGYM_VB_EQ(v1, zero));
                SOFTGYM_VB_T stat = zero;
                if (SOFTGYM_VB_BITS(SOFTGYM_VB_AND(contact, still))) {
                    SOFTGYM_VB_T sf = SOFTGYM_VB_SQRT((f0 * f0) + (f1 * f1));
                    stat = SOFTGYM_VB_LT(sf, (SOFTGYM_VB_AT(mu_s + i) * n));
                }
                SOFTGYM_VB_T moving = SOFTGYM_VB_ANDNOT(still, contact), stop = zero;  /* ~a & b */
                if (SOFTGYM_VB_BITS(moving)) {
                    SOFTGYM_VB_T vsp = SOFTGYM_VB_SQRT((v0 * v0) + (v1 * v1));
                    SOFTGYM_VB_T kin = SOFTGYM_VB_LT((fd * dt), (m * vsp));
                    SOFTGYM_VB_T slide = SOFTGYM_VB_AND(moving, kin);  /* kinetic friction */
                    stop = SOFTGYM_VB_ANDNOT(kin, moving);  /* friction stops it */
                    if (SOFTGYM_VB_BITS(slide)) {
                        SOFTGYM_VB_T f0k = f0 - ((fd * v0) / vsp);
                        SOFTGYM_VB_T f1k = f1 - ((fd * v1) / vsp);
                        f0 = SOFTGYM_VB_PICK(slide, f0k, f0);
                        f1 = SOFTGYM_VB_PICK(slide, f1k, f1);
                    }
                }
                SOFTGYM_VB_T stick =
                    SOFTGYM_VB_OR(SOFTGYM_VB_AND(SOFTGYM_VB_AND(contact, still), stat), stop);
                v0 = SOFTGYM_VB_PICK(stop, zero, v0);
                v1 = SOFTGYM_VB_PICK(stop, zero, v1);
                SOFTGYM_VB_T f2c = f2 + (n - (SOFTGYM_VB_AT(c_floor + i) * v2));
                f2 = SOFTGYM_VB_PICK(contact, f2c, f2);
                f0 = SOFTGYM_VB_PICK(stick, zero, f0);
                f1 = SOFTGYM_VB_PICK(stick, zero, f1);
            }
        }
    } else {
        /* the corotational model (integrate_corotational: its floor the common surface
           contact with the normal (0, 0, 1)), as softgym_corot_voxels8 */
        f0 = (F0 + E0) - (cg * v0);
        f1 = (F1 + E1) - (cg * v1);
        f2 = ((F2 + E2) - (cg * v2)) + (m * g);
        if (has_floor) {
            SOFTGYM_VB_T pen = (0.5 * SOFTGYM_VB_AT(scale + i)) - p2;
            SOFTGYM_VB_T contact = SOFTGYM_VB_GT(pen, zero);
            if (SOFTGYM_VB_BITS(contact)) {
                /* surface_contact with n = (0, 0, 1), every product as the scalar code's */
                const SOFTGYM_VB_T nx = zero, ny = zero, nz = zero + 1.0;
                SOFTGYM_VB_T vn = ((v0 * nx) + (v1 * ny)) + (v2 * nz);
                SOFTGYM_VB_T fn = (SOFTGYM_VB_AT(k_floor + i) * pen) - (SOFTGYM_VB_AT(c_floor + i) * vn);
                contact = SOFTGYM_VB_AND(contact, SOFTGYM_VB_NLE(fn, zero));
                if (SOFTGYM_VB_BITS(contact)) {
                    SOFTGYM_VB_T g0 = f0 + (fn * nx), g1 = f1 + (fn * ny), g2 = f2 + (fn * nz);
                    SOFTGYM_VB_T vtx = v0 - (vn * nx), vty = v1 - (vn * ny), vtz = v2 - (vn * nz);
                    SOFTGYM_VB_T ftn = ((g0 * nx) + (g1 * ny)) + (g2 * nz);
                    SOFTGYM_VB_T ftx = g0 - (ftn * nx), fty = g1 - (ftn * ny), ftz = g2 - (ftn * nz);
                    SOFTGYM_VB_T rest = SOFTGYM_VB_AND(
                        SOFTGYM_VB_AND(SOFTGYM_VB_EQ(vtx, zero), SOFTGYM_VB_EQ(vty, zero)),
                        SOFTGYM_VB_EQ(vtz, zero));
                    SOFTGYM_VB_T ms = SOFTGYM_VB_AT(mu_s + i) * fn;
                    SOFTGYM_VB_T hold = SOFTGYM_VB_AND(
                        rest, SOFTGYM_VB_LE(((ftx * ftx) + (fty * fty)) + (ftz * ftz), (ms * ms)));
                    /* moving: not at rest, in contact (every use below is in contact) */
                    SOFTGYM_VB_T moving = SOFTGYM_VB_ANDNOT(rest, contact);
                    SOFTGYM_VB_T stop = zero, slide = zero;
                    SOFTGYM_VB_T s0 = g0, s1 = g1, s2 = g2;
                    if (SOFTGYM_VB_BITS(moving)) {
                        SOFTGYM_VB_T vt = SOFTGYM_VB_SQRT(((vtx * vtx) + (vty * vty)) + (vtz * vtz));
                        SOFTGYM_VB_T fk = SOFTGYM_VB_AT(mu_k + i) * fn;
                        SOFTGYM_VB_T ge = SOFTGYM_VB_GE((fk * dt), (m * vt));
                        stop = SOFTGYM_VB_AND(moving, ge);
                        slide = SOFTGYM_VB_ANDNOT(ge, moving);
                        if (SOFTGYM_VB_BITS(slide)) {
                            SOFTGYM_VB_T fkv = fk / vt;
                            s0 = g0 - (fkv * vtx);
                            s1 = g1 - (fkv * vty);
                            s2 = g2 - (fkv * vtz);
                        }
                    }
                    /* hold, stop: f - ft; slide: f - fk vt / |vt|; rest without hold: f */
                    SOFTGYM_VB_T minus_ft = SOFTGYM_VB_AND(contact, SOFTGYM_VB_OR(hold, stop));
                    SOFTGYM_VB_T h0 = SOFTGYM_VB_PICK(minus_ft, g0 - ftx, SOFTGYM_VB_PICK(slide, s0, g0));
                    SOFTGYM_VB_T h1 = SOFTGYM_VB_PICK(minus_ft, g1 - fty, SOFTGYM_VB_PICK(slide, s1, g1));
                    SOFTGYM_VB_T h2 = SOFTGYM_VB_PICK(minus_ft, g2 - ftz, SOFTGYM_VB_PICK(slide, s2, g2));
                    f0 = SOFTGYM_VB_PICK(contact, h0, f0);
                    f1 = SOFTGYM_VB_PICK(contact, h1, f1);
                    f2 = SOFTGYM_VB_PICK(contact, h2, f2);
                    v0 = SOFTGYM_VB_PICK(stop, v0 - vtx, v0);
                    v1 = SOFTGYM_VB_PICK(stop, v1 - vty, v1);
                    v2 = SOFTGYM_VB_PICK(stop, v2 - vtz, v2);
                }
            }
        }
    }
    /* the translation, the runaway check (nothing stored before it), the stores */
    SOFTGYM_VB_T M0, M1, M2;
    SOFTGYM_VB_FORCES(moment + SOFTGYM_FM_STRIDE * i, lf ? lf + 3 * lfs : lf, lfs, i, &M0, &M1, &M2);
    SOFTGYM_VB_T h = dt * SOFTGYM_VB_AT(inv_mass + i);
    SOFTGYM_VB_T vx = v0 + (f0 * h), vy = v1 + (f1 * h), vz = v2 + (f2 * h);
    SOFTGYM_VB_T px = p0 + (vx * dt), py = p1 + (vy * dt), pz = p2 + (vz * dt);
    SOFTGYM_VB_T run = (SOFTGYM_VB_ABS(px) + SOFTGYM_VB_ABS(py)) + SOFTGYM_VB_ABS(pz);
    const SOFTGYM_VB_T bound = zero + runaway;
    if (SOFTGYM_VB_BITS(SOFTGYM_VB_LT(run, bound)) != (1 << SOFTGYM_VB_LANES) - 1)
        return 0;
    SOFTGYM_VB_STORE3(vel + 3 * i, vx, vy, vz);
    SOFTGYM_VB_STORE3(pos + 3 * i, px, py, pz);
    SOFTGYM_VB_CLEAR(force + SOFTGYM_FM_STRIDE * i, lf, lfs, i);
    if (ref != NULL) {
        SOFTGYM_VB_T r0, r1, r2;
        SOFTGYM_VB_LOAD3(ref + 3 * (i - vs), &r0, &r1, &r2);
        SOFTGYM_VB_T e0 = px - r0, e1 = py - r1, e2 = pz - r2;
        if (i == vs) {
            /* the robot's first voxel's displacement, lane 0 (the scalar loop's c) */
            c[0] = e0[0];
            c[1] = e1[0];
            c[2] = e2[0];
        }
        SOFTGYM_VB_T d0 = e0 - c[0], d1 = e1 - c[1], d2 = e2 - c[2];
        SOFTGYM_VB_RAISE(((d0 * d0) + (d1 * d1)) + (d2 * d2), dmax);
    }
    if (track_speed) {
        SOFTGYM_VB_RAISE(SOFTGYM_VB_SPEED2(vx, vy, vz), vmax2);
    }
    SOFTGYM_VB_T w0, w1, w2;
    SOFTGYM_VB_LOAD3(av + 3 * i, &w0, &w1, &w2);
    SOFTGYM_VB_T hi = dt * SOFTGYM_VB_AT(inv_inertia + i), rd = SOFTGYM_VB_AT(rot_damp + i);
    w0 = (w0 + (M0 * hi)) * rd;
    w1 = (w1 + (M1 * hi)) * rd;
    w2 = (w2 + (M2 * hi)) * rd;
    SOFTGYM_VB_STORE3(av + 3 * i, w0, w1, w2);
    return 1;
}
