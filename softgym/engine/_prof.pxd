# The cycle probes of the seed model's step (include/softgym_prof.h): empty inline
# functions unless the engine is built with SOFTGYM_PROFILE_CYCLES (setup.py), for
# `benchmarks/profile_engine.py --cycles`. Declarations only: no module behind this file.

cdef extern from "softgym_prof.h":
    int softgym_prof_enabled() noexcept nogil
    unsigned long long softgym_prof_tsc() noexcept nogil
    void softgym_prof_add(int k, unsigned long long t0) noexcept nogil
    unsigned long long softgym_prof_get(int k) noexcept nogil
    void softgym_prof_reset() noexcept nogil
