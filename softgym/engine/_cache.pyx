# What the kernel keeps between calls: ContactCache, the self-collision candidate
# lists of a batch's robots (built and searched by _contact.pyx) and the kernels'
# scratch, one block per thread (sized and carved up by _core.advance). Its fields
# are declared in _cache.pxd.

from libc.stdlib cimport calloc, realloc, free
from libc.stdint cimport uintptr_t

import numpy as np

from softgym.engine._contact cimport Contacts
from softgym.engine._typedefs cimport float64_t, intp_t


cdef class ContactCache:
    """Self-collision candidate lists of a batch's robots, kept between calls.

    Owned by a :class:`~softgym.engine.Simulation`; :meth:`invalidate` must be
    called whenever voxels are moved from outside the kernel (set_state, reset).
    Whether and when a list is rebuilt never changes results: a list always
    holds every touching pair, in sorted order. Also holds the kernels'
    scratch (one block per thread), reused from call to call.
    """

    def __cinit__(self, intp_t n_robots):
        self.n = n_robots
        self.items = <Contacts*> calloc(n_robots if n_robots > 0 else 1, sizeof(Contacts))
        if self.items == NULL:
            raise MemoryError("cannot allocate the self-collision cache")
        self.invalidate()

    def pairs(self, intp_t r):
        """Robot r's self-collision candidate pairs (i, j) as of its last rebuild: an
        (n_pairs, 2) int array of batch voxel indices, i < j, sorted (a copy)."""
        if not 0 <= r < self.n:
            raise IndexError(f"robot {r} not in 0..{self.n - 1}")
        if self.items[r].n_pairs == 0:
            return np.empty((0, 2), dtype=np.intp)
        return np.array(<intp_t[:self.items[r].n_pairs, :2]> self.items[r].pairs)

    def invalidate(self):
        """Mark every robot's candidate list for a rebuild before its next use."""
        cdef intp_t r
        for r in range(self.n):
            self.items[r].stale = 1

    def __dealloc__(self):
        cdef intp_t r
        if self.items != NULL:
            for r in range(self.n):
                free(self.items[r].pairs)
                free(self.items[r].cells)
                free(self.items[r].row)
                free(self.items[r].ref)
                free(self.items[r].opairs)
                free(self.items[r].ocells)
                free(self.items[r].dense)
                free(self.items[r].sur)
                free(self.items[r].sur_idx)
                free(self.items[r].hit)
                free(self.items[r].xbits)
            free(self.items)
        free(self.link_scratch)

    cdef float64_t* scratch(self, intp_t size) except NULL:
        # at least `size` doubles of scratch (contents undefined), starting on a
        # 64-byte boundary: the passes' rows start on cache lines (their strides are
        # multiples of 16 doubles), so a 512-bit load or store of a row never spans
        # two lines. malloc gives 16 bytes, and on an Intel Xeon every vector access
        # to the rows was split (benchmarks/RESULTS.md)
        cdef float64_t* p
        if size > self.link_scratch_size:
            p = <float64_t*> realloc(self.link_scratch, (size + 8) * sizeof(float64_t))
            if p == NULL:
                raise MemoryError("no memory for the kernels' scratch")
            self.link_scratch = p
            self.link_scratch_size = size
        return <float64_t*> ((<uintptr_t> self.link_scratch + 63) & ~(<uintptr_t> 63))
