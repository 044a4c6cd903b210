"""Benchmark: Kalthoff's impact problem by the damage particle method, serially and over MPI ranks.

The regularized model of ``rkfx.cases.kalthoff`` with tracking at ``--nodes`` particles per side
(450: 202,950 particles) through ``--t-end``. On more than one rank the run is distributed
(``rkfx.models.damage_ranks``). Prints the set-up and stepping wall times (the largest over the
ranks), each rank's peak RSS and, against a serial run
saved with ``--save``, whether the damage, crack openings and displacements are the same bit
for bit and the largest relative difference of the dissipation history.

``--nonlocal R`` runs the nonlocal equivalent strain of radius R [m] (``rkfx.fracture.nonlocal_average``).
``--fem H`` runs the crack-band finite elements of element size H [m] instead
(``fem_baselines.crack_band_dynamics``; on several ranks its time loop is distributed too).

Usage:
    python bench/parallel_explicit.py [--nodes 450] [--t-end 8e-5] [--save serial.npz]
    mpiexec -n 2 python bench/parallel_explicit.py --compare serial.npz
    python bench/parallel_explicit.py --fem 2e-4 --save fem.npz
The cases give each rank its share of the cores for numba; set NUMBA_NUM_THREADS to choose.
The last line reads ``<ranks> ranks x <threads> threads, <N> particles: <seconds> s stepping``
(``cells`` for ``--fem``).
"""
import argparse
import resource
import time

import dolfinx_solver  # noqa: F401  (before mpi4py)
import numba
import numpy as np
from mpi4py import MPI

from fem_baselines.crack_band_dynamics import kalthoff_crack_band
from rkfx.cases import _dynamic_fracture as dyn
from rkfx.cases import kalthoff as k
from rkfx.fracture import damage as dm
from rkfx.parallel.threads import share_cores
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=450, help="particles per side")
    ap.add_argument("--t-end", type=float, default=80e-6, help="end time [s]")
    ap.add_argument("--fem", type=float, help="run the crack-band FEM of this element size [m] instead")
    ap.add_argument("--nonlocal", type=float, default=0.0, dest="radius",
                    help="run the nonlocal equivalent strain of this radius R [m] (0: the local law)")
    ap.add_argument("--save", help="write the run's results (rank 0) to this .npz file")
    ap.add_argument("--compare", help="compare with the results saved by --save")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    if comm.size > 1:
        share_cores(comm)
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    k.run(methods=("rkpm",), h=k.spacings([40]), unregularized_h=[], no_tracking_h=[], fem_h=[], nonlocal_h=[],
          t_end=5e-6)  # compile the step kernels
    prm = {name: spec.default for name, spec in k.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
    comm.Barrier()
    t0 = time.perf_counter()
    if args.fem:
        fem = kalthoff_crack_band(args.fem, args.t_end, E=prm["E"], nu=prm["nu"], rho=prm["rho"], ft=prm["ft"],
                                  GF=prm["GF"], v0=prm["v0"], comm=comm)
        run, n, what = fem.run, fem.num_cells, "cells"
        setup = fem.wall_time_s - run.wall_time_s
    else:
        pl, track, model = k.setup(args.nodes, material, prm, comm=comm, nonlocal_radius=args.radius)
        setup = time.perf_counter() - t0
        run = dyn.simulate("bench", pl, model, track, k.model_conditions(pl, prm["v0"]), args.t_end, comm=comm)
        n, what = pl.p.num_nodes, "particles"
    stepping = comm.allreduce(run.wall_time_s, op=MPI.MAX)
    setup = comm.allreduce(setup, op=MPI.MAX)
    rss = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20)  # GB (ru_maxrss in kB)
    if comm.rank == 0:
        print(f"{n:,} {what}, {run.steps} steps to {1e6 * args.t_end:.0f} us; set-up {setup:.1f} s, stepping "
              f"{stepping:.1f} s ({1e3 * stepping / run.steps:.2f} ms per step)")
        print("peak RSS per rank [GB]: " + ", ".join(f"{r:.2f}" for r in rss))
        print(f"dissipated {run.history[-1, 1]:.1f} J/m, cracked {what} {int((run.opening >= 0.5).sum())}")
        if args.save:
            np.savez(args.save, damage=run.damage, opening=run.opening, displacement=run.displacement,
                     history=run.history)
        if args.compare:
            ref = np.load(args.compare)
            same = all(np.array_equal(ref[key], getattr(run, key)) for key in ("damage", "opening", "displacement"))
            gap = np.abs(ref["history"][:, 1] - run.history[:, 1]).max() / max(np.abs(ref["history"][:, 1]).max(),
                                                                            1e-300)
            print(f"against {args.compare}: damage, openings and displacements "
                  f"{'identical' if same else 'DIFFERENT'}; dissipation history within {gap:.1e}")
        print(f"{comm.size} ranks x {numba.get_num_threads()} threads, {n} {what}: {stepping:.1f} s stepping")


if __name__ == "__main__":
    main()
