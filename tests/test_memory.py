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


def _huge_pages_asked() -> bool:
    import numpy as np  # noqa: PLC0415

    setter = np._core.multiarray._set_madvise_hugepage
    now = setter(True)
    setter(now)
    return now


_PAGES = """
import resource
import numpy as np
from rkfx.memory import ordinary_pages
with ordinary_pages():
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    a = np.ones(2**25)
    print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="transparent huge pages")
def test_ordinary_pages_are_local_to_the_block():
    """Inside, a 256 MB array is faulted in 4 kB pages (65,536 of them; a huge page would
    take 512 of those at once); numpy's choice is restored after, also on an error and when
    the switch decorates a function."""
    from rkfx.memory import ordinary_pages  # noqa: PLC0415

    faults = int(subprocess.run([sys.executable, "-c", _PAGES], capture_output=True, text=True,
                                check=True).stdout)
    assert faults >= 0.9 * 2**25 * 8 / 4096, faults
    start = _huge_pages_asked()
    with pytest.raises(ZeroDivisionError):
        with ordinary_pages():
            assert not _huge_pages_asked()
            1 / 0
    assert _huge_pages_asked() == start

    @ordinary_pages()
    def inside():
        return _huge_pages_asked()

    assert inside() is False and inside() is False and _huge_pages_asked() == start
