# C scalar types of the engine, in one place: the engine's modules take their scalar types
# from here and declare none of their own (the restrict pointer types are _batch.pxd's);
# docs/ARCHITECTURE.md, "Folders", lists the engine's files.
from libc.stdint cimport int8_t, int32_t, int64_t

ctypedef double float64_t      # every physical quantity (SI units)
ctypedef Py_ssize_t intp_t     # indices and counts into the flat batch arrays
ctypedef int64_t step_t        # step counters
ctypedef int32_t int32         # small integer codes (link axis, flags)
ctypedef int8_t flag_t         # booleans stored in arrays
ctypedef int64_t lane_flag_t   # booleans read in 64-bit vector lanes (links' mode and material flags,
                               # the all-pairs hits): 8-bit ones sized those loops for 64 lanes
