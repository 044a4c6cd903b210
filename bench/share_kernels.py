"""Benchmark: the force stencil of Kalthoff's plate, whole or as each rank's share, alone or side by side.

Why two ranks with one thread each step the 202,950-particle Kalthoff run more slowly than one
rank with two threads: this times the lattice-stencil force kernel
(``rkfx.assembly.lattice_stencil``) of the plate at ``--nodes`` particles per side on random
subcell loads, ``--calls`` calls each:

* serially (one process): the whole plate's stencil, with the numba threads the process has;
* on P ranks: each rank's share stencil (``rkfx.assembly.local_strain``), first all ranks at
  once, then one rank at a time while the others wait at a barrier.

Usage:
    NUMBA_NUM_THREADS=1 python bench/share_kernels.py
    NUMBA_NUM_THREADS=2 python bench/share_kernels.py
    mpiexec -n 2 env NUMBA_NUM_THREADS=1 python bench/share_kernels.py
Each line reads ``<label>: <ms> per call``.
"""
import argparse
import time

import dolfinx_solver  # noqa: F401  (before mpi4py)
import numba
import numpy as np
from mpi4py import MPI

from rkfx.assembly.lattice_stencil import _stencil_force
from rkfx.assembly.local_strain import local_smeared_strain
from rkfx.cases import kalthoff as k
from rkfx.fracture import damage as dm
from rkfx.memory import reuse_freed_memory
from rkfx.parallel.partition import rcb


def timed(stencil, loads: np.ndarray, out: np.ndarray, calls: int) -> float:
    """Milliseconds per call of the stencil force kernel."""
    args = (stencil.force_start, stencil.force_node, stencil.force_length, stencil.force_shift,
            stencil.force_slot, stencil.force_grad, out)
    _stencil_force(loads, *args)
    t0 = time.perf_counter()
    for _ in range(calls):
        _stencil_force(loads, *args)
    return 1e3 * (time.perf_counter() - t0) / calls


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=450, help="particles per side")
    ap.add_argument("--calls", type=int, default=100)
    args = ap.parse_args()
    comm = MPI.COMM_WORLD
    reuse_freed_memory()
    prm = {name: spec.default for name, spec in k.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
    pl, _, _ = k.setup(args.nodes, material, prm, comm=comm)
    if comm.size > 1:
        stencil = local_smeared_strain(pl.op, rcb(pl.p.x, comm.size), comm).stencil
    else:
        op = pl.op.build() if hasattr(pl.op, "build") else pl.op
        stencil = op.stabilization.stencil
    loads = np.random.default_rng(comm.rank).random((stencil.template.slots, 3, stencil.positions))
    out = np.empty(2 * stencil.positions)
    threads = numba.get_num_threads()
    if comm.size == 1:
        print(f"whole plate, 1 rank x {threads} threads: {timed(stencil, loads, out, args.calls):.2f} ms per call")
        return
    comm.Barrier()
    together = timed(stencil, loads, out, args.calls)
    print(f"rank {comm.rank} of {comm.size} x {threads} threads, all ranks at once: {together:.2f} ms per call",
          flush=True)
    for r in range(comm.size):
        comm.Barrier()
        if comm.rank == r:
            alone = timed(stencil, loads, out, args.calls)
            print(f"rank {r} of {comm.size} x {threads} threads, alone: {alone:.2f} ms per call", flush=True)
        comm.Barrier()


if __name__ == "__main__":
    main()
