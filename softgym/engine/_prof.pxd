# The cycle probes of the seed model's step (include/softgym_prof.h): empty inline
# functions unless the engine is built with SOFTGYM_PROFILE_CYCLES (setup.py), for
# `benchmarks/profile_engine.py --cycles`. Declarations only: no module behind this file.

cdef extern from "softgym_prof.h":
    int softgym_prof_enabled() noexcept nogil
    unsigned long long softgym_prof_tsc() noexcept nogil
    void softgym_prof_add(int k, unsigned long long t0) noexcept nogil
    unsigned long long softgym_prof_get(int k) noexcept nogil
    void softgym_prof_reset() noexcept nogil


cdef inline object prof_counts(tuple names, bint reset):
    # the calling module's counters (each module has its own) by slot name, as a dict;
    # None in a build without probes
    if not softgym_prof_enabled():
        return None
    out = {name: int(softgym_prof_get(k)) for k, name in enumerate(names)}
    if reset:
        softgym_prof_reset()
    return out
