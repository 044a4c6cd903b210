"""The crack-band u-p FEM injection (h = 0.05 m to 2000 s) on any number of ranks; rank 0 saves
the notch pressure, tips, Newton iterations, p at the sample points and the damage per element.

Run serially and under ``mpiexec -n 2`` by ``tests/test_fem_hydraulic_fracture.py``; the two
saved files must agree. Usage: ``python fem_hydraulic_fracture.py OUT.npz``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import dolfinx_solver  # noqa: E402,F401  (must precede dolfinx / petsc4py)

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from fem_baselines import hydraulic_fracture as hf  # noqa: E402
from rkfx.cases.injection import default_rock  # noqa: E402
from rkfx.solvers.newmark import damped  # noqa: E402
from rkfx.solvers.newton import NewtonOptions  # noqa: E402


def main(out: str) -> None:
    r = hf.solve_hydraulic_fracture(0.05, default_rock(), times=np.arange(0.0, 2001.0, 100.0),
                                    output_times=[1500.0, 2000.0],
                                    stepper=damped(newton=NewtonOptions(line_search=True)),
                                    comm=MPI.COMM_WORLD)
    if r.stopped is not None:
        raise SystemExit(r.stopped)
    if MPI.COMM_WORLD.rank == 0:
        np.savez(out, notch_p=r.notch_p, left=r.left, right=r.right, iterations=r.iterations, p=r.p,
                 damage=r.damage, opening=r.opening, centroids=r.centroids)


if __name__ == "__main__":
    main(sys.argv[1])
