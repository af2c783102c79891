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
    Build the step kernel for the portable instruction set only (no
    variants, below).
SOFTGYM_NATIVE=1
    Compile the portable kernel with ``-march=native`` too (a local build
    for the building machine alone; never for a wheel).

Generated sources
-----------------
``softgym/engine/_batch.pxd`` and ``_bind.pyx`` are rendered from the kernel's
contract (``softgym/engine/contract.py``: every array and setting that crosses into
the kernel, and the named codes) and their ``.tp`` templates before anything is
cythonized, as scikit-learn renders its Tempita templates; both are committed too
(``python softgym/engine/_codegen.py`` renders them without a build).

Kernel variants and run-time dispatch
-------------------------------------
On x86-64 (GCC or Clang) every compiled module of the engine
(``softgym.engine._core`` and the modules it calls) is built three times from
the same generated C: for the portable baseline (SSE2), and again with
``-march=x86-64-v3`` (AVX2, FMA, BMI2) and ``-march=x86-64-v4`` (AVX-512) into
``softgym/engine/_x86_64_v3/`` and ``_x86_64_v4/`` under the same module
names. ``softgym.engine`` loads the newest set the running CPU supports
(``softgym/engine/_dispatch.py``; profiled: the AVX2 build runs the seed preset
~2x the portable one, the vectorised link passes are 4 doubles wide), so a
wheel built anywhere runs at full speed everywhere.

Fused multiply-adds: the kernel is compiled with ``-ffp-contract=fast``, so
the x86-64-v3 and v4 builds (and any target whose base instruction set has
FMA, e.g. aarch64) fuse ``a * b + c`` into one correctly rounded operation
(profiled on Zen 4: 12-15 % faster; ``benchmarks/fidelity_seed.py`` holds the
seed preset as faithful to the seed's engine as before). The x86-64-v3 and v4
builds give bit-identical results to each other; the portable x86-64 build
(SSE2, no FMA instructions) rounds each product and differs from them in the
last bits, so results are reproducible bit for bit on every machine that
runs the same build (any AVX2 or AVX-512 x86-64 CPU: the same bits).
``tests/engine/test_kernel_variants.py`` checks both. The kernel uses no
other fast-math flag that changes a result (``-fno-trapping-math`` only
allows speculative evaluation; floating-point traps are never enabled).
"""

import glob
import importlib.util
import os
import platform
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import warnings

import numpy as np
from Cython.Build import cythonize
from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

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


def _compiler_takes(flag):
    """True when the C compiler builds and links a trivial program with ``flag``."""
    cc = (os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc").split()
    if shutil.which(cc[0]) is None:
        return False
    tmp = tempfile.mkdtemp(prefix="softgym-flag-")
    try:
        src = os.path.join(tmp, "probe.c")
        with open(src, "w") as fh:
            fh.write("int main(void) { return 0; }\n")
        cmd = [*cc, flag, src, "-o", os.path.join(tmp, "probe")]
        try:
            return subprocess.run(cmd, capture_output=True, timeout=60).returncode == 0
        except (OSError, subprocess.SubprocessError):
            return False
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _native_flags():
    """["-march=native"] when SOFTGYM_NATIVE=1 asks for it and the compiler takes it."""
    if not os.environ.get("SOFTGYM_NATIVE") or sys.platform == "win32":
        return []
    return ["-march=native"] if _compiler_takes("-march=native") else []


def _kernel_levels():
    """The x86-64 levels the kernel is built for besides the portable baseline."""
    if os.environ.get("SOFTGYM_PORTABLE") or os.environ.get("SOFTGYM_NATIVE"):
        return []
    if sys.platform == "win32" or platform.machine().lower() not in ("x86_64", "amd64"):
        return []
    # the target, not the build machine: a cross build (cibuildwheel's arm64 wheels on an
    # x86-64 Mac set _PYTHON_HOST_PLATFORM and ARCHFLAGS) gets the portable kernel only
    target = sysconfig.get_platform().lower()
    archflags = os.environ.get("ARCHFLAGS", "").split()[1::2]
    if not target.endswith(("x86_64", "amd64")) or any(a != "x86_64" for a in archflags):
        return []
    levels = [lvl for lvl in ("v3", "v4") if _compiler_takes(f"-march=x86-64-{lvl}")]
    dropped = [f"x86-64-{lvl}" for lvl in ("v3", "v4") if lvl not in levels]
    if dropped:  # a build without them runs at the portable kernel's speed: say so in the log
        cc = os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc"
        warnings.warn(
            f"softgym: the compiler ({cc}) does not take -march={' / -march='.join(dropped)}; "
            f"the kernel variant(s) {', '.join(dropped)} are NOT built (a CPU that has them runs "
            "an older, slower build; `softgym info` shows the build in use); a newer GCC or "
            "Clang builds them.",
            stacklevel=1,
        )
    return levels


class BuildExt(build_ext):
    """build_ext that compiles the extensions in parallel (one job per CPU) by default."""

    def finalize_options(self):
        super().finalize_options()
        if self.parallel is None:
            self.parallel = os.cpu_count() or 1


def _variant_copy(source, folder):
    """A copy of the generated C file ``source`` under ``build/<folder>/`` (its own objects)."""
    target = os.path.join("build", folder, source)
    os.makedirs(os.path.dirname(target), exist_ok=True)
    with open(source, "rb") as fh:
        data = fh.read()
    if not os.path.exists(target) or open(target, "rb").read() != data:
        with open(target, "wb") as fh:  # rewritten only when changed: no needless rebuild
            fh.write(data)
    return target


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
    # -ffp-contract=fast: fused multiply-adds where the instruction set has
    # them (x86-64-v3/v4, aarch64; the module docstring says what it changes).
    # -fno-trapping-math lets the compiler evaluate both sides of a select
    # (the seed kernel's vectorised bond-frame pass); it changes no result
    opt = ["-O3", "-ffp-contract=fast", "-fno-math-errno", "-fno-trapping-math", *_native_flags()]

# the engine's C helpers (static inline kernels) live in softgym/engine/include
ENGINE_INCLUDE = os.path.join("softgym", "engine", "include")

ext_kwargs = dict(
    include_dirs=[np.get_include(), ENGINE_INCLUDE],
    define_macros=[
        ("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION"),
        ("SOFTGYM_OPENMP", "1" if omp is not None else "0"),
        # cycle probes around the passes (include/softgym_prof.h), for
        # `benchmarks/profile_engine.py --cycles`, which builds a copy with it
        *([("SOFTGYM_PROFILE_CYCLES", "1")] if os.environ.get("SOFTGYM_PROFILE_CYCLES") else []),
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
    "_bind",          # binds a batch's arrays and settings to Batch (rendered from contract.py)
    "_cache",         # ContactCache: self-collision candidates and scratch kept between calls
    "_corotational",  # model 1's link forces
    "_seed",          # model 0's link forces (C passes in include/softgym_seed.h)
    "_contact",       # self-collision (one spatial hash); floor/box laws inline in the .pxd
    "_integrate",     # the voxel update of both models
    "_record",        # centre of mass, trace, aux, energy
)


def _render_contract():
    """Render the engine's generated Cython from its contract (softgym/engine/_codegen.py).

    ``_batch.pxd`` and ``_bind.pyx`` come from ``contract.py`` and their ``.tp``
    templates; a file is rewritten only when its text changes, so an unchanged contract
    rebuilds nothing. Loaded from its path: the package is not importable before it is
    built.
    """
    path = os.path.join("softgym", "engine", "_codegen.py")
    spec = importlib.util.spec_from_file_location("_softgym_engine_codegen", path)
    codegen = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(codegen)
    for target in codegen.generate():
        print(f"softgym: rendered {target} from the kernel's contract")


_render_contract()

extensions = [
    *(Extension(f"softgym.engine.{m}", [f"softgym/engine/{m}.pyx"], **core_kwargs)
      for m in ENGINE_MODULES),
    Extension("softgym.engine._openmp", ["softgym/engine/_openmp.pyx"], **ext_kwargs),
    Extension("softgym.engine._cpu", ["softgym/engine/_cpu.pyx"], **ext_kwargs),
    # the robots' contact sensor (read after an engine call; never part of a step)
    Extension("softgym.engine._sense", ["softgym/engine/_sense.pyx"], **ext_kwargs),
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

extensions = cythonize(extensions, compiler_directives=directives)
# every engine module again for each newer x86-64 level, from the same C (their
# calls into one another resolve within one build: softgym/engine/_dispatch.py)
base = [e for e in extensions if e.name in {f"softgym.engine.{m}" for m in ENGINE_MODULES}]
for level in _kernel_levels():
    folder = f"_x86_64_{level}"
    for ext in base:
        # softgym.engine._x86_64_v3._core: the generated C of softgym.engine._core
        # (copied, so its objects are its own) compiled with the level's flags;
        # softgym/engine/_dispatch.py loads it under the module's own name
        package, _, module = ext.name.rpartition(".")
        extensions.append(Extension(
            f"{package}.{folder}.{module}",
            [_variant_copy(src, folder) for src in ext.sources],
            include_dirs=list(ext.include_dirs),
            define_macros=list(ext.define_macros),
            extra_compile_args=[*ext.extra_compile_args, f"-march=x86-64-{level}"],
            extra_link_args=list(ext.extra_link_args),
            depends=list(ext.depends),
        ))  # fmt: skip
        # an in-place (editable) build copies the library there: the folder must exist
        os.makedirs(os.path.join(*package.split("."), folder), exist_ok=True)

setup(ext_modules=extensions, cmdclass={"build_ext": BuildExt})
