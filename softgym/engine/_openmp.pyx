# Run-time report of the OpenMP build (sklearn's _openmp_helpers pattern).
# SOFTGYM_OPENMP is a C macro set by setup.py after it probed the compiler.

cdef extern from *:
    """
    #if SOFTGYM_OPENMP
    #include <omp.h>
    static int sg_openmp_enabled(void) { return 1; }
    static int sg_omp_max_threads(void) { return omp_get_max_threads(); }
    #else
    static int sg_openmp_enabled(void) { return 0; }
    static int sg_omp_max_threads(void) { return 1; }
    #endif
    """
    int sg_openmp_enabled() noexcept nogil
    int sg_omp_max_threads() noexcept nogil


def openmp_enabled():
    """Return True when the engine was compiled with OpenMP (robots of a batch run in parallel)."""
    return bool(sg_openmp_enabled())


def omp_max_threads():
    """Return OpenMP's default thread count (1 in a serial build)."""
    return int(sg_omp_max_threads())
