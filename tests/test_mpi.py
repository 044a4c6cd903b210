"""The same solve serially and on 2 (and 3) MPI ranks gives the same answer."""
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

# (script, ranks): the elastostatic solves are assembled by owned rows on more than one rank.
RUNS = [("solve_manufactured.py", 2), ("solve_manufactured.py", 3), ("solve_patch.py", 2), ("solve_patch.py", 3),
        ("solve_mandel.py", 2), ("solve_mandel.py", 3)]
MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize(("script", "ranks"), RUNS)
def test_serial_and_parallel_agree(tmp_path, script, ranks):
    """Elastostatics on gmsh nodes (manufactured solution, patch test) and a u-p time loop:
    the same answer on 1 rank and on 2 or 3."""
    script = Path(__file__).parent / "mpi" / script
    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    serial, parallel = tmp_path / "serial.npy", tmp_path / "parallel.npy"
    subprocess.run([sys.executable, str(script), str(serial)], check=True, timeout=300)
    subprocess.run([mpiexec, "-n", str(ranks), sys.executable, str(script), str(parallel)], check=True, timeout=300)
    a, b = np.load(serial), np.load(parallel)
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()
