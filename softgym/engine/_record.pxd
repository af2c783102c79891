# Recording: centre of mass, aux measurements, trace samples, energy; see
# _record.pyx. The nogil helpers take one robot r of a batch.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport float64_t, intp_t


cdef void robot_cm(Batch* b, intp_t r, float64_t* out) noexcept nogil
    # out[0:3]: mass-weighted centre of the robot's own voxels (m)
cdef void robot_aux(Batch* b, intp_t r, float64_t* out) noexcept nogil
    # out[0:N_AUX]: objects' CM, heading sum, bounding box (see N_AUX)
cdef void record(Batch* b, intp_t r) noexcept nogil
    # after a step: IniCM (cm_init, aux_init) and the trace samples
cdef void robot_energy(Batch* b, intp_t r, float64_t* out) noexcept nogil
    # out[0:3]: kinetic, elastic (links, floor, boxes), gravitational (J)
