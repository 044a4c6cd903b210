"""3-D on MPI ranks: the manufactured elastic solution (MSCNI, Nitsche) on the gmsh l-block and a
few u-p steps of Cryer's sphere octant (SCNI + FPP, collocated conditions); rank 0 saves the
displacement coefficients and the pressures.

Run serially or as ``mpiexec -n P python solve_3d.py OUT.npy``: with P > 1 ranks the particles
are split by RCB, each rank integrates over its own nodes' cells and the systems are assembled
by owned rows.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement, Pressure, Traction
from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model
from rkfx.geometry.gmsh_solids import l_block, sphere_octant
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_elasticity
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from verification.manufactured import SineField3D

comm = MPI.COMM_WORLD


def particles(builder, **kw):
    with scratch_model("mpi3d") as m:
        if comm.rank == 0:
            builder(model=m, **kw)
        return from_gmsh_3d(m, comm)


material = ElasticMaterial(1.0, 0.3)
field = SineField3D(material.lame_lambda, material.shear_modulus)
p = particles(l_block, mesh_size=0.2)
bcs = [Displacement(name, lambda x, t: field.displacement(x)) for name in p.boundary_names]
u = solve_elasticity(p, material, bcs, body_force=field.body_force, rule="mscni", comm=comm).coefficients

p = particles(sphere_octant, radius=1.0, mesh_size=0.2)
times = np.arange(6) * 2e-3
sol = solve_biot(p, PoroMaterial(1e4, 0.0, 1e-4), times, times[1:],
                 [Displacement("x0", 0.0, (0,)), Displacement("y0", 0.0, (1,)), Displacement("z0", 0.0, (2,))],
                 [Pressure("surface", 0.0)], [Traction("surface", lambda x, t, n: -n)], comm=comm)
if comm.rank == 0:
    np.save(sys.argv[1], np.concatenate([u.ravel(), sol.U.ravel(), sol.P.ravel()]))
