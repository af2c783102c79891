# The voxel update of both models, see _integrate.pyx.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport float64_t, intp_t


cdef int integrate_corotational(Batch* b, intp_t r, const float64_t* ref,
                                float64_t* dmax2) noexcept nogil
    # model 1. IN: force, moment (cleared on the way). OUT: pos, vel, quat,
    # angvel, and rot unless the steps do not read it (rotations_deferred: then
    # refresh_robot_rotations when the step loop returns); dmax2: the largest squared displacement from ref (the
    # positions of the last candidate rebuild, NULL: none). Returns a STATUS_*.
cdef int integrate_seed(Batch* b, intp_t r, const float64_t* ref,
                        float64_t* dmax2) noexcept nogil
    # model 0 (the seed's EulerStep), same contract (rot: as integrate_corotational).
cdef void voxel_state_enter(Batch* b, intp_t r) noexcept nogil
    # before the first step of a call: where the build's step loops keep the voxels' state
    # in the voxel rows of b.vox_out (SOFTGYM_STATE_ROWS) and robot r's voxel update runs
    # 8-voxel blocks (no fluid, no terrain box), its state into them (positions,
    # velocities, angular velocities, quaternions, and a copy of the external forces:
    # include/softgym_simd.h, SOFTGYM_ROW_*), and b.state_rows set. The rows
    # are then the robot's state (both models' voxel updates, orientation steps and link
    # kernels read and write them, not the records) until voxel_state_leave. Else the
    # records stay its state, and voxel_link_rows fills the link kernels' rows from them
    # once a step (the scalar voxel loop would otherwise copy its run to the records and
    # back every step)
cdef void voxel_link_rows(Batch* b, intp_t r, int seed) noexcept nogil
    # at each step's start: where the records are robot r's state (b.state_rows NULL) in a
    # build with the rows, the rows its link kernels read (seed: positions and quaternions;
    # else also velocities and angular velocities), from the records; else nothing
cdef void voxel_state_leave(Batch* b, intp_t r) noexcept nogil
    # when the step loop returns: robot r's pos, quat, vel and angvel from the voxel rows
    # where voxel_state_enter put its state there; b.state_rows cleared
cdef bint rotations_deferred(const Batch* b) noexcept nogil
    # whether the step loops leave b.rot to refresh_robot_rotations: no step reads it in
    # the AVX-512 builds (SOFTGYM_ROT_DEFERRED), nor in the seed model's with
    # single-precision links in any build (their push turns the forces with the
    # geometry's float rows of voxel 1's rotation: include/softgym_seed.h)
cdef void refresh_robot_rotations(Batch* b, intp_t r) noexcept nogil
    # robot r's rot from its quat where the voxel updates leave it (rotations_deferred;
    # else nothing)
cdef void clear_robot(Batch* b, intp_t r) noexcept nogil
    # zero robot r's force and moment scratch (before its steps, after an early exit)
