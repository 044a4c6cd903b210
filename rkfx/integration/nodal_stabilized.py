"""Nodal integration for moving nodes: DNI, SNNI, and the naturally stabilized NSNI (eqs. 6.50-6.79).

Each node L integrates over a cell Omega_L of its volume V_L. Under large motion conforming
cells (SCNI) cannot be kept, so the cells here are squares of area V_L centred on the current
node position: they overlap and leave gaps (non-conforming, Fig. 6.3b).

* DNI: direct gradients at the nodes (6.50-6.51); spurious low-energy modes.
* SNNI: gradients smoothed over each square by the divergence theorem (6.68), one point at
  the middle of each side. On non-conforming cells the integration constraint (6.66) fails,
  and with it the linear patch test.
* VC: the test-function gradients corrected by a constant per node (6.69-6.71) so that
  ``sum_L V_L grad^c N_I(x_L) = int_Gamma N_I n``, which restores the patch test (the trial
  gradients stay as they are).
* Natural stabilization: the Taylor expansion of the gradients about x_L (6.52, 6.59) adds
  ``m_Lx B_I,x^T D B_,x + m_Ly B_I,y^T D B_,y`` with the second moments m_Lx, m_Ly of Omega_L
  (6.55-6.56; V_L^2 / 12 for a square). The gradients of the gradient rows (6.72-6.75) are the
  derivatives of the implicit gradients N^∇_I (6.29) at x_L, which stand for N_I,ij at about
  the cost of a direct gradient and vanish on linear fields, so the patch test is kept. (The
  implicit gradient of the *nodal samples* of B~ would not do: it vanishes on exactly the modes
  that are zero at the nodes, the ones stabilization is for; ``tests/test_nodal_stabilized.py``.)

``nsni`` is the seed's final form (6.78-6.79): SNNI, corrected test gradients, stabilization.
"""
from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial import cKDTree

from rkfx.approximation.semi_lagrangian import MovingRK, evaluate_moving
from rkfx.approximation.sparse_rows import SparseRows, combine_rows, gathered_rows
from rkfx.errors import InputError

# name: (smoothed gradients, natural stabilization, corrected test gradients)
RULES = {
    "dni": (False, False, False),
    "dni-ns": (False, True, False),
    "snni": (True, False, False),
    "snni-vc": (True, False, True),
    "nsni-novc": (True, True, False),
    "nsni": (True, True, True),
}

# Two-point Gauss rule on [-1, 1]: integrates the linear N_I n along a straight side exactly.
_GAUSS = np.array([-1.0, 1.0]) / np.sqrt(3.0)


@dataclass(frozen=True)
class NodalCells:
    """Square non-conforming smoothing cells, one per node.

    Attributes:
        center: Current node positions, shape ``(num_nodes, 2)`` [m].
        volume: Cell areas V_L, shape ``(num_nodes,)`` [m^2].
    """

    center: np.ndarray
    volume: np.ndarray

    @property
    def side(self) -> np.ndarray:
        return np.sqrt(self.volume)

    @property
    def second_moments(self) -> np.ndarray:
        """m_Lx, m_Ly of each square (6.55-6.56), shape ``(num_nodes, 2)`` [m^4]."""
        m = self.volume ** 2 / 12.0
        return np.stack([m, m], axis=1)

    @property
    def reach(self) -> float:
        """Farthest smoothing point from its node: the largest half side [m]."""
        return float(0.5 * self.side.max())

    def smoothing_points(self) -> tuple[np.ndarray, np.ndarray]:
        """The midpoint of each side: points ``(4 n, 2)`` [m] and outward normal times side ``(4 n, 2)`` [m].

        One point per side integrates N_I n exactly for the linear fields that the shape
        functions reproduce, which is what (6.66) asks of the smoothed gradients.
        """
        normals = np.array([[0.0, -1.0], [1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
        points = self.center[:, None, :] + 0.5 * self.side[:, None, None] * normals[None]
        weight = normals[None] * self.side[:, None, None]
        return points.reshape(-1, 2), weight.reshape(-1, 2)


def nodal_cells(x: np.ndarray, volume: np.ndarray) -> NodalCells:
    """Square cells of areas ``volume`` [m^2] centred on the nodes ``x`` [m]."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    volume = np.ascontiguousarray(np.broadcast_to(np.asarray(volume, dtype=np.float64), (len(x),)))
    bad = np.flatnonzero(~(volume > 0))
    if bad.size:
        raise InputError(f"node {bad[0]} has cell volume {volume[bad[0]]}; nodal volumes must be positive")
    return NodalCells(x, volume)


@dataclass(frozen=True)
class BoundaryRule:
    """Points on the domain boundary Gamma with outward normal times weight, for int_Gamma N_I n.

    Attributes:
        points: Shape ``(num_points, 2)`` [m].
        normal_length: Outward unit normal times quadrature weight, shape ``(num_points, 2)`` [m].
        owner: A node within ``reach`` of each point (whose candidate row finds its neighbours).
    """

    points: np.ndarray
    normal_length: np.ndarray
    owner: np.ndarray


def boundary_rule(x: np.ndarray, segments: np.ndarray) -> BoundaryRule:
    """Two Gauss points on each boundary segment between nodes.

    Args:
        x: Current node positions, shape ``(num_nodes, 2)`` [m].
        segments: Node pairs ``(a, b)`` along the boundary, shape ``(num_segments, 2)``, oriented
            with the domain on the left (counter-clockwise around the outer boundary).
    """
    segments = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    pa, pb = x[segments[:, 0]], x[segments[:, 1]]
    edge = pb - pa
    normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)  # outward for the domain on the left, |n| = length
    t = 0.5 * (1.0 + _GAUSS)
    points = pa[:, None, :] + t[None, :, None] * edge[:, None, :]
    nl = np.broadcast_to(0.5 * normal[:, None, :], points.shape)
    owner = np.where(t[None, :] < 0.5, segments[:, :1], segments[:, 1:])
    return BoundaryRule(points.reshape(-1, 2), np.ascontiguousarray(nl.reshape(-1, 2)), owner.ravel())


@dataclass(frozen=True)
class NodalIntegration:
    """The rows a nodal-integration form needs, with the nodes as integration points L.

    Attributes:
        weights: V_L, shape ``(num_nodes,)`` [m^2].
        values: Rows N_I(x_L).
        trial: Gradient rows of the trial functions at x_L [1/m] (direct or smoothed).
        test: Gradient rows of the test functions (the trial rows, or VC-corrected ones).
        moments: m_Lx, m_Ly, shape ``(num_nodes, 2)`` [m^4], or ``None`` without stabilization.
        trial_x: Rows of d/dx of the trial gradient rows at x_L [1/m^2], or ``None``.
        trial_y: Rows of d/dy of the trial gradient rows at x_L [1/m^2], or ``None``.
        name: The rule (a key of ``RULES``).
    """

    weights: np.ndarray
    values: SparseRows
    trial: SparseRows
    test: SparseRows
    moments: np.ndarray | None
    trial_x: SparseRows | None
    trial_y: SparseRows | None
    name: str

    def columns(self) -> np.ndarray:
        """The nodes that any of the rows touches, increasing."""
        rows = [r.indices for r in (self.values, self.trial, self.test, self.trial_x, self.trial_y) if r is not None]
        return np.unique(np.concatenate(rows))

    def localized(self, nodes: np.ndarray) -> "NodalIntegration":
        """The same rows over the local nodes ``nodes`` (an MPI rank's: indices into the whole
        node set, covering ``columns()``), column j standing for node ``nodes[j]``."""
        nodes = np.asarray(nodes, np.int64)
        column = np.full(self.values.num_cols, -1, np.int64)
        column[nodes] = np.arange(len(nodes))
        if np.any(column[self.columns()] < 0):
            raise InputError("localized: the local nodes do not cover every column of the rule's rows")
        rows = {name: None if (r := getattr(self, name)) is None
                else gathered_rows(r, np.arange(r.num_rows), column, len(nodes))
                for name in ("values", "trial", "test", "trial_x", "trial_y")}
        return NodalIntegration(self.weights, moments=self.moments, name=self.name, **rows)


def smoothed_gradients(rk: MovingRK, cells: NodalCells, nodes: np.ndarray | None = None) -> SparseRows:
    """SNNI gradients (6.68): ``(1 / V_L) sum_q N_I(y_q) n_q w_q`` over the sides of each square
    (of every node, or of ``nodes`` only, one row each in their order)."""
    if cells.reach > rk.reach * (1 + 1e-12):
        raise InputError(f"the smoothing cells reach {cells.reach:.4g} from their nodes but the approximation "
                         f"was built with reach = {rk.reach:.4g}; pass reach >= the largest half-diagonal")
    if nodes is not None:
        cells = NodalCells(cells.center[nodes], cells.volume[nodes])
    points, nl = cells.smoothing_points()
    n = len(cells.volume)
    owner = np.repeat(np.arange(n) if nodes is None else nodes, 4)
    values = evaluate_moving(rk, points, owner)
    weight = nl / np.repeat(cells.volume, 4)[:, None]
    return combine_rows(values, 4 * np.arange(n + 1), np.arange(4 * n), weight)


def _column_sums(rows: SparseRows, weights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``sum_L w_L row_L`` of every column, shape ``(num_cols, num_components)``, and
    ``sum_L w_L [I in row L]`` of every column I (sums in entry order)."""
    sums = np.zeros((rows.num_cols, rows.data.shape[1]))
    covered = np.zeros(rows.num_cols)
    _add_columns(rows.indptr, rows.indices, np.ascontiguousarray(rows.data), np.asarray(weights, float), sums, covered)
    return sums, covered


@numba.njit(cache=True)
def _add_columns(indptr, indices, data, weights, sums, covered):
    """sums[I] += w_L row_L[I] and covered[I] += w_L over the rows L, in entry order."""
    for r in range(len(indptr) - 1):
        w = weights[r]
        for e in range(indptr[r], indptr[r + 1]):
            i = indices[e]
            for k in range(data.shape[1]):
                sums[i, k] += data[e, k] * w
            covered[i] += w


def vc_correction(gradients: SparseRows, weights: np.ndarray, boundary_values: SparseRows,
                  boundary: BoundaryRule) -> np.ndarray:
    """The constants zeta_I of (6.71), shape ``(num_nodes, 2)`` [1/m].

    With R_I = 1 on the rows where N_I has a gradient entry, the corrected gradients
    ``grad N_I + zeta_I`` meet ``sum_L w_L grad^c N_I(x_L) = sum_b N_I(x_b) n_b w_b`` (6.66) exactly.
    """
    n = gradients.num_cols
    domain, covered = _column_sums(gradients, weights)
    gamma = boundary_values.matrix().T @ boundary.normal_length
    zeta = np.zeros((n, 2))
    hit = covered > 0
    zeta[hit] = (gamma[hit] - domain[hit]) / covered[hit, None]
    return zeta


def corrected(gradients: SparseRows, zeta: np.ndarray) -> SparseRows:
    """Gradient rows with zeta_I added to every entry of node I (6.69)."""
    data = np.empty_like(gradients.data)
    _plus_columns(np.ascontiguousarray(gradients.data), gradients.indices, np.ascontiguousarray(zeta, float), data)
    return SparseRows(gradients.indptr, gradients.indices, data, gradients.num_cols)


@numba.njit(parallel=True, cache=True)
def _plus_columns(data, indices, zeta, out):
    """out[e] = data[e] + zeta[indices[e]] for every entry e."""
    for e in numba.prange(len(indices)):
        for k in range(data.shape[1]):
            out[e, k] = data[e, k] + zeta[indices[e], k]


def second_gradient_rows(rk: MovingRK, nodes: np.ndarray | None = None) -> tuple[SparseRows, SparseRows]:
    """Rows [N_I,xx, N_I,yx] and [N_I,xy, N_I,yy] at the nodes (or at ``nodes`` only): the
    derivatives of the implicit gradients (``evaluate_moving(second=True)``), the x- and
    y-derivatives of the gradient rows."""
    s = evaluate_moving(rk, second=True) if nodes is None else evaluate_moving(rk, rk.x[nodes], nodes, second=True)
    # entries [N, gx, gy, gx_x, gx_y, gy_x, gy_y]
    dx = SparseRows(s.indptr, s.indices, np.ascontiguousarray(s.data[:, [3, 5]]), s.num_cols)
    dy = SparseRows(s.indptr, s.indices, np.ascontiguousarray(s.data[:, [4, 6]]), s.num_cols)
    return dx, dy


def nodal_integration(rk: MovingRK, cells: NodalCells, boundary: BoundaryRule | None = None,
                      rule: str = "nsni", points: np.ndarray | None = None) -> NodalIntegration:
    """The rows of one nodal integration rule in the current configuration.

    Args:
        rk: The moving approximation; its ``reach`` must cover the cells (``cells.reach``).
        cells: The nodes' cells (centres = ``rk.x``).
        boundary: The domain boundary, needed by the corrected rules (``snni-vc``, ``nsni``).
        rule: One of ``RULES``.
        points: Integrate over the cells of these nodes only (an MPI rank's own nodes, say;
            increasing): the rule's rows at them, equal bit for bit to the whole rule's rows
            there. With the correction, the gradients are also evaluated at every node whose
            rows may reach the points' columns, so that their column sums (6.71) hold every
            term of the whole rule's, in its order. ``None``: every node.
    """
    if rule not in RULES:
        raise InputError(f"unknown nodal integration rule {rule!r}; choose one of {', '.join(RULES)}")
    smoothed, stabilized, correct = RULES[rule]
    if correct and boundary is None:
        raise InputError(f"rule {rule!r} corrects the test gradients against int_Gamma N n: pass the boundary")
    if points is not None:
        points = np.asarray(points, dtype=np.int64)
        n = rk.num_nodes
        if points.ndim != 1 or np.any(np.diff(points) <= 0) or (points.size and (points[0] < 0 or points[-1] >= n)):
            raise InputError(f"points must be increasing node indices in [0, {n}): {points.size} given, out of "
                             "order or range")
    values, trial = _gradient_rows(rk, cells, smoothed, points)
    test = trial
    if correct:
        gamma = evaluate_moving(rk, boundary.points, boundary.owner)
        if points is None:
            zeta = vc_correction(trial, cells.volume, gamma, boundary)
        else:
            around = _reaching(rk, cells, trial.indices)
            ring = _gradient_rows(rk, cells, smoothed, around, values=False)[1]
            zeta = vc_correction(ring, cells.volume[around], gamma, boundary)
        test = corrected(trial, zeta)
    moments = trial_x = trial_y = None
    if stabilized:
        trial_x, trial_y = second_gradient_rows(rk, points)
        moments = cells.second_moments if points is None else cells.second_moments[points]
    weights = cells.volume if points is None else cells.volume[points]
    return NodalIntegration(weights, values, trial, test, moments, trial_x, trial_y, rule)


def _gradient_rows(rk: MovingRK, cells: NodalCells, smoothed: bool, nodes: np.ndarray | None,
                   values: bool = True) -> tuple[SparseRows | None, SparseRows]:
    """Value rows at the nodes (``None`` unless ``values``; the direct gradients bring them
    anyway) and trial gradient rows (smoothed or direct) of their cells, at ``nodes`` (every
    node when ``None``)."""
    at = () if nodes is None else (rk.x[nodes], nodes)
    if smoothed:
        return evaluate_moving(rk, *at) if values else None, smoothed_gradients(rk, cells, nodes)
    rows = evaluate_moving(rk, *at, gradients=True)
    return rows.component(0), SparseRows(rows.indptr, rows.indices, np.ascontiguousarray(rows.data[:, 1:]),
                                         rows.num_cols)


def _reaching(rk: MovingRK, cells: NodalCells, columns: np.ndarray) -> np.ndarray:
    """The nodes (increasing) whose cells' evaluation points may lie in the support of any of
    ``columns``: those within a_J plus the cells' reach of a node J of them."""
    columns = np.unique(columns)
    radius = (rk.support[columns] + cells.reach) * (1.0 + 1e-12)
    found = cKDTree(rk.x).query_ball_point(rk.x[columns], radius, return_sorted=False)
    return np.unique(np.concatenate([np.asarray(f, np.int64) for f in found] + [np.zeros(0, np.int64)]))
