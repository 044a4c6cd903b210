"""A short Mandel run (RKPM SCNI+FPP); rank 0 saves the pressure coefficients at the outputs.

Run serially or as ``mpiexec -n P python solve_mandel.py OUT.npy``: the u-p system of every
step is distributed by rows over the ranks.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from rkfx.geometry.particles import structured
from rkfx.conditions import Displacement, Pressure
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from verification.mandel import Mandel

comm = MPI.COMM_WORLD
exact = Mandel(1.0e4, 0.2, 1.0e-4, 20.0, 2.0, 40.0)
times = time_grid([4.0, 40.0], 4.0e-4, 1.6, hold=5)
sol = solve_biot(structured(20.0, 2.0, 41, 5), PoroMaterial(1.0e4, 0.2, 1.0e-4), times, [4.0, 40.0],
                 [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
                  Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,))],
                 [Pressure("right")], comm=comm)
if comm.rank == 0:
    np.save(sys.argv[1], sol.P)
