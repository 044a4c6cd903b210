"""A short Mandel run by the field-split solver (Nitsche's displacement conditions, the system
whole on every rank and distributed by PETSc's rows); rank 0 saves the pressure coefficients.

Run serially or as ``mpiexec -n P python solve_mandel_fieldsplit.py OUT.npy``.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement, Pressure
from rkfx.geometry.particles import structured
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from verification.mandel import Mandel

comm = MPI.COMM_WORLD
exact = Mandel(1.0e4, 0.0, 1.0e-4, 20.0, 2.0, 40.0)
times = (20.0 / 60) ** 2 / exact.c * np.arange(4)
sol = solve_biot(structured(20.0, 2.0, 61, 7), PoroMaterial(1.0e4, 0.0, 1.0e-4), times, times[1:],
                 [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
                  Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,))],
                 [Pressure("right")], comm=comm, distributed=False, bc_method="nitsche", solver="fieldsplit")
if comm.rank == 0:
    np.save(sys.argv[1], sol.P)
