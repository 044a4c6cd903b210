"""The rectangular dam without tailwater, its downstream face a seepage face, marched to its
steady state by RKPM (NSNI) and FEM (Taylor-Hood); rank 0 saves [Q, outflow] of each.

Run serially or as ``mpiexec -n P python steady_dam.py OUT.npy``.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from verification.rectangular_dam import Dam, discharge, fem_dam, levee_sand, rkpm_dam

comm = MPI.COMM_WORLD
soil, dam = levee_sand(), Dam(head_down=0.0, seepage=True)
found = []
for build in (rkpm_dam, fem_dam):
    model = build(soil, dam, 11, comm=comm)
    q, done = discharge(model, dam, comm=comm)
    found += [q, model.seepage_outflow(done.state.x)]
    if comm.rank == 0:
        print(f"{build.__name__}: Q = {q:.12e}, {done.run.steps} steps, {done.run.newton_iterations} Newton iterations")
if comm.rank == 0:
    np.save(sys.argv[1], np.array(found))
