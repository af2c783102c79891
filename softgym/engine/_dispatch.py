"""The build of the compiled engine that runs: portable, or for a newer x86-64 level.

``setup.py`` compiles the engine's kernel modules (its ``ENGINE_MODULES``) for
the portable instruction set and, on x86-64, again from the same C with
``-march=x86-64-v3`` (AVX2) and ``-march=x86-64-v4`` (AVX-512), into the
folders ``_x86_64_v3/`` and ``_x86_64_v4/`` beside this file. :func:`install`
(called by ``softgym/engine/__init__.py`` before any of them is imported)
makes Python load the newest set this CPU runs under the modules' own names,
so the modules' calls into one another stay within one build. The
x86-64-v3 and v4 builds fuse multiply-adds and give bit-identical results to
each other; the portable build (no FMA instructions on x86-64) differs from
them in the last bits (``setup.py``'s docstring). Within one build, results
never depend on the thread count or on batching.

The environment variable ``SOFTGYM_KERNEL`` forces one (``baseline``,
``x86-64-v3`` or ``x86-64-v4``), e.g. to compare them; a build that was not
made, or that this CPU cannot run, is refused with a clear error.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import os
import sys
from pathlib import Path

from softgym.engine._cpu import cpu_level
from softgym.exceptions import InvalidParameterError

__all__ = [
    "FUSED_KERNELS",
    "KERNELS",
    "available_kernels",
    "install",
    "installed_kernels",
    "kernel_build",
]

#: Kernel builds by name: (folder beside this file, x86-64 level it needs).
KERNELS: dict[str, tuple[str | None, int]] = {
    "baseline": (None, 0),
    "x86-64-v3": ("_x86_64_v3", 3),
    "x86-64-v4": ("_x86_64_v4", 4),
}

#: The builds that fuse multiply-adds (bit-identical to one another, not to "baseline").
FUSED_KERNELS: frozenset[str] = frozenset({"x86-64-v3", "x86-64-v4"})

_HERE = Path(__file__).resolve().parent
_chosen: str | None = None


def _files(name: str) -> dict[str, Path] | None:
    """The compiled modules of build ``name`` (full name -> file), None if it was not built.

    The build's folder holds one library per kernel module, named as the
    module (``_core.cpython-311-x86_64-linux-gnu.so``...).
    """
    folder = KERNELS[name][0]
    if folder is None:
        return {}
    found = {}
    if (_HERE / folder).is_dir():
        for suffix in importlib.machinery.EXTENSION_SUFFIXES:
            for path in sorted((_HERE / folder).glob(f"*{suffix}")):
                stem = path.name[: -len(suffix)]
                found.setdefault(f"{__package__}.{stem}", path)
    return found or None


def available_kernels() -> list[str]:
    """The kernel builds present in this installation that this CPU runs, oldest first."""
    level = cpu_level()
    return [n for n, (_, need) in KERNELS.items() if level >= need and _files(n) is not None]


def installed_kernels() -> list[str]:
    """The kernel builds present in this installation, oldest first, whether or not this CPU
    runs them (:func:`available_kernels`: the ones it runs).
    """
    return [n for n in KERNELS if _files(n) is not None]


class _KernelFinder(importlib.abc.MetaPathFinder):
    """Finds the engine's kernel modules in the chosen build's folder."""

    def __init__(self, files: dict[str, Path]) -> None:
        self.files = files

    def find_spec(self, fullname, path=None, target=None):  # noqa: D102
        where = self.files.get(fullname)
        if where is None:
            return None
        loader = importlib.machinery.ExtensionFileLoader(fullname, str(where))
        return importlib.util.spec_from_file_location(fullname, where, loader=loader)


def install(name: str | None = None) -> str:
    """Choose the kernel build (``name``, else ``SOFTGYM_KERNEL``, else the newest available).

    Must run before the kernel modules are first imported (the engine's
    ``__init__`` does it); later calls return the build already chosen.

    Raises
    ------
    InvalidParameterError
        If the build named is unknown, was not built, or needs instructions
        this CPU does not have.
    """
    global _chosen
    if _chosen is not None:
        return _chosen
    name = name or os.environ.get("SOFTGYM_KERNEL") or None
    if name is None:
        name = available_kernels()[-1]
    if name not in KERNELS:
        raise InvalidParameterError(
            f"SOFTGYM_KERNEL must be one of {', '.join(KERNELS)}, got {name!r}"
        )
    if cpu_level() < KERNELS[name][1]:
        raise InvalidParameterError(
            f"kernel build {name!r} needs an x86-64-v{KERNELS[name][1]} CPU; this one runs "
            f"{', '.join(available_kernels())}"
        )
    files = _files(name)
    if files is None:
        raise InvalidParameterError(
            f"kernel build {name!r} was not built in this installation "
            f"(available: {', '.join(available_kernels())})"
        )
    loaded = [m for m in files if m in sys.modules]
    if files and loaded:
        raise InvalidParameterError(f"the kernel modules {loaded} were imported before the "
                                    f"kernel build was chosen")  # fmt: skip
    if files:
        sys.meta_path.insert(0, _KernelFinder(files))
    _chosen = name
    return name


def kernel_build() -> str:
    """The name of the kernel build in use: ``baseline``, ``x86-64-v3`` or ``x86-64-v4``."""
    return install()
