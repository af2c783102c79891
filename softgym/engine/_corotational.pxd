# Model 1's link forces (co-rotational beams), see _corotational.pyx.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport intp_t


cdef int links_corotational(Batch* b, intp_t r) noexcept nogil
    # IN: positions, rotations, velocities, sizes of robot r. OUT (accumulated):
    # force, moment. Returns STATUS_OK or STATUS_STRAIN.
