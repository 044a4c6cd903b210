"""Domain integration rules, all producing ``Quadrature``: points, weights and shape rows.

* ``gauss``  — Gauss points on the background triangles, direct gradients.
* ``dni``    — direct nodal integration: nodes, weights A_L, direct gradients.
* ``scni``   — stabilized conforming nodal integration: nodes, weights A_L, gradients
  smoothed over Omega_L by the divergence theorem (eq. 3.55).
* ``mscni``  — SCNI plus the subcell stabilization of eq. (3.56): extra "points" whose rows
  are the differences grad~N_I(x_L) - grad~N_I(x_hat_C) with weights eps_p A_C.

A bilinear form int B^T D B dOmega is then ``sum over rules and points of w B^T D B``, the
same code for elasticity, Darcy flow and coupling (``rkfx.assembly.operators``).
"""
from dataclasses import dataclass

import numba
import numpy as np

from rkfx.errors import InputError
from rkfx.geometry.cells import cell_measures
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles
from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.approximation.sparse_rows import (RowStack, SparseRows, combine_job, difference_rows, gathered_rows,
                                           spread_rows, stacked_rows)

# Symmetric Gauss rules on the reference triangle: barycentric points and weights (sum 1).
_TRIANGLE_RULES = {
    1: (np.array([[1 / 3, 1 / 3, 1 / 3]]), np.array([1.0])),
    2: (np.array([[2 / 3, 1 / 6, 1 / 6], [1 / 6, 2 / 3, 1 / 6], [1 / 6, 1 / 6, 2 / 3]]), np.full(3, 1 / 3)),
    4: (np.array([[0.108103018168070, 0.445948490915965, 0.445948490915965],
                  [0.445948490915965, 0.108103018168070, 0.445948490915965],
                  [0.445948490915965, 0.445948490915965, 0.108103018168070],
                  [0.816847572980459, 0.091576213509771, 0.091576213509771],
                  [0.091576213509771, 0.816847572980459, 0.091576213509771],
                  [0.091576213509771, 0.091576213509771, 0.816847572980459]]),
        np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)),
}


@dataclass(frozen=True)
class Quadrature:
    """Integration points of one rule with the shape rows a bilinear form needs.

    Attributes:
        points: Shape ``(num_points, 2)`` [m] (for stabilization rows: the subcell centroids).
        weights: Shape ``(num_points,)`` [m^2].
        values: Rows with entries [N_I], or ``None`` where a rule has no value part.
        gradients: Rows with entries [N_I,x, N_I,y] [1/m] (direct or smoothed), or ``None``
            where a rule has no gradient part.
        name: Rule name, for reports.
    """

    points: np.ndarray
    weights: np.ndarray
    values: SparseRows | None
    gradients: SparseRows | None
    name: str


def gauss(p: Particles, rk: RKApproximation, degree: int = 2) -> Quadrature:
    """Gauss quadrature on the triangles, exact for polynomials of ``degree`` (1, 2 or 4)."""
    if degree not in _TRIANGLE_RULES:
        raise InputError(f"Gauss degree {degree!r} not available; use one of {sorted(_TRIANGLE_RULES)}")
    bary, w = _TRIANGLE_RULES[degree]
    xt = p.x[p.triangles]
    e1, e2 = xt[:, 1] - xt[:, 0], xt[:, 2] - xt[:, 0]
    area = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    pts = np.einsum("qk,tkd->tqd", bary, xt).reshape(-1, 2)
    rows = evaluate(rk, pts, gradients=True)
    return Quadrature(pts, np.outer(area, w).ravel(), rows.component(0),
                      SparseRows(rows.indptr, rows.indices, rows.data[:, 1:], rows.num_cols), f"gauss{degree}")


def dni(p: Particles, rk: RKApproximation, domains: NodalDomains, nodes: np.ndarray | None = None) -> Quadrature:
    """Direct nodal integration: N and its direct gradient at the nodes (or at ``nodes`` only),
    weights A_L."""
    x, area = (p.x, domains.area) if nodes is None else (p.x[nodes], domains.area[nodes])
    rows = evaluate(rk, x, gradients=True)
    return Quadrature(x, area, rows.component(0),
                      SparseRows(rows.indptr, rows.indices, rows.data[:, 1:], rows.num_cols), "dni")


@dataclass(frozen=True)
class SmoothedGradients:
    """Smoothed gradients of all shape functions on (a selection of) the nodal cells (eq. 3.55).

    Attributes:
        cell: Rows per node L of ``nodes``: grad~N_I(x_L) [1/m].
        node_values: Rows per node L of ``nodes``: N_I(x_L).
        cell_minus_subcell: Rows per subcell C of ``subcells``: grad~N_I(x_L) - grad~N_I(x_hat_C),
            the subcell gradient smoothed over C (the MSCNI terms of eq. 3.56), or ``None``.
        nodes: The nodes L of the rows, shape ``(num_rows,)`` (all nodes unless selected).
        subcells: The subcells C of the stabilization rows, shape ``(num_subcell_rows,)``.
    """

    cell: SparseRows
    node_values: SparseRows
    cell_minus_subcell: SparseRows | None
    nodes: np.ndarray
    subcells: np.ndarray


# N is evaluated at about this many smoothing points at a time: the rows of one block of points
# are held (~0.06 GB), never those of all (1.3 GB at 10^6 nodes), and each block's combined rows
# go straight into the result (``stacked_rows``).
POINTS_PER_BLOCK = 250_000


def selected_cells(domains: NodalDomains, nodes: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The cells ``nodes`` (all when ``None``) and their subcells, in index order (2-D domains
    or 3-D ``NodalCells3D``)."""
    cell, subcell = cell_measures(domains)
    if nodes is None:
        return np.arange(len(cell)), np.arange(len(subcell))
    nodes = np.asarray(nodes, dtype=np.int64)
    mine = np.zeros(len(cell), bool)
    mine[nodes] = True
    return nodes, np.flatnonzero(mine[domains.subcell_node])


def _value_differences(rk: RKApproximation, d: NodalDomains, node_values: SparseRows, nodes: np.ndarray,
                       sub: np.ndarray) -> SparseRows:
    """The rows N(x_L) - N(x_hat_C) of the subcells ``sub`` (eq. 3.58); ``node_values``: N at ``nodes``."""
    row_of = np.full(len(d.area), -1, np.int64)
    row_of[nodes] = np.arange(len(nodes))
    return difference_rows(node_values, row_of[d.subcell_node[sub]], evaluate(rk, d.subcell_centroid[sub]))


def smoothed_gradients(p: Particles, rk: RKApproximation, domains: NodalDomains,
                       subcells: bool = True, nodes: np.ndarray | None = None) -> SmoothedGradients:
    """N at the smoothing points, combined into cell smoothed gradients and, with ``subcells``,
    the MSCNI differences (formed in one pass, without storing subcell gradients).

    ``nodes`` (indices) restricts the rows to the cells of those nodes and their subcells (a
    rank's owned cells, ``rkfx.parallel.ownership``): N is then evaluated only at their
    smoothing points; the columns stay all nodes. The points are taken in blocks of about
    ``POINTS_PER_BLOCK``; every row is the same, entry for entry, whatever the blocks.
    """
    d = domains
    nodes, sub = selected_cells(d, nodes)
    slot = np.full(len(d.smoothing_points), -1, np.int32)
    if subcells:
        cell, diff = _cells_and_subcells(rk, d, nodes, sub, slot)
    else:
        cell, diff = stacked_rows(_cell_blocks(rk, d, nodes, slot), len(nodes)), None
    return SmoothedGradients(cell, evaluate(rk, p.x[nodes]), diff, nodes, sub)


def _block_bounds(counts: np.ndarray, per_block: int) -> list[tuple[int, int]]:
    """Consecutive ranges of the items with ``counts`` points each, about ``per_block`` points a range."""
    total = np.cumsum(counts)
    if total.size == 0:
        return [(0, 0)]
    cuts = np.searchsorted(total, np.arange(per_block, total[-1], per_block), side="right")
    bounds = np.unique(np.concatenate([[0], cuts, [len(counts)]]))
    return list(zip(bounds[:-1].tolist(), bounds[1:].tolist()))


@numba.njit(cache=True)
def _renumber(point, slot):
    """The distinct entries of ``point`` in the order first met, and the place of each entry
    among them; ``slot`` (-1 everywhere, one per point of the domains) is left as it was found."""
    local = np.empty(len(point), np.int64)
    seen = np.empty(len(point), np.int64)
    k = 0
    for t in range(len(point)):
        j = point[t]
        s = slot[j]
        if s < 0:
            s = k
            slot[j] = k
            seen[k] = j
            k += 1
        local[t] = s
    for t in range(k):
        slot[seen[t]] = -1
    return seen[:k].copy(), local


def _cell_terms(d: NodalDomains, block: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cell-boundary segments of the nodes ``block``: their row pointer, their indices and
    their weights n l / A_L (eq. 3.55)."""
    ptr, point, normal_length = d.cell_segments(block)
    return ptr, point, normal_length / np.repeat(d.area[block], np.diff(ptr))[:, None]


def _cell_blocks(rk: RKApproximation, d: NodalDomains, nodes: np.ndarray, slot: np.ndarray):
    """The cell rows of ``nodes`` (eq. 3.55), a block of nodes at a time."""
    for lo, hi in _block_bounds(d.segment_counts()[nodes], POINTS_PER_BLOCK):
        ptr, segment_points, weight = _cell_terms(d, nodes[lo:hi])
        points, local = _renumber(segment_points, slot)
        yield combine_job(evaluate(rk, d.smoothing_points[points]), ptr, local, weight)


@numba.njit(cache=True)
def _first_block(owner, block_end, num_nodes):
    """The first block (``block_end``: the end of each block in ``owner``) holding a subcell of
    each node; the number of blocks for nodes without one."""
    first = np.full(num_nodes, len(block_end), np.int64)
    k = 0
    for i in range(len(owner)):
        while i >= block_end[k]:
            k += 1
        if first[owner[i]] > k:
            first[owner[i]] = k
    return first


def _cell_block(d: NodalDomains, nodes: np.ndarray, owner: np.ndarray, bounds: list[tuple[int, int]]) -> np.ndarray:
    """The block that forms the cell row of each of ``nodes``: the earliest block needing it or
    a later one of the nodes after it (the suffix minimum: blocks in the order of ``nodes``),
    unless that would crowd a block with more than 4 blocks' worth of cell segments (subcells
    far out of the nodes' order): then the first block needing each. Nodes without subcells
    go with the nodes after them, or after the blocks."""
    end = np.array([hi for _, hi in bounds], np.int64)
    first = _first_block(owner, end, len(d.area))[nodes]
    ordered = np.minimum.accumulate(first[::-1])[::-1]
    load = np.bincount(ordered, d.segment_counts()[nodes], len(bounds) + 1)[:-1]
    return ordered if load.max(initial=0) <= 4 * POINTS_PER_BLOCK else first


def _cells_and_subcells(rk: RKApproximation, d: NodalDomains, nodes: np.ndarray, sub: np.ndarray, slot: np.ndarray,
                        difference: bool = True, with_cells: bool = True) -> tuple[SparseRows | None, SparseRows]:
    """The cell rows of ``nodes`` and the rows of their subcells ``sub`` (in that order), a
    block of subcells at a time: the MSCNI rows grad~N(x_L) - grad~N(x_hat_C) (eq. 3.56), or
    without ``difference`` the subcell gradients grad~N(x_hat_C) themselves; without
    ``with_cells`` (and ``difference``) the subcell rows alone, the cell rows ``None``.

    A block evaluates N once, at its subcells' sides and at the cell boundaries of the nodes
    whose cell rows it forms (a cell's boundary segments are sides of its subcells: mostly the
    same points). A cell row is formed by the first block that needs it or an earlier one
    (``_cell_block``), so that they come out in the order of ``nodes``, without a reordering
    copy (0.27 GB at 10^6 nodes), whenever the subcells follow the nodes closely enough.
    """
    owner = d.subcell_node[sub]
    where = np.full(len(d.area), -1, np.int64)  # row of each node's cell among those formed
    cells, subs = RowStack(len(nodes)), RowStack(len(sub))
    bounds = _block_bounds(np.full(len(sub), 4), POINTS_PER_BLOCK)
    if with_cells or difference:
        block_of = _cell_block(d, nodes, owner, bounds)
        by_block = np.argsort(block_of, kind="stable")
        starts = np.searchsorted(block_of[by_block], np.arange(len(bounds) + 1))
    for k, (lo, hi) in enumerate(bounds):
        block = sub[lo:hi]
        new = nodes[by_block[starts[k]:starts[k + 1]]] if with_cells or difference else owner[:0]
        ptr, segment_points, weight = _cell_terms(d, new)
        points, local = _renumber(np.concatenate([segment_points, d.subcell_point[block].ravel()]), slot)
        at = evaluate(rk, d.smoothing_points[points])
        where[new] = cells.count + np.arange(len(new))
        cells.append(combine_job(at, ptr, local[:len(segment_points)], weight))
        side_weight = (d.side_normal_length(block) / d.subcell_area[block, None, None]).reshape(-1, 2)
        sides = np.arange(0, 4 * len(block) + 1, 4)
        subs.append(combine_job(at, sides, local[len(segment_points):], -side_weight, base=cells.rows(),
                                base_row=where[owner[lo:hi]]) if difference else
                    combine_job(at, sides, local[len(segment_points):], side_weight))
        del at
    if not (with_cells or difference):
        return None, subs.rows()
    rest = nodes[where[nodes] < 0]  # cells without subcells
    if rest.size:
        where[rest] = cells.count + np.arange(len(rest))
        for job in _cell_blocks(rk, d, rest, slot):
            cells.append(job)
    order = where[nodes]
    cell = cells.rows()
    if not np.array_equal(order, np.arange(len(nodes))):
        cell = gathered_rows(cell, order)
    return cell, subs.rows()


def subcell_gradients(rk: RKApproximation, domains: NodalDomains, nodes: np.ndarray | None = None,
                      with_cells: bool = True) -> tuple[SparseRows | None, SparseRows, np.ndarray]:
    """The smoothed gradients of eq. (3.55) over each cell, grad~N_I(x_L), and over each of
    its subcells, grad~N_I(x_hat_C) (the subcell rows of eq. 3.56), a block of subcells at a
    time (``POINTS_PER_BLOCK``).

    ``nodes`` (ascending indices) fills only the rows of those particles' cells and subcells,
    evaluating N only at their smoothing points; the other rows stay empty, so the rows keep
    their places (a rank's share of an explicit run, ``rkfx.assembly.local_strain``). Each
    filled row equals the whole build's entry for entry.

    Returns:
        (cell rows, subcell rows, order): subcell row k belongs to subcell ``order[k]`` of
        ``domains``; the rows are grouped by particle (stable sort of ``subcell_node``). The
        cell rows are ``None`` without ``with_cells``.
    """
    d = domains
    order = np.argsort(d.subcell_node, kind="stable")
    slot = np.full(len(d.smoothing_points), -1, np.int32)
    if nodes is None:
        cell, sub = _cells_and_subcells(rk, d, np.arange(len(d.area)), order, slot, difference=False,
                                        with_cells=with_cells)
        return cell, sub, order
    nodes = np.asarray(nodes, dtype=np.int64)
    mine = np.zeros(len(d.area), bool)
    mine[nodes] = True
    filled = np.flatnonzero(mine[d.subcell_node[order]])  # places of the selected subcells' rows
    cell, sub = _cells_and_subcells(rk, d, nodes, order[filled], slot, difference=False, with_cells=with_cells)
    return (None if cell is None else spread_rows(cell, nodes, len(d.area))), spread_rows(sub, filled, len(order)), \
        order


def subcell_rule(rk: RKApproximation, domains: NodalDomains, nodes: np.ndarray | None = None) -> Quadrature:
    """The subcells as points: weights A_C, the gradients smoothed over each subcell
    grad~N_I(x_hat_C) (``subcell_gradients``; with ``nodes``, only those nodes' subcells hold
    entries). Over a grad-grad form it is MSCNI at eps_p = 1: the subcells partition each cell
    (sum_C A_C B_C = A_L B_L, sum_C A_C = A_L), so eq. (3.56) gives
    A_L B_L^T D B_L + sum_C A_C (B_L - B_C)^T D (B_L - B_C) = sum_C A_C B_C^T D B_C,
    from fewer and shorter rows."""
    _, sub, order = subcell_gradients(rk, domains, nodes=nodes, with_cells=False)
    return Quadrature(domains.subcell_centroid[order], domains.subcell_area[order], None, sub, "subcells")


def mscni_rules(p: Particles, rk: RKApproximation, domains: NodalDomains, eps_p: float = 1.0,
                nodes: np.ndarray | None = None, with_values: bool = True
                ) -> tuple[Quadrature, list[Quadrature], Quadrature | None]:
    """MSCNI (eqs. 3.55-3.59) over the cells of ``nodes`` (default all) and their subcells (in
    index order), from one evaluation of N per block of subcells (``_cells_and_subcells``).

    Returns ``(nodal, gradient_rules, values)``:
        nodal: SCNI, points x_L, weights A_L, values N(x_L), cell gradients grad~N(x_L).
        gradient_rules: the quadratures of every grad-grad form (stiffness, Darcy): since the
            subcells partition each cell (sum_C A_C B_C = A_L B_L), eq. (3.56)
            A_L B_L^T D B_L + eps_p sum_C A_C (B_L - B_C)^T D (B_L - B_C)
            = (1 - eps_p) A_L B_L^T D B_L + eps_p sum_C A_C B_C^T D B_C, with D the cell's:
            SCNI weighted (1 - eps_p) (left out at eps_p = 1) and the subcells weighted
            eps_p A_C with their gradients grad~N(x_hat_C).
        values: the value rows N(x_L) - N(x_hat_C) of eq. (3.58) at the subcells, weights
            eps_p A_C (no gradients); ``None`` without ``with_values``.
    """
    if not eps_p >= 0:
        raise InputError(f"eps_p = {eps_p!r} must be >= 0 (1 is the usual MSCNI choice)")
    d = domains
    whole = nodes is None
    nodes, sub = selected_cells(d, nodes)
    cell, grads = _cells_and_subcells(rk, d, nodes, sub, np.full(len(d.smoothing_points), -1, np.int32),
                                      difference=False)
    # The whole build's points and weights are the domains' arrays themselves (no copies: 0.17 GB
    # at 10^6 nodes).
    x, area = (p.x, d.area) if whole else (p.x[nodes], d.area[nodes])
    centroids, sub_area = (d.subcell_centroid, d.subcell_area) if whole else (d.subcell_centroid[sub],
                                                                              d.subcell_area[sub])
    node_values = evaluate(rk, x)
    nodal = Quadrature(x, area, node_values, cell, "scni")
    weights = sub_area if eps_p == 1.0 else eps_p * sub_area
    rules = [Quadrature(centroids, weights, None, grads, "mscni-subcells")]
    if eps_p != 1.0:
        rules.insert(0, Quadrature(nodal.points, (1.0 - eps_p) * nodal.weights, None, cell, "scni"))
    if not with_values:
        return nodal, rules, None
    values = _value_differences(rk, d, node_values, nodes, sub)
    return nodal, rules, Quadrature(centroids, weights, values, None, "mscni-values")


def scni(p: Particles, rk: RKApproximation, domains: NodalDomains,
         smoothed: SmoothedGradients | None = None, nodes: np.ndarray | None = None) -> Quadrature:
    """SCNI: smoothed gradients at the nodes, weights A_L (eq. 3.55); with ``nodes``, only the
    points of those nodes (ignored when ``smoothed`` is given: its nodes are used)."""
    s = smoothed or smoothed_gradients(p, rk, domains, subcells=False, nodes=nodes)
    return Quadrature(p.x[s.nodes], domains.area[s.nodes], s.node_values, s.cell, "scni")


def mscni_stabilization(p: Particles, rk: RKApproximation, domains: NodalDomains,
                        smoothed: SmoothedGradients | None = None, eps_p: float = 1.0,
                        with_values: bool = False, nodes: np.ndarray | None = None) -> Quadrature:
    """The subcell terms of eq. (3.56): rows grad~N(x_L) - grad~N(x_hat_C), weights eps_p A_C.

    With ``with_values`` the value rows N(x_L) - N(x_hat_C) of eq. (3.58) are formed too.
    With ``nodes``, only the subcells of those nodes (``smoothed``, when given, decides).
    """
    if not eps_p >= 0:
        raise InputError(f"eps_p = {eps_p!r} must be >= 0 (1 is the usual MSCNI choice)")
    d = domains
    s = smoothed if smoothed is not None and smoothed.cell_minus_subcell is not None else \
        smoothed_gradients(p, rk, d, subcells=True, nodes=nodes)
    diff = s.cell_minus_subcell
    values = None
    if with_values:
        values = _value_differences(rk, d, s.node_values, s.nodes, s.subcells)
    return Quadrature(d.subcell_centroid[s.subcells], eps_p * d.subcell_area[s.subcells], values, diff,
                      "mscni-stabilization")


RULES = ("gauss1", "gauss2", "gauss4", "dni", "scni", "mscni")


NODAL_RULES = ("scni", "mscni")  # the rules whose points are the nodes' cells (selectable by ``nodes``)


def integration_rules(name: str, p: Particles, rk: RKApproximation, domains: NodalDomains,
                      eps_p: float = 1.0, nodes: np.ndarray | None = None) -> list[Quadrature]:
    """The quadratures of a named rule (``mscni`` gives two: SCNI and its stabilization).

    ``nodes`` (indices) keeps only the integration points of those nodes' cells (a rank's
    owned cells); only the nodal rules ``scni`` and ``mscni`` have such a selection.
    """
    if nodes is not None and name not in NODAL_RULES:
        raise InputError(f"rule {name!r} has no selection of points by node; use one of {', '.join(NODAL_RULES)} "
                         "(or assemble on every rank whole)")
    if name.startswith("gauss") and name in RULES:
        return [gauss(p, rk, int(name[5:]))]
    if name == "dni":
        return [dni(p, rk, domains)]
    if name == "scni":
        return [scni(p, rk, domains, nodes=nodes)]
    if name == "mscni":
        s = smoothed_gradients(p, rk, domains, subcells=True, nodes=nodes)
        return [scni(p, rk, domains, s), mscni_stabilization(p, rk, domains, s, eps_p)]
    raise InputError(f"unknown integration rule {name!r}; choose one of {', '.join(RULES)}")
