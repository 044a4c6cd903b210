"""Benchmark: the u-p consolidation solve (Mandel, SCNI+FPP, backward Euler) serially and over MPI ranks.

Mandel's problem on an nx x ny grid of nodes through t_D = 0.1; on more than one rank the
particles are split by RCB, each rank assembles its own nodes' terms and steps its local
unknowns, and the system of every step is assembled by owned rows (``rkfx.parallel.unknowns``).
Prints the assembly and stepping times (max over ranks), the peak RSS of every rank and the
relative difference of the gathered pressure coefficients to a serial run's saved with ``--save``.

Usage:
    python bench/parallel_biot.py [--nx 301 --ny 31] [--save serial.npy]
    mpiexec -n 2 env NUMBA_NUM_THREADS=1 python bench/parallel_biot.py --compare serial.npy
The last line printed reads ``<ranks> ranks x <threads> threads, <N> nodes: <seconds> s``.
"""
import argparse
import resource
import time

import dolfinx_solver  # noqa: F401  (before mpi4py)
import numba
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement, Pressure
from rkfx.geometry.particles import structured
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up
from verification.mandel import Mandel


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=301, help="nodes along the 20 m side")
    ap.add_argument("--ny", type=int, default=31, help="nodes along the 2 m side")
    ap.add_argument("--save", help="write the pressure coefficients (rank 0) to this .npy file")
    ap.add_argument("--compare", help="report the relative difference to these saved coefficients")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    material = PoroMaterial(1.0e4, 0.2, 1.0e-4)
    exact = Mandel(material.E, material.nu, material.k, 20.0, 2.0, 40.0)
    t_end = 0.1 * 20.0**2 / material.consolidation_coefficient
    times = time_grid([0.1 * t_end, t_end], 1e-4 * t_end, 1.6, hold=5)
    p = structured(20.0, 2.0, args.nx, args.ny)
    bcs = [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
           Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,))]
    comm.Barrier()
    t0 = time.perf_counter()
    sol = solve_biot(p, material, times, [0.1 * t_end, t_end], bcs, [Pressure("right")], comm=comm)
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    stages = {k: comm.allreduce(v, op=MPI.MAX) for k, v in sol.timings.items()}
    rss = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, root=0)
    if comm.rank != 0:
        return
    print(f"{len(times) - 1} steps; stages [s, max over ranks]: " + ", ".join(f"{k} {v:.2f}" for k, v in stages.items()))
    print("peak RSS per rank [MB]: " + ", ".join(f"{r:.0f}" for r in rss))
    if args.save:
        np.save(args.save, sol.P)
    if args.compare:
        ref = np.load(args.compare)
        print(f"max relative difference to {args.compare}: {np.abs(sol.P - ref).max() / np.abs(ref).max():.2e}")
    print(f"{comm.size} ranks x {numba.get_num_threads()} threads, {p.num_nodes} nodes: {wall:.2f} s")


if __name__ == "__main__":
    main()
