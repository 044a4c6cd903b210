"""RKPM discretizations of laterally confined u-p columns (§6.4.1 and §6.4.2).

``column_discretization``: a uniform grid of nodes on [0, W] x [0, L], a = 2 h, the cells
their median-dual areas as squares, and any rule of ``rkfx.integration.nodal_stabilized.RULES``.

``confined_column``: the wave-column model, three nodes across (rollers on both sides), the
base fixed in y and impermeable, the top drained (p = 0) and loaded by a compressive traction
q from t = 0.

On a communicator of several ranks the nodes are split by RCB: each rank's rule covers its own
nodes' cells only, and ``rkfx.cases._nodal_up.split_over_ranks`` gives its local unknowns (own
nodes, then ghosts).
"""
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from rkfx.approximation.semi_lagrangian import MovingRK
from rkfx.cases._nodal_up import edge_load, nodal_discretization, split_over_ranks
from rkfx.errors import InputError
from rkfx.geometry.particles import Particles, structured
from rkfx.integration.nodal_stabilized import NodalIntegration
from rkfx.models.explicit_poroelasticity import Constituents, ExplicitPoroDynamics, collocation_rows
from rkfx.parallel.ownership import Numbering
from rkfx.solvers.central_difference import Constraint

#: The data of §6.4.1 (Soares 2014).
SOARES = Constituents(E=254423076.9, nu=0.298, rho_s=2700.0, rho_f=1000.0, porosity=0.48, k=3.55e-9,
                      K_s=1.1e10, K_f=3.3e9)


class ColumnDiscretization(NamedTuple):
    """Nodes, approximation and rule of a column, and its boundary nodes (indices); on MPI
    ranks the rank's own nodes (whose cells its rule covers) and the partition's numbering."""

    particles: Particles
    rk: MovingRK
    rule: NodalIntegration
    bottom: np.ndarray
    top: np.ndarray
    sides: np.ndarray
    own: np.ndarray | None = None
    numbering: Numbering | None = None


def column_discretization(width: float, height: float, nx: int, ny: int, rule: str = "nsni",
                          comm=None) -> ColumnDiscretization:
    """``nx`` x ``ny`` nodes on [0, width] x [0, height] with equal spacings h, a = 2 h. On a
    communicator of several ranks the nodes are split by RCB and the rule covers the cells of
    the rank's own nodes only (``own``, ``numbering``); otherwise every node's."""
    h = height / (ny - 1)
    if abs(width / (nx - 1) - h) > 1e-9 * h:
        raise InputError(f"nx = {nx}, ny = {ny} give unequal spacings {width / (nx - 1):.4g} and {h:.4g} m on a "
                         f"{width} x {height} m column; take nx - 1 = (ny - 1) width / height")
    p = structured(width, height, nx, ny)
    d = nodal_discretization(p, h, rule, comm)
    x, tol = p.x, 1e-9 * height
    return ColumnDiscretization(p, d.rk, d.rule, np.flatnonzero(x[:, 1] < tol), np.flatnonzero(x[:, 1] > height - tol),
                                np.flatnonzero((x[:, 0] < tol) | (x[:, 0] > width - tol)), d.own, d.numbering)


class ConfinedColumn(NamedTuple):
    """The column's model and where it is observed.

    Attributes:
        model: The explicit u-p model (on MPI ranks the rank's part, ``model.share``).
        top: A node on the top (index).
        base: A node on the base (index).
        observe: [u_y(W/2, L), p(W/2, 0)] = u_y^h on the axis at the top and p^h at the base,
            of the model's vector (on MPI ranks of the rank's local vector, collective).
    """

    model: ExplicitPoroDynamics
    top: int
    base: int
    observe: Callable[[np.ndarray], np.ndarray]


def confined_column(ny: int, rule: str = "nsni", medium: Constituents = SOARES, height: float = 10.0,
                    load: float = 3000.0, comm=None, fpp: bool = False) -> ConfinedColumn:
    """The model of a column of ``ny`` nodes along y, two of its nodes and its probe.

    Args:
        ny: Nodes along the height.
        rule: The nodal integration rule.
        medium: The constituents.
        height: L [m].
        load: q [Pa], compressive, on the top from t = 0.
        comm: On a communicator of several ranks the model is split over them (RCB): each rank
            integrates over its own nodes' cells and keeps the rows of every essential
            condition over its local unknowns (the columns of the conditions are its ghosts).
        fpp: Stabilize the storage rows by the fluid pressure projection (``ExplicitPoroDynamics``).
    """
    h = height / (ny - 1)
    d = column_discretization(2 * h, height, 3, ny, rule, comm=comm)
    p, rk, r, bottom, top, sides = d.particles, d.rk, d.rule, d.bottom, d.top, d.sides
    x, n = p.x, p.num_nodes
    size = 3 * n
    tol = 1e-9 * height
    rows = [collocation_rows(rk, bottom, 1, n, 0, size),      # u_y = 0 at the base
            collocation_rows(rk, sides, 0, n, 0, size),       # rollers
            collocation_rows(rk, top, None, n, 2 * n, size)]  # drained top
    top_edges = p.boundary_edges[np.all(x[p.boundary_edges][:, :, 1] > height - tol, axis=1)]
    f = np.zeros(size)
    f[:2 * n] = edge_load(rk, top_edges, lambda xs, normal: [0.0, -load] * np.ones_like(xs))
    axis = np.abs(x[:, 0] - h) < tol
    probe = sp.vstack([collocation_rows(rk, np.flatnonzero(axis & (x[:, 1] > height - tol)), 1, n, 0, size),
                       collocation_rows(rk, np.flatnonzero(axis & (x[:, 1] < tol)), None, n, 2 * n, size)]).tocsr()
    local, rows, sample = split_over_ranks(d, comm, rows, probe)
    essential = [Constraint(g) for g in rows]
    return ConfinedColumn(ExplicitPoroDynamics(r, medium, essential, load=lambda t: f, local=local, fpp=fpp), int(top[0]),
                          int(bottom[0]), sample)
