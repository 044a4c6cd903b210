"""Equal-order RK u-p poroelasticity (chapter 3): nodal integration, fluid pressure projection,
monolithic backward Euler.

Governing equations (3.1)-(3.10): tensile effective stress and compressive pore pressure
positive, total stress sigma'' - alpha p I; storage alpha div(du/dt) + S dp/dt - div(k grad p) = 0
with S = 1/Q and k the mobility k_h / gamma_f. Displacement and pressure share the RK shape
functions (3.26). Integration variants:

=========  ======================================  ============================
variant    domain integration                      pressure stabilization
=========  ======================================  ============================
ni         direct nodal integration (DNI)          none
scni       SCNI + MSCNI subcells, eps_p = 1 (3.56)  none
ni+fpp     DNI                                     FPP (3.49)-(3.52)
scni+fpp   SCNI + MSCNI subcells (3.56)-(3.59)     FPP on the same cells (3.60)
=========  ======================================  ============================

The same model runs in 3-D on ``rkfx.geometry.particles3d.Particles3D``: the cells of
``rkfx.geometry.nodal_cells3d``, the rules of ``rkfx.integration.nodal_rules3d`` (MSCNI with
direct gradients at the stabilization points, the seed's 13-point rule on box cells) and the
characteristic length h = V_L^(1/3) in eps_f.

Each step solves J X = R of eqs. (3.50)-(3.51) with the essential conditions imposed at the
boundary nodes by collocation (the transformation method; see ``rkfx.assembly.boundary``), which keeps
prescribed pressures exact however small the time step.

The projection term of eq. (3.49) is applied to the pressure *rate*,
int eps_f (psi - Pi psi)(dp/dt - Pi dp/dt), as in White & Borja (2008): eps_f of eq. (3.53)
is a compressibility [1/Pa] (it scales with 1/M'), so only the rate form is dimensionally
consistent with eq. (3.2). After backward Euler and multiplication by Delta t (3.40) the
stabilization enters J as -S and the right-hand side as -S P_n, like the storage matrix
K_pp^(S), rather than as -Delta t S of eq. (3.51), which would vanish in the undrained limit
Delta t -> 0 that the stabilization is for.
"""
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from rkfx.assembly.boundary import (BC_METHODS, BoundaryQuadrature, Collocation, boundary_quadrature, collocation,
                                   nitsche_pressure_coupling, nitsche_rows, part_points, traction_values)
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.conditions import Displacement, Flux, Pressure, Traction, values
from rkfx.errors import InputError
from rkfx.geometry.cells import cell_measures, nodal_cells
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.assembly.galerkin import mixed_form
from rkfx.assembly.operators import laplacian, mass, stiffness
from rkfx.geometry.particles import Particles
from rkfx.linalg.linear_solver import DisplacementSplit, Factorizations
from rkfx.integration.nodal_rules3d import dni_3d, mscni_rules_3d, scni_3d
from rkfx.integration.quadrature import Quadrature, dni, mscni_rules, scni, selected_cells
from rkfx.approximation.shape_functions import RKApproximation, evaluate, rk_approximation
from rkfx.parallel.ownership import numbering
from rkfx.parallel.partition import rcb
from rkfx.parallel.unknowns import LocalUnknowns, local_unknowns, touched_nodes
from rkfx.solvers.fields import layout
from rkfx.solvers.integrate import integrate
from rkfx.solvers.model import Constraints, PerStepSize, Stateless
from rkfx.solvers.newmark import backward_euler
from rkfx.approximation.sparse_rows import SparseRows, combine_rows

VARIANTS = ("ni", "scni", "ni+fpp", "scni+fpp")
SOLVER_CHOICES = ("auto", "mumps", "fieldsplit")

# solver="auto" factorizes by MUMPS up to this many unknowns and takes the Schur field split
# (GMRES, GAMG on u, fixed stress) above, for 2-D Nitsche displacement conditions. Measured on
# Mandel (bench/biot_solvers.py, five steps of one size, 2026-12-05), MUMPS / field split:
# 49k unknowns 2.1 / 2.4 s, 0.93 / 0.62 GB; 195k 11.6 / 10.1 s, 3.5 / 1.8 GB; 383k 31.1 / 20.9 s,
# 7.1 / 3.2 GB; at 773k MUMPS ran out of memory. Below the switch MUMPS is as fast and its later
# solves of the same step size cost little; above it its fill takes more than twice the memory.
# The transformation method's collocated conditions and 3-D stay direct (on the 3-D sphere of
# rkfx.cases.cryer the split took 130 GMRES iterations per step, 14 times MUMPS's time).
U_P_AUTO_DIRECT_MAX_DOFS = 300_000


def choose_solver(solver: str, n_dofs: int, bc_method: str, dim: int) -> str:
    """The linear solver of the u-p steps that ``solver="auto"`` stands for (see
    ``U_P_AUTO_DIRECT_MAX_DOFS``); any other choice is returned as it is."""
    if solver not in SOLVER_CHOICES:
        raise InputError(f"unknown u-p solver {solver!r}; choose one of {', '.join(SOLVER_CHOICES)}")
    if solver != "auto":
        return solver
    split = bc_method == "nitsche" and dim == 2 and n_dofs > U_P_AUTO_DIRECT_MAX_DOFS
    return "fieldsplit" if split else "mumps"


@dataclass(frozen=True)
class PoroMaterial:
    """Linear poroelastic solid saturated by one fluid.

    Attributes:
        E: Drained Young's modulus [Pa].
        nu: Drained Poisson's ratio [-].
        k: Mobility k_f = k_h / gamma_f [m^2/(Pa s)].
        alpha: Biot coefficient in (0, 1].
        S: Storage coefficient 1/Q [1/Pa]; 0 for incompressible constituents.
    """

    E: float
    nu: float
    k: float
    alpha: float = 1.0
    S: float = 0.0

    def __post_init__(self):
        ElasticMaterial(self.E, self.nu)  # validates E and nu
        if not (np.isfinite(self.k) and self.k > 0):
            raise InputError(f"mobility k = {self.k!r} must be positive [m^2/(Pa s)] (k_h / gamma_f)")
        if not (0.0 < self.alpha <= 1.0):
            raise InputError(f"Biot coefficient alpha = {self.alpha!r} must lie in (0, 1]")
        if not (np.isfinite(self.S) and self.S >= 0.0):
            raise InputError(f"storage coefficient S = {self.S!r} must be >= 0 [1/Pa] (0: incompressible)")

    @property
    def elastic(self) -> ElasticMaterial:
        return ElasticMaterial(self.E, self.nu)

    @property
    def oedometric_storage_modulus(self) -> float:
        """M' = (K + 4G/3) / ((K + 4G/3) S + alpha^2) of eq. (3.54) [Pa]."""
        kv = self.elastic.constrained_modulus
        return kv / (kv * self.S + self.alpha**2)

    @property
    def consolidation_coefficient(self) -> float:
        """c_v = k M' of eq. (3.54) [m^2/s]."""
        return self.k * self.oedometric_storage_modulus


def fpp_parameter(material: PoroMaterial, dt: float, h: np.ndarray) -> np.ndarray:
    """Stabilization parameter eps_f of the fluid pressure projection, eqs. (3.53)-(3.54).

    eps_f = <1 - 3 r> (1 + tanh(2 - 12 r)) / M' with r = c_v dt / h^2 (after Sun et al. 2013);
    the RK solver and the FEM baseline (``fem_baselines.poroelasticity``) both use it.

    Args:
        material: The poroelastic solid (M' and c_v of eq. 3.54).
        dt: Time step [s].
        h: Characteristic lengths, any shape [m].

    Returns:
        eps_f, shaped like ``h`` [1/Pa].
    """
    r = material.consolidation_coefficient * dt / np.asarray(h, float) ** 2
    return np.maximum(1.0 - 3.0 * r, 0.0) * (1.0 + np.tanh(2.0 - 12.0 * r)) / material.oedometric_storage_modulus


@dataclass(frozen=True)
class BiotOperators:
    """The matrices of eqs. (3.32)-(3.35) and (3.60) for one discretization.

    Attributes:
        Kuu: Solid stiffness, shape ``(g n, g n)`` (g = 2, or 3 in 3-D).
        Kup: Coupling int B^T alpha m N, shape ``(g n, n)``.
        Ks: Compressibility int N^T S N, shape ``(n, n)``.
        Kh: Permeability int grad N^T k grad N, shape ``(n, n)``.
        fpp_rows: Rows N - Pi N on cells (3.61) and subcells (3.62), or empty when unstabilized.
        fpp_weights: Matching weights A_L and eps_p A_C [m^2] (volumes V_L, eps_p V_C in 3-D).
        fpp_node: Node whose eps_f applies to each row.
        h: Characteristic length sqrt(A_L) (3-D: V_L^(1/3)) of each node [m].
    """

    Kuu: sp.csr_matrix
    Kup: sp.csr_matrix
    Ks: sp.csr_matrix
    Kh: sp.csr_matrix
    fpp_rows: list[SparseRows]
    fpp_weights: list[np.ndarray]
    fpp_node: list[np.ndarray]
    h: np.ndarray

    def stabilization(self, eps_f: np.ndarray) -> sp.csr_matrix:
        """S of eq. (3.60) for per-node eps_f, shape ``(n, n)``."""
        n = self.Kh.shape[0]
        total = sp.csr_matrix((n, n))
        for rows, w, node in zip(self.fpp_rows, self.fpp_weights, self.fpp_node):
            r = rows.matrix()
            total = total + r.T @ sp.diags(eps_f[node] * w) @ r
        return total.tocsr()


def divergence_matrix(q: Quadrature) -> sp.csr_matrix:
    """Rows div u^h(x_q) over interleaved displacement coefficients, shape ``(m, g n)``."""
    g = q.gradients
    dim = g.num_components
    row = np.repeat(np.arange(g.num_rows), np.diff(g.indptr))
    col = dim * g.indices.astype(np.int64)
    return sp.csr_matrix((np.concatenate([g.data[:, c] for c in range(dim)]),
                          (np.concatenate([row] * dim), np.concatenate([col + c for c in range(dim)]))),
                         shape=(g.num_rows, dim * g.num_cols))


@dataclass(frozen=True)
class NodalFields:
    """Material fields that vary from particle to particle (e.g. degraded by damage, eq. 5.3-5.8).

    Nodal integration evaluates the u-p forms at the particles; the MSCNI subcell points
    take the values of the particle that owns them. Any field left ``None`` is the
    material's constant.

    Attributes:
        D: Elasticity per particle, shape ``(n, 3, 3)`` [Pa] (``(n, 6, 6)`` in 3-D).
        k: Mobility per particle, isotropic ``(n,)`` or a tensor ``(n, g, g)`` [m^2/(Pa s)].
        alpha: Biot coefficient per particle, shape ``(n,)`` [-].
        S: Storage coefficient per particle, shape ``(n,)`` [1/Pa].
    """

    D: np.ndarray | None = None
    k: np.ndarray | None = None
    alpha: np.ndarray | None = None
    S: np.ndarray | None = None

    def check(self, n: int, dim: int = 2) -> None:
        """Raise if a field does not have one value per particle (in ``dim`` dimensions)."""
        v = 3 if dim == 2 else 6
        for name, shapes in (("D", [(n, v, v)]), ("k", [(n,), (n, dim, dim)]), ("alpha", [(n,)]), ("S", [(n,)])):
            v = getattr(self, name)
            if v is not None and np.shape(v) not in shapes:
                raise InputError(f"nodal field {name} has shape {np.shape(v)}; give one value per particle: "
                                 f"{' or '.join(map(str, shapes))}")


@dataclass(frozen=True)
class BiotIntegration:
    """The integration points of one u-p variant.

    Attributes:
        nodal: The nodal points (SCNI or DNI) of the integrated nodes.
        quads: The quadratures of the value forms (storage, projection): ``[nodal]``, or
            ``[nodal, subcells]`` with the MSCNI value rows N(x_L) - N(x_hat_C) (3.58).
        owners: The particle whose fields apply at each point of each of ``quads``.
        gradient_quads: The quadratures of the grad-grad forms (stiffness, Darcy): ``[nodal]``,
            or MSCNI's (3.56), (3.59) as SCNI and subcell gradients (``mscni_rules``).
        gradient_owners: The particle whose fields apply at each point of each of those.
        nodes: The integrated nodes (ascending).
        subcells: Indices of the integrated subcells, or ``None`` for all of them.
    """

    nodal: Quadrature
    quads: list[Quadrature]
    owners: list[np.ndarray]
    gradient_quads: list[Quadrature]
    gradient_owners: list[np.ndarray]
    nodes: np.ndarray
    subcells: np.ndarray | None

    def at_points(self, value, constant, gradients: bool = False):
        """A per-particle field at the points of every quadrature of the value forms (of the
        grad-grad forms with ``gradients``); ``constant`` where ``value`` is ``None``."""
        owners = self.gradient_owners if gradients else self.owners
        return constant if value is None else [np.asarray(value, float)[o] for o in owners]


def biot_integration(p: Particles, rk: RKApproximation, domains: NodalDomains, variant: str = "scni+fpp",
                     eps_p: float = 1.0, nodes: np.ndarray | None = None) -> BiotIntegration:
    """The integration points of ``variant`` over the domains of ``nodes`` (default all)."""
    if variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}; choose one of {', '.join(VARIANTS)}")
    d = domains
    mine = np.arange(p.num_nodes) if nodes is None else np.asarray(nodes, np.int64)
    if p.x.shape[1] == 3:
        _, sub = selected_cells(d, nodes)
        owner = d.subcell_node[sub]
        if variant.startswith("scni"):
            nodal, rules, values = mscni_rules_3d(p, rk, d, eps_p, nodes=nodes)
            return BiotIntegration(nodal, [nodal, values], [mine, owner], rules, [mine] * (len(rules) - 1) + [owner],
                                   mine, sub)
        nodal = dni_3d(p, rk, d, nodes=nodes)
        return BiotIntegration(nodal, [nodal], [mine], [nodal], [mine], mine, sub)
    if variant.startswith("scni"):
        nodal, rules, values = mscni_rules(p, rk, d, eps_p, nodes=nodes)
        _, sub = selected_cells(d, nodes)
        owner = d.subcell_node[sub]
        return BiotIntegration(nodal, [nodal, values], [mine, owner], rules,
                               [mine] * (len(rules) - 1) + [owner], mine, sub)
    nodal = dni(p, rk, d, nodes=nodes)
    subcells = selected_cells(d, nodes)[1] if nodes is not None else None
    return BiotIntegration(nodal, [nodal], [mine], [nodal], [mine], mine, subcells)


def projection_rows(rk: RKApproximation, domains: NodalDomains, integration: BiotIntegration
                    ) -> tuple[list[SparseRows], list[np.ndarray], list[np.ndarray]]:
    """The rows N - Pi N of the fluid pressure projection on cells (3.61) and, with the MSCNI
    subcells, on subcells (3.62), with their weights and the node whose eps_f applies."""
    d, it = domains, integration
    area, subcell_area = cell_measures(d)  # volumes in 3-D
    n, mine = len(area), it.nodes
    # (3.61): Pi N(x_L) = sum_C N(x_hat_C) A_C / A_L, so the cell rows are N(x_L) - Pi N(x_L).
    sub = np.arange(len(d.subcell_node)) if it.subcells is None else it.subcells
    owner = d.subcell_node[sub]
    at_centroids = evaluate(rk, d.subcell_centroid[sub])
    order = np.argsort(owner, kind="stable")
    counts = np.bincount(owner, minlength=n)[mine]
    ptr = np.r_[0, np.cumsum(counts)]
    cell_rows = combine_rows(at_centroids, ptr, order, -(subcell_area[sub] / area[owner])[order],
                             base=it.nodal.values, base_row=np.arange(len(mine)))
    rows, weights, row_nodes = [cell_rows], [area[mine]], [mine]
    if len(it.quads) > 1:
        # (3.62): Pi N(x_hat_C) = N(x_hat_C): the subcell rows are the MSCNI value rows.
        stab = it.quads[1]
        rows.append(stab.values)
        weights.append(stab.weights)
        row_nodes.append(owner)
    return rows, weights, row_nodes


def biot_operators(p: Particles, rk: RKApproximation, domains: NodalDomains, material: PoroMaterial,
                   variant: str = "scni+fpp", eps_p: float = 1.0, fields: NodalFields | None = None,
                   nodes: np.ndarray | None = None) -> BiotOperators:
    """Assemble the u-p operators of one integration variant.

    Args:
        p, rk, domains: Particles, their RK approximation and nodal domains.
        material: Constant poroelastic properties.
        variant: ``ni``, ``scni``, ``ni+fpp`` or ``scni+fpp``.
        eps_p: MSCNI stabilization factor of the subcell terms (3.56).
        fields: Per-particle material fields overriding the constants.
        nodes: Integrate over the nodal domains of these nodes only (indices, ascending: a
            rank's own nodes); the operators of a partition's parts sum to the whole ones.
    """
    d = domains
    n, dim = p.num_nodes, p.x.shape[1]
    fields = NodalFields() if fields is None else fields
    fields.check(n, dim)
    it = biot_integration(p, rk, d, variant, eps_p, nodes)
    quads, nodal, mine = it.quads, it.nodal, it.nodes
    kuu = stiffness(it.gradient_quads, it.at_points(fields.D, material.elastic.voigt(dim), gradients=True))
    # Coupling (3.57): nodal points only.
    alpha = material.alpha if fields.alpha is None else np.asarray(fields.alpha, float)[mine]
    kup = mixed_form(nodal.gradients, nodal.values, alpha * nodal.weights)
    ks = mass(quads, it.at_points(fields.S, material.S)) if (material.S > 0 or fields.S is not None) \
        else sp.csr_matrix((n, n))
    kh = laplacian(it.gradient_quads, it.at_points(fields.k, material.k, gradients=True))
    rows, weights, row_nodes = projection_rows(rk, d, it) if variant.endswith("+fpp") else ([], [], [])
    # eq. (3.53): h = sqrt(A_I) in 2-D, the cube root of the cell volume in 3-D.
    h = cell_measures(d)[0] ** (1.0 / dim)
    if nodes is not None:  # the other nodes' cells may be partial (domains built around ``nodes``)
        h = np.ones(n)
        h[mine] = cell_measures(d)[0][mine] ** (1.0 / dim)
    return BiotOperators(kuu, kup, ks, kh, rows, weights, row_nodes, h)


# Boundary conditions: the core's vocabulary (``rkfx.conditions``); a traction of the u-p
# model is the total traction (sigma'' - alpha p I) n.
@dataclass
class BiotSolution:
    """Nodal coefficients at the output times and the approximation to evaluate them.

    Attributes:
        rk: The approximation (shared by u and p).
        times: Output times, shape ``(k,)`` [s].
        U: Displacement coefficients, shape ``(k, n, g)`` [m] (g = 2, or 3 in 3-D).
        P: Pressure coefficients, shape ``(k, n)`` [Pa].
        n_dofs: Unknowns per step ((g + 1) n).
        wall_time_s: Assembly plus time stepping [s].
        steps: Number of time steps taken.
        timings: Wall times of the stages [s].
        linear: The linear solver, its ``solves`` and their Krylov ``iterations`` in all
            (1 per direct solve).
    """

    rk: RKApproximation
    times: np.ndarray
    U: np.ndarray
    P: np.ndarray
    n_dofs: int
    wall_time_s: float
    steps: int
    timings: dict[str, float] = field(default_factory=dict)
    linear: dict = field(default_factory=dict)

    def pressure(self, points: np.ndarray) -> np.ndarray:
        """p^h at points for every output time, shape ``(k, m)`` [Pa]."""
        return (evaluate(self.rk, points).matrix() @ self.P.T).T

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """u^h at points for every output time, shape ``(k, m, g)`` [m]."""
        n = evaluate(self.rk, points).matrix()
        return np.stack([(n @ self.U[:, :, c].T).T for c in range(self.U.shape[2])], axis=-1)

    def strain(self, points: np.ndarray) -> np.ndarray:
        """Strain of u^h (direct gradients) at points for every output time, Voigt (xx, yy, 2 xy),
        shape ``(k, m, 3)`` [-]; in 3-D (xx, yy, zz, 2 yz, 2 xz, 2 xy), shape ``(k, m, 6)``."""
        rows = evaluate(self.rk, points, gradients=True)
        g = self.U.shape[2]
        du = [[(rows.matrix(1 + j) @ self.U[:, :, i].T).T for j in range(g)] for i in range(g)]  # du_i/dx_j
        if g == 2:
            return np.stack([du[0][0], du[1][1], du[0][1] + du[1][0]], axis=-1)
        return np.stack([du[0][0], du[1][1], du[2][2], du[1][2] + du[2][1], du[0][2] + du[2][0],
                         du[0][1] + du[1][0]], axis=-1)


class BiotModel(Stateless):
    """The u-p equations (3.32)-(3.37) as a model for the steppers (``rkfx.solvers``).

    Unknowns ``[u (g n, interleaved), p (n)]``, both of time order 1 (u is quasi-static; its
    rate enters the storage equation). With C = [[0, 0], [Kup^T, S(dt)]] and
    r = [Kuu u - Kup p - F^ext(t), Kh p - Q^ext(t)] the model reads C x' + r(x, t) = 0:
    Kup^T u' + S p' + Kh p = Q^ext. S(dt) is the compressibility plus the rate-form projection
    stabilization (3.60), whose eps_f (3.53) depends on the step size.

    With ``nitsche`` (K_N, C) the displacement conditions are imposed by Nitsche's method
    instead of collocation: the momentum rows hold (Kuu + K_N) u - (Kup - C) p, C the
    pore-pressure part of the total traction in the consistency term; the storage rows keep
    Kup^T u' (the Jacobian is then not symmetric).

    Attributes:
        operators: The matrices of one discretization.
        material: Poroelastic constants.
        collocation: Collocated essential conditions (of u and p, or of p alone with Nitsche).
        nodes: Node coordinates at which the conditions are collocated, shape ``(n, g)`` [m].
        loads: F^ext(t), Q^ext(t) as ``(g n,)`` and ``(n,)`` arrays.
        local: On MPI ranks, the rank's local unknowns (``rkfx.parallel.unknowns``): the
            operators, loads and collocation rows are then the rank's own contributions, and the
            model lives on the local nodes (``share`` tells the steppers); ``None``: the whole model.
    """

    def __init__(self, operators: BiotOperators, material: PoroMaterial, col: Collocation,
                 nodes: np.ndarray, loads: Callable[[float], tuple[np.ndarray, np.ndarray]],
                 local: LocalUnknowns | None = None,
                 nitsche: tuple[sp.csr_matrix, sp.csr_matrix] | None = None):
        self.operators, self.material, self.collocation, self.loads = operators, material, col, loads
        self.nodes, self.local = nodes, local
        self.share = None if local is None else local.share
        n = operators.Kh.shape[0] if local is None else len(local.nodes)
        self.dim = operators.Kuu.shape[0] // operators.Kh.shape[0]
        self.layout = layout(("u", self.dim, 1), ("p", 1, 1), nodes=n)
        self.linear = True
        o = operators
        kuu, kup = o.Kuu, o.Kup
        if nitsche is not None:  # Nitsche's terms of the displacement conditions (``biot_nitsche``)
            kuu, kup = kuu + nitsche[0], kup - nitsche[1]
        self._K = self._local(sp.bmat([[kuu, -kup], [None, o.Kh]], format="csr"))
        self._G = col.G if local is None else col.G[:, local.index].tocsr()
        self._per_step = PerStepSize(keep=5)
        self._n = n

    def _local(self, a: sp.csr_matrix) -> sp.csr_matrix:
        return a if self.local is None else self.local.matrix(a)

    def storage(self, dt: float) -> sp.csr_matrix:
        """Compressibility plus the projection stabilization (3.60) for steps of dt, ``(n, n)``."""
        o = self.operators
        return o.Ks + o.stabilization(fpp_parameter(self.material, dt, o.h)) if o.fpp_rows else o.Ks

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        f, q = self.loads(t)
        fq = np.concatenate([f, q])
        return self._K @ x - (fq if self.local is None else self.local.vector(fq))

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        return self._K

    def mass(self) -> None:
        return None

    def capacity(self, dt: float) -> sp.csr_matrix:
        n, g = self.operators.Kh.shape[0], self.dim
        return self._per_step.get("capacity", dt, lambda dt: self._local(sp.bmat(
            [[sp.csr_matrix((g * n, g * n)), None], [self.operators.Kup.T, self.storage(dt)]], format="csr")))

    def constraints(self, t: float) -> Constraints:
        return Constraints(self._G, self.collocation.values(self.nodes, t))

    def equation_weights(self, co) -> np.ndarray:
        """-1 / (du'/du) on the storage rows: the symmetric saddle-point Jacobian
        [[Kuu, -Kup], [-Kup^T, -S - theta dt Kh]] of eqs. (3.50)-(3.51)."""
        n = self._n
        return np.r_[np.ones(self.dim * n), np.full(n, -1.0 / co.dv[0])]


class _Outputs:
    """Nodal coefficients kept at the output times (on MPI ranks, each rank those of its own
    nodes; ``whole`` sums them over the ranks)."""

    def __init__(self, wanted: np.ndarray, n: int, local: LocalUnknowns | None = None, dim: int = 2):
        self.wanted, self.local = wanted, local
        self.U = np.zeros((len(wanted), n, dim))
        self.P = np.zeros((len(wanted), n))
        self.n, self.g = n, dim

    def record(self, s) -> None:
        j = np.flatnonzero(np.abs(self.wanted - s.t) <= 1e-12 * np.maximum(self.wanted, 1.0))
        g = self.g
        for i in j:
            if self.local is None:
                self.U[i] = s.x[:g * self.n].reshape(self.n, g)
                self.P[i] = s.x[g * self.n:]
            else:
                loc, own = self.local, self.local.num_owned_nodes
                m = len(loc.nodes)
                self.U[i][loc.nodes[:own]] = s.x[:g * m].reshape(m, g)[:own]
                self.P[i][loc.nodes[:own]] = s.x[g * m:g * m + own]

    def whole(self) -> tuple[np.ndarray, np.ndarray]:
        """U and P of every node (a sum over the ranks of their own nodes' values)."""
        if self.local is None:
            return self.U, self.P
        comm = self.local.share.comm
        return comm.allreduce(self.U), comm.allreduce(self.P)  # exact: one rank holds each node

    def arrays(self) -> dict[str, np.ndarray]:
        return {"U": self.U, "P": self.P}

    def restore(self, arrays) -> None:
        self.U[...] = arrays["U"]
        self.P[...] = arrays["P"]


def boundary_loads(p: Particles, bq: BoundaryQuadrature, tractions: Sequence[Traction], fluxes: Sequence[Flux]
                   ) -> Callable[[float], tuple[np.ndarray, np.ndarray]]:
    """t -> (int N^T t_bar dGamma (g n,), -int N q_bar . n dGamma (n,)): the boundary terms of
    F^ext (3.36) and Q^ext (3.37) on the boundary quadrature ``bq``."""
    n = p.num_nodes
    nb = bq.rows.matrix(0)
    traction_points = [part_points(p, bq, tr.boundary) for tr in tractions]
    flux_points = [part_points(p, bq, fl.boundary) for fl in fluxes]

    def loads(t):
        f = np.zeros((n, bq.dim))
        for tr, sel in zip(tractions, traction_points):
            f += nb[sel].T @ (bq.weights[sel, None] * traction_values(tr, bq, sel, t))
        q = np.zeros(n)
        for fl, sel in zip(fluxes, flux_points):
            q -= nb[sel].T @ (bq.weights[sel] * values(fl, bq.points[sel], t, bq.normals[sel])[:, 0])
        return f.ravel(), q

    return loads


def solve_biot(p: Particles, material: PoroMaterial, times: np.ndarray, output_times: Sequence[float],
               displacements: Sequence[Displacement] = (), pressures: Sequence[Pressure] = (),
               tractions: Sequence[Traction] = (), fluxes: Sequence[Flux] = (),
               variant: str = "scni+fpp", support_factor: float = 1.5,
               gravity: Sequence[float] | None = None, density: float = 0.0, fluid_density: float = 0.0,
               comm=None, solver: str = "auto", progress: Callable | None = None,
               rk: RKApproximation | None = None, domains: NodalDomains | None = None,
               fields: NodalFields | None = None, checkpoint_every: int = 0, checkpoint_dir=None,
               resume=None, distributed: bool | None = None, bc_method: str = "transformation",
               nitsche_penalty: float = 100.0) -> BiotSolution:
    """Solve the u-p equations by backward Euler on the step times ``times`` (t_0 = 0).

    Initial state u = 0, p = 0. Loads and prescribed values are evaluated at t_{n+1} (3.39)-(3.40).

    Args:
        p: Particles with named boundary parts: 2-D ``Particles`` (plane strain) or 3-D
            ``Particles3D``.
        material: Poroelastic constants.
        times: Step times, shape ``(N + 1,)`` [s], starting at 0 (see ``time_grid``).
        output_times: Times at which to keep the solution; each must be one of ``times``.
        displacements, pressures: Essential conditions (collocated at boundary nodes).
        tractions, fluxes: Natural conditions; unlisted boundaries are traction-free and
            impermeable.
        variant: ``ni``, ``scni``, ``ni+fpp`` or ``scni+fpp``.
        support_factor: a_I = c h_I.
        gravity: Gravitational acceleration g, e.g. ``(0, -9.81)`` (3-D: ``(0, 0, -9.81)``)
            [m/s^2]; ``None`` for none.
        density: Mixture density rho = n_f rho_f + (1 - n_f) rho_s [kg/m^3] (body force rho g).
        fluid_density: rho_f [kg/m^3] (Darcy flux -k (grad p - rho_f g), eq. 3.10).
        comm: MPI communicator of the linear solves (PETSc when installed).
        solver: ``auto`` (MUMPS up to ``U_P_AUTO_DIRECT_MAX_DOFS`` unknowns, the field split above
            with 2-D Nitsche conditions), ``mumps`` or ``fieldsplit`` (needs ``bc_method="nitsche"``).
            The solver used and its iterations: ``BiotSolution.linear``.
        progress: Optional wrapper of the step iterator (e.g. a progress bar).
        rk: The RK approximation of u and p (default: linear basis, support
            ``support_factor`` h_I, no cracks).
        domains: Nodal domains of the integration (default: ``rkfx.geometry.cells.nodal_cells``:
            median-dual cells of ``p``, or the box cells of a 3-D tensor grid).
        fields: Per-particle material fields (stiffness, permeability tensor, Biot coefficient,
            storage) in place of the material's constants.
        checkpoint_every, checkpoint_dir: Write a checkpoint every so many steps.
        resume: A checkpoint folder to continue from (same particles, material and times).
        distributed: Split the particles over the ranks of ``comm`` (RCB): each rank
            integrates over its own nodes' domains and steps its local unknowns, the system is
            assembled by owned rows (``rkfx.parallel.unknowns``), and the checkpoints are one
            per rank. ``None`` (default): when ``comm`` has more than one rank. The solution is
            gathered on every rank at the end.
        bc_method: How the displacement conditions are imposed: ``transformation``
            (collocated at the boundary nodes, by multipliers) or ``nitsche`` (Nitsche's method
            with the total traction, no multipliers: what an iterative solver of the u block
            needs, see ``rkfx.linalg.petsc``). Pressures are collocated either way.
        nitsche_penalty: Dimensionless Nitsche parameter (``rkfx.assembly.boundary``).
    """
    t_all = np.asarray(times, float)
    if t_all[0] != 0.0 or np.any(np.diff(t_all) <= 0):
        raise InputError("times must start at 0 and increase strictly")
    wanted = np.asarray(output_times, float)
    where = np.searchsorted(t_all, wanted)
    if np.any(where >= len(t_all)) or np.any(np.abs(t_all[np.minimum(where, len(t_all) - 1)] - wanted)
                                             > 1e-12 * np.maximum(wanted, 1.0)):
        raise InputError("every output time must be one of the step times (use rkfx.solvers.integrate.time_grid)")
    if not (displacements or pressures):
        raise InputError("no essential boundary conditions: prescribe displacements (and pressures)")
    if bc_method not in BC_METHODS:
        raise InputError(f"unknown bc_method {bc_method!r}; choose one of {', '.join(BC_METHODS)}")
    nitsche = bc_method == "nitsche"
    g = p.x.shape[1]
    solver = choose_solver(solver, (g + 1) * p.num_nodes, bc_method, g)
    if solver == "fieldsplit" and not nitsche:
        raise InputError("solver='fieldsplit' preconditions the displacement block by multigrid, which needs the "
                         "displacement conditions in it: use bc_method='nitsche'")
    if nitsche and fields is not None and (fields.D is not None or fields.alpha is not None):
        raise InputError("bc_method='nitsche' takes the material's constant D and alpha on the boundary; per-particle "
                         "fields D or alpha need bc_method='transformation'")
    if distributed is None:
        distributed = comm is not None and comm.size > 1
    elif distributed and comm is None:
        raise InputError("distributed=True needs comm, the MPI communicator to split the particles over")
    timings = {}
    t0 = time.perf_counter()
    rk = rk_approximation(p.x, p.spacing, support_factor) if rk is None else rk
    n = p.num_nodes
    num = mine = segments = None
    if distributed:
        num = numbering(rcb(p.x, comm.size), comm.size)
        mine = num.old_of_new[num.ranges[comm.rank]:num.ranges[comm.rank + 1]]
    # On ranks, only the domains around the rank's own nodes (the cells it integrates over).
    d = nodal_cells(p, nodes=mine) if domains is None else domains
    if distributed:
        segments = np.flatnonzero(np.isin(d.boundary.node, mine))
    ops = biot_operators(p, rk, d, material, variant, fields=fields, nodes=mine)
    bq = boundary_quadrature(p, d, rk, segments=segments)
    collocated = [(pressures, g * n, 1)] if nitsche else [(displacements, 0, g), (pressures, g * n, 1)]
    col = collocation(p, rk, collocated, (g + 1) * n, nodes=mine)
    weak = nitsche_rows(p, bq, material.elastic.voigt(g), displacements, nitsche_penalty) if nitsche else []
    boundary_terms = None
    if nitsche:
        boundary_terms = (sum((r.matrix() for r in weak), sp.csr_matrix((g * n, g * n))).tocsr(),
                          nitsche_pressure_coupling(bq, weak, material.alpha))
    nb = bq.rows.matrix(0)
    # Gravity (3.36)-(3.37), integrated at the nodes like the other nodal terms.
    f_gravity, q_gravity = np.zeros(g * n), np.zeros(n)
    if gravity is not None:
        gv = np.asarray(gravity, float).reshape(g)
        if g == 3:
            nodal = dni_3d(p, rk, d, nodes=mine) if not variant.startswith("scni") else scni_3d(p, rk, d, nodes=mine)
        else:
            nodal = dni(p, rk, d, nodes=mine) if not variant.startswith("scni") else scni(p, rk, d, nodes=mine)
        w = nodal.weights
        f_gravity = (nodal.values.matrix().T @ (w[:, None] * density * gv)).ravel()
        grad = nodal.gradients
        q_gravity = material.k * fluid_density * sum(grad.matrix(c).T @ (w * gv[c]) for c in range(g))
    timings["assemble"] = time.perf_counter() - t0
    t0 = time.perf_counter()

    boundary = boundary_loads(p, bq, tractions, fluxes)

    def loads(t):
        f, q = boundary(t)
        for r in weak:  # Nitsche's terms of the prescribed displacements
            f = f + r.load(bq, t)
        return f + f_gravity, q + q_gravity  # F^ext (3.36) and Q^ext (3.37)

    local = None
    if distributed:
        # The nodes this rank's terms touch: its own and the ghosts (stiffness, coupling,
        # storage with the projection pattern, collocation rows, boundary loads).
        kuu, kup = (ops.Kuu, ops.Kup) if boundary_terms is None else (ops.Kuu + boundary_terms[0],
                                                                     ops.Kup + boundary_terms[1])
        whole = sp.bmat([[kuu, -kup], [ops.Kup.T, ops.Ks + ops.stabilization(np.ones(n))]], format="csr")
        touched = touched_nodes((g, 1), n, whole, constraints=(col.G,))
        local = local_unknowns(num, np.unique(np.r_[touched, nb.indices, mine]), (g, 1), comm)
    model = BiotModel(ops, material, col, p.x, loads, local, nitsche=boundary_terms)
    kept = _Outputs(wanted, n, local, g)
    split = None
    if solver == "fieldsplit":
        # Fixed stress: the coupling's share of the pressure Schur complement, alpha^2 / K_dr
        # int N_I with the drained bulk modulus K_dr = lambda + 2 mu / g (lambda + mu in plane
        # strain) and int N_I = A_I (V_I in 3-D; partition of unity).
        lam, mu = material.elastic.lame if g == 2 else (material.elastic.lame_lambda, material.elastic.shear_modulus)
        split = DisplacementSplit(p.x, material.alpha**2 / (lam + 2.0 * mu / g) * cell_measures(d)[0])
    # A 3-D factorization holds ~2 GB at 4,270 nodes (rows of ~950 entries): keep the current step
    # size's and one more (a step shortened to hit an output time), not five.
    solves = Factorizations(comm, solver, keep=5 if g == 2 else 2, split=split)
    try:
        integrate(backward_euler(), model, t_all, recorder=kept, comm=comm, solves=solves,
                  progress=progress, max_cuts=0, checkpoint_every=checkpoint_every,
                  checkpoint_dir=checkpoint_dir, resume=resume)
    finally:
        solves.destroy()
    timings["steps"] = time.perf_counter() - t0
    count, iterations = solves.linear_iterations()
    U, P = kept.whole()
    return BiotSolution(rk, wanted, U, P, (g + 1) * n, sum(timings.values()), len(t_all) - 1, timings,
                        {"solver": solver, "solves": count, "iterations": iterations})
