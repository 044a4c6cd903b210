"""``bench/parallel_explicit.py`` runs as documented at a small size: serially with ``--save``,
then on 2 ranks with ``--compare``, which finds the serial damage, openings and displacements."""
import re
import shutil

import pytest

from test_mpi_explicit import MPIEXEC, ROOT, mpiexec

BENCH = str(ROOT / "bench" / "parallel_explicit.py")


@pytest.mark.mpi
@pytest.mark.skipif(not MPIEXEC.exists() and shutil.which("mpiexec") is None, reason="no mpiexec")
def test_parallel_explicit_bench_on_two_ranks_matches_its_serial_run(tmp_path):
    saved = tmp_path / "serial.npz"
    serial = mpiexec(1, BENCH, "--nodes", "30", "--t-end", "4e-6", "--save", str(saved))
    assert re.search(r"1 ranks x \d+ threads, \d+ particles: [\d.]+ s stepping", serial.stdout)
    assert saved.exists()
    two = mpiexec(2, BENCH, "--nodes", "30", "--t-end", "4e-6", "--compare", str(saved))
    assert "damage, openings and displacements identical" in two.stdout
    assert re.search(r"peak RSS per rank \[GB\]: [\d.]+, [\d.]+", two.stdout)
