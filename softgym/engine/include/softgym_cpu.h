/* The x86-64 microarchitecture level of the running CPU, for the choice of
   the step kernel's build (softgym/engine/_dispatch.py): 0 where it cannot be
   told (another architecture, another compiler), else 1 (baseline), 3
   (x86-64-v3: AVX2, FMA, BMI1/2, F16C, LZCNT, MOVBE) or 4 (x86-64-v4:
   AVX-512 F, BW, CD, DQ, VL). __builtin_cpu_supports also checks that the
   operating system saves the wide registers (XSAVE / OSXSAVE). */
#ifndef SOFTGYM_CPU_H
#define SOFTGYM_CPU_H

static int softgym_cpu_level(void)
{
#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__))
    int v3, v4;
    __builtin_cpu_init();
    v3 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")
         && __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2")
         && __builtin_cpu_supports("avx");
    v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw")
         && __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq")
         && __builtin_cpu_supports("avx512vl");
    return v4 ? 4 : (v3 ? 3 : 1);
#else
    return 0;
#endif
}

#endif
