# The running CPU's x86-64 level (C in include/softgym_cpu.h), read once by
# softgym/engine/_dispatch.py to pick the step kernel's build.

cdef extern from "softgym_cpu.h":
    int softgym_cpu_level() noexcept nogil


def cpu_level():
    """The x86-64 level of this CPU: 4, 3 or 1; 0 where it cannot be told (other architectures)."""
    return int(softgym_cpu_level())
