"""Build the Cython extensions of softgym, with OpenMP when the compiler has it.

OpenMP is probed, not assumed: a tiny ``omp.h`` program is compiled and linked;
if that fails the extensions are built serially and one warning says so.
``softgym.engine.openmp_enabled()`` reports the outcome at run time.

Environment switches
--------------------
SOFTGYM_DEBUG=1
    Turn Cython's bounds, wraparound and initialisation checks back on
    (for a debug test run).
SOFTGYM_NO_OPENMP=1
    Build serially even when OpenMP is available.
SOFTGYM_PORTABLE=1
    Do not tune for the building machine's CPU. By default the kernel is
    compiled with ``-march=native`` when the compiler accepts it (AVX's
    three-operand instructions cut the step's instruction count by ~20 %);
    set this when the build runs on another CPU than the simulations.
    Results are the same either way: ``-ffp-contract=off`` keeps the
    compiler from fusing multiply-adds, and the kernel uses no fast-math
    flag that changes a result (``-fno-trapping-math`` only allows
    speculative evaluation; floating-point traps are never enabled).
"""

import glob
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import warnings

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup

PROBE = r"""
#include <omp.h>
int main(void) {
    int n = 0;
    #pragma omp parallel reduction(+:n)
    n += 1;
    return omp_get_max_threads() > 0 && n > 0 ? 0 : 1;
}
"""


def _openmp_flags():
    """Return (compile_args, link_args) for OpenMP, or None when it does not build."""
    if os.environ.get("SOFTGYM_NO_OPENMP"):
        return None
    if sys.platform == "win32":
        candidates = [(["/openmp"], [])]
    elif sys.platform == "darwin":
        candidates = [(["-Xpreprocessor", "-fopenmp"], ["-lomp"]), (["-fopenmp"], ["-fopenmp"])]
    else:
        candidates = [(["-fopenmp"], ["-fopenmp"])]
    cc = os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc"
    cc = cc.split()
    if shutil.which(cc[0]) is None:
        return None
    tmp = tempfile.mkdtemp(prefix="softgym-omp-")
    try:
        src = os.path.join(tmp, "probe.c")
        with open(src, "w") as fh:
            fh.write(PROBE)
        for cflags, lflags in candidates:
            exe = os.path.join(tmp, "probe")
            cmd = [*cc, *cflags, src, "-o", exe, *lflags]
            try:
                res = subprocess.run(cmd, capture_output=True, timeout=60)
            except (OSError, subprocess.SubprocessError):
                continue
            if res.returncode == 0 and subprocess.run([exe], capture_output=True).returncode == 0:
                return cflags, lflags
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return None


def _native_flags():
    """Return ["-march=native"] when the compiler takes it, else []."""
    if os.environ.get("SOFTGYM_PORTABLE") or sys.platform == "win32":
        return []
    cc = (os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc").split()
    if shutil.which(cc[0]) is None:
        return []
    tmp = tempfile.mkdtemp(prefix="softgym-native-")
    try:
        src = os.path.join(tmp, "probe.c")
        with open(src, "w") as fh:
            fh.write("int main(void) { return 0; }\n")
        cmd = [*cc, "-march=native", src, "-o", os.path.join(tmp, "probe")]
        try:
            ok = subprocess.run(cmd, capture_output=True, timeout=60).returncode == 0
        except (OSError, subprocess.SubprocessError):
            ok = False
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return ["-march=native"] if ok else []


debug = bool(os.environ.get("SOFTGYM_DEBUG"))
omp = _openmp_flags()
if omp is None:
    warnings.warn(
        "softgym: OpenMP is not available with this compiler; building the engine serially "
        "(robots in a batch run one after another).",
        stacklevel=1,
    )
    omp_cflags, omp_lflags = [], []
else:
    omp_cflags, omp_lflags = omp

if sys.platform == "win32":
    opt = ["/O2"]
else:
    # -fno-trapping-math lets the compiler evaluate both sides of a select
    # (the seed kernel's vectorised bond-frame pass); it changes no result
    opt = ["-O3", "-ffp-contract=off", "-fno-math-errno", "-fno-trapping-math", *_native_flags()]

# the engine's C helpers (static inline kernels) live in softgym/engine/include
ENGINE_INCLUDE = os.path.join("softgym", "engine", "include")

ext_kwargs = dict(
    include_dirs=[np.get_include(), ENGINE_INCLUDE],
    define_macros=[
        ("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION"),
        ("SOFTGYM_OPENMP", "1" if omp is not None else "0"),
    ],
    extra_compile_args=opt + omp_cflags,
    extra_link_args=omp_lflags,
)

core_kwargs = dict(ext_kwargs)
# the headers' own includes are not tracked by cythonize: any header change rebuilds the kernel
core_kwargs["depends"] = sorted(glob.glob(os.path.join(ENGINE_INCLUDE, "*.h")))
# the kernel's `cdef inline` helpers take constant lattice axes: force inlining
# so the compiler specialises them (Cython's guard lets us predefine the macro)
if sys.platform != "win32":
    core_kwargs["define_macros"] = ext_kwargs["define_macros"] + [
        ("CYTHON_INLINE", "__inline__ __attribute__((always_inline))"),
    ]

# the engine, one extension module per concept (each .pyx with its .pxd contract;
# a call across modules goes through a function pointer, so only per-robot
# functions cross them: per-link and per-voxel code inlines within a module, or
# comes inline from a .pxd or an include/*.h header)
ENGINE_MODULES = (
    "_core",          # the step loop and the Python entry points
    "_corotational",  # model 1's link forces
    "_seed",          # model 0's link forces (C passes in include/softgym_seed.h)
    "_contact",       # self-collision (one spatial hash); floor/box laws inline in the .pxd
    "_integrate",     # the voxel update of both models
    "_record",        # centre of mass, trace, aux, energy
)

extensions = [
    *(Extension(f"softgym.engine.{m}", [f"softgym/engine/{m}.pyx"], **core_kwargs)
      for m in ENGINE_MODULES),
    Extension("softgym.engine._openmp", ["softgym/engine/_openmp.pyx"], **ext_kwargs),
]

directives = {
    "language_level": 3,
    "boundscheck": debug,
    "wraparound": debug,
    "initializedcheck": debug,
    "cdivision": True,
    "nonecheck": False,
    "embedsignature": True,
}

setup(
    ext_modules=cythonize(
        extensions,
        compiler_directives=directives,
    ),
)
