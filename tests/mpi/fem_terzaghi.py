"""Small Terzaghi column with the dolfinx Biot baseline; rank 0 saves sampled p and u.

Run serially and under ``mpiexec -n 2`` by ``tests/test_fem_poroelasticity.py``; the two
saved arrays must agree to round-off. Usage: ``python fem_terzaghi.py OUT.npy``.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402

from fem_baselines import poroelasticity as pe  # noqa: E402
from rkfx.conditions import Displacement, Pressure, Traction  # noqa: E402


def main(out: str) -> None:
    E, nu, k, alpha, S, q = 1e3, 0.0, 1e-9, 1.0, 0.0, 1e3
    xs = np.linspace(0.0, 1.0, 3)
    ys = np.linspace(0.0, 10.0, 21)
    bcs = [
        Displacement("bottom"),
        Displacement("left", 0.0, (0,)),
        Displacement("right", 0.0, (0,)),
        Traction("top", lambda x, t, n: -q * n),  # the normal of the top facets: (0, 1)
        Pressure("top"),
    ]
    times = np.r_[0.0, np.cumsum(1e4 * 1.5 ** np.arange(12))]
    pts = np.column_stack([np.full(len(ys), 0.25), ys])
    rows = []
    for element, cell in (("taylor-hood", "triangle"), ("q1q1-fpp", "quadrilateral")):
        mesh = pe.rectangle_mesh(xs, ys, cell, comm=MPI.COMM_WORLD)
        res = pe.solve_biot(mesh, E, nu, k, alpha, S, element, bcs, times, pts, times[[1, 6, 12]],
                            fpp_form="rate")
        rows.append(np.concatenate([res.p.ravel(), res.u.ravel()]))
    if MPI.COMM_WORLD.rank == 0:
        np.save(out, np.stack(rows))


if __name__ == "__main__":
    main(sys.argv[1])
