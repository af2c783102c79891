/* Cycle probes around the engine's passes, for `python benchmarks/profile_engine.py
   --cycles` (the time split that instruction counts miss: gathers, the divider).
   Compiled in only when the extension is built with SOFTGYM_PROFILE_CYCLES set
   (setup.py reads the environment variable of that name) on x86-64, where the
   time-stamp counter is read; otherwise every probe is an empty inline function
   and the passes compile as without it. The counters are per module and not
   atomic: profile one thread. */
#ifndef SOFTGYM_PROF_H
#define SOFTGYM_PROF_H

#define SOFTGYM_PROF_SLOTS 16
#if defined(SOFTGYM_PROFILE_CYCLES) && (defined(__x86_64__) || defined(_M_X64))
#if defined(_MSC_VER)
#include <intrin.h>
#else
#include <x86intrin.h>
#endif
static unsigned long long softgym_prof_cycles[SOFTGYM_PROF_SLOTS];
static inline int softgym_prof_enabled(void) { return 1; }
static inline unsigned long long softgym_prof_tsc(void) { return __rdtsc(); }
/* adds the cycles since t0 to slot k */
static inline void softgym_prof_add(int k, unsigned long long t0)
{
    softgym_prof_cycles[k] += __rdtsc() - t0;
}
static inline unsigned long long softgym_prof_get(int k) { return softgym_prof_cycles[k]; }
static inline void softgym_prof_reset(void)
{
    for (int k = 0; k < SOFTGYM_PROF_SLOTS; k++)
        softgym_prof_cycles[k] = 0;
}
#else
static inline int softgym_prof_enabled(void) { return 0; }
static inline unsigned long long softgym_prof_tsc(void) { return 0; }
static inline void softgym_prof_add(int k, unsigned long long t0) { (void)k; (void)t0; }
static inline unsigned long long softgym_prof_get(int k) { (void)k; return 0; }
static inline void softgym_prof_reset(void) {}
#endif

#endif  /* SOFTGYM_PROF_H */
