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

``ordinary_pages`` is for assemblies whose large arrays are temporaries: numpy asks the kernel
for transparent huge pages on its large arrays (on Linux, by default), and where the system
serves such requests with direct defragmentation ("madvise", as on these machines) the first
touch of each may wait for the kernel to compact memory. The 263k-node beam's operator build
(subcell rows and stiffness, first pass in a fresh process) spent 2.4-2.5 s of system time
there against 0.5 s in ordinary pages; its assembly took 3.86 / 4.12 s against 2.69 / 2.75 s
(``bench/beam_scale.py``, alternating). Arrays that a time loop keeps reading are better off
in huge pages: Kalthoff's run at 202,950 particles, all in ordinary pages, was 4% and 10%
slower in two pairs (``bench/kalthoff_speed.py``), so the switch is local to the assembly.
"""
import ctypes
import sys
from contextlib import contextmanager

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


@contextmanager
def ordinary_pages():
    """Within the block (or the decorated function), numpy's new large arrays go in ordinary
    pages, without asking for transparent huge pages; numpy's setting is restored after. Does
    nothing where numpy offers no such switch."""
    import numpy as np  # noqa: PLC0415

    core = getattr(np, "_core", None) or getattr(np, "core", None)
    setter = getattr(getattr(core, "multiarray", None), "_set_madvise_hugepage", None)
    if setter is None:
        yield
        return
    before = setter(False)
    try:
        yield
    finally:
        setter(before)
