"""rkfx.memory: with freed memory reused, a second large temporary costs no fresh page faults."""
import subprocess
import sys

import pytest

# In a fresh process: page faults of touching a 256 MB temporary, freed, then a second one.
_PROBE = """
import resource, sys
import numpy as np
from rkfx.memory import reuse_freed_memory
took = reuse_freed_memory() if sys.argv[1] == "reuse" else None
def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
counts = []
for _ in range(2):
    before = faults()
    a = np.ones(2**25)
    counts.append(faults() - before)
    del a
print(took, *counts)
"""


def _probe(mode: str) -> tuple[str, int, int]:
    out = subprocess.run([sys.executable, "-c", _PROBE, mode], capture_output=True, text=True, check=True)
    took, first, second = out.stdout.split()
    return took, int(first), int(second)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_freed_memory_is_reused():
    took, first, second = _probe("reuse")
    assert took == "True"
    assert first > 0 and second <= 0.05 * first, (first, second)
    # Without it the second temporary is faulted in again: the test sees the difference.
    _, first, second = _probe("system")
    assert second >= 0.5 * first, (first, second)
