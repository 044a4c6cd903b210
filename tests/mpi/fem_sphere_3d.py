"""Consolidation of a sphere octant with the dolfinx Biot baseline in 3-D; rank 0 saves samples.

Taylor-Hood P2-P1 on the tetrahedra of ``rkfx.geometry.gmsh_solids.sphere_octant`` (built on rank
0, distributed by ``fem_baselines.gmsh_mesh.build_mesh``): symmetry rollers on x0, y0, z0, a
uniform compressive total traction and p = 0 on the spherical surface, 8 backward-Euler steps.
Run serially and under ``mpiexec -n 2`` by ``tests/test_fem_3d.py``; the saved pressures and
displacements must agree to round-off (p in units of sigma0, u in sigma0 R / E).
Usage: ``python fem_sphere_3d.py OUT.npy``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import dolfinx_solver  # noqa: E402,F401  (must precede dolfinx / petsc4py)
import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from fem_baselines import poroelasticity as pe  # noqa: E402
from fem_baselines.gmsh_mesh import build_mesh  # noqa: E402
from rkfx.conditions import Displacement, Pressure, Traction  # noqa: E402
from rkfx.geometry import gmsh_solids  # noqa: E402


def main(out: str) -> None:
    E, nu, k, alpha, S, sigma0 = 1e4, 0.2, 1e-4, 0.9, 1e-5, 1.0
    data = build_mesh(gmsh_solids.sphere_octant, radius=1.0, mesh_size=0.25, comm=MPI.COMM_WORLD)
    bcs = [Displacement("x0", 0.0, (0,)), Displacement("y0", 0.0, (1,)), Displacement("z0", 0.0, (2,)),
           Traction("surface", lambda x, t, n: -sigma0 * n, (0, 1, 2)), Pressure("surface")]
    times = np.r_[0.0, np.geomspace(1e-3, 1e-1, 8)]  # T = c t / R^2 from 1.2e-3 to 0.12 (c = 1.2 m^2/s)
    pts = np.array([[0.0, 0.0, 0.0], [0.4, 0.0, 0.0], [0.2, 0.3, 0.4], [0.5, 0.5, 0.5], [0.0, 0.1, 0.95]])
    res = pe.solve_biot(data, E, nu, k, alpha, S, "taylor-hood", bcs, times, pts, times[[1, 4, 8]])
    if MPI.COMM_WORLD.rank == 0:
        # u in units of sigma0 R / E: both parts O(1), compared with one relative bound
        np.save(out, np.concatenate([res.p.ravel() / sigma0, res.u.ravel() * E / sigma0]))


if __name__ == "__main__":
    main(sys.argv[1])
