"""The explicit model side of central differences: the smeared strain operator, its
internal force, the lumped mass, the stable step and constraint rows (eq. 4.35).

Unknowns are the RK displacement coefficients d (interleaved per node, shape ``(2 n,)``).
The mass is lumped, M_I = rho V_L (the nodal-integration mass; ``lumped_mass`` also gives the
row-sum of the nodally integrated consistent mass). For SCNI the internal force is
f_int = B~^T Sigma(B~ d) V (eqs. 4.31-4.34) with B~ the smeared strain operator of
``smeared_strain``, one sparse product each way per step; a damage law plugs in through the
stresses (``rkfx.models.damage_dynamics``).

Essential conditions are collocation rows G (u^h(x_I) = g(t) at boundary nodes, as in
``rkfx.assembly.boundary``) built by ``constraint`` from ``rkfx.conditions.Displacement`` or
``Velocity`` conditions (a prescribed velocity, e.g. an impact). The central-difference
stepper that advances these models, imposes the conditions by projection and keeps the
energies and checkpoints is ``rkfx.solvers.central_difference`` (``CentralDifference``;
``run_explicit`` for a problem of callables).

Stable step (CFL): dt = C min(h_I) / c_d, c_d = sqrt((lambda + 2 mu) / rho) (plane strain),
C = 0.5 by default; ``max_frequency`` measures omega_max for the exact bound dt < 2/omega_max
(uniform grids, support 1.5 h: omega_max dt = 0.87-0.92 at C = 0.5 for nu = 0-0.3, so the
critical C is about 1.1).
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property

import numba
import numpy as np
import scipy.sparse as sp

from rkfx.assembly.boundary import collocation
from rkfx.conditions import Displacement, Velocity
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import NodalDomains, nodal_domains
from rkfx.assembly.operators import strain_matrix
from rkfx.assembly.lattice_stencil import (LatticeStencil, Snap, lattice_of, lattice_stencil, snap_to_template,
                                           sort_rows, template_particle, template_rows)
from rkfx.assembly.row_products import damaged_stress, node_force, particle_average, particle_load, row_strain
from rkfx.geometry.particles import Particles
from rkfx.integration.quadrature import smoothed_gradients, subcell_gradients
from rkfx.approximation.shape_functions import RKApproximation
from rkfx.solvers.central_difference import Constraint
from rkfx.approximation.sparse_rows import SparseRows, spread_rows


@numba.njit(parallel=True, cache=True)
def _strain(indptr, indices, grad, d, out):
    """Smeared strains of every node L: sum_I B~_I(x_L) d_I, rows in parallel (eq. 4.31)."""
    for row in numba.prange(len(indptr) - 1):
        row_strain(indptr, indices, grad, d, row, out)


@numba.njit(parallel=True, cache=True)
def _force(indptr, indices, grad, stress, volume, out):
    """f_I = sum_L B~_I(x_L)^T Sigma_L V_L over the transposed rows (eq. 4.34), nodes in parallel."""
    for node in numba.prange(len(indptr) - 1):
        node_force(indptr, indices, grad, stress, volume, node, out)


@numba.njit(parallel=True, cache=True)
def cell_average(ptr, fraction, sub):
    """Cell strains e_L = sum_C (A_C / A_L) e_C from the subcell strains of each particle,
    shape ``(n, 3)``; ``sub`` becomes the differences e_L - e_C in place."""
    n = len(ptr) - 1
    cell = np.empty((n, 3))
    for ell in numba.prange(n):
        particle_average(ptr, fraction, sub, ell, cell)
    return cell


@numba.njit(parallel=True, cache=True)
def subcell_load(ptr, fraction, weight, volume, stress, sub_stress, out):
    """tau_C = (A_C / A_L) (V_L Sigma_L + sum_C' w_C' s_C') - w_C s_C per subcell C of each
    particle L: the stresses whose transposed subcell product is the whole force
    (``sub_stress`` empty: no MSCNI terms)."""
    with_sub = sub_stress.shape[0] > 0
    for ell in numba.prange(len(ptr) - 1):
        particle_load(ptr, fraction, weight, volume, stress, sub_stress, with_sub, ell, out)


@numba.njit(parallel=True, cache=True)
def damaged_subcell_stress(strain, c, owner, damage, stress):
    """(1 - D_L) C (B~_L - B~_C) d per subcell C of particle L (the damaged MSCNI terms), from
    the differences ``strain`` into ``stress`` (which may be ``strain``)."""
    for k in numba.prange(strain.shape[0]):
        s = 1.0 - damage[owner[k]]
        e0 = strain[k, 0]
        e1 = strain[k, 1]
        e2 = strain[k, 2]
        for j in range(3):
            stress[k, j] = damaged_stress(c, s, e0, e1, e2, j)


@numba.njit(parallel=True, cache=True)
def _linear_stress(e, c, out):
    for i in numba.prange(e.shape[0]):
        for j in range(3):
            out[i, j] = c[j, 0] * e[i, 0] + c[j, 1] * e[i, 1] + c[j, 2] * e[i, 2]


def transpose_rows(rows: SparseRows) -> SparseRows:
    """The entries of ``rows`` grouped by column (stable: each column's entries in row order)."""
    n = rows.num_rows
    row = np.repeat(np.arange(n, dtype=np.int32), np.diff(rows.indptr))
    perm = np.argsort(rows.indices, kind="stable")
    ptr_t = np.zeros(rows.num_cols + 1, np.int64)
    np.cumsum(np.bincount(rows.indices, minlength=rows.num_cols), out=ptr_t[1:])
    return SparseRows(ptr_t, row[perm], np.ascontiguousarray(rows.data[perm]), n)


@dataclass(frozen=True)
class Stabilization:
    """The MSCNI stabilization of eq. (3.56) for explicit dynamics, and the subcell rows that
    evaluate the whole operator.

    Per subcell C of particle L, the strain difference (B~_L - B~_C) d between the cell's
    smoothed strain and the subcell's, weighted by eps_p A_C: the force
    sum_C (B~_L - B~_C)^T s_L C (B~_L - B~_C) d eps_p A_C penalizes the zero-energy modes of
    SCNI (the checkerboards of a nodal grid), with s_L = 1 - D_L under damage.

    The subcells partition the cell and their interior sides cancel, so
    A_L B~_L = sum_C A_C B~_C: one product with the subcell rows gives the subcell strains,
    their area average the cell strains, and the force with the cell stresses Sigma_L and the
    subcell stresses s_C is one transposed product of the subcell rows with
    tau_C = (A_C / A_L) (V_L Sigma_L + sum_C' eps_p A_C' s_C') - eps_p A_C s_C.

    Attributes:
        rows: grad~N_I(x_hat_C) per subcell, grouped by particle (``rows_t``, their transpose,
            is built on first use).
        ptr: The subcells of particle L are rows ``ptr[L]:ptr[L+1]``, shape ``(n + 1,)``.
        owner: Particle L of each subcell, shape ``(num_subcells,)``.
        fraction: A_C / A_L, shape ``(num_subcells,)``.
        weight: eps_p A_C, shape ``(num_subcells,)`` [m^2].
        stencil: The products as lattice stencils where the rows are a uniform grid's
            template (``rkfx.assembly.lattice_stencil``), or ``None``.
        snap: The template the rows were snapped to and the particles that have it (a rank's
            share builds its stencils from it, ``rkfx.assembly.local_strain``), or ``None``.
    """

    rows: SparseRows
    ptr: np.ndarray
    owner: np.ndarray
    fraction: np.ndarray
    weight: np.ndarray
    stencil: LatticeStencil | None = None
    snap: Snap | None = None

    @cached_property
    def rows_t(self) -> SparseRows:
        """The subcell rows grouped by column (``transpose_rows``)."""
        return transpose_rows(self.rows)

    @cached_property
    def _unit(self) -> np.ndarray:
        return np.ones(len(self.owner))


@dataclass(frozen=True)
class SmearedStrain:
    """The smeared strain operator B~ of eqs. (4.31)-(4.33) and the nodal volumes.

    Stored as the smoothed gradient rows grad~N_I(x_L) (2 numbers and a node index per
    entry) and their transpose, which is all B~ d and B~^T Sigma V read: 20 bytes per entry
    against 48 for B~ as a (3 n, 2 n) CSR matrix, and both products are memory bound. The
    CSR matrices are built on demand (``B``, ``BT``), e.g. for a tangent stiffness. With the
    MSCNI terms the products run over the subcell rows instead (``Stabilization``): one
    product each way gives cell strains, subcell differences and the whole force, about 40%
    fewer entries than the cell rows plus the difference rows.

    Attributes:
        rows: grad~N_I(x_L) per node L, shape ``(n, n)`` with 2 components [1/m] (``rows_t``,
            the same entries grouped by I, is built on first use: an MSCNI operator never
            needs it).
        volume: V_L, shape ``(n,)`` [m^2] (per unit thickness).
        stabilization: MSCNI subcell terms, or ``None`` (plain SCNI).
    """

    rows: SparseRows
    volume: np.ndarray
    stabilization: Stabilization | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.volume)

    @cached_property
    def rows_t(self) -> SparseRows:
        """The cell rows grouped by column (``transpose_rows``)."""
        return transpose_rows(self.rows)

    def strain(self, d: np.ndarray) -> np.ndarray:
        """Smeared strains (eps_xx, eps_yy, gamma_xy) at the nodes, shape ``(n, 3)``, for
        interleaved coefficients d of shape ``(2 n,)`` [m]."""
        if self.stabilization is not None:
            return self.strains(d)[0]
        return row_strains(self.rows, d)

    def strains(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The smeared strains ``(n, 3)`` and the MSCNI differences (B~_L - B~_C) d per subcell
        ``(num_subcells, 3)``, from one product with the subcell rows."""
        s = self.stabilization
        if s is None:
            raise InputError("this operator has no MSCNI terms; build it with smeared_strain(..., eps_p=1)")
        d = np.ascontiguousarray(d, dtype=np.float64)
        if s.stencil is not None:
            return s.stencil.strains(s.rows, s.ptr, s.fraction, d)
        sub = row_strains(s.rows, d)
        return cell_average(s.ptr, s.fraction, sub), sub

    def force(self, stress: np.ndarray, subcell_stress: np.ndarray | None = None) -> np.ndarray:
        """f_int = sum_L B~_L^T Sigma_L V_L (eq. 4.34) for nodal stresses ``(n, 3)`` [Pa], plus
        sum_C (B~_L - B~_C)^T s_C eps_p A_C for subcell stresses s_C ``(num_subcells, 3)``
        (MSCNI operators only); shape ``(2 n,)`` [N]."""
        s = self.stabilization
        stress = np.ascontiguousarray(stress, dtype=np.float64)
        if s is None:
            if subcell_stress is not None:
                raise InputError("subcell stresses given to an operator without MSCNI terms")
            return transposed_force(self.rows_t, stress, self.volume)
        sub = np.empty((0, 3)) if subcell_stress is None else \
            np.ascontiguousarray(subcell_stress, dtype=np.float64)
        if s.stencil is not None:
            return s.stencil.force(s.rows_t, s.ptr, s.fraction, s.weight, self.volume, stress, sub, s._unit)
        load = np.empty((len(s.owner), 3))
        subcell_load(s.ptr, s.fraction, s.weight, self.volume, stress, sub, load)
        return transposed_force(s.rows_t, load, s._unit)

    def damaged_force(self, stress: np.ndarray, differences: np.ndarray, c: np.ndarray,
                      damage: np.ndarray) -> np.ndarray:
        """``force(stress, s)`` with the subcell stresses s_C = (1 - D_L) C (B~_L - B~_C) d of
        the MSCNI differences ``differences`` (``strains``; overwritten), elasticity ``c``
        (3, 3) and damage D per particle: the damage particle method's force (eq. 4.34 with
        the terms of 3.56)."""
        s = self.stabilization
        if s.stencil is not None:
            return s.stencil.damaged_force(s.rows_t, s.ptr, s.fraction, s.weight, self.volume,
                                           np.ascontiguousarray(stress, dtype=np.float64), differences, c, damage,
                                           s._unit)
        damaged_subcell_stress(differences, c, s.owner, damage, differences)
        return self.force(stress, differences)

    @cached_property
    def B(self) -> sp.csr_matrix:
        """B~ as CSR, shape ``(3 n, 2 n)``: rows (eps_xx, eps_yy, gamma_xy) per node."""
        return strain_matrix(self.rows)

    @cached_property
    def BT(self) -> sp.csr_matrix:
        """B~ transposed as CSR, shape ``(2 n, 3 n)``."""
        return self.B.T.tocsr()


def row_strains(rows: SparseRows, d: np.ndarray) -> np.ndarray:
    """Voigt strains of every row of smoothed gradients for interleaved d, shape ``(num_rows, 3)``."""
    out = np.empty((rows.num_rows, 3))
    _strain(rows.indptr, rows.indices, rows.data, np.ascontiguousarray(d, dtype=np.float64), out)
    return out


def transposed_force(rows_t: SparseRows, stress: np.ndarray, weight: np.ndarray,
                     out: np.ndarray | None = None) -> np.ndarray:
    """Interleaved force sum_rows grad^T stress weight per column of ``rows_t`` (transposed rows:
    each node's entries in row order), shape ``(2 num_nodes,)``, into ``out`` if given."""
    out = np.empty(2 * rows_t.num_rows) if out is None else out
    _force(rows_t.indptr, rows_t.indices, rows_t.data, np.ascontiguousarray(stress, dtype=np.float64), weight, out)
    return out


# Largest relative mismatch between the cell strains and the area average of the subcell
# strains accepted at set-up (round-off is ~1e-14).
_PARTITION_TOL = 1e-9


def check_eps_p(eps_p: float) -> None:
    """Raise InputError unless the MSCNI weight ``eps_p`` is finite and >= 0."""
    if not (np.isfinite(eps_p) and eps_p >= 0):
        raise InputError(f"eps_p = {eps_p!r} must be >= 0 (0: plain SCNI, 1: MSCNI)")


def smeared_strain(p: Particles, rk: RKApproximation, domains: NodalDomains | None = None,
                   eps_p: float = 0.0, points: np.ndarray | None = None, lattice: bool = True) -> SmearedStrain:
    """B~ from the SCNI smoothed gradients on the nodal cells (eq. 3.55 = eq. 4.33), with the
    MSCNI subcell terms of eq. (3.56) when ``eps_p`` > 0 (1 is the usual choice).

    On a uniform grid (and ``lattice``) the subcell rows of the particles away from the
    boundary and the cracks are snapped to one template and, for the whole operator, evaluated
    by stencils (``rkfx.assembly.lattice_stencil``: the same numbers bit for bit, fewer bytes).

    ``points`` (ascending particle indices) builds only the rows of those particles (the others
    stay empty, in their places): enough for a rank's ``local_smeared_strain`` when they are
    its own particles and every particle whose rows touch one of its nodes (``near_part``).
    """
    check_eps_p(eps_p)
    domains = domains or nodal_domains(p)
    volume = np.ascontiguousarray(domains.area, dtype=np.float64)
    if points is not None:
        bare = np.asarray(points)[domains.segment_counts()[points] == 0]
        if bare.size:
            raise InputError(f"{bare.size} of the particles whose rows are built (first: {bare[0]}) have no cell "
                             "in these nodal domains; build the domains with nodes= covering them")
    if eps_p == 0:
        if points is None:
            cell = smoothed_gradients(p, rk, domains, subcells=False).cell
        else:
            cell = spread_rows(smoothed_gradients(p, rk, domains, subcells=False, nodes=points).cell, points,
                           p.num_nodes)
        op = SmearedStrain(cell, volume)
        if points is None:
            op.rows_t  # noqa: B018 - the transpose f_int reads, built at set-up
        return op
    cell, sub, order = subcell_gradients(rk, domains, nodes=points)
    owner = np.ascontiguousarray(domains.subcell_node[order])
    ptr = np.zeros(p.num_nodes + 1, np.int64)
    np.cumsum(np.bincount(owner, minlength=p.num_nodes), out=ptr[1:])
    area = domains.subcell_area[order]
    snap = _snapped(p, rk, domains, sub, ptr, points) if lattice else None
    stencil = None if snap is None or points is not None else \
        lattice_stencil(sub, ptr, snap.matched, snap.template, snap.lattice)
    stab = Stabilization(sub, ptr, owner, np.ascontiguousarray(area / volume[owner]),
                         np.ascontiguousarray(eps_p * area, dtype=np.float64), stencil, snap)
    op = SmearedStrain(cell, volume, stab)
    probe = np.random.default_rng(0).standard_normal(2 * p.num_nodes)
    direct = row_strains(cell, probe)
    gap = np.abs(op.strain(probe) - direct).max() / max(np.abs(direct).max(), 1e-300)
    if not gap <= _PARTITION_TOL:
        raise InputError(f"the subcells do not partition the nodal cells (cell and subcell strains differ by "
                         f"{gap:.1e}); use eps_p=0 with these domains or rebuild them with nodal_domains/grid_domains")
    if points is None:
        stab.rows_t  # noqa: B018 - the transpose f_int reads, built at set-up
    return op


def _snapped(p: Particles, rk: RKApproximation, domains: NodalDomains, sub: SparseRows, ptr: np.ndarray,
             points: np.ndarray | None) -> Snap | None:
    """Snap the subcell rows ``sub`` of a uniform grid to the template particle's
    (``rkfx.assembly.lattice_stencil``); ``None`` (rows untouched) off a grid, without a
    template particle, or when these domains hold no cell of it."""
    lat = lattice_of(p.x)
    c = None if lat is None else template_particle(p.x, rk)
    if c is None:
        return None
    if points is None or np.isin(c, points):
        source = sub
    elif domains.segment_counts()[c] > 0:
        source = subcell_gradients(rk, domains, nodes=np.array([c]), with_cells=False)[1]
        sort_rows(source)
    else:
        return None
    sort_rows(sub)
    template = template_rows(source, ptr, c)
    return Snap(template, lat, snap_to_template(sub, ptr, template, lat))


@dataclass(frozen=True)
class StrainRecipe:
    """What ``smeared_strain`` builds B~ from, for a run that builds it itself: whole on one rank,
    on MPI ranks only the rows of each rank's share (``rkfx.models.damage_ranks``), so that no
    rank ever holds the whole operator.

    Attributes:
        p, rk, domains: Particles, their RK approximation and nodal domains.
        eps_p: MSCNI weight (0: plain SCNI).
    """

    p: Particles
    rk: RKApproximation
    domains: NodalDomains
    eps_p: float = 0.0

    @property
    def num_nodes(self) -> int:
        return self.p.num_nodes

    def build(self, points: np.ndarray | None = None) -> SmearedStrain:
        """``smeared_strain`` of the recipe (only the rows of ``points`` if given)."""
        return smeared_strain(self.p, self.rk, self.domains, self.eps_p, points=points)

    def near(self, part: np.ndarray, rank: int) -> np.ndarray:
        """The particles whose rows rank ``rank`` of the partition ``part`` reads: its own and
        every particle's whose rows touch one of its nodes (``near_part``)."""
        return near_part(self.p.x, part, rank, 1.001 * (self.rk.support.max() + reach(self.p.x, self.domains)))

    def share(self, part: np.ndarray, rank: int) -> SmearedStrain:
        """The rows of ``near``, each other row left empty in its place."""
        return self.build(self.near(part, rank))


def near_part(x: np.ndarray, part: np.ndarray, rank: int, margin: float) -> np.ndarray:
    """The particles (ascending) of part ``rank`` and those within ``margin`` of its bounding
    box: with ``margin`` at least the largest support plus the farthest smoothing point of a
    particle from it, every particle whose rows touch a node of the part."""
    x = np.asarray(x, float)
    own = x[np.asarray(part) == rank]
    if own.size == 0:
        return np.zeros(0, np.int64)
    lo, hi = own.min(axis=0) - margin, own.max(axis=0) + margin
    return np.flatnonzero(np.all((x >= lo) & (x <= hi), axis=1) | (np.asarray(part) == rank))


def reach(x: np.ndarray, domains: NodalDomains) -> float:
    """The largest distance from a particle (coordinates ``x``) to one of its smoothing points
    (those of its subcells' sides, which include its cell's) [m]."""
    d = domains
    sub = np.linalg.norm(d.smoothing_points[d.subcell_point] - x[d.subcell_node][:, None], axis=2)
    return float(sub.max(initial=0.0))


def elastic_force(op: SmearedStrain, d_matrix: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    """Linear elastic f_int(d) = B~^T V D B~ d (plus the MSCNI terms when ``op`` carries them),
    for the elasticity matrix ``d_matrix`` (3, 3) [Pa]."""
    c = np.asarray(d_matrix, float)
    if c.shape != (3, 3):
        raise InputError(f"elasticity matrix must have shape (3, 3), got {c.shape}")

    c = np.ascontiguousarray(c)

    def f_int(d: np.ndarray) -> np.ndarray:  # _linear_stress, not e @ c.T: BLAS threads would fight numba's
        if op.stabilization is None:
            e = op.strain(d)
            sigma = np.empty_like(e)
            _linear_stress(e, c, sigma)
            return op.force(sigma)
        e, diff = op.strains(d)
        sigma = np.empty_like(e)
        _linear_stress(e, c, sigma)
        sub = np.empty_like(diff)
        _linear_stress(diff, c, sub)
        return op.force(sigma, sub)
    return f_int


def lumped_mass(volume: np.ndarray, rho: float, node_values: SparseRows | None = None) -> np.ndarray:
    """Lumped mass per interleaved unknown, shape ``(2 n,)`` [kg per unit thickness].

    Args:
        volume: Nodal volumes V_L, shape ``(n,)`` [m^2].
        rho: Density [kg/m^3].
        node_values: Rows N_I(x_L) at the nodes; if given, the row sums of the nodally
            integrated consistent mass, sum_L rho V_L N_I(x_L), instead of rho V_I.
    """
    if not rho > 0:
        raise InputError(f"density rho = {rho!r} must be positive")
    m = rho * np.asarray(volume, float)
    if node_values is not None:
        m = node_values.matrix(0).T @ m
    if not np.all(m > 0):
        i = int(np.argmin(m))
        raise InputError(f"lumped mass of node {i} is {m[i]:.3g} <= 0; use the nodal mass rho V_I")
    return np.repeat(m, 2)


def dilatational_wave_speed(material: ElasticMaterial, rho: float) -> float:
    """c_d = sqrt((lambda + 2 mu) / rho) [m/s] (plane strain; = sqrt(E / rho) for nu = 0)."""
    return float(np.sqrt(material.constrained_modulus / rho))


def stable_time_step(spacing: np.ndarray, material: ElasticMaterial, rho: float, courant: float = 0.5) -> float:
    """CFL time step dt = C min(h_I) / c_d [s]."""
    if not 0 < courant <= 1:
        raise InputError(f"Courant number C = {courant!r} must lie in (0, 1]; 0.5 is the default")
    return float(courant * np.min(spacing) / dilatational_wave_speed(material, rho))


def max_frequency(mass: np.ndarray, internal_force: Callable[[np.ndarray], np.ndarray],
                  iterations: int = 200, seed: int = 0) -> float:
    """omega_max of M^-1 K by power iteration, for a linear internal force K d [rad/s].

    Central differences are stable for dt < 2 / omega_max (free boundaries; constraints only
    lower omega_max).
    """
    rng = np.random.default_rng(seed)
    w = rng.standard_normal(len(mass))
    lam = 0.0
    for _ in range(iterations):
        w /= np.sqrt(w @ (mass * w))
        kw = internal_force(w)
        lam = w @ kw
        w = kw / mass
    return float(np.sqrt(max(lam, 0.0)))


def constraint(p: Particles, rk: RKApproximation, conditions: Sequence[Displacement | Velocity]) -> Constraint:
    """Collocation conditions u^h(x_I) = u_bar(x_I, t) (or du^h/dt(x_I) = v_bar(x_I, t)) at the
    nodes of the conditions' boundary parts, as essential conditions of the central-difference
    stepper (``rkfx.solvers.central_difference``).

    Args:
        conditions: ``rkfx.conditions.Displacement`` [m] or ``rkfx.conditions.Velocity`` [m/s]
            conditions, all of one kind (build one constraint per kind). Constant values are
            evaluated once, and a displacement constraint with only zeros is homogeneous
            (``displacement=None``); function values value(x, t) are evaluated at the boundary
            nodes each time the stepper asks for g(t).
    """
    kinds = {type(c) for c in conditions}
    if not kinds <= {Displacement, Velocity} or len(kinds) > 1:
        raise InputError(f"constraint takes rkfx.conditions.Displacement or Velocity conditions, all of one kind, "
                         f"got {', '.join(sorted(k.__name__ for k in kinds))}; build one constraint per kind")
    velocity = Velocity in kinds
    col = collocation(p, rk, [(conditions, 0, 2)], 2 * p.num_nodes)
    if any(callable(c.value) for c in conditions):
        g = lambda t: col.values(p.x, t)  # noqa: E731
    else:
        constant = col.values(p.x)
        homogeneous = not velocity and not np.any(constant)
        g = None if homogeneous else lambda t: constant  # noqa: E731
    return Constraint(col.G, velocity=g) if velocity else Constraint(col.G, displacement=g)
