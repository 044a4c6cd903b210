"""Benchmark: the RK elastic solve (MSCNI, Nitsche, MUMPS) serially and over MPI ranks.

The manufactured sine field on an n x n grid of nodes; on more than one rank the system is
assembled by owned rows (``rkfx.parallel``). Prints the assembly and solve times (max over
ranks), the peak RSS of every rank, and the relative difference of the gathered coefficients
to a serial run's saved with ``--save``.

Usage:
    python bench/parallel_elastic.py [--nodes 300] [--save serial.npy]
    mpiexec -n 2 env NUMBA_NUM_THREADS=1 python bench/parallel_elastic.py --compare serial.npy
    python bench/parallel_elastic.py --nodes 1000 --solver cg-gamg   (10^6 nodes: ~9 GB serially)
    python bench/parallel_elastic.py --dim 3 --nodes 40 --cells median --solver cg-gamg
``--dim 3`` solves the 3-D sine field on an n x n x n grid of the unit cube, with its box cells
or (``--cells median``) the median-dual cells of its tetrahedra; each rank builds only the
cells of its own nodes.
Further PETSc options through PETSC_OPTIONS, e.g. "-rkfx_pc_gamg_threshold 0.02".
The last line printed reads ``<ranks> ranks x <threads> threads, <N> nodes: <seconds> s``.
"""
import argparse
import resource
import time
from dataclasses import replace

import dolfinx_solver  # noqa: F401  (before mpi4py)
import numba
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement
from rkfx.geometry.particles import structured
from rkfx.geometry.particles3d import box
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_elasticity, solve_plane_strain
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up
from verification.manufactured import SineField, SineField3D


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=300, help="nodes per side")
    ap.add_argument("--solver", default="mumps", help="auto | mumps | gmres-ilu | cg-gamg")
    ap.add_argument("--dim", type=int, choices=(2, 3), default=2, help="2: plane strain square, 3: unit cube")
    ap.add_argument("--cells", choices=("box", "median"), default="box", help="3-D nodal cells")
    ap.add_argument("--save", help="write the coefficients (rank 0) to this .npy file")
    ap.add_argument("--compare", help="report the relative difference to these saved coefficients")
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    material = ElasticMaterial(1.0, 0.3)
    if args.dim == 2:
        p = structured(1.0, 1.0, args.nodes, args.nodes)
        field, solve = SineField(material.lame_lambda, material.shear_modulus), solve_plane_strain
    else:
        p = box(1.0, 1.0, 1.0, args.nodes, args.nodes, args.nodes)
        p = p if args.cells == "box" else replace(p, grid=None)  # no grid: median-dual cells
        field, solve = SineField3D(material.lame_lambda, material.shear_modulus), solve_elasticity
    bcs = [Displacement(side, lambda x, t: field.displacement(x)) for side in p.boundary_names]
    comm.Barrier()
    t0 = time.perf_counter()
    sol = solve(p, material, bcs, body_force=field.body_force, rule="mscni", comm=comm, solver=args.solver)
    wall = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    stages = {k: comm.allreduce(v, op=MPI.MAX) for k, v in sol.timings.items()}
    rss = comm.gather(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, root=0)
    if comm.rank != 0:
        return
    print("stages [s, max over ranks]: " + ", ".join(f"{k} {v:.2f}" for k, v in stages.items()))
    print("peak RSS per rank [MB]: " + ", ".join(f"{r:.0f}" for r in rss))
    print(f"linear solve: {sol.linear['solver']}, {sol.linear['iterations']} iterations ({sol.linear['reason']})")
    if args.save:
        np.save(args.save, sol.coefficients)
    if args.compare:
        ref = np.load(args.compare)
        print(f"max relative difference to {args.compare}: "
              f"{np.abs(sol.coefficients - ref).max() / np.abs(ref).max():.2e}")
    print(f"{comm.size} ranks x {numba.get_num_threads()} threads, {p.num_nodes} nodes: {wall:.2f} s")


if __name__ == "__main__":
    main()
