"""The build of the step kernel that runs: portable, or for a newer x86-64 level.

``setup.py`` builds the kernel (``softgym.engine._core``) for the portable
instruction set and, on x86-64, again for x86-64-v3 (AVX2) and x86-64-v4
(AVX-512) as ``_core_v3`` and ``_core_v4``. :data:`core` is the newest build
that this CPU runs and that was built; every build gives bit-identical results
(no fused multiply-adds, no result-changing fast-math), only the speed differs.

The environment variable ``SOFTGYM_KERNEL`` forces one (``baseline``,
``x86-64-v3`` or ``x86-64-v4``), e.g. to compare them; a build that was not
made or that this CPU cannot run is refused with a clear error.
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType

from softgym.engine._cpu import cpu_level
from softgym.exceptions import InvalidParameterError

__all__ = ["KERNELS", "available_kernels", "core", "kernel_build", "load_kernel"]

#: Kernel builds by name: (module, x86-64 level it needs).
KERNELS: dict[str, tuple[str, int]] = {
    "baseline": ("softgym.engine._core", 0),
    "x86-64-v3": ("softgym.engine._core_v3", 3),
    "x86-64-v4": ("softgym.engine._core_v4", 4),
}


def _built(name: str) -> ModuleType | None:
    try:
        return importlib.import_module(KERNELS[name][0])
    except ImportError:
        return None


def available_kernels() -> list[str]:
    """The kernel builds present in this installation that this CPU can run, oldest first."""
    level = cpu_level()
    return [n for n, (_, need) in KERNELS.items() if level >= need and _built(n) is not None]


def load_kernel(name: str | None = None) -> tuple[str, ModuleType]:
    """``(name, module)`` of the kernel build ``name``, or of the newest one available.

    Raises
    ------
    InvalidParameterError
        If ``name`` is not a kernel build, was not built, or needs
        instructions this CPU does not have.
    """
    if name is None:
        name = available_kernels()[-1]
    if name not in KERNELS:
        raise InvalidParameterError(
            f"SOFTGYM_KERNEL must be one of {', '.join(KERNELS)}, got {name!r}"
        )
    if cpu_level() < KERNELS[name][1]:
        raise InvalidParameterError(
            f"kernel build {name!r} needs an x86-64-v{KERNELS[name][1]} CPU; this one is "
            f"level {cpu_level()} (available: {', '.join(available_kernels())})"
        )
    module = _built(name)
    if module is None:
        raise InvalidParameterError(
            f"kernel build {name!r} was not built in this installation "
            f"(available: {', '.join(available_kernels())})"
        )
    return name, module


_name, core = load_kernel(os.environ.get("SOFTGYM_KERNEL") or None)


def kernel_build() -> str:
    """The name of the kernel build in use (``baseline``, ``x86-64-v3`` or ``x86-64-v4``)."""
    return _name
