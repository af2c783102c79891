# The voxel update of both models, see _integrate.pyx.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport float64_t, intp_t


cdef int integrate_corotational(Batch* b, intp_t r, const float64_t* ref,
                                float64_t* dmax2) noexcept nogil
    # model 1. IN: force, moment (cleared on the way). OUT: pos, vel, quat,
    # angvel, and rot unless the build's steps do not read it (SOFTGYM_ROT_DEFERRED:
    # then refresh_robot_rotations when the step loop returns); dmax2: the largest squared displacement from ref (the
    # positions of the last candidate rebuild, NULL: none). Returns a STATUS_*.
cdef int integrate_seed(Batch* b, intp_t r, const float64_t* ref,
                        float64_t* dmax2) noexcept nogil
    # model 0 (the seed's EulerStep), same contract (rot: as integrate_corotational).
cdef void seed_voxel_rows(Batch* b, intp_t r) noexcept nogil
    # robot r's voxel rows (rows 0-6 of b.vox_out: quaternions, positions; 7-15:
    # velocities, angular velocities, external forces) from quat, pos, vel, angvel and
    # ext_force, where the build's seed step reads them (SOFTGYM_SEED_R_USED; else
    # nothing): before its first step of a call, integrate_seed keeps them after each.
    # The velocity and angular velocity rows are then the robot's state (integrate_seed
    # reads and writes them, not vel and angvel) until seed_state_back
cdef void seed_state_back(Batch* b, intp_t r) noexcept nogil
    # robot r's vel and angvel from the voxel rows, when the seed step loop returns
    # (SOFTGYM_SEED_R_USED; else nothing)
cdef void refresh_robot_rotations(Batch* b, intp_t r) noexcept nogil
    # robot r's rot from its quat where the voxel updates leave it
    # (SOFTGYM_ROT_DEFERRED; else nothing)
cdef void clear_robot(Batch* b, intp_t r) noexcept nogil
    # zero robot r's force and moment scratch (after an early exit)
