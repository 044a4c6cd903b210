"""The linear patch test (MSCNI, Nitsche, tractions on two sides) on gmsh nodes; rank 0 saves
the coefficients and exits non-zero if the patch test fails.

Run serially or as ``mpiexec -n P python solve_patch.py OUT.npy``: the particles are split
over the ranks (assembly by owned rows), the answer gathered.
"""
import sys

import dolfinx_solver  # noqa: F401
import numpy as np
from mpi4py import MPI

from rkfx.conditions import Displacement, Traction
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from square import unit_square
from verification.manufactured import LinearField

comm = MPI.COMM_WORLD
p = unit_square(comm, 0.1, {name: [i] for i, name in enumerate(("bottom", "right", "top", "left"))})
material = ElasticMaterial(2.0, 0.3)
field = LinearField(G=np.array([[1e-3, 2e-3], [-1.5e-3, 3e-3]]), c=np.array([1e-3, -2e-3]),
                    lam=material.lame_lambda, mu=material.shear_modulus)
bcs = [Displacement(s, lambda x, t: field.displacement(x)) for s in ("bottom", "left")]
bcs += [Traction(s, lambda x, t, n: field.traction(x, n)) for s in ("right", "top")]
sol = solve_plane_strain(p, material, bcs, rule="mscni", bc_method="nitsche", comm=comm)
# RK reproduces linear fields: the coefficients are the field's nodal values.
error = np.abs(sol.coefficients - field.displacement(p.x)).max() / np.abs(field.displacement(p.x)).max()
if comm.rank == 0:
    np.save(sys.argv[1], sol.coefficients)
    if not error <= 1e-10:
        sys.exit(f"patch test failed on {comm.size} ranks: relative error {error:.3e}")
