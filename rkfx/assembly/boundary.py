"""Boundary integration, loads and essential boundary conditions for RK approximations.

The conditions are those of ``rkfx.conditions`` (``Displacement``, ``Velocity``, ``Pressure``,
``Traction``, ``Flux``), evaluated with ``rkfx.conditions.values``: a constant, a constant
vector or a function value(x, t) (value(x, t, n) for tractions, with the boundary normals).
A condition's boundary part is a name (a tagged part of the particles) or a marker
``marker(x) -> bool (m,)``; ``part_nodes`` and ``part_points`` resolve it, to the nodes of the
part (a name's nodes, or the boundary nodes the marker accepts) and to the boundary quadrature
points of the part (by tag, or the points the marker accepts).

RK shape functions do not interpolate nodal values, so u = u_bar on Gamma_u needs care:

* ``transformation`` — the mixed transformation method: u^h(x_I) = u_bar(x_I) at every node
  I on Gamma_u. Writing the transformed system back in the RK coefficients gives the
  collocation constraints G d = g with G_IJ = N_J(x_I), imposed by multipliers:
  [[K, G^T], [G, 0]] [d, lambda] = [f, g] (``collocation``, ``transformation_constraints``).
* ``nitsche`` — symmetric Nitsche: adds -int(eta.t(u) + t(eta).u) + beta int(eta.u) on
  Gamma_u, with beta = penalty (lambda + 2 mu) / h. Evaluated at the midpoints of the
  boundary half-segments, the same points SCNI's divergence form uses, so the linear
  patch test is passed to round-off (``nitsche_terms``).

Tractions load f_I = int_Gamma_t N_I t_bar dGamma at the same points (``traction_load``).
"""
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.conditions import ESSENTIAL, Boundary, Condition, Displacement, Region, Traction, values
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles
from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.approximation.sparse_rows import SparseRows

BC_METHODS = ("transformation", "nitsche")


@dataclass(frozen=True)
class BoundaryQuadrature:
    """Points on the boundary (Gauss points of the boundary half-segments in 2-D, the facet
    centroids of the nodal cells in 3-D) with shape rows [N, N_x, N_y(, N_z)].

    Attributes:
        points, normals: Shape ``(m, 2)`` (``(m, 3)`` in 3-D).
        weights: Shape ``(m,)`` [m] (facet areas [m^2] in 3-D).
        tag: Boundary tag of each point, shape ``(m,)``.
        spacing: Nodal spacing of the segment's owning node, shape ``(m,)`` [m].
        rows: Shape rows at the points.
    """

    points: np.ndarray
    normals: np.ndarray
    weights: np.ndarray
    tag: np.ndarray
    spacing: np.ndarray
    rows: SparseRows

    def select(self, tags: Sequence[int]) -> np.ndarray:
        return np.isin(self.tag, list(tags))

    @property
    def dim(self) -> int:
        """Spatial dimension, 2 or 3."""
        return self.points.shape[1]


def boundary_quadrature(p: Particles, domains: NodalDomains, rk: RKApproximation,
                        points_per_segment: int = 1, segments: np.ndarray | None = None) -> BoundaryQuadrature:
    """Gauss-Legendre points on every boundary half-segment (1 point = SCNI's midpoint rule);
    in 3-D (``domains`` a ``rkfx.geometry.nodal_cells3d.NodalCells3D``) the centroids of the
    cells' planar boundary facets, weights their areas (the points SCNI's divergence form uses;
    ``points_per_segment`` must be 1).

    ``segments`` (indices of boundary half-segments, or of boundary facets in 3-D, e.g. those of
    a rank's owned nodes) keeps every point but gives shape rows and weights only to the points
    of those segments; the others get empty rows and zero weight, so boundary parts are still
    resolved on the whole boundary and the loads and Nitsche terms sum to the whole ones over a
    partition.
    """
    if points_per_segment < 1:
        raise InputError(f"points_per_segment = {points_per_segment!r} must be >= 1")
    b = domains.boundary
    k = points_per_segment
    if p.x.shape[1] == 3:
        if k != 1:
            raise InputError(f"points_per_segment = {k!r}: 3-D boundary facets take their centroid only (1)")
        pts, normals, weights = domains.points[b.point], b.normal, b.area.copy()
    else:
        s, w = np.polynomial.legendre.leggauss(points_per_segment)
        t = 0.5 * (s + 1.0)
        pts = (b.ends[:, None, 0] * (1 - t)[None, :, None] + b.ends[:, None, 1] * t[None, :, None]).reshape(-1, 2)
        normals, weights = np.repeat(b.normal, k, axis=0), (0.5 * np.outer(b.length, w)).ravel()
    if segments is None:
        rows = evaluate(rk, pts, gradients=True)
    else:
        keep = np.zeros(len(b.node), bool)
        keep[segments] = True
        keep = np.repeat(keep, k)
        weights = np.where(keep, weights, 0.0)
        mine = evaluate(rk, pts[keep], gradients=True)
        indptr = np.zeros(len(pts) + 1, np.int64)
        indptr[1:][keep] = np.diff(mine.indptr)
        rows = SparseRows(np.cumsum(indptr), mine.indices, mine.data, mine.num_cols)
    return BoundaryQuadrature(points=pts, normals=normals, weights=weights, tag=np.repeat(b.tag, k),
                              spacing=np.repeat(p.spacing[b.node], k), rows=rows)


def _only(conditions: Sequence[Condition], kinds: tuple[type, ...], where: str) -> Sequence[Condition]:
    """The conditions, if each is one of ``kinds``; else a one-line error naming the culprit."""
    for c in conditions:
        if not isinstance(c, kinds):
            names = " or ".join(f"rkfx.conditions.{k.__name__}" for k in kinds)
            raise InputError(f"{where} takes {names} conditions, not {c!r}")
    return conditions


def _part_label(boundary: Boundary) -> str:
    return repr(boundary) if isinstance(boundary, str) else f"marker {getattr(boundary, '__name__', repr(boundary))}"


def _marked(boundary: Boundary, x: np.ndarray, what: str,
            fix: str = "make it accept points on the boundary (e.g. np.isclose(x[:, 1], top)), or name a tagged part"
            ) -> np.ndarray:
    """The marker's answer at points x, shape ``(m,)`` bool; raises if it selects none."""
    accepted = np.asarray(boundary(x))
    if accepted.shape != (len(x),):
        raise InputError(f"boundary {_part_label(boundary)} returned shape {accepted.shape} for {len(x)} points; "
                         "a marker(x) takes x of shape (m, 2) and returns a bool array of shape (m,)")
    accepted = accepted.astype(bool)
    if not accepted.any():
        raise InputError(f"boundary {_part_label(boundary)} selects no {what}; {fix}")
    return accepted


def _tag(p: Particles, boundary: Boundary) -> int:
    """The tag of a named part, with the fix in the message for anything else."""
    if not isinstance(boundary, str):
        raise InputError(f"boundary part {boundary!r} is neither a name nor a marker; use the name of a tagged "
                         "part or a function marker(x) -> bool (m,)")
    if boundary not in p.boundary_names:
        raise InputError(f"unknown boundary {boundary!r}; this geometry names {sorted(p.boundary_names)}: use one "
                         "of them or a marker(x) -> bool (m,)")
    return p.boundary_names[boundary]


def part_nodes(p: Particles, boundary: Boundary) -> np.ndarray:
    """Sorted indices of the nodes of a boundary part: the nodes of a named part, the
    boundary nodes whose coordinates a marker accepts, or every node a ``Region`` accepts."""
    if isinstance(boundary, Region):
        return np.flatnonzero(_marked(boundary.marker, p.x, f"particle of region {boundary.name!r}",
                                      "widen the region's marker or refine the particles"))
    if callable(boundary):
        nodes = p.boundary_nodes()
        return nodes[_marked(boundary, p.x[nodes], "boundary node")]
    _tag(p, boundary)
    return p.boundary_nodes(boundary)


def part_points(p: Particles, bq: BoundaryQuadrature, boundary: Boundary) -> np.ndarray:
    """Indices of the boundary quadrature points of a part: those with the part's tag, or those
    a marker accepts."""
    if isinstance(boundary, Region):
        raise InputError(f"region {boundary.name!r} is inside the domain; natural conditions (tractions, fluxes) "
                         "act on boundary parts: name a tagged part or give a marker(x)")
    if callable(boundary):
        return np.flatnonzero(_marked(boundary, bq.points, "boundary quadrature point"))
    return np.flatnonzero(bq.select([_tag(p, boundary)]))


def traction_load(p: Particles, bq: BoundaryQuadrature, tractions: Sequence[Traction],
                  t: float = 0.0) -> np.ndarray:
    """f_I = int_Gamma_t N_I t_bar dGamma (eq. 3.36) at time t, interleaved, shape ``(g n,)`` (g = 2 or 3).

    Args:
        tractions: ``rkfx.conditions.Traction`` conditions; value(x, t, n) is evaluated at the
            boundary quadrature points of each part with their outward normals. Components
            not listed carry no traction.
        t: Time [s].
    """
    f = np.zeros((p.num_nodes, bq.dim))
    nmat = bq.rows.matrix(0)
    for tr in _only(tractions, (Traction,), "traction_load"):
        sel = part_points(p, bq, tr.boundary)
        f += nmat[sel].T @ (bq.weights[sel, None] * traction_values(tr, bq, sel, t))
    return f.ravel()


def traction_values(traction: Traction, bq: BoundaryQuadrature, sel: np.ndarray, t: float = 0.0) -> np.ndarray:
    """t_bar(x, t, n) at the boundary quadrature points ``sel`` (indices), shape ``(len(sel), 2)``:
    zero in the components the traction does not list (``(len(sel), 3)`` in 3-D)."""
    tv = np.zeros((len(sel), bq.dim))
    tv[:, list(traction.prescribed(bq.dim))] = values(traction, bq.points[sel], t, bq.normals[sel])
    return tv


@dataclass(frozen=True)
class Collocation:
    """Rows ``u^h_c(x_I)`` at the nodes of prescribed boundary parts (the transformation method).

    Attributes:
        G: Constraint rows over all unknowns of the problem, shape ``(k, num_unknowns)``.
        parts: ``(condition, j, component, nodes, num_components)`` per block of rows, to
            evaluate the prescribed values in the same order.
    """

    G: sp.csr_matrix
    parts: list

    def values(self, x: np.ndarray, t: float = 0.0) -> np.ndarray:
        """Prescribed values g at time t, shape ``(k,)``: ``rkfx.conditions.values`` of each
        condition at its nodes x_I, the column of the block's component."""
        out = [values(bc, x[nodes], t)[:, j] for bc, j, _, nodes, _ in self.parts]
        return np.concatenate(out) if out else np.zeros(0)


def collocation(p: Particles, rk: RKApproximation, fields: Sequence[tuple[Sequence, int, int]],
                num_unknowns: int, nodes: np.ndarray | None = None) -> Collocation:
    """Collocation rows for the conditions of several fields of one problem.

    Args:
        fields: ``(conditions, offset, num_components)`` per field: essential conditions of
            ``rkfx.conditions`` (``Displacement``, ``Velocity``, ``Pressure``) collocated at the
            nodes of their parts (``part_nodes``); the field's unknowns start at ``offset`` and
            are interleaved per node. A (node, component) pair already prescribed by an earlier
            condition is not prescribed again.
        num_unknowns: Columns of G.
        nodes: Collocate only at these nodes (indices, e.g. a rank's owned nodes); the rows of
            a partition's parts together are the rows of the whole.
    """
    blocks, parts, seen, only = [], [], set(), nodes
    for conditions, offset, ncomp in fields:
        for bc in _only(conditions, ESSENTIAL, "collocation"):
            nodes = part_nodes(p, bc.boundary)
            for j, c in enumerate(bc.prescribed(p.x.shape[1])):
                fresh = np.array([(offset, c, i) not in seen for i in nodes], bool)
                seen.update((offset, c, i) for i in nodes)
                sel = nodes[fresh] if only is None else nodes[fresh & np.isin(nodes, only)]
                if sel.size == 0:
                    continue
                coo = evaluate(rk, p.x[sel]).matrix(0).tocoo()
                blocks.append(sp.csr_matrix((coo.data, (coo.row, offset + ncomp * coo.col + c)),
                                            shape=(len(sel), num_unknowns)))
                parts.append((bc, j, c, sel, ncomp))
    g = sp.vstack(blocks).tocsr() if blocks else sp.csr_matrix((0, num_unknowns))
    return Collocation(g, parts)


def transformation_constraints(p: Particles, rk: RKApproximation, conditions: Sequence[Condition],
                               t: float = 0.0, nodes: np.ndarray | None = None) -> tuple[sp.csr_matrix, np.ndarray]:
    """Rows G (k, g n) and values g (k,) at time t of u^h_c(x_I) = u_bar_c(x_I, t) at the nodes
    of Gamma_u (g = 2, or 3 in 3-D), for essential conditions of ``rkfx.conditions`` on the
    displacement field (or its velocity, ``Velocity``); with ``nodes``, only at those of them
    (see ``collocation``)."""
    g = p.x.shape[1]
    col = collocation(p, rk, [(conditions, 0, g)], g * p.num_nodes, nodes)
    return col.G, col.values(p.x, t)


@dataclass(frozen=True)
class NitscheRows:
    """The rows at the boundary quadrature points of one condition's prescribed components,
    component-major (all points of the first component, then of the next).

    Attributes:
        condition: The ``Displacement`` condition.
        points: Its boundary quadrature points (indices into the ``BoundaryQuadrature``).
        components: The prescribed components.
        values: u_c(x_q) over the interleaved coefficients, shape ``(m nc, 2 n)``.
        tractions: t_c(u)(x_q) = (T D B u)_c, the elastic traction, shape ``(m nc, 2 n)``.
        weights: The points' weights, shape ``(m nc,)`` [m].
        penalty: beta = penalty (lambda + 2 mu) / h, shape ``(m nc,)`` [Pa/m].
        normals: n_c at each point, shape ``(m nc,)``.
    """

    condition: Displacement
    points: np.ndarray
    components: list[int]
    values: sp.csr_matrix
    tractions: sp.csr_matrix
    weights: np.ndarray
    penalty: np.ndarray
    normals: np.ndarray

    def matrix(self) -> sp.csr_matrix:
        """-int(eta.t(u) + t(eta).u) + beta int(eta.u) over the prescribed components."""
        w = sp.diags(self.weights)
        return (-self.values.T @ w @ self.tractions - self.tractions.T @ w @ self.values
                + self.values.T @ sp.diags(self.weights * self.penalty) @ self.values)

    def load(self, bq: BoundaryQuadrature, t: float) -> np.ndarray:
        """-int t(eta).u_bar + beta int eta.u_bar at time t, shape ``(2 n,)``."""
        ubar = values(self.condition, bq.points[self.points], t).T.ravel()
        return -self.tractions.T @ (self.weights * ubar) + self.values.T @ (self.weights * self.penalty * ubar)


def nitsche_rows(p: Particles, bq: BoundaryQuadrature, d: np.ndarray, conditions: Sequence[Displacement],
                 penalty: float = 100.0) -> list[NitscheRows]:
    """The Nitsche rows of every condition with boundary points (``NitscheRows``).

    Args:
        d: Elasticity matrix (3, 3) [Pa] of the traction t(u) = T D B u ((6, 6) in 3-D).
        conditions: ``rkfx.conditions.Displacement`` conditions, on their parts' boundary
            quadrature points (``part_points``).
        penalty: Dimensionless Nitsche parameter.
    """
    if not penalty > 0:
        raise InputError(f"Nitsche penalty = {penalty!r} must be positive (e.g. 100)")
    from rkfx.materials.elasticity import traction_operator  # noqa: PLC0415
    from rkfx.assembly.operators import block_diagonal, strain_matrix  # noqa: PLC0415

    g = bq.dim
    v = 3 if g == 2 else 6
    n2 = g * p.num_nodes
    grad = SparseRows(bq.rows.indptr, bq.rows.indices, bq.rows.data[:, 1:], bq.rows.num_cols)
    b_all = strain_matrix(grad)
    out = []
    for bc in _only(conditions, (Displacement,), "nitsche_terms"):
        sel = part_points(p, bq, bc.boundary)
        if sel.size == 0:
            continue
        m = len(sel)
        nmat = bq.rows.matrix(0)[sel]
        # Displacement rows u_c(x_q) for the prescribed components c: (m * nc, 2n).
        comps = list(bc.prescribed(g))
        proj = sp.vstack([sp.csr_matrix((nmat.data, nmat.indices * g + c, nmat.indptr), shape=(m, n2))
                          for c in comps]).tocsr()
        # Traction rows t_c(u)(x_q) = (T D B u)_c for the same components.
        bq_rows = b_all[np.ravel(v * sel[:, None] + np.arange(v))]
        tdb = np.einsum("mij,jk->mik", traction_operator(bq.normals[sel]), d)
        trac = block_diagonal(tdb) @ bq_rows  # (g m, g n), rows (q, component)
        trac = sp.vstack([trac[c::g] for c in comps]).tocsr()
        out.append(NitscheRows(bc, sel, comps, proj, trac, np.tile(bq.weights[sel], len(comps)),
                               penalty * d[0, 0] / np.tile(bq.spacing[sel], len(comps)),
                               np.concatenate([bq.normals[sel, c] for c in comps])))
    return out


def nitsche_terms(p: Particles, bq: BoundaryQuadrature, d: np.ndarray, conditions: Sequence[Displacement],
                  penalty: float = 100.0, t: float = 0.0) -> tuple[sp.csr_matrix, np.ndarray]:
    """Symmetric Nitsche matrix (2n, 2n) and load (2n,) for the prescribed components.

    Args:
        d: Elasticity matrix (3, 3) [Pa].
        conditions: ``rkfx.conditions.Displacement`` conditions, value(x, t) evaluated at the
            boundary quadrature points of each part (``part_points``).
        penalty: Dimensionless Nitsche parameter.
        t: Time [s].
    """
    n2 = bq.dim * p.num_nodes
    k_total = sp.csr_matrix((n2, n2))
    f_total = np.zeros(n2)
    for rows in nitsche_rows(p, bq, d, conditions, penalty):
        k_total = k_total + rows.matrix()
        f_total += rows.load(bq, t)
    return k_total.tocsr(), f_total


def nitsche_pressure_coupling(bq: BoundaryQuadrature, rows: Sequence[NitscheRows], alpha: float) -> sp.csr_matrix:
    """C = int_Gamma_u alpha p eta_c n_c over the prescribed components, shape ``(2 n, n)``:
    the pore-pressure part of the total traction (sigma'' - alpha p I) n in Nitsche's
    consistency term -int eta.(sigma n) of the u-p equations (the momentum rows then hold
    -(K_up - C) p)."""
    n = bq.rows.num_cols
    total = sp.csr_matrix((bq.dim * n, n))
    nmat = bq.rows.matrix(0)
    for r in rows:
        at = sp.vstack([nmat[r.points]] * len(r.components)).tocsr()
        total = total + r.values.T @ sp.diags(alpha * r.weights * r.normals) @ at
    return total.tocsr()
