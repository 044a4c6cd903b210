"""Solve the manufactured plane-strain problem on gmsh nodes; rank 0 saves the coefficients.

Run serially or as ``mpiexec -n P python solve_manufactured.py OUT.npy``: geometry is meshed on
rank 0 and broadcast, the PETSc system is distributed by rows, the answer gathered.
"""
import sys

import dolfinx_solver  # noqa: F401
import gmsh
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.geometry.gmsh_nodes import from_gmsh
from verification.manufactured import SineField

comm = MPI.COMM_WORLD
if comm.rank == 0:
    gmsh.initialize(interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    geo = gmsh.model.geo
    pts = [geo.addPoint(x, y, 0, 0.08) for x, y in ((0, 0), (1, 0), (1, 1), (0, 1))]
    lines = [geo.addLine(pts[i], pts[(i + 1) % 4]) for i in range(4)]
    surf = geo.addPlaneSurface([geo.addCurveLoop(lines)])
    geo.synchronize()
    gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, lines), "boundary")
    gmsh.model.addPhysicalGroup(2, [surf])
    gmsh.model.mesh.generate(2)
p = from_gmsh(gmsh.model if comm.rank == 0 else None, comm=comm)
if comm.rank == 0:
    gmsh.finalize()
material = ElasticMaterial(1.0, 0.3)
field = SineField(material.lame_lambda, material.shear_modulus)
sol = solve_plane_strain(p, material, [Displacement("boundary", lambda x, t: field.displacement(x))],
                         body_force=field.body_force, rule="mscni", bc_method="transformation", comm=comm)
if comm.rank == 0:
    np.save(sys.argv[1], sol.coefficients)
