"""Plain ``import dolfinx`` and ``from petsc4py import PETSc`` work, with nothing imported first.

The mpich wheel's libmpi sits outside the loader's search path; ``make env`` installs
tools/rkfx-mpi.pth and tools/rkfx_mpi_first.py into site-packages to load it on demand.
"""
import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

TOOLS = Path(__file__).resolve().parents[1] / "tools"
PLAIN_IMPORTS = ["import dolfinx", "from petsc4py import PETSc"]
needs_dolfinx = pytest.mark.skipif(importlib.util.find_spec("dolfinx") is None,
                                   reason="dolfinx is not installed")


def _python(code: str, site_dir: Path | None = None) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter of this environment, with the repo's hook first if given."""
    if site_dir is not None:
        # -S, then the hook's folder before site-packages: the repo's copy is the one imported,
        # even where an older copy is installed.
        code = f"import site; site.addsitedir({str(site_dir)!r}); site.main(); {code}"
    args = [sys.executable, "-S", "-c", code] if site_dir is not None else [sys.executable, "-c", code]
    return subprocess.run(args, capture_output=True, text=True, timeout=60, check=False)


@pytest.fixture
def hook_dir(tmp_path) -> Path:
    """A folder holding the two files exactly as ``make env`` installs them."""
    shutil.copy(TOOLS / "rkfx-mpi.pth", tmp_path / "rkfx-mpi.pth")
    shutil.copy(TOOLS / "rkfx_mpi_first.py", tmp_path / "_rkfx_mpi_first.py")
    return tmp_path


@needs_dolfinx
@pytest.mark.parametrize("code", PLAIN_IMPORTS)
def test_plain_import_works_in_this_environment(code):
    run = _python(code)
    last = (run.stderr.strip().splitlines() or [""])[-1]
    assert run.returncode == 0, f"{code!r} fails alone in {sys.prefix} ({last}); run `make env`"


@needs_dolfinx
@pytest.mark.parametrize("code", PLAIN_IMPORTS)
def test_the_hook_makes_the_plain_import_work(hook_dir, code):
    run = _python(code, hook_dir)
    assert run.returncode == 0, run.stderr


@needs_dolfinx
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/maps")
def test_dolfinx_and_mpi4py_share_one_libmpi(hook_dir):
    code = ("import dolfinx; from mpi4py import MPI; "
            "print(len({l.split()[-1] for l in open('/proc/self/maps') if 'libmpi.so' in l}))")
    run = _python(code, hook_dir)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "1"


def test_the_hook_loads_nothing_at_start_up(hook_dir):
    code = ("import sys, _rkfx_mpi_first as m; "
            "print(m.MpiFirst in sys.meta_path, *(n in sys.modules for n in ('numpy', 'mpi4py', '_ctypes')))")
    run = _python(code, hook_dir)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split() == ["True", "False", "False", "False"]
