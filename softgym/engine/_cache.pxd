# What the kernel keeps between calls (see _cache.pyx): the self-collision
# candidate lists of a batch's robots and the kernels' scratch. Declared here so
# that _core.advance reaches the lists and the scratch without Python.

from softgym.engine._contact cimport Contacts
from softgym.engine._typedefs cimport float64_t, intp_t


cdef class ContactCache:
    cdef Contacts* items             # (n,) robot r's candidate lists (_contact.pxd)
    cdef intp_t n                    # robots in the batch
    cdef float64_t* link_scratch     # the kernels' scratch (one block per thread), as allocated
    cdef intp_t link_scratch_size    # its doubles usable from its first 64-byte boundary

    cdef float64_t* scratch(self, intp_t size) except NULL
        # at least `size` doubles of scratch (contents undefined) on a 64-byte boundary
