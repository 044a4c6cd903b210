"""The quasi-static damage bar: the RK strip of seed 4.3.1 and its damage points as a model.

A bar [0, L] x [0, H] is a strip of two rows of n nodes (H = h = L / (n - 1)) with thickness
A / H, in plane stress with nu = 0; linear RK basis, cubic B-spline kernel. ``strip`` integrates
it by SCNI (smeared strains at the nodes, Voronoi grid cells or median-dual cells),
``gauss_strip`` by 8 x 2 Gauss points per background cell with direct gradients. Essential
conditions are collocation (transformation) rows: u_x = 0 and u_y = 0 at the left nodes, u_x =
u_T and u_y = 0 at the right ones, so G d = u_T g^.

``DamageBarModel`` is the model of ``rkfx.solvers.quasi_static`` with the tip displacement u_T
as load factor: r(d) = B^T (V sigma(B d)) with trial damage from the committed state
(``rkfx.fracture.damage.update``), K its consistent tangent, the reaction F = t sum mu_right. What every
quasi-static damage-point model shares (trial and commit, the loading tolerance per control
mode, the damage growth and the dissipation of a trial) is ``DamageHistory``.
"""
from dataclasses import dataclass, fields

import numpy as np
import scipy.sparse as sp

from rkfx.fracture import damage as dm
from rkfx.assembly.boundary import transformation_constraints
from rkfx.conditions import Displacement
from rkfx.errors import InputError
from rkfx.geometry.grid_cells import grid_domains
from rkfx.linalg.linear_solver import linear_solver
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.assembly.operators import block_diagonal, strain_matrix
from rkfx.geometry.particles import Particles, structured
from rkfx.integration.quadrature import smoothed_gradients
from rkfx.approximation.shape_functions import RKApproximation, evaluate, rk_approximation
from rkfx.solvers.fields import single
from rkfx.solvers.model import Constraints
from rkfx.solvers.quasi_static import DISPLACEMENT, DISSIPATION
from rkfx.approximation.sparse_rows import SparseRows

CELLS = ("voronoi", "median-dual")
GAUSS_ALONG, GAUSS_ACROSS = 8, 2
TANGENT_FLOOR = 1e-8  # lower bound of 1 - D in the Newton matrix only (failed points)
# Loading tolerance of the damage tangent (``rkfx.fracture.damage.update``) per control mode: a point
# within it of its threshold softens in the tangent, so that Newton's first prediction of a
# dissipation-controlled step follows the softening branch.
LOADING_TOLERANCE = {DISPLACEMENT: 1e-9, DISSIPATION: 1e-3}


# --------------------------------------------------------------------------- discretization


@dataclass(frozen=True)
class Strip:
    """The 2-D bar: particles, RK approximation, an integration rule and the constraints.

    Attributes:
        p: Particles (two rows of nodes).
        rk: RK approximation.
        b: Strain rows (eps_xx, eps_yy, gamma_xy) per integration point, shape ``(3 m, 2 n)``.
        points: Integration points (the nodes for SCNI), shape ``(m, 2)``.
        volume: Weights V_L, shape ``(m,)`` [area per unit thickness].
        extent: x-range of each point's cell, shape ``(m, 2)``.
        geometry: Cell geometry of the SCNI cells (for A_L), or ``None`` for Gauss points.
        g: Constraint rows, shape ``(k, 2 n)``; g_unit: their values at u_T = 1, shape ``(k,)``.
        right: Constraint rows of u_x on the right end (their multipliers sum to the force).
        H: Height [length]; thickness: A / H.
    """

    p: Particles
    rk: RKApproximation
    b: sp.csr_matrix
    points: np.ndarray
    volume: np.ndarray
    extent: np.ndarray
    geometry: dm.CellGeometry | None
    g: sp.csr_matrix
    g_unit: np.ndarray
    right: np.ndarray
    H: float
    thickness: float


def strip(L: float, A: float, n: int, cells: str = "voronoi", support_factor: float = 1.5) -> Strip:
    """The SCNI discretization of the bar with ``n`` nodes along the axis."""
    h = L / (n - 1)
    p = structured(L, h, n, 2)
    rk = rk_approximation(p.x, p.spacing, support_factor)
    if cells == "voronoi":
        domains = grid_domains(np.linspace(0.0, L, n), np.array([0.0, h]))  # the node order of structured
        geometry = dm.cell_geometry(domains)
    elif cells == "median-dual":
        domains = nodal_domains(p)
        geometry = dm.cell_geometry(p)
    else:
        raise InputError(f"unknown cells {cells!r}; choose from {', '.join(CELLS)}")
    grad = smoothed_gradients(p, rk, domains, subcells=False).cell
    lo, hi = np.full(p.num_nodes, np.inf), np.full(p.num_nodes, -np.inf)
    np.minimum.at(lo, geometry.node, geometry.vertices[:, :, 0].min(axis=1))
    np.maximum.at(hi, geometry.node, geometry.vertices[:, :, 0].max(axis=1))
    return _with_constraints(p, rk, strain_matrix(grad).tocsr(), p.x, domains.area, np.c_[lo, hi], geometry, h, A)


def gauss_strip(L: float, A: float, n: int, support_factor: float = 1.5) -> Strip:
    """The same bar integrated by Gauss points on the background cells [x_i, x_i+1] x [0, H]
    (8 along the axis x 2 across), with direct gradients of the RK shape functions."""
    h = L / (n - 1)
    p = structured(L, h, n, 2)
    rk = rk_approximation(p.x, p.spacing, support_factor)
    s1, w1 = np.polynomial.legendre.leggauss(GAUSS_ALONG)
    s2, w2 = np.polynomial.legendre.leggauss(GAUSS_ACROSS)
    x0 = np.linspace(0.0, L, n)[:-1]
    px = (x0[:, None, None] + 0.5 * h * (1 + s1)[None, :, None]) + 0 * s2[None, None, :]
    py = np.broadcast_to(0.5 * h * (1 + s2)[None, None, :], px.shape)
    pts = np.column_stack([px.ravel(), py.ravel()])
    weights = np.broadcast_to(0.25 * h * h * w1[None, :, None] * w2[None, None, :], px.shape).ravel()
    rows = evaluate(rk, pts, gradients=True)
    grad = SparseRows(rows.indptr, rows.indices, rows.data[:, 1:], rows.num_cols)
    cell = np.repeat(x0, GAUSS_ALONG * GAUSS_ACROSS)
    return _with_constraints(p, rk, strain_matrix(grad).tocsr(), pts, np.ascontiguousarray(weights),
                             np.c_[cell, cell + h], None, h, A)


def _with_constraints(p, rk, b, points, volume, extent, geometry, h, A) -> Strip:
    bcs = [Displacement("right", 1.0, (0,)), Displacement("left", 0.0, (0,)),
           Displacement("left", 0.0, (1,)), Displacement("right", 0.0, (1,))]
    g, g_unit = transformation_constraints(p, rk, bcs)
    right = np.arange(len(p.boundary_nodes("right")))  # the first condition's rows
    return Strip(p, rk, b, points, volume, extent, geometry, g, g_unit, right, h, A / h)


def elastic_limit(s: Strip, model: dm.DamageModel, comm=None) -> float:
    """Tip displacement at which the first point reaches its damage threshold (elastic solve)."""
    state = dm.initial_state(model)
    upd = dm.update(model, state, np.zeros((len(model.volume), 3)))
    k = s.b.T @ block_diagonal(model.volume[:, None, None] * upd.tangent) @ s.b
    nd = s.b.shape[1]
    ls = linear_solver(sp.bmat([[k, -s.g.T], [s.g, None]], format="csr"), comm)
    try:
        x = ls.solve(np.r_[np.zeros(nd), s.g_unit])
    finally:
        ls.destroy()
    eq = dm.equivalent_strain((s.b @ x[:nd]).reshape(-1, 3), model.material.nu, model.material.plane)
    return float(np.min(model.kappa0[eq > 0] / eq[eq > 0]))


# --------------------------------------------------------------------------- the model


class DamageHistory:
    """Trial and commit of the damage points of a quasi-static model.

    ``update(strain)`` evaluates the damage law from the committed state with the loading
    tolerance of the current control mode and keeps the result as the trial (``trial``,
    ``strain``); ``commit`` makes it the committed state (``committed``). Gives the optional
    methods of ``rkfx.solvers.quasi_static``: ``set_control``, ``history_increment`` (largest
    damage growth) and ``dissipation``, and ``state``/``restore`` for checkpoints.

    Attributes:
        points: The damage points.
        committed: Committed state; trial: update of the last residual, or ``None``.
        strain: Strains of the last residual, shape ``(m, 3)``.
    """

    def _start_history(self, points: dm.DamageModel) -> None:
        self.points = points
        self.committed = dm.initial_state(points)
        self.trial: dm.DamageUpdate | None = None
        self.strain = np.zeros((points.num_points, 3))
        self.loading_tolerance = LOADING_TOLERANCE[DISPLACEMENT]

    def update(self, strain: np.ndarray) -> dm.DamageUpdate:
        """The trial response to ``strain``, shape ``(m, 3)``, from the committed state."""
        self.strain = strain
        self.trial = dm.update(self.points, self.committed, strain, tangent_floor=TANGENT_FLOOR,
                               loading_tolerance=self.loading_tolerance)
        return self.trial

    def set_control(self, mode: str) -> None:
        self.loading_tolerance = LOADING_TOLERANCE[mode]

    def history_increment(self) -> float:
        return float(np.max(self.trial.state.damage - self.committed.damage))

    def dissipation(self) -> float:
        return self.trial.dissipation

    def commit(self) -> None:
        self.committed = self.trial.state

    def state(self) -> dict[str, np.ndarray]:
        return {f.name: getattr(self.committed, f.name) for f in fields(dm.DamageState)}

    def restore(self, arrays) -> None:
        self.committed = dm.DamageState(**{f.name: np.array(arrays[f.name]) for f in fields(dm.DamageState)})

    def mass(self) -> None:
        return None

    def capacity(self, dt: float) -> None:
        return None


class _FixedPattern:
    """K = B^T blockdiag(V_q T_q) B in a fixed CSR pattern from dense blocks per point (a
    point's three strain rows touch few columns): one batched matmul and one bincount per
    Newton iteration instead of a chain of sparse products."""

    def __init__(self, b: sp.csr_matrix):
        b = b.tocsr()
        n = b.shape[1]
        m = b.shape[0] // 3
        cols = [np.unique(b.indices[b.indptr[3 * q]:b.indptr[3 * q + 3]]) for q in range(m)]
        width = max(len(c) for c in cols)
        self.cols = np.zeros((m, width), np.int64)
        self.local = np.zeros((m, 3, width))
        for q, c in enumerate(cols):
            self.cols[q, :len(c)] = c
            for a in range(3):
                lo, hi = b.indptr[3 * q + a], b.indptr[3 * q + a + 1]
                np.add.at(self.local[q, a], np.searchsorted(c, b.indices[lo:hi]), b.data[lo:hi])
        rows = np.repeat(self.cols, width, axis=1).ravel()
        cols_ = np.tile(self.cols, (1, width)).ravel()
        unique, self.slot = np.unique(rows * n + cols_, return_inverse=True)
        self.indices = (unique % n).astype(np.int32)
        self.indptr = np.r_[0, np.cumsum(np.bincount(unique // n, minlength=n))].astype(np.int32)
        self.n, self.nnz = n, len(unique)

    def __call__(self, weighted_tangent: np.ndarray) -> sp.csr_matrix:
        """K for blocks V_q T_q, shape ``(m, 3, 3)``."""
        k_loc = np.matmul(self.local.transpose(0, 2, 1), np.matmul(weighted_tangent, self.local))
        data = np.bincount(self.slot, k_loc.ravel(), self.nnz)
        return sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n, self.n))


class DamageBarModel(DamageHistory):
    """The strip ``s`` with the damage points ``points`` (one per row triple of ``s.b``) as a
    quasi-static model; the load factor is the tip displacement u_T (module docstring).

    Attributes:
        strip: The discretization.
        layout: One field u (2 components per node, time order 0).
        force_scale: f_t H, a nodal force per unit thickness (Newton's tolerance scale).
        reaction_weights: The thickness on the right-end u_x rows: F = t sum mu_right.
    """

    linear = False

    def __init__(self, s: Strip, points: dm.DamageModel):
        if s.b.shape[0] != 3 * points.num_points:
            raise InputError(f"the strip has {s.b.shape[0] // 3} integration points but {points.num_points} "
                             "damage points were given; build the damage model on s.volume")
        self.strip = s
        self._start_history(points)
        self.layout = single("u", 2, 0, s.p.num_nodes)
        self.force_scale = points.material.ft * s.H
        self.reaction_weights = np.zeros(s.g.shape[0])
        self.reaction_weights[s.right] = s.thickness
        self._bt = s.b.T.tocsr()
        self._stiffness = _FixedPattern(s.b)

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        upd = self.update((self.strip.b @ x).reshape(-1, 3))
        return self._bt @ (self.points.volume[:, None] * upd.stress).ravel()

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        return self._stiffness(self.points.volume[:, None, None] * self.trial.tangent)

    def constraints(self, t: float) -> Constraints:
        return Constraints(self.strip.g, t * self.strip.g_unit, self.strip.g_unit)


class LoadCurve:
    """A recorder of ``rkfx.solvers.quasi_static.march`` for a bar of damage points: per
    accepted step (starting at 0) the tip displacement, force, crack opening w = int D eps_xx dx
    / H (4.13), dissipated and stored elastic energy (times the thickness), and the stress and
    damage at the first step reaching each of ``snapshots``.

    Args:
        model: A ``DamageHistory`` model (its committed state and last strain and stress).
        thickness, height: Out-of-plane thickness and height H of the bar [length].
        snapshots: Tip displacements of the snapshots.

    Attributes:
        snapshots: Requested u_T -> (stress (m, 3), damage (m,), u_T reached).
    """

    KEYS = ("u", "force", "cod", "dissipated", "elastic")

    def __init__(self, model: DamageHistory, thickness: float, height: float, snapshots=()):
        self.model, self.thickness, self.height = model, float(thickness), float(height)
        self.curve = {key: [0.0] for key in self.KEYS}
        self.pending = sorted(float(u) for u in snapshots)
        self.snapshots: dict[float, tuple[np.ndarray, np.ndarray, float]] = {}

    def record(self, s) -> None:
        st, eps, sig, v = self.model.committed, self.model.strain, self.model.trial.stress, self.model.points.volume
        for key, value in zip(self.KEYS, (s.lam, s.force, float(np.sum(st.damage * eps[:, 0] * v)) / self.height,
                                          float(st.dissipated.sum()) * self.thickness,
                                          0.5 * float(np.sum(v[:, None] * sig * eps)) * self.thickness)):
            self.curve[key].append(value)
        while self.pending and s.lam >= self.pending[0] * (1 - 1e-12):
            self.snapshots[self.pending.pop(0)] = (sig.copy(), st.damage.copy(), s.lam)

    def series(self) -> dict[str, np.ndarray]:
        """The curves as arrays."""
        return {key: np.array(val) for key, val in self.curve.items()}

    def arrays(self) -> dict[str, np.ndarray]:
        done = sorted(self.snapshots)
        m = self.model.points.num_points
        return {**self.series(), "pending": np.array(self.pending), "snap_u": np.array(done),
                "snap_stress": np.array([self.snapshots[u][0] for u in done]).reshape(-1, m, 3),
                "snap_damage": np.array([self.snapshots[u][1] for u in done]).reshape(-1, m),
                "snap_reached": np.array([self.snapshots[u][2] for u in done])}

    def restore(self, arrays) -> None:
        self.curve = {key: [float(v) for v in arrays[key]] for key in self.KEYS}
        self.pending = [float(u) for u in arrays["pending"]]
        self.snapshots = {float(u): (arrays["snap_stress"][i].copy(), arrays["snap_damage"][i].copy(),
                                     float(arrays["snap_reached"][i])) for i, u in enumerate(arrays["snap_u"])}
