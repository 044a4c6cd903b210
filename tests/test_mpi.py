"""The same solve serially and on 2 MPI ranks gives the same answer."""
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

SCRIPTS = ["solve_manufactured.py", "solve_mandel.py"]
MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize("script", SCRIPTS)
def test_serial_and_two_ranks_agree(tmp_path, script):
    """Elastostatics on gmsh nodes and a u-p time loop: same answer on 1 and 2 ranks."""
    script = Path(__file__).parent / "mpi" / script
    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    serial, parallel = tmp_path / "serial.npy", tmp_path / "parallel.npy"
    subprocess.run([sys.executable, str(script), str(serial)], check=True, timeout=300)
    subprocess.run([mpiexec, "-n", "2", sys.executable, str(script), str(parallel)], check=True, timeout=300)
    a, b = np.load(serial), np.load(parallel)
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()
