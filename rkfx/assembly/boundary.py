"""Boundary integration, loads and essential boundary conditions for RK approximations.

RK shape functions do not interpolate nodal values, so u = u_bar on Gamma_u needs care:

* ``transformation`` — the mixed transformation method: u^h(x_I) = u_bar(x_I) at every node
  I on Gamma_u. Writing the transformed system back in the RK coefficients gives the
  collocation constraints G d = g with G_IJ = N_J(x_I), imposed by multipliers:
  [[K, G^T], [G, 0]] [d, lambda] = [f, g].
* ``nitsche`` — symmetric Nitsche: adds -int(eta.t(u) + t(eta).u) + beta int(eta.u) on
  Gamma_u, with beta = penalty (lambda + 2 mu) / h. Evaluated at the midpoints of the
  boundary half-segments, the same points SCNI's divergence form uses, so the linear
  patch test is passed to round-off.
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.conditions import ESSENTIAL, values
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles
from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.approximation.sparse_rows import SparseRows

BC_METHODS = ("transformation", "nitsche")


@dataclass(frozen=True)
class Dirichlet:
    """Prescribed displacement on a named boundary part.

    Attributes:
        boundary: Boundary part name.
        value: u_bar(x) for x of shape ``(m, 2)`` [m], returning ``(m, 2)`` (or ``(m,)`` when
            one component is prescribed).
        components: Prescribed components: ``(0, 1)``, ``(0,)`` or ``(1,)``.
    """

    boundary: str
    value: Callable[[np.ndarray], np.ndarray]
    components: tuple[int, ...] = (0, 1)

    def values_at(self, x: np.ndarray) -> np.ndarray:
        """Prescribed values at x, shape ``(m, len(components))``."""
        v = np.asarray(self.value(x), float)
        return v.reshape(len(x), -1)[:, list(self.components)] if v.ndim == 2 and v.shape[1] == 2 \
            else v.reshape(len(x), len(self.components))


@dataclass(frozen=True)
class Traction:
    """Prescribed traction t_bar(x, n) [Pa] on a named boundary part (``(m, 2)`` arrays in and out)."""

    boundary: str
    value: Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class BoundaryQuadrature:
    """Gauss points on boundary half-segments with shape rows [N, N_x, N_y].

    Attributes:
        points, normals: Shape ``(m, 2)``.
        weights: Shape ``(m,)`` [m].
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


def boundary_quadrature(p: Particles, domains: NodalDomains, rk: RKApproximation,
                        points_per_segment: int = 1) -> BoundaryQuadrature:
    """Gauss-Legendre points on every boundary half-segment (1 point = SCNI's midpoint rule)."""
    if points_per_segment < 1:
        raise InputError(f"points_per_segment = {points_per_segment!r} must be >= 1")
    b = domains.boundary
    s, w = np.polynomial.legendre.leggauss(points_per_segment)
    t = 0.5 * (s + 1.0)
    pts = (b.ends[:, None, 0] * (1 - t)[None, :, None] + b.ends[:, None, 1] * t[None, :, None]).reshape(-1, 2)
    k = points_per_segment
    return BoundaryQuadrature(
        points=pts, normals=np.repeat(b.normal, k, axis=0), weights=(0.5 * np.outer(b.length, w)).ravel(),
        tag=np.repeat(b.tag, k), spacing=np.repeat(p.spacing[b.node], k),
        rows=evaluate(rk, pts, gradients=True))


def _restrict(rows: SparseRows, mask: np.ndarray) -> sp.csr_matrix:
    """Value matrix of the selected rows."""
    return rows.matrix(0)[np.flatnonzero(mask)]


def traction_load(p: Particles, bq: BoundaryQuadrature, tractions: Sequence[Traction]) -> np.ndarray:
    """f_I = int_Gamma_t N_I t_bar dGamma (eq. 3.36), interleaved, shape ``(2 n,)``."""
    f = np.zeros((p.num_nodes, 2))
    for t in tractions:
        sel = bq.select([p.tag(t.boundary)])
        tv = np.asarray(t.value(bq.points[sel], bq.normals[sel]), float).reshape(-1, 2)
        f += _restrict(bq.rows, sel).T @ (bq.weights[sel, None] * tv)
    return f.ravel()


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

    def values(self, x: np.ndarray, *args) -> np.ndarray:
        """Prescribed values, shape ``(k,)``: ``condition.value(x_I, *args)`` per block.

        A value function may return every component ``(m, num_components)`` (the prescribed
        component is taken), only the prescribed ones ``(m, len(components))``, or ``(m,)``.
        """
        out = []
        for bc, j, c, nodes, ncomp in self.parts:
            if isinstance(bc, ESSENTIAL):  # rkfx.conditions: values of (x, t), constants
                out.append(values(bc, x[nodes], *args)[:, j])
                continue
            v = np.asarray(bc.value(x[nodes], *args), float).reshape(len(nodes), -1)
            col = c if (v.shape[1] == ncomp and ncomp > 1) else (j if v.shape[1] > 1 else 0)
            out.append(v[:, col])
        return np.concatenate(out) if out else np.zeros(0)


def collocation(p: Particles, rk: RKApproximation, fields: Sequence[tuple[Sequence, int, int]],
                num_unknowns: int) -> Collocation:
    """Collocation rows for the conditions of several fields of one problem.

    Args:
        fields: ``(conditions, offset, num_components)`` per field: each condition has
            ``boundary``, ``value`` and (for vector fields) ``components``; the field's unknowns
            start at ``offset`` and are interleaved per node. A (node, component) pair already
            prescribed by an earlier condition is not prescribed again.
        num_unknowns: Columns of G.
    """
    blocks, parts, seen = [], [], set()
    for conditions, offset, ncomp in fields:
        for bc in conditions:
            nodes = p.boundary_nodes(bc.boundary)
            for j, c in enumerate(getattr(bc, "components", (0,))):
                fresh = np.array([(offset, c, i) not in seen for i in nodes], bool)
                seen.update((offset, c, i) for i in nodes)
                sel = nodes[fresh]
                if sel.size == 0:
                    continue
                coo = evaluate(rk, p.x[sel]).matrix(0).tocoo()
                blocks.append(sp.csr_matrix((coo.data, (coo.row, offset + ncomp * coo.col + c)),
                                            shape=(len(sel), num_unknowns)))
                parts.append((bc, j, c, sel, ncomp))
    g = sp.vstack(blocks).tocsr() if blocks else sp.csr_matrix((0, num_unknowns))
    return Collocation(g, parts)


def transformation_constraints(p: Particles, rk: RKApproximation,
                               dirichlet: Sequence[Dirichlet]) -> tuple[sp.csr_matrix, np.ndarray]:
    """Rows G (k, 2n) and values g (k,) of u^h_c(x_I) = u_bar_c(x_I) at the nodes of Gamma_u."""
    col = collocation(p, rk, [(dirichlet, 0, 2)], 2 * p.num_nodes)
    return col.G, col.values(p.x)


def nitsche_terms(p: Particles, bq: BoundaryQuadrature, d: np.ndarray, dirichlet: Sequence[Dirichlet],
                  penalty: float = 100.0) -> tuple[sp.csr_matrix, np.ndarray]:
    """Symmetric Nitsche matrix (2n, 2n) and load (2n,) for the prescribed components."""
    if not penalty > 0:
        raise InputError(f"Nitsche penalty = {penalty!r} must be positive (e.g. 100)")
    from rkfx.materials.elasticity import traction_operator  # noqa: PLC0415
    from rkfx.assembly.operators import block_diagonal, strain_matrix  # noqa: PLC0415

    n2 = 2 * p.num_nodes
    k_total = sp.csr_matrix((n2, n2))
    f_total = np.zeros(n2)
    grad = SparseRows(bq.rows.indptr, bq.rows.indices, bq.rows.data[:, 1:], bq.rows.num_cols)
    b_all = strain_matrix(grad)
    for bc in dirichlet:
        sel = np.flatnonzero(bq.select([p.tag(bc.boundary)]))
        if sel.size == 0:
            continue
        m = len(sel)
        w = bq.weights[sel]
        nmat = bq.rows.matrix(0)[sel]
        # Displacement rows u_c(x_q) for the prescribed components c: (m * nc, 2n).
        comps = list(bc.components)
        proj = sp.vstack([sp.csr_matrix((nmat.data, nmat.indices * 2 + c, nmat.indptr), shape=(m, n2))
                          for c in comps]).tocsr()
        # Traction rows t_c(u)(x_q) = (T D B u)_c for the same components.
        bq_rows = b_all[np.ravel(3 * sel[:, None] + np.arange(3))]
        tdb = np.einsum("mij,jk->mik", traction_operator(bq.normals[sel]), d)
        trac = block_diagonal(tdb) @ bq_rows  # (2 m, 2n), rows (q, component)
        trac = sp.vstack([trac[c::2] for c in comps]).tocsr()
        wc = np.tile(w, len(comps))
        beta = penalty * d[0, 0] / np.tile(bq.spacing[sel], len(comps))
        wmat = sp.diags(wc)
        k_total = k_total - proj.T @ wmat @ trac - trac.T @ wmat @ proj + proj.T @ sp.diags(wc * beta) @ proj
        ubar = bc.values_at(bq.points[sel]).T.ravel()
        f_total += -trac.T @ (wc * ubar) + proj.T @ (wc * beta * ubar)
    return k_total.tocsr(), f_total
