/* The orientation step of SOFTGYM_ORIENT_BLOCK voxels i.. in vector lanes, from their
   records to their records: softgym_orient.h includes this file for the 4 lanes of AVX
   and the 2 of SSE2, with SOFTGYM_OB_NAME (the function), SOFTGYM_OB_T (GCC's vector of
   the lanes' doubles, whose arithmetic operators act lane by lane; SOFTGYM_OB_TI its
   integer twin, a comparison's type) and the operations defined: SOFTGYM_OB_LOADQ and
   SOFTGYM_OB_STOREQ (records of 4 as rows w, x, y, z and back), SOFTGYM_OB_LOAD3 (records
   of 3 as rows), SOFTGYM_OB_STOREROT (rows of the 9 matrix elements as records of 9),
   SOFTGYM_OB_ANY (whether a comparison holds in a lane), SOFTGYM_OB_SQRT and
   SOFTGYM_OB_ABS. The same formulas as softgym_quats_impl (SOFTGYM_QUAT_TURN,
   SOFTGYM_QUAT_NEWTON, SOFTGYM_QUAT_COROT) and softgym_quat_matrix_wxyz
   (SOFTGYM_QUAT_MATRIX), so the same operations lane by lane, the same bits.

   The voxels, none fixed: their quaternions (quat) turned by their angular velocities
   (av) and renormalised as softgym_quats_impl's seed (a compile-time constant where
   inlined), stored in place, and their rotation matrices into rot (rot NULL: none).
   Returns 0, with nothing stored, where the seed's Newton steps leave a lane to the
   exact renormalisation (softgym_quats_impl's "far"). SOFTGYM_OB_NAME stays defined
   (softgym_orient_records calls it); the operations are undefined at the end. No include
   guard, on purpose. */
SOFTGYM_ALWAYS_INLINE int SOFTGYM_OB_NAME(const int seed, Py_ssize_t i, double dt,
                                          const double *av, double *quat, double *rot)
{
    typedef SOFTGYM_OB_T T;
    typedef SOFTGYM_OB_TI TI;
    T Q0, Q1, Q2, Q3, a0, a1, a2;
    SOFTGYM_OB_LOADQ(quat + 4 * i, Q0, Q1, Q2, Q3);
    SOFTGYM_OB_LOAD3(av + 3 * i, &a0, &a1, &a2);
    SOFTGYM_QUAT_TURN(T, a0, a1, a2, Q0, Q1, Q2, Q3, dt);
    T nw, nx, ny, nz;
    const T zero = {0.0}, one = zero + 1.0;
/* lanes of a where m is set (all bits of a lane), else of b */
#define SOFTGYM_OB_PICK(m, a, b) do { \
        TI ia_, ib_; \
        T a__ = (a), b__ = (b); \
        memcpy(&ia_, &a__, sizeof ia_); \
        memcpy(&ib_, &b__, sizeof ib_); \
        ia_ = (ia_ & (m)) | (ib_ & ~(m)); \
        memcpy(&pick_, &ia_, sizeof pick_); \
    } while (0)
    T pick_;
    if (seed == 2) {
        SOFTGYM_QUAT_NEWTON(T);
        TI out = (SOFTGYM_OB_ABS(s - 1.0) > SOFTGYM_QUAT_NEWTON_TOL) | (s != s);
        if (SOFTGYM_OB_ANY(out))
            return 0;
        nw = qw * y;
        nx = qx * y;
        ny = qy * y;
        nz = qz * y;
    } else if (seed == 1) {
        T nq = SOFTGYM_OB_SQRT(qw * qw + qx * qx + qy * qy + qz * qz);
        T inv = 1.0 / nq;
        TI nz0 = nq != 0.0;
        SOFTGYM_OB_PICK(nz0, qw * inv, qw);
        nw = pick_;
        SOFTGYM_OB_PICK(nz0, qx * inv, qx);
        nx = pick_;
        SOFTGYM_OB_PICK(nz0, qy * inv, qy);
        ny = pick_;
        SOFTGYM_OB_PICK(nz0, qz * inv, qz);
        nz = pick_;
    } else {
        SOFTGYM_QUAT_COROT(T);
        nw = qw * nq;
        nx = qx * nq;
        ny = qy * nq;
        nz = qz * nq;
    }
    if (seed != 0) {
        /* snapped to the identity at w >= 1 */
        TI snap = nw >= 1.0;
        SOFTGYM_OB_PICK(snap, one, nw);
        nw = pick_;
        SOFTGYM_OB_PICK(snap, zero, nx);
        nx = pick_;
        SOFTGYM_OB_PICK(snap, zero, ny);
        ny = pick_;
        SOFTGYM_OB_PICK(snap, zero, nz);
        nz = pick_;
    }
#undef SOFTGYM_OB_PICK
    (void)pick_;
    SOFTGYM_OB_STOREQ(quat + 4 * i, nw, nx, ny, nz);
    if (rot != NULL) {
        T R[9];
        SOFTGYM_QUAT_MATRIX(nw, nx, ny, nz, R);
        SOFTGYM_OB_STOREROT(rot + 9 * i, R);
    }
    return 1;
}
#undef SOFTGYM_OB_T
#undef SOFTGYM_OB_TI
#undef SOFTGYM_OB_ANY
#undef SOFTGYM_OB_SQRT
#undef SOFTGYM_OB_ABS
#undef SOFTGYM_OB_LOADQ
#undef SOFTGYM_OB_STOREQ
#undef SOFTGYM_OB_STOREROT
#undef SOFTGYM_OB_LOAD3
