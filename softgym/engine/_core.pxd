# The step loop (see _core.pyx): the one per-robot entry point of the kernel.
# The batch's contract (Batch, STATUS_*, N_AUX) is _batch.pxd; each concept's
# contract is its own .pxd (_corotational, _seed, _contact, _integrate,
# _record).

from softgym.engine._batch cimport Batch
from softgym.engine._contact cimport Contacts
from softgym.engine._typedefs cimport intp_t, step_t


cdef int advance_robot(Batch* b, intp_t r, step_t target, Contacts* c) noexcept nogil
    # Step robot r until steps[r] == target, or until it diverges; modifies
    # its state arrays, step count, traces, divergence flags and its
    # self-collision candidates c in place. Returns a STATUS_* code.
