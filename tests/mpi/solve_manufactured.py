"""Solve the manufactured plane-strain problem on gmsh nodes; rank 0 saves the coefficients.

Run serially or as ``mpiexec -n P python solve_manufactured.py OUT.npy``: geometry is meshed on
rank 0 and broadcast; on more than one rank the system is assembled by owned rows (each rank
integrates over its part of the nodes), the answer gathered.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from square import unit_square
from verification.manufactured import SineField

comm = MPI.COMM_WORLD
p = unit_square(comm, 0.08, {"boundary": [0, 1, 2, 3]})
material = ElasticMaterial(1.0, 0.3)
field = SineField(material.lame_lambda, material.shear_modulus)
sol = solve_plane_strain(p, material, [Displacement("boundary", lambda x, t: field.displacement(x))],
                         body_force=field.body_force, rule="mscni", bc_method="transformation", comm=comm)
if comm.rank == 0:
    np.save(sys.argv[1], sol.coefficients)
