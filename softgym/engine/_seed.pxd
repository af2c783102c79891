# Model 0's link forces (the seed engine's bonds), see _seed.pyx.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport intp_t


cdef int links_seed(Batch* b, intp_t r) noexcept nogil
    # IN: positions, orientations, sizes, the links' mode and memory of robot r.
    # OUT (accumulated): force, moment; the links' mode (link_sa) and memory
    # (link_last). Returns STATUS_OK or STATUS_STRAIN.


cdef extern from "softgym_seed.h":
    # links_seed's chunks of links and the forces pass's rows for one chunk (their
    # compile-time stride: softgym_seed_scatter addresses them from one pointer)
    enum:
        SOFTGYM_CHUNK_LINKS
        SOFTGYM_CHUNK_STRIDE
        SOFTGYM_CHUNK_ROWS
        SOFTGYM_CHUNK_FSTRIDE
        SOFTGYM_CHUNK_FROWS
        SOFTGYM_CHUNK_FOUT
