"""The same solve serially and on 2 (and 3) MPI ranks gives the same answer."""
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

# (script, ranks): the elastostatic solves are assembled by owned rows on more than one rank.
RUNS = [("solve_manufactured.py", 2), ("solve_manufactured.py", 3), ("solve_patch.py", 2), ("solve_patch.py", 3),
        ("solve_mandel.py", 2), ("solve_mandel.py", 3), ("solve_3d.py", 2), ("solve_3d.py", 3),
        ("steady_dam.py", 2), ("steady_dam.py", 3)]
MPIEXEC = Path(sys.executable).parent / "mpiexec"


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize(("script", "ranks"), RUNS)
def test_serial_and_parallel_agree(tmp_path, script, ranks):
    """Elastostatics on gmsh nodes (manufactured solution, patch test), a u-p time loop, and both
    in 3-D, and a steady unsaturated seepage through a seepage face (RKPM and FEM): the same
    answer on 1 rank and on 2 or 3."""
    a, b = _serial_and_parallel(tmp_path, script, ranks)
    assert np.abs(a - b).max() <= 1e-10 * np.abs(a).max()


def _serial_and_parallel(tmp_path, script: str, ranks: int) -> tuple[np.ndarray, np.ndarray]:
    """What ``tests/mpi/<script> OUT.npy`` saves run serially and on ``ranks`` ranks (same shape)."""
    script = Path(__file__).parent / "mpi" / script
    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    serial, parallel = tmp_path / "serial.npy", tmp_path / "parallel.npy"
    subprocess.run([sys.executable, str(script), str(serial)], check=True, timeout=300)
    subprocess.run([mpiexec, "-n", str(ranks), sys.executable, str(script), str(parallel)], check=True, timeout=300)
    a, b = np.load(serial), np.load(parallel)
    assert a.shape == b.shape
    return a, b


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize("ranks", [2, 3])
def test_field_split_solves_alike_on_ranks(tmp_path, ranks):
    """The field-split u-p solve (GMRES to a 1e-10 residual) on 1 rank and on 2 or 3: the same
    pressures to the solver's tolerance (the ranks' rows change the preconditioner)."""
    a, b = _serial_and_parallel(tmp_path, "solve_mandel_fieldsplit.py", ranks)
    assert np.abs(a - b).max() <= 1e-5 * np.abs(a).max()


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize("ranks", [1, 2, 3])
def test_contributions_assemble_at_their_owners(ranks):
    """``UnknownShare.assemble`` and ``row_system`` give the whole vector and matrix rows."""
    script = Path(__file__).parent / "mpi" / "assemble_by_owners.py"
    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    done = subprocess.run([mpiexec, "-n", str(ranks), sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0 and "ok" in done.stdout, done.stderr[-2000:]


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize("ranks", [2, 3])
@pytest.mark.parametrize("case", ["mandel", "liakopoulos", "wave_column", "wave_column --set fpp=true",
                                  "levee --set plastic=true"])
def test_quick_runs_on_ranks_are_the_serial_run(tmp_path, case, ranks):
    """``mandel``, ``liakopoulos``, ``wave_column`` and ``levee --quick`` (RKPM: Biot on SCNI,
    unsaturated u-p on NSNI, explicit u-p dynamics on NSNI and DNI, the levee's steady seepage
    through a seepage face on gmsh nodes and its elastic-plastic state; each rank integrating
    over its own nodes' cells; the explicit one also with the pressure projection's storage
    solve) on 1 rank and on 2 or 3:
    every series within 1e-10 of its largest value (the
    early-time overshoots are round-off sized themselves: compared absolutely), the same Newton
    iterations and steps."""
    _quick_run_on_ranks(tmp_path, case, ranks)


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
def test_levee_split_along_its_wet_slope_is_the_serial_run(tmp_path):
    """On 4 ranks RCB cuts the river's wet slope: the river's load must reach every owner
    (formed whole on each rank, added at the owned entries) for the serial run's fields."""
    _quick_run_on_ranks(tmp_path, "levee", 4)


def _quick_run_on_ranks(tmp_path, case: str, ranks: int) -> None:
    import json

    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    name, *extra = case.split()
    args = ["-m", f"rkfx.cases.{name}", "--quick", "--method", "rkpm", *extra, "--out"]
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
            # An observed rate is a log of a ratio of errors; where those are ~1e-5 of their
            # quantity (the drained steady state) it carries the series' round-off times 1e5.
            tol = 1e-8 if key.startswith("rate_") else 1e-10
            assert abs(x - b["errors"][key]) <= tol * max(abs(x), 1e-3), (a["method"], key)
        for key in ("newton_iterations", "steps", "dt"):
            assert a["info"].get(key) == b["info"].get(key), (a["method"], key)


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
@pytest.mark.parametrize(("case", "every", "run", "step"), [("mandel", 4, "rkpm-scni+fpp-profiles", 12),
                                                          ("liakopoulos", 30, "rkpm-nsni", 90),
                                                          ("wave_column", 200, "rkpm-nsni", 600)])
def test_killed_on_two_ranks_resumes_on_two_ranks(tmp_path, case, every, run, step):
    """The u-p runs are distributed (each rank steps its own unknowns, one checkpoint per rank):
    killed on 2 ranks after a checkpoint, refused on 3, resumed on 2 to the serial results."""
    import json
    import os

    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    mpiexec = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    args = ["-m", f"rkfx.cases.{case}", "--quick", "--method", "rkpm", "--checkpoint-every", str(every)]
    out = tmp_path / "run"
    subprocess.run([sys.executable, *args, "--out", str(tmp_path / "serial")], check=True, timeout=300,
                   capture_output=True, env=env)
    killed = subprocess.run([mpiexec, "-n", "2", sys.executable, str(root / "tests" / "faults" / "killed_run.py"),
                             str(out), "after-checkpoint", "3", case], timeout=300, capture_output=True, env=env)
    assert killed.returncode != 0 and not (out / "results.json").exists()
    folder = out / "checkpoints" / run
    assert sorted(p.name for p in folder.iterdir() if p.is_dir()) == ["rank0-of-2", "rank1-of-2"]
    refused = subprocess.run([mpiexec, "-n", "3", sys.executable, *args, "--out", str(out), "--resume", str(out)],
                             timeout=300, capture_output=True, text=True, env=env)
    errors = [line for line in refused.stderr.splitlines() if "error" in line]
    assert refused.returncode != 0 and errors and "written on 2 ranks" in errors[0], refused.stderr[-2000:]
    resumed = subprocess.run([mpiexec, "-n", "2", sys.executable, *args, "--out", str(out), "--resume", str(out)],
                             timeout=300, capture_output=True, text=True, env=env, check=True)
    assert f"continues from step {step}" in resumed.stderr
    serial, parallel = (json.loads((d / "results.json").read_text())["runs"] for d in (tmp_path / "serial", out))
    for a, b in zip(serial, parallel, strict=True):
        for key, x in a["series"].items():
            x, y = np.asarray(x, float), np.asarray(b["series"][key], float)
            assert np.nanmax(np.abs(x - y)) <= 1e-10 * np.nanmax(np.abs(x)), (a["method"], key)
