# Binding a batch to the kernel (see _bind.pyx, rendered from _bind.pyx.tp and
# contract.py): the one place a Batch is pointed at a batch's arrays.

from softgym.engine._batch cimport Batch
from softgym.engine._typedefs cimport intp_t


cdef int bind(Batch* b, dict a, dict s) except -1
    # b's settings from s, its array pointers into a's arrays (contract.ARRAYS; NULL
    # where one may be empty and is), its scratch pointers NULL; raises ValueError if
    # the link rows the forces pass reads together have two strides

cpdef intp_t row_stride(intp_t n)
    # the row stride of rows of n per-link or per-voxel values a pass reads together:
    # n rounded up to an odd multiple of 16
