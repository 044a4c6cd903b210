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


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize("ranks", [2, 3])
def test_mandel_quick_on_ranks_is_the_serial_run(tmp_path, ranks):
    """``mandel --quick`` (RKPM) on 1 rank and on 2 or 3: every series within 1e-10 of its
    largest value (the early-time overshoots are round-off sized themselves: compared absolutely)."""
    import json

    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    args = ["-m", "rkfx.cases.mandel", "--quick", "--method", "rkpm", "--out"]
    subprocess.run([sys.executable, *args, str(tmp_path / "serial")], check=True, timeout=300, capture_output=True)
    subprocess.run([mpiexec, "-n", str(ranks), sys.executable, *args, str(tmp_path / "parallel")], check=True,
                   timeout=300, capture_output=True)
    serial, parallel = (json.loads((tmp_path / d / "results.json").read_text())["runs"] for d in ("serial", "parallel"))
    assert [r["method"] for r in serial] == [r["method"] for r in parallel]
    for a, b in zip(serial, parallel):
        for key, x in a["series"].items():
            x, y = np.asarray(x, float), np.asarray(b["series"][key], float)
            assert np.nanmax(np.abs(x - y)) <= 1e-10 * np.nanmax(np.abs(x)), (a["method"], key)
        for key, x in a["errors"].items():
            assert abs(x - b["errors"][key]) <= 1e-10 * max(abs(x), 1e-3), (a["method"], key)
