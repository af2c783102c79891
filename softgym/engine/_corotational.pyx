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
# The link forces come from a branch-free kernel (include/softgym_corot.h: one
# formula macro, run on vectors of links with loads of our own where the build
# has AVX, else by the compiler's vectoriser), then are scattered in link order,
# so results are deterministic and independent of threads and batching.

from softgym.engine._batch cimport Batch, STATUS_OK, STATUS_STRAIN
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
    if COROT_ROWS_USED:
        # the voxels' rotation matrices as rows from their quaternion rows, once a step (the
        # rest of the rows the kernel reads is the step loop's state: softgym_corot_rows)
        softgym_corot_rows(b.vox_start[r], b.vox_start[r + 1], b.vox_stride, b.vox_out)
    if _links_along(b, r, lo, lo + nx, 0) != STATUS_OK:
        return STATUS_STRAIN
    if _links_along(b, r, lo + nx, lo + nx + ny, 1) != STATUS_OK:
        return STATUS_STRAIN
    return _links_along(b, r, lo + nx + ny, hi, 2)


cdef extern from "softgym_corot.h":
    # the link kernel: links lo..hi along axis ax, branch-free (vectorised by hand
    # where the build has AVX), into rows 0-9 of the scratch o (stride n): |axial
    # extension|, the force on voxel 2 (voxel 1 gets minus it), the moments on
    # voxels 1 and 2 (documented in include/softgym_corot.h)
    void softgym_corot_links(int ax, intp_t lo, intp_t hi, intp_t n, float64_t inv_L,
                             const intp_t* v1, const intp_t* v2, const float64_t* pos,
                             const float64_t* vel, const float64_t* av, const float64_t* rot,
                             const float64_t* scale, const float64_t* k_axial,
                             const float64_t* c_axial, const float64_t* k_bend,
                             const float64_t* c_bend, const float64_t* k_torsion,
                             const float64_t* c_torsion, const float64_t* vr, intp_t vn,
                             intp_t vend, float64_t* o) noexcept nogil
    # the voxels' rows the kernel's 8-lane paths load (AVX-512 builds: SOFTGYM_COROT_ROWS
    # rows of b.vox_out; elsewhere a no-op, and COROT_ROWS_USED is 0)
    void softgym_corot_rows(intp_t lo, intp_t hi, intp_t n, float64_t* rows) noexcept nogil
    enum: COROT_ROWS_USED
    # the strain check and the scatter in link order: hi, or the first strained link
    intp_t softgym_corot_scatter(intp_t lo, intp_t hi, intp_t n, float64_t max_ext,
                                 const intp_t* v1, const intp_t* v2, const float64_t* o,
                                 float64_t* force, float64_t* moment) noexcept nogil


cdef inline int _links_along(Batch* b, intp_t r, intp_t lo, intp_t hi, int ax) noexcept nogil:
    # Links lo..hi along axis `ax`: the vectorised kernel, then the strain
    # check and the scatter of forces and moments in link order.
    cdef:
        intp_t n = b.link_stride  # the scratch's row stride
        float64_t* o = b.link_out
    if hi <= lo:
        return STATUS_OK
    softgym_corot_links(ax, lo, hi, n, 1.0 / b.L, b.v1, b.v2, b.pos, b.vel, b.angvel, b.rot,
                        b.scale, b.k_axial, b.c_axial, b.k_bend, b.c_bend, b.k_torsion,
                        b.c_torsion, b.vox_out if COROT_ROWS_USED else NULL, b.vox_stride,
                        b.vox_start[r + 1], o)
    if softgym_corot_scatter(lo, hi, n, b.max_strain * b.L, b.v1, b.v2, o, b.force,
                             b.moment) < hi:
        return STATUS_STRAIN  # also for NaN
    return STATUS_OK
