"""Nodal integration in three dimensions (seed §3.3.2): DNI, SCNI and MSCNI over the conforming
nodal cells of ``rkfx.geometry.nodal_cells3d``, each a ``Quadrature`` as in 2-D.

* ``dni_3d``  — N and its direct gradient at the nodes, weights V_L.
* ``scni_3d`` — the gradient smoothed over each cell by the divergence theorem (eq. 3.55 with
  facets): grad~N_I(x_L) = (1/V_L) sum_G N_I(x_G) S_G over the cell's planar facets G, S_G
  their outward area vectors and x_G their centroids. Shared facets carry one point, so the
  sums telescope and SCNI passes the linear patch test.
* ``mscni_rules_3d`` — SCNI plus the subcell stabilization of eqs. (3.56)-(3.59) with the
  seed's 3-D economy: at the stabilization points x_hat_C (the subcell centroids) the *direct*
  gradients stand in for smoothed ones, so a hexahedral cell needs N at 13 points: the node,
  6 face centroids and 6 subcell centroids. The stabilization rows grad~N(x_L) - grad N(x_hat_C)
  vanish on linear fields (both are exact there), so the patch test still passes.

The value rows of the same points serve the storage form (3.58) and the fluid pressure
projection (3.60)-(3.62): ``rkfx.models.poroelasticity`` takes these rules for 3-D particles.
"""
import numpy as np

from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.approximation.sparse_rows import SparseRows, combine_rows, difference_rows
from rkfx.errors import InputError
from rkfx.integration.quadrature import Quadrature, selected_cells


def smoothed_gradient_rows(rk: RKApproximation, cells, nodes: np.ndarray) -> SparseRows:
    """Rows grad~N_I(x_L) of eq. (3.55) for the cells ``nodes``, 3 components [1/m].

    N is evaluated once at each smoothing point the cells use; each row is the sparse sum of
    those rows weighted by S_G / V_L.
    """
    lo, hi = cells.facet_ptr[nodes], cells.facet_ptr[nodes + 1]
    count = hi - lo
    term_ptr = np.zeros(len(nodes) + 1, np.int64)
    np.cumsum(count, out=term_ptr[1:])
    facets = np.repeat(lo - term_ptr[:-1], count) + np.arange(term_ptr[-1])
    point = cells.facet_point[facets]
    used = np.zeros(len(cells.points), bool)
    used[point] = True
    slot = np.cumsum(used) - 1  # place of each used point among those evaluated
    values = evaluate(rk, cells.points[used])
    weights = cells.facet_vector[facets] / np.repeat(cells.volume[nodes], count)[:, None]
    return combine_rows(values, term_ptr, slot[point], weights)


def dni_3d(p, rk: RKApproximation, cells, nodes: np.ndarray | None = None) -> Quadrature:
    """Direct nodal integration: N and its direct gradient at the nodes, weights V_L."""
    nodes, _ = selected_cells(cells, nodes)
    rows = evaluate(rk, p.x[nodes], gradients=True)
    return Quadrature(p.x[nodes], cells.volume[nodes], rows.component(0),
                      SparseRows(rows.indptr, rows.indices, rows.data[:, 1:], rows.num_cols), "dni")


def scni_3d(p, rk: RKApproximation, cells, nodes: np.ndarray | None = None) -> Quadrature:
    """SCNI: the gradients smoothed over the cells (eq. 3.55) at the nodes, weights V_L."""
    nodes, _ = selected_cells(cells, nodes)
    return Quadrature(p.x[nodes], cells.volume[nodes], evaluate(rk, p.x[nodes]),
                      smoothed_gradient_rows(rk, cells, nodes), "scni")


def mscni_rules_3d(p, rk: RKApproximation, cells, eps_p: float = 1.0, nodes: np.ndarray | None = None,
                   with_values: bool = True) -> tuple[Quadrature, list[Quadrature], Quadrature | None]:
    """MSCNI in 3-D over the cells of ``nodes`` (default all) and their subcells.

    Returns ``(nodal, gradient_rules, values)`` as ``rkfx.integration.quadrature.mscni_rules``:
        nodal: SCNI, points x_L, weights V_L, values N(x_L), gradients grad~N(x_L).
        gradient_rules: the quadratures of every grad-grad form (stiffness 3.56, Darcy 3.59),
            whose sum is SCNI plus eps_p sum_C V_C (B~_L - B_C)^T D (B~_L - B_C), B~_L the
            smoothed and B_C the direct gradients at the subcell centroids (see below).
        values: the rows N(x_L) - N(x_hat_C) of eq. (3.58) at the subcells, weights eps_p V_C
            (``None`` without ``with_values``).

    The stabilization sum is formed without one long row per subcell: with the mean
    B_bar = sum_C V_C B_C / V_L of the direct gradients (the subcells partition the cell),
    sum_C V_C (B~ - B_C)^T D (B~ - B_C) = V_L (B~ - B_bar)^T D (B~ - B_bar) - V_L B_bar^T D B_bar
    + sum_C V_C B_C^T D B_C exactly. The rows B~ and B_bar span the supports of the whole cell
    (~130 nodes in 3-D at a = 1.5 h), B_C only its centroid's (~35): three rules, (node,
    eps_p V_L, B~ - B_bar), (node, -eps_p V_L, B_bar) and (centroid, eps_p V_C, B_C), cost a
    third of the difference rows' stiffness assembly for the same matrix.
    """
    if not eps_p >= 0:
        raise InputError(f"eps_p = {eps_p!r} must be >= 0 (1 is the usual MSCNI choice)")
    nodes, sub = selected_cells(cells, nodes)
    nodal = scni_3d(p, rk, cells, nodes)
    row_of = np.full(len(cells.volume), -1, np.int64)
    row_of[nodes] = np.arange(len(nodes))
    owner_row = row_of[cells.subcell_node[sub]]
    centroids = cells.subcell_centroid[sub]
    at_centroids = evaluate(rk, centroids, gradients=True)
    grads = SparseRows(at_centroids.indptr, at_centroids.indices, at_centroids.data[:, 1:], at_centroids.num_cols)
    weights = eps_p * cells.subcell_volume[sub]
    # B_bar: the volume-weighted mean of the centroid gradients of each cell (rows by node).
    order = np.argsort(owner_row, kind="stable")
    term_ptr = np.zeros(len(nodes) + 1, np.int64)
    np.cumsum(np.bincount(owner_row, minlength=len(nodes)), out=term_ptr[1:])
    mean = _combined_vectors(grads, term_ptr, order, (cells.subcell_volume[sub] / cells.volume[cells.subcell_node[sub]])[order])
    volume = nodal.weights
    rules = [nodal,
             Quadrature(nodal.points, eps_p * volume, None, difference_rows(nodal.gradients, np.arange(len(nodes)), mean),
                        "mscni-cell-spread"),
             Quadrature(nodal.points, -eps_p * volume, None, mean, "mscni-cell-mean"),
             Quadrature(centroids, weights, None, grads, "mscni-subcells")]
    if not with_values:
        return nodal, rules, None
    values = difference_rows(nodal.values, owner_row, at_centroids.component(0))
    return nodal, rules, Quadrature(centroids, weights, values, None, "mscni-values")


def _combined_vectors(rows: SparseRows, term_ptr: np.ndarray, term_row: np.ndarray, w: np.ndarray) -> SparseRows:
    """Rows r = sum_t w_t rows[term_row[t]] over t in term_ptr[r]:term_ptr[r+1] of vector-valued
    rows: ``combine_rows`` per component (it combines scalar rows), the components merged."""
    parts = [combine_rows(rows.component(k), term_ptr, term_row, w) for k in range(rows.num_components)]
    first = parts[0]
    return SparseRows(first.indptr, first.indices, np.column_stack([q.data[:, 0] for q in parts]), first.num_cols)


RULES_3D = ("dni", "scni", "mscni")


def integration_rules_3d(name: str, p, rk: RKApproximation, cells, eps_p: float = 1.0,
                         nodes: np.ndarray | None = None) -> list[Quadrature]:
    """The quadratures of a named 3-D rule over the cells of ``nodes`` (default all): ``dni``,
    ``scni``, or ``mscni`` (SCNI and its subcell stabilization)."""
    if name == "dni":
        return [dni_3d(p, rk, cells, nodes)]
    if name == "scni":
        return [scni_3d(p, rk, cells, nodes)]
    if name == "mscni":
        return mscni_rules_3d(p, rk, cells, eps_p, nodes, with_values=False)[1]
    raise InputError(f"unknown 3-D integration rule {name!r}; choose one of {', '.join(RULES_3D)}")
