"""Freed memory kept by the process and reused, instead of handed back to the system.

glibc's malloc maps every block above its mmap threshold (128 KB, rising to 32 MB) as fresh
pages and unmaps it on free, so each large temporary of an operator build or of PETSc's
multigrid set-up is faulted in and zeroed by the kernel again: on the 263k-node beam
(``bench/beam_scale.py``) 17% of the solve's samples sit in the kernel's page clearing.
``reuse_freed_memory`` turns that off for the rest of the process: allocations come from the
heap, and what is freed stays there for the next one. Measured on the beam, the same run
before and after: 1,051,137 nodes, assembly 18.1 -> 14.1 s, solve 46.7 -> 40.1 s, peak RSS
6.88 -> 7.46 GB (the heap keeps what fragmentation strands).

The cases' command line and the benchmarks call it; a script of one's own calls it first.
"""
import ctypes
import sys

# mallopt(3) parameters of glibc's malloc.h.
_M_TRIM_THRESHOLD, _M_MMAP_MAX = -1, -4
# Free memory at the top of the heap above this much is still given back (mallopt takes an int).
_TRIM_BYTES = 2**31 - 1


def reuse_freed_memory() -> bool:
    """Serve every allocation of this process from the heap and keep freed memory there
    (glibc's ``mallopt``: no mmap'd blocks, top trimmed only beyond 2 GB). Returns whether
    the C library took it: False off glibc (another C library, another system), where
    nothing changes."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_MAX, 0)) and bool(mallopt(_M_TRIM_THRESHOLD, _TRIM_BYTES))
