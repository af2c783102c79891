# Model 1, "corotational": softgym's symmetric co-rotational beam lattice.
# The link forces of one robot (links_corotational); the voxel update is in
# _integrate.pyx, self-collision in _contact.pyx, the step loop in _core.pyx.
#
# Physics (see docs/PHYSICS.md):
# - each voxel is a rigid cube (position, quaternion, velocity, angular velocity);
# - each face-adjacent pair is joined by an Euler-Bernoulli beam measured in a
#   frame that turns with the link (co-rotational), so large rigid rotations are
#   exact:
#       axial extension   e    = |d| - (s1 + s2) / 2   along u = d / |d|
#       bending vectors   b_i  = r x a_i - r x d / L
#                         (a_i = voxel i's lattice axis of the link,
#                          r = (a1 + a2) / |a1 + a2|, L the nominal size: the
#                          seed's small-angle beam, whose stiffness does not
#                          grow when actuated voxels shrink)
#       twist             tau  = (z1 . y2 - y1 . z2) / 2  (y, z: the other lattice axes)
#   with the Hermite beam element's moments M1 = -k_b (2 b1 + b2),
#   M2 = -k_b (b1 + 2 b2), torsion +-k_t tau r, axial force -k_a e u on voxel 2
#   and the shear force that balances the moments, r x (M1 + M2) / L.
#   Damping uses the same forms with the deformation rates, so its power is
#   never positive.
#
# The link forces come from a branch-free kernel over restrict pointers that
# the compiler vectorises (gathers + SIMD), then are scattered in link order,
# so results are deterministic and independent of threads and batching.

from libc.math cimport sqrt, fabs

from softgym.engine._batch cimport (Batch, STATUS_OK, STATUS_STRAIN, f64_rp, cf64_rp,
                                    cintp_rp)
from softgym.engine._typedefs cimport float64_t, intp_t


cdef int links_corotational(Batch* b, intp_t r) noexcept nogil:
    # IN: positions, rotations, velocities, scales. OUT (accumulated): force, moment.
    # A robot's links are sorted by axis (x, then y, then z); each run gets a
    # copy of the loop with constant axis indices.
    cdef:
        intp_t lo = b.link_start[r]
        intp_t hi = b.link_start[r + 1]
        intp_t nx = b.link_axis_count[3 * r]
        intp_t ny = b.link_axis_count[3 * r + 1]
    if _links_along(b, lo, lo + nx, 0, 1, 2) != STATUS_OK:
        return STATUS_STRAIN
    if _links_along(b, lo + nx, lo + nx + ny, 1, 2, 0) != STATUS_OK:
        return STATUS_STRAIN
    return _links_along(b, lo + nx + ny, hi, 2, 0, 1)


cdef void _link_kernel(intp_t lo, intp_t hi, intp_t ax, intp_t p, intp_t q,
                       float64_t inv_L, cintp_rp v1, cintp_rp v2,
                       cf64_rp pos, cf64_rp vel, cf64_rp av, cf64_rp rot, cf64_rp scale,
                       cf64_rp k_axial, cf64_rp c_axial, cf64_rp k_bend, cf64_rp c_bend,
                       cf64_rp k_torsion, cf64_rp c_torsion,
                       f64_rp ext, f64_rp fx, f64_rp fy, f64_rp fz,
                       f64_rp m1x, f64_rp m1y, f64_rp m1z,
                       f64_rp m2x, f64_rp m2y, f64_rp m2z) noexcept nogil:
    # Links lo..hi, all along lattice axis `ax` ((ax, p, q) a cyclic
    # permutation of (0, 1, 2)). IN: the voxels' state. OUT, per link: |axial
    # extension| (ext), force on voxel 2 (f; voxel 1 gets -f) and moments on
    # voxels 1 and 2 (m1, m2). No branches and no scatter: the loop vectorises.
    cdef:
        intp_t li, i, j
        float64_t dx, dy, dz, ell, inv_l, e, edot, fa, ax_x, ax_y, ax_z
        float64_t dvx, dvy, dvz, a1x, a1y, a1z, a2x, a2y, a2z
        float64_t rx, ry, rz, inv_r, cx, cy, cz, hx, hy, hz, tw, twdot, uw
        float64_t wcx, wcy, wcz, w1x, w1y, w1z, w2x, w2y, w2z
        float64_t kb, cb, tor, n1x, n1y, n1z, n2x, n2y, n2z, sx, sy, sz
    for li in range(lo, hi):
        i = v1[li]
        j = v2[li]
        dx = pos[3 * j] - pos[3 * i]
        dy = pos[3 * j + 1] - pos[3 * i + 1]
        dz = pos[3 * j + 2] - pos[3 * i + 2]
        ell = sqrt(dx * dx + dy * dy + dz * dz)
        e = ell - 0.5 * (scale[i] + scale[j])
        ext[li] = fabs(e)  # NaN stays NaN: the caller's check catches it
        # axial force on voxel 2 along the chord u = d / |d| (elastic + damping)
        dvx = vel[3 * j] - vel[3 * i]
        dvy = vel[3 * j + 1] - vel[3 * i + 1]
        dvz = vel[3 * j + 2] - vel[3 * i + 2]
        inv_l = 1.0 / ell
        edot = (dx * dvx + dy * dvy + dz * dvz) * inv_l
        fa = (k_axial[li] * e + c_axial[li] * edot) * inv_l
        ax_x = -fa * dx
        ax_y = -fa * dy
        ax_z = -fa * dz
        # lattice axis of the link in each voxel (column ax of its rotation)
        # and the link's frame axis r, their bisector
        a1x = rot[9 * i + ax]
        a1y = rot[9 * i + 3 + ax]
        a1z = rot[9 * i + 6 + ax]
        a2x = rot[9 * j + ax]
        a2y = rot[9 * j + 3 + ax]
        a2z = rot[9 * j + 6 + ax]
        rx = a1x + a2x
        ry = a1y + a2y
        rz = a1z + a2z
        # 1 / |a1 + a2| by one Newton step from 1/2 (|a1 + a2|^2 = 4 - |a1 - a2|^2
        # is near 4): relative error 0.14 % at 0.5 rad of relative bending
        inv_r = 0.5 * (1.5 - 0.125 * (rx * rx + ry * ry + rz * rz))
        rx = rx * inv_r
        ry = ry * inv_r
        rz = rz * inv_r
        # transverse offset of voxel 2 as an angle on the nominal length,
        # c = r x d / L (the seed's Pos2.y / L: stiffness does not grow when
        # actuated voxels shrink)
        cx = (ry * dz - rz * dy) * inv_L
        cy = (rz * dx - rx * dz) * inv_L
        cz = (rx * dy - ry * dx) * inv_L
        # bending of each voxel relative to the link, b_i = r x a_i - c; as r
        # bisects a1 and a2, r x a2 = -(r x a1) = h = inv_r (a1 x a2), so
        # b1 = -h - c and b2 = h - c
        hx = (a1y * a2z - a1z * a2y) * inv_r
        hy = (a1z * a2x - a1x * a2z) * inv_r
        hz = (a1x * a2y - a1y * a2x) * inv_r
        # twist of voxel 2 relative to voxel 1 about the link: with y, z the
        # voxels' two other lattice axes, sin(twist) = (z1 . y2 - y1 . z2) / 2
        tw = 0.5 * (rot[9 * i + q] * rot[9 * j + p] + rot[9 * i + 3 + q] * rot[9 * j + 3 + p]
                    + rot[9 * i + 6 + q] * rot[9 * j + 6 + p] - rot[9 * i + p] * rot[9 * j + q]
                    - rot[9 * i + 3 + p] * rot[9 * j + 3 + q]
                    - rot[9 * i + 6 + p] * rot[9 * j + 6 + q])
        # rates: transverse angle (wc = r x dv / L), the voxels' angular
        # velocities across the link (w_i minus its part along r) and twist
        wcx = (ry * dvz - rz * dvy) * inv_L
        wcy = (rz * dvx - rx * dvz) * inv_L
        wcz = (rx * dvy - ry * dvx) * inv_L
        w1x = av[3 * i]
        w1y = av[3 * i + 1]
        w1z = av[3 * i + 2]
        uw = rx * w1x + ry * w1y + rz * w1z
        w1x = w1x - uw * rx
        w1y = w1y - uw * ry
        w1z = w1z - uw * rz
        twdot = -uw
        w2x = av[3 * j]
        w2y = av[3 * j + 1]
        w2z = av[3 * j + 2]
        uw = rx * w2x + ry * w2y + rz * w2z
        w2x = w2x - uw * rx
        w2y = w2y - uw * ry
        w2z = w2z - uw * rz
        twdot = twdot + uw
        # bending moments: elastic -k_b (2 b1 + b2) = k_b (h + 3 c) on voxel 1,
        # -k_b (b1 + 2 b2) = k_b (3 c - h) on voxel 2; damping the same form
        # with the bending rates (w_i - wc)
        kb = k_bend[li]
        cb = c_bend[li]
        n1x = kb * (hx + 3.0 * cx) - cb * (2.0 * w1x + w2x - 3.0 * wcx)
        n1y = kb * (hy + 3.0 * cy) - cb * (2.0 * w1y + w2y - 3.0 * wcy)
        n1z = kb * (hz + 3.0 * cz) - cb * (2.0 * w1z + w2z - 3.0 * wcz)
        n2x = kb * (3.0 * cx - hx) - cb * (w1x + 2.0 * w2x - 3.0 * wcx)
        n2y = kb * (3.0 * cy - hy) - cb * (w1y + 2.0 * w2y - 3.0 * wcy)
        n2z = kb * (3.0 * cz - hz) - cb * (w1z + 2.0 * w2z - 3.0 * wcz)
        # force on voxel 2: axial plus the shear that balances the bending
        # moments over the nominal length
        sx = n1x + n2x
        sy = n1y + n2y
        sz = n1z + n2z
        fx[li] = ax_x + (ry * sz - rz * sy) * inv_L
        fy[li] = ax_y + (rz * sx - rx * sz) * inv_L
        fz[li] = ax_z + (rx * sy - ry * sx) * inv_L
        # torsion, equal and opposite along r
        tor = k_torsion[li] * tw + c_torsion[li] * twdot
        m1x[li] = n1x + tor * rx
        m1y[li] = n1y + tor * ry
        m1z[li] = n1z + tor * rz
        m2x[li] = n2x - tor * rx
        m2y[li] = n2y - tor * ry
        m2z[li] = n2z - tor * rz


cdef inline int _links_along(Batch* b, intp_t lo, intp_t hi,
                             const intp_t ax, const intp_t p, const intp_t q) noexcept nogil:
    # Links lo..hi along axis `ax`: the vectorised kernel, then the strain
    # check and the scatter of forces and moments in link order.
    cdef:
        intp_t li, i, j
        intp_t n = b.link_stride  # the scratch's row stride
        float64_t max_ext = b.max_strain * b.L
        float64_t* o = b.link_out
        float64_t* force = b.force
        float64_t* moment = b.moment
    if hi <= lo:
        return STATUS_OK
    _link_kernel(lo, hi, ax, p, q, 1.0 / b.L, b.v1, b.v2, b.pos, b.vel, b.angvel, b.rot,
                 b.scale, b.k_axial, b.c_axial, b.k_bend, b.c_bend, b.k_torsion, b.c_torsion,
                 o, o + n, o + 2 * n, o + 3 * n, o + 4 * n, o + 5 * n, o + 6 * n,
                 o + 7 * n, o + 8 * n, o + 9 * n)
    for li in range(lo, hi):
        if not (o[li] <= max_ext):
            return STATUS_STRAIN  # also catches NaN
        i = b.v1[li]
        j = b.v2[li]
        force[4 * j] += o[n + li]
        force[4 * j + 1] += o[2 * n + li]
        force[4 * j + 2] += o[3 * n + li]
        force[4 * i] -= o[n + li]
        force[4 * i + 1] -= o[2 * n + li]
        force[4 * i + 2] -= o[3 * n + li]
        moment[4 * i] += o[4 * n + li]
        moment[4 * i + 1] += o[5 * n + li]
        moment[4 * i + 2] += o[6 * n + li]
        moment[4 * j] += o[7 * n + li]
        moment[4 * j + 1] += o[8 * n + li]
        moment[4 * j + 2] += o[9 * n + li]
    return STATUS_OK
