"""Benchmark: a small explicit case under MPI costs no more than it costs serially.

Runs ``kalthoff --quick --method fem`` (the crack-band FEM, whose time loop is distributed over
the ranks: ``rkfx.assembly.matrix_strain``) serially with the thread count one of P ranks gets,
then on P ranks, and fails (exit 1) when the P-rank run takes more than ``--max-ratio`` times as
long or its results differ from the serial ones (wall times and the energy balance error, a
small difference of sums that the ranks add in another order, excepted). At this size the
exchanges cost about what the split saves; idle or spinning ranks, or threads fighting over the
cores (``rkfx.parallel.threads``), would show as a ratio well above 1. (Large runs:
``bench/parallel_explicit.py``.)

Usage: python bench/mpi_idle.py [--ranks 2] [--max-ratio 1.5]
The last line printed reads ``<P> ranks / serial: <ratio>``.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CASE = ["-m", "rkfx.cases.kalthoff", "--quick", "--method", "fem"]


def timed(cmd: list[str], env: dict[str, str]) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def runs(path: Path) -> list:
    data = json.loads((path / "results.json").read_text())
    return [{k: v if k != "errors" else {e: x for e, x in v.items() if e != "energy_error"}
             for k, v in r.items() if k != "wall_time_s"} for r in data["runs"]]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--max-ratio", type=float, default=1.5)
    args = ap.parse_args()
    python = sys.executable
    mpiexec = str(Path(python).parent / "mpiexec")
    threads = max(1, len(os.sched_getaffinity(0)) // args.ranks)
    with tempfile.TemporaryDirectory() as tmp:
        serial_out, mpi_out = Path(tmp) / "serial", Path(tmp) / "mpi"
        env = {**os.environ, "NUMBA_NUM_THREADS": str(threads)}
        subprocess.run([python, "-c", "import rkfx.warmup as w; w.warm_up()"], env=env, check=True)
        serial = timed([python, *CASE, "--out", str(serial_out)], env)
        parallel = timed([mpiexec, "-n", str(args.ranks), python, *CASE, "--out", str(mpi_out)],
                         {k: v for k, v in os.environ.items() if k != "NUMBA_NUM_THREADS"})
        same = runs(serial_out) == runs(mpi_out)
    ratio = parallel / serial
    print(f"serial with {threads} thread(s): {serial:.1f} s; {args.ranks} ranks: {parallel:.1f} s; "
          f"results {'identical' if same else 'DIFFER'}")
    print(f"{args.ranks} ranks / serial: {ratio:.2f}")
    return 0 if same and ratio <= args.max_ratio else 1


if __name__ == "__main__":
    sys.exit(main())
