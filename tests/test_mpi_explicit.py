"""Explicit fracture runs distributed over MPI ranks (``rkfx.models.damage_ranks``) are the
serial runs: the same damaged particles, damage and crack openings bit for bit, the same
crack angles and dissipation histories to round-off; a run killed on 2 ranks resumes on 2
ranks to the uninterrupted result, and a resume on another number of ranks is refused in
one line."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

MPIEXEC = Path(sys.executable).parent / "mpiexec"
ROOT = Path(__file__).resolve().parents[1]
KILLED_RUN = ROOT / "tests" / "faults" / "killed_run.py"
sys.path.insert(0, str(ROOT / "tests" / "faults"))
from killed_run import ARGS  # noqa: E402  (a small Kalthoff invocation)

pytestmark = [pytest.mark.mpi,
              pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")]
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))


def mpiexec(ranks: int, *args, check=True):
    launcher = str(MPIEXEC) if MPIEXEC.exists() else "mpiexec"
    cmd = [sys.executable, *args] if ranks == 1 else [launcher, "-n", str(ranks), sys.executable, *args]
    return subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600, check=check)


def kalthoff(ranks: int, out: Path, *extra, check=True):
    return mpiexec(ranks, "-m", "rkfx.cases.kalthoff", *ARGS, "--out", str(out), *extra, check=check)


def runs(out: Path) -> dict:
    return {r["method"]: r for r in json.loads((out / "results.json").read_text())["runs"]}


def assert_same_runs(a: dict, b: dict) -> None:
    assert list(a) == list(b)
    for name, ra in a.items():
        rb = b[name]
        for key in ("damaged_index", "damaged_D", "damaged_w", "damage", "opening"):
            assert ra["series"].get(key) == rb["series"].get(key), (name, key)
        for key in ("dissipated", "damaged", "kinetic", "internal", "external", "released"):
            if key in ra["series"]:
                x, y = np.asarray(ra["series"][key], float), np.asarray(rb["series"][key], float)
                assert np.abs(x - y).max() <= 1e-10 * max(np.abs(x).max(), 1e-300), (name, key)
        for key, value in ra["errors"].items():
            if key != "energy_error" and isinstance(value, float):
                assert value == pytest.approx(rb["errors"][key], rel=1e-10, abs=1e-12), (name, key)


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    kalthoff(1, out)
    return runs(out)


@pytest.mark.parametrize("ranks", [2, 3])
def test_kalthoff_on_ranks_is_the_serial_run(serial, tmp_path, ranks):
    done = kalthoff(ranks, tmp_path / "run")
    assert done.stdout.count("results:") == 1
    assert_same_runs(serial, runs(tmp_path / "run"))
    run = next(d for d in (tmp_path / "run" / "checkpoints").iterdir() if d.is_dir())
    assert sorted(p.name for p in run.iterdir() if p.is_dir()) == [f"rank{r}-of-{ranks}" for r in range(ranks)]
    assert (run / "result.npz").is_file()  # finished results are gathered and written once


def test_killed_on_two_ranks_resumes_on_two_ranks(serial, tmp_path):
    out = tmp_path / "run"
    killed = mpiexec(2, str(KILLED_RUN), str(out), "after-checkpoint", "6", check=False)
    assert killed.returncode != 0 and not (out / "results.json").exists(), killed.stderr[-2000:]
    for ranks, word in ((3, "written on 2 ranks"), (1, "written on 2 ranks")):
        refused = kalthoff(ranks, out, "--resume", str(out), check=False)
        lines = [line for line in refused.stderr.splitlines() if "error" in line]
        assert refused.returncode != 0 and lines and word in lines[0], refused.stderr[-2000:]
    kalthoff(2, out, "--resume", str(out))
    assert_same_runs(serial, runs(out))


@pytest.mark.parametrize("ranks", [1, 2, 3])
def test_a_share_runs_stencils_and_is_the_whole_operator(ranks):
    """Each rank's share evaluates most of its rows as lattice stencils over its box, with the
    whole operator's strains and forces bit for bit (``tests/mpi/share_stencil.py`` asserts)."""
    done = mpiexec(ranks, str(ROOT / "tests" / "mpi" / "share_stencil.py"), check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert float(done.stdout.split("coverage")[1]) > 0.3


FEM_ARGS = ["--method", "fem", "--set", "fem_h=2e-3", "t_end=3e-5", "--checkpoint-every", "50", "--vtk"]


@pytest.fixture(scope="module")
def serial_fem(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial_fem")
    mpiexec(1, "-m", "rkfx.cases.kalthoff", *FEM_ARGS, "--out", str(out))
    return out


@pytest.mark.parametrize("ranks", [2, 3])
def test_crack_band_fem_on_ranks_is_the_serial_run(serial_fem, tmp_path, ranks):
    """The crack-band FEM's time loop is distributed too (``rkfx.assembly.matrix_strain``): the
    same damaged cells, damage and openings bit for bit, one checkpoint folder per rank, and the
    ParaView frames written once (rank 0), byte for byte the serial run's."""
    out = tmp_path / "run"
    mpiexec(ranks, "-m", "rkfx.cases.kalthoff", *FEM_ARGS, "--out", str(out))
    serial = runs(serial_fem)
    assert_same_runs(serial, runs(out))
    assert any(max(r["series"].get("damage", [0])) == 1.0 for r in serial.values())  # cracked cells compared
    run = next(d for d in (out / "checkpoints").iterdir() if d.is_dir())
    assert sorted(p.name for p in run.iterdir() if p.is_dir()) == [f"rank{r}-of-{ranks}" for r in range(ranks)]
    frames = sorted(p.name for p in (out / "vtk").glob("*.vtu"))
    assert frames and frames == sorted(p.name for p in (serial_fem / "vtk").glob("*.vtu"))
    assert all((out / "vtk" / f).read_bytes() == (serial_fem / "vtk" / f).read_bytes() for f in frames)


def test_branching_crack_band_fem_on_two_ranks_is_the_serial_run(tmp_path):
    """The branching plate's crack-band FEM (no supports, edge tractions) on 2 ranks: the same
    damaged cells and damage, histories to round-off."""
    args = ["-m", "rkfx.cases.crack_branching", "--quick", "--method", "fem"]
    mpiexec(1, *args, "--out", str(tmp_path / "serial"))
    mpiexec(2, *args, "--out", str(tmp_path / "ranks"))
    serial = runs(tmp_path / "serial")
    assert any(r["series"].get("damaged_index") for r in serial.values())
    assert_same_runs(serial, runs(tmp_path / "ranks"))


def test_nonlocal_branching_on_ranks_is_the_serial_run(tmp_path):
    """The nonlocal equivalent strain on ranks (the averages read the strains of the particles
    within R through a halo exchange per step): the same damaged particles, damage and openings
    on 2 and 3 ranks."""
    args = ["-m", "rkfx.cases.crack_branching", "--method", "rkpm", "--set", "h=1.6e-3", "unregularized_h=1.6e-3",
            "nonlocal_h=1.6e-3", "nonlocal_radius=3.2e-3", "t_end=5e-5"]
    mpiexec(1, *args, "--out", str(tmp_path / "serial"))
    serial = runs(tmp_path / "serial")
    assert serial["rkpm-dpm-nonlocal h=0.0016"]["series"]["damaged_index"]
    for ranks in (2, 3):
        mpiexec(ranks, *args, "--out", str(tmp_path / f"ranks{ranks}"))
        assert_same_runs(serial, runs(tmp_path / f"ranks{ranks}"))
