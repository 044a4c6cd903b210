"""Explicit central-difference time integration of M d'' = f_ext - f_int (eq. 4.35).

Unknowns are the RK displacement coefficients d (interleaved per node, shape ``(2 n,)``).
The mass is lumped, M_I = rho V_L (the nodal-integration mass; ``lumped_mass`` also gives the
row-sum of the nodally integrated consistent mass). The internal force is any callable of d,
so a damage law plugs in: for SCNI, f_int = B~^T Sigma(B~ d) V (eqs. 4.31-4.34) with B~ the
smeared strain operator of ``smeared_strain``, one sparse product each way per step.

One step n -> n+1 (Belytschko, Liu & Moran, Box 6.1), with a_n = M^-1 (f_ext_n - f_int_n):

    v_{n+1/2} = v_n + dt/2 a_n,  projected so that G v_{n+1/2} = (g(t_{n+1}) - G d_n) / dt
    d_{n+1}   = d_n + dt v_{n+1/2}                  (so G d_{n+1} = g(t_{n+1}) exactly)
    a_{n+1}   = M^-1 (f_ext(t_{n+1}) - f_int(d_{n+1}))
    v_{n+1}   = v_{n+1/2} + dt/2 a_{n+1},  projected so that G v_{n+1} = g'(t_{n+1})

Essential conditions are collocation rows G (u^h(x_I) = g(t) at boundary nodes, as in
``rkfx.boundary``), imposed by projection with the lumped mass: w <- w + M^-1 G^T lambda with
(G M^-1 G^T) lambda = target - G w, factorized once. A prescribed velocity (e.g. an impact)
replaces the half-step target by v_bar(t_{n+1/2}). The full-step projection only changes the
reported velocity, never the trajectory (the next half-step projection removes the same
component).

Energies per step: kinetic 1/2 v^T M v; internal = work of f_int (trapezoidal in d: stored
plus dissipated energy; exact 1/2 d^T K d for linear elasticity); external work of f_ext;
work of the constraint forces, the impulses M (v+ - v-) of the two projections of a step
over dt (zero for fixed supports). ``balance`` = kinetic + internal - external - constraint
- initial kinetic stays near zero.

Stable step (CFL): dt = C min(h_I) / c_d, c_d = sqrt((lambda + 2 mu) / rho) (plane strain),
C = 0.5 by default; ``max_frequency`` measures omega_max for the exact bound dt < 2/omega_max
(uniform grids, support 1.5 h: omega_max dt = 0.87-0.92 at C = 0.5 for nu = 0-0.3, so the
critical C is about 1.1).

Checkpoints (``checkpoint_every``) hold the whole state at a step boundary: d, v, a, the
forces, step, time, energies, history and any extra state arrays (e.g. damage variables that
the force callable updates in place); ``resume`` restores them and the run continues exactly
as an uninterrupted one would (bitwise, with the same thread count).
"""
import os
import time as _time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .boundary import Dirichlet, transformation_constraints
from .elasticity import ElasticMaterial
from .errors import InputError
from .nodal_domains import NodalDomains, nodal_domains
from .operators import strain_matrix
from .particles import Particles
from .quadrature import smoothed_gradients, subcell_gradients
from .shape_functions import RKApproximation
from .sparse_rows import SparseRows

CHECKPOINT = "checkpoint.npz"
ENERGIES = ("kinetic", "internal", "external", "constraint")


@numba.njit(parallel=True, cache=True)
def _strain(indptr, indices, grad, d, out):
    """Smeared strains of every node L: sum_I B~_I(x_L) d_I, rows in parallel (eq. 4.31)."""
    for row in numba.prange(len(indptr) - 1):
        exx = 0.0
        eyy = 0.0
        gxy = 0.0
        for q in range(indptr[row], indptr[row + 1]):
            i = indices[q]
            gx = grad[q, 0]
            gy = grad[q, 1]
            ux = d[2 * i]
            uy = d[2 * i + 1]
            exx += gx * ux
            eyy += gy * uy
            gxy += gy * ux + gx * uy
        out[row, 0] = exx
        out[row, 1] = eyy
        out[row, 2] = gxy


@numba.njit(parallel=True, cache=True)
def _force(indptr, indices, grad, stress, volume, out):
    """f_I = sum_L B~_I(x_L)^T Sigma_L V_L over the transposed rows (eq. 4.34), nodes in parallel."""
    for node in numba.prange(len(indptr) - 1):
        fx = 0.0
        fy = 0.0
        for q in range(indptr[node], indptr[node + 1]):
            ell = indices[q]
            gx = grad[q, 0] * volume[ell]
            gy = grad[q, 1] * volume[ell]
            fx += gx * stress[ell, 0] + gy * stress[ell, 2]
            fy += gy * stress[ell, 1] + gx * stress[ell, 2]
        out[2 * node] = fx
        out[2 * node + 1] = fy


@numba.njit(parallel=True, cache=True)
def _cell_average(ptr, fraction, sub):
    """Cell strains e_L = sum_C (A_C / A_L) e_C from the subcell strains of each particle,
    shape ``(n, 3)``; ``sub`` becomes the differences e_L - e_C in place."""
    n = len(ptr) - 1
    cell = np.empty((n, 3))
    for ell in numba.prange(n):
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for c in range(ptr[ell], ptr[ell + 1]):
            f = fraction[c]
            a0 += f * sub[c, 0]
            a1 += f * sub[c, 1]
            a2 += f * sub[c, 2]
        cell[ell, 0] = a0
        cell[ell, 1] = a1
        cell[ell, 2] = a2
        for c in range(ptr[ell], ptr[ell + 1]):
            sub[c, 0] = a0 - sub[c, 0]
            sub[c, 1] = a1 - sub[c, 1]
            sub[c, 2] = a2 - sub[c, 2]
    return cell


@numba.njit(parallel=True, cache=True)
def _subcell_load(ptr, fraction, weight, volume, stress, sub_stress, out):
    """tau_C = (A_C / A_L) (V_L Sigma_L + sum_C' w_C' s_C') - w_C s_C per subcell C of each
    particle L: the stresses whose transposed subcell product is the whole force
    (``sub_stress`` empty: no MSCNI terms)."""
    with_sub = sub_stress.shape[0] > 0
    for ell in numba.prange(len(ptr) - 1):
        t0 = volume[ell] * stress[ell, 0]
        t1 = volume[ell] * stress[ell, 1]
        t2 = volume[ell] * stress[ell, 2]
        if with_sub:
            for c in range(ptr[ell], ptr[ell + 1]):
                t0 += weight[c] * sub_stress[c, 0]
                t1 += weight[c] * sub_stress[c, 1]
                t2 += weight[c] * sub_stress[c, 2]
        for c in range(ptr[ell], ptr[ell + 1]):
            f = fraction[c]
            out[c, 0] = f * t0
            out[c, 1] = f * t1
            out[c, 2] = f * t2
            if with_sub:
                out[c, 0] -= weight[c] * sub_stress[c, 0]
                out[c, 1] -= weight[c] * sub_stress[c, 1]
                out[c, 2] -= weight[c] * sub_stress[c, 2]


@numba.njit(cache=True)
def _wdot(a, w, b):
    """sum_i a_i w_i b_i, in order (reproducible; and no BLAS call, whose threads would
    contend with numba's on small machines)."""
    s = 0.0
    for i in range(len(a)):
        s += a[i] * w[i] * b[i]
    return s


# Per-step vector updates, fused and parallel (numpy temporaries cost ~1 ms each at 10^5
# nodes). Reductions use a fixed number of chunks summed in order, so results do not
# depend on the thread count.
_CHUNKS = 64


@numba.njit(parallel=True, cache=True)
def _kick(v, a, half, out):
    for i in numba.prange(len(v)):
        out[i] = v[i] + half * a[i]


@numba.njit(parallel=True, cache=True)
def _drift(d, vh, dt, d_new, dd):
    for i in numba.prange(len(d)):
        dd[i] = dt * vh[i]
        d_new[i] = d[i] + dd[i]


@numba.njit(parallel=True, cache=True)
def _accelerate(f_ext, f_int, mass, vh, half, a, v):
    for i in numba.prange(len(mass)):
        a[i] = (f_ext[i] - f_int[i]) / mass[i]
        v[i] = vh[i] + half * a[i]


@numba.njit(parallel=True, cache=True)
def _energy_increments(v, mass, dd, f_int0, f_int1, f_ext0, f_ext1, dv):
    """(kinetic, internal, external, constraint) increments of a step (dv empty: no constraints)."""
    n = len(v)
    part = np.zeros((_CHUNKS, 4))
    size = (n + _CHUNKS - 1) // _CHUNKS
    with_dv = len(dv) > 0
    for c in numba.prange(_CHUNKS):
        k = w = x = r = 0.0
        for i in range(c * size, min(n, (c + 1) * size)):
            k += mass[i] * v[i] * v[i]
            w += dd[i] * (f_int0[i] + f_int1[i])
            x += dd[i] * (f_ext0[i] + f_ext1[i])
            if with_dv:
                r += dd[i] * mass[i] * dv[i]
        part[c, 0] = k
        part[c, 1] = w
        part[c, 2] = x
        part[c, 3] = r
    out = np.zeros(4)
    for c in range(_CHUNKS):
        for j in range(4):
            out[j] += part[c, j]
    out[0] *= 0.5
    out[1] *= 0.5
    out[2] *= 0.5
    return out


@numba.njit(parallel=True, cache=True)
def _linear_stress(e, c, out):
    for i in numba.prange(e.shape[0]):
        for j in range(3):
            out[i, j] = c[j, 0] * e[i, 0] + c[j, 1] * e[i, 1] + c[j, 2] * e[i, 2]


def _transpose(rows: SparseRows) -> SparseRows:
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
        rows, rows_t: grad~N_I(x_hat_C) per subcell, grouped by particle, and transposed.
        ptr: The subcells of particle L are rows ``ptr[L]:ptr[L+1]``, shape ``(n + 1,)``.
        owner: Particle L of each subcell, shape ``(num_subcells,)``.
        fraction: A_C / A_L, shape ``(num_subcells,)``.
        weight: eps_p A_C, shape ``(num_subcells,)`` [m^2].
    """

    rows: SparseRows
    rows_t: SparseRows
    ptr: np.ndarray
    owner: np.ndarray
    fraction: np.ndarray
    weight: np.ndarray

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
        rows: grad~N_I(x_L) per node L, shape ``(n, n)`` with 2 components [1/m].
        rows_t: The same entries grouped by I (the transpose), with components [1/m].
        volume: V_L, shape ``(n,)`` [m^2] (per unit thickness).
        stabilization: MSCNI subcell terms, or ``None`` (plain SCNI).
    """

    rows: SparseRows
    rows_t: SparseRows
    volume: np.ndarray
    stabilization: Stabilization | None = None

    @property
    def num_nodes(self) -> int:
        return len(self.volume)

    def strain(self, d: np.ndarray) -> np.ndarray:
        """Smeared strains (eps_xx, eps_yy, gamma_xy) at the nodes, shape ``(n, 3)``, for
        interleaved coefficients d of shape ``(2 n,)`` [m]."""
        if self.stabilization is not None:
            return self.strains(d)[0]
        return _apply(self.rows, d)

    def strains(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The smeared strains ``(n, 3)`` and the MSCNI differences (B~_L - B~_C) d per subcell
        ``(num_subcells, 3)``, from one product with the subcell rows."""
        s = self.stabilization
        if s is None:
            raise InputError("this operator has no MSCNI terms; build it with smeared_strain(..., eps_p=1)")
        sub = _apply(s.rows, d)
        return _cell_average(s.ptr, s.fraction, sub), sub

    def force(self, stress: np.ndarray, subcell_stress: np.ndarray | None = None) -> np.ndarray:
        """f_int = sum_L B~_L^T Sigma_L V_L (eq. 4.34) for nodal stresses ``(n, 3)`` [Pa], plus
        sum_C (B~_L - B~_C)^T s_C eps_p A_C for subcell stresses s_C ``(num_subcells, 3)``
        (MSCNI operators only); shape ``(2 n,)`` [N]."""
        s = self.stabilization
        stress = np.ascontiguousarray(stress, dtype=np.float64)
        if s is None:
            if subcell_stress is not None:
                raise InputError("subcell stresses given to an operator without MSCNI terms")
            return _apply_t(self.rows_t, stress, self.volume)
        sub = np.empty((0, 3)) if subcell_stress is None else \
            np.ascontiguousarray(subcell_stress, dtype=np.float64)
        load = np.empty((len(s.owner), 3))
        _subcell_load(s.ptr, s.fraction, s.weight, self.volume, stress, sub, load)
        return _apply_t(s.rows_t, load, s._unit)

    @cached_property
    def B(self) -> sp.csr_matrix:
        """B~ as CSR, shape ``(3 n, 2 n)``: rows (eps_xx, eps_yy, gamma_xy) per node."""
        return strain_matrix(self.rows)

    @cached_property
    def BT(self) -> sp.csr_matrix:
        """B~ transposed as CSR, shape ``(2 n, 3 n)``."""
        return self.B.T.tocsr()


def _apply(rows: SparseRows, d: np.ndarray) -> np.ndarray:
    out = np.empty((rows.num_rows, 3))
    _strain(rows.indptr, rows.indices, rows.data, np.ascontiguousarray(d, dtype=np.float64), out)
    return out


def _apply_t(rows_t: SparseRows, stress: np.ndarray, weight: np.ndarray) -> np.ndarray:
    out = np.empty(2 * rows_t.num_rows)
    _force(rows_t.indptr, rows_t.indices, rows_t.data, np.ascontiguousarray(stress, dtype=np.float64), weight, out)
    return out


# Largest relative mismatch between the cell strains and the area average of the subcell
# strains accepted at set-up (round-off is ~1e-14).
_PARTITION_TOL = 1e-9


def smeared_strain(p: Particles, rk: RKApproximation, domains: NodalDomains | None = None,
                   eps_p: float = 0.0) -> SmearedStrain:
    """B~ from the SCNI smoothed gradients on the nodal cells (eq. 3.55 = eq. 4.33), with the
    MSCNI subcell terms of eq. (3.56) when ``eps_p`` > 0 (1 is the usual choice)."""
    if not (np.isfinite(eps_p) and eps_p >= 0):
        raise InputError(f"eps_p = {eps_p!r} must be >= 0 (0: plain SCNI, 1: MSCNI)")
    domains = domains or nodal_domains(p)
    volume = np.ascontiguousarray(domains.area, dtype=np.float64)
    if eps_p == 0:
        cell = smoothed_gradients(p, rk, domains, subcells=False).cell
        return SmearedStrain(cell, _transpose(cell), volume)
    cell, sub, order = subcell_gradients(rk, domains)
    owner = np.ascontiguousarray(domains.subcell_node[order])
    ptr = np.zeros(p.num_nodes + 1, np.int64)
    np.cumsum(np.bincount(owner, minlength=p.num_nodes), out=ptr[1:])
    area = domains.subcell_area[order]
    stab = Stabilization(sub, _transpose(sub), ptr, owner, np.ascontiguousarray(area / volume[owner]),
                         np.ascontiguousarray(eps_p * area, dtype=np.float64))
    op = SmearedStrain(cell, _transpose(cell), volume, stab)
    probe = np.random.default_rng(0).standard_normal(2 * p.num_nodes)
    direct = _apply(cell, probe)
    gap = np.abs(op.strain(probe) - direct).max() / max(np.abs(direct).max(), 1e-300)
    if not gap <= _PARTITION_TOL:
        raise InputError(f"the subcells do not partition the nodal cells (cell and subcell strains differ by "
                         f"{gap:.1e}); use eps_p=0 with these domains or rebuild them with nodal_domains/grid_domains")
    return op


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


@dataclass(frozen=True)
class Constraint:
    """Essential conditions G d = g(t) on the coefficients (collocation rows).

    Attributes:
        G: Rows over the interleaved coefficients, shape ``(k, 2 n)``.
        displacement: g(t) [m], shape ``(k,)``; ``None`` with no ``velocity`` means g = 0.
        velocity: g'(t) [m/s], shape ``(k,)``. Alone, it prescribes the velocity (the
            displacement follows by integration); with ``displacement``, it is its rate
            (default: a central difference of ``displacement``).
    """

    G: sp.csr_matrix
    displacement: Callable[[float], np.ndarray] | None = None
    velocity: Callable[[float], np.ndarray] | None = None

    @property
    def prescribes_velocity(self) -> bool:
        return self.velocity is not None and self.displacement is None


def constraint(p: Particles, rk: RKApproximation, dirichlet: Sequence[Dirichlet],
               amplitude: Callable[[float], float] | None = None, kind: str = "displacement") -> Constraint:
    """Collocation conditions u^h(x_I) = a(t) u_bar(x_I) at the nodes of the named boundaries.

    Args:
        dirichlet: Conditions as for the static solvers; ``value`` gives u_bar(x) (a
            displacement [m], or a velocity [m/s] with ``kind="velocity"``).
        amplitude: Time factor a(t) (default 1).
        kind: ``displacement`` or ``velocity``.
    """
    if kind not in ("displacement", "velocity"):
        raise InputError(f"kind = {kind!r}: choose 'displacement' or 'velocity'")
    g, values = transformation_constraints(p, rk, dirichlet)
    amp = amplitude or (lambda t: 1.0)
    homogeneous = amplitude is None and not np.any(values)
    f = None if homogeneous else (lambda t: amp(t) * values)
    return Constraint(g, displacement=f) if kind == "displacement" else \
        Constraint(g, velocity=f or (lambda t: values))


@dataclass(frozen=True)
class ExplicitDynamics:
    """M d'' = f_ext(t) - f_int(d) with essential conditions, for central differences.

    Attributes:
        mass: Lumped mass per unknown, shape ``(2 n,)`` [kg].
        internal_force: f_int(d) for d of shape ``(2 n,)``; called exactly once per step
            with the new coefficients, so it may update history variables (damage) in place.
        dt: Time step [s] (see ``stable_time_step``).
        external_force: f_ext(t), shape ``(2 n,)`` [N]; ``None`` for none.
        constraints: Essential conditions.
    """

    mass: np.ndarray
    internal_force: Callable[[np.ndarray], np.ndarray]
    dt: float
    external_force: Callable[[float], np.ndarray] | None = None
    constraints: Sequence[Constraint] = ()


@dataclass
class ExplicitState:
    """The state at a step boundary; everything a checkpoint holds.

    Attributes:
        step, time: Step index n and t_n = n dt [s].
        d, v, a: Coefficients [m], velocities [m/s] and unconstrained accelerations
            M^-1 (f_ext - f_int) [m/s^2], shapes ``(2 n,)``.
        f_int, f_ext: Forces at t_n [N].
        energy: Kinetic, internal, external and constraint work [J per unit thickness].
    """

    step: int
    time: float
    d: np.ndarray
    v: np.ndarray
    a: np.ndarray
    f_int: np.ndarray
    f_ext: np.ndarray
    energy: np.ndarray

    def energies(self) -> dict[str, float]:
        return dict(zip(ENERGIES, map(float, self.energy)))


@dataclass
class ExplicitResult:
    """A run: final state, per-step energy history and outputs.

    Attributes:
        state: Final state.
        dt: Time step [s].
        time: t_n of every step 0..N [s], shape ``(N + 1,)``.
        energy: Energies per step, shape ``(N + 1, 4)`` (columns ``ENERGIES``).
        snapshots: ``(step, time, d, v)`` every ``output_every`` steps (without ``on_output``).
        resumed_from: Step of the checkpoint the run resumed from, or ``None``.
        wall_time_s: Wall time of the steps run here [s].
    """

    state: ExplicitState
    dt: float
    time: np.ndarray
    energy: np.ndarray
    snapshots: list = field(default_factory=list)
    resumed_from: int | None = None
    wall_time_s: float = 0.0

    @property
    def balance(self) -> np.ndarray:
        """kinetic + internal - external - constraint - initial kinetic, per step [J]."""
        e = self.energy
        return e[:, 0] + e[:, 1] - e[:, 2] - e[:, 3] - e[0, 0]

    def relative_energy_error(self) -> float:
        """max |balance| / max(kinetic, internal, external) over the run (the energy check
        of Belytschko, Liu & Moran, ch. 6)."""
        scale = np.abs(self.energy[:, :3]).max()
        return float(np.abs(self.balance).max() / scale) if scale > 0 else 0.0


class _Projection:
    """M-orthogonal projection onto {G w = target}, G M^-1 G^T factorized once."""

    def __init__(self, constraints: Sequence[Constraint], mass: np.ndarray):
        self.parts = list(constraints)
        self.G = sp.vstack([c.G for c in self.parts]).tocsr() if self.parts else None
        if self.G is None or self.G.shape[0] == 0:
            self.G = None
            return
        if self.G.shape[1] != len(mass):
            raise InputError(f"constraint rows have {self.G.shape[1]} columns for {len(mass)} unknowns")
        self.GT = self.G.T.tocsr()
        self.minv_gt = sp.diags(1.0 / mass) @ self.GT
        a = (self.G @ self.minv_gt).tocsc()
        try:
            self.lu = spla.splu(a)
            pivots = np.abs(self.lu.U.diagonal())
            singular = not pivots.min() > 1e-12 * pivots.max()
        except RuntimeError:
            singular = True
        if singular:
            raise InputError("the constraint rows are linearly dependent (G M^-1 G^T is singular); "
                             "prescribe each (node, component) once")
        self.sizes = [c.G.shape[0] for c in self.parts]

    def project(self, w: np.ndarray, target: np.ndarray) -> np.ndarray:
        """w + M^-1 G^T lambda with G (w + ...) = target; returns the correction."""
        lam = self.lu.solve(target - self.G @ w)
        dw = self.minv_gt @ lam
        w += dw
        return dw

    def _blocks(self, fn) -> np.ndarray:
        return np.concatenate([fn(c) for c in self.parts])

    def half_step_target(self, d: np.ndarray, t_next: float, dt: float) -> np.ndarray:
        """Velocity target for v_{n+1/2}: G v = (g(t_{n+1}) - G d_n) / dt, or v_bar(t_{n+1/2})."""
        gd = self.G @ d
        out, i = [], 0
        for c, k in zip(self.parts, self.sizes):
            if c.prescribes_velocity:
                out.append(np.broadcast_to(np.asarray(c.velocity(t_next - 0.5 * dt), float), (k,)))
            else:
                g = np.zeros(k) if c.displacement is None else \
                    np.broadcast_to(np.asarray(c.displacement(t_next), float), (k,))
                out.append((g - gd[i:i + k]) / dt)
            i += k
        return np.concatenate(out)

    def velocity_target(self, t: float, dt: float) -> np.ndarray:
        def one(c):
            k = c.G.shape[0]
            if c.velocity is not None:
                return np.broadcast_to(np.asarray(c.velocity(t), float), (k,))
            if c.displacement is None:
                return np.zeros(k)
            return (np.asarray(c.displacement(t + 0.5 * dt), float)
                    - np.asarray(c.displacement(t - 0.5 * dt), float)) / dt * np.ones(k)
        return self._blocks(one)

    def displacement_target(self, d: np.ndarray, t: float) -> np.ndarray:
        """g(t) where a displacement is prescribed; G d elsewhere (left unchanged)."""
        gd = self.G @ d
        out, i = [], 0
        for c, k in zip(self.parts, self.sizes):
            if c.prescribes_velocity:
                out.append(gd[i:i + k])
            elif c.displacement is None:
                out.append(np.zeros(k))
            else:
                out.append(np.broadcast_to(np.asarray(c.displacement(t), float), (k,)))
            i += k
        return np.concatenate(out)


def _vector(f, n2: int, what: str) -> np.ndarray:
    f = np.ascontiguousarray(f, dtype=np.float64)
    if f.shape != (n2,):
        raise InputError(f"{what} returned shape {f.shape}; expected ({n2},) (interleaved per node)")
    return f


def initial_state(problem: ExplicitDynamics, d0: np.ndarray | None = None,
                  v0: np.ndarray | None = None) -> ExplicitState:
    """State at t = 0 from initial coefficients and velocities (projected on the constraints)."""
    return _initial_state(problem, _Projection(problem.constraints, problem.mass), d0, v0)


def _initial_state(problem, proj, d0, v0):
    n2 = len(problem.mass)
    d = np.zeros(n2) if d0 is None else np.array(d0, float).reshape(n2)
    v = np.zeros(n2) if v0 is None else np.array(v0, float).reshape(n2)
    if proj.G is not None:
        proj.project(d, proj.displacement_target(d, 0.0))
        proj.project(v, proj.velocity_target(0.0, problem.dt))
    f_int = _vector(problem.internal_force(d), n2, "internal_force(d)")
    f_ext = np.zeros(n2) if problem.external_force is None else \
        _vector(problem.external_force(0.0), n2, "external_force(t)")
    a = (f_ext - f_int) / problem.mass
    energy = np.array([0.5 * _wdot(v, problem.mass, v), 0.0, 0.0, 0.0])
    return ExplicitState(0, 0.0, d, v, a, f_int, f_ext, energy)


def save_checkpoint(directory: str | Path, state: ExplicitState, dt: float, time: np.ndarray,
                    energy: np.ndarray, extra_state: Mapping[str, np.ndarray] | None = None) -> Path:
    """Write ``DIR/checkpoint.npz`` atomically (temporary file, fsync, then ``os.replace``)."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    target = directory / CHECKPOINT
    tmp = directory / (CHECKPOINT + ".tmp")
    arrays = {"d": state.d, "v": state.v, "a": state.a, "f_int": state.f_int, "f_ext": state.f_ext,
              "energy": state.energy, "step": np.int64(state.step), "time": np.float64(state.time),
              "dt": np.float64(dt), "history_time": time[:state.step + 1],
              "history_energy": energy[:state.step + 1]}
    for k, v in (extra_state or {}).items():
        arrays[f"extra__{k}"] = np.asarray(v)
    with open(tmp, "wb") as fh:
        np.savez(fh, **arrays)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, target)
    return target


def load_checkpoint(directory: str | Path) -> dict[str, np.ndarray]:
    """The arrays of ``DIR/checkpoint.npz``."""
    path = Path(directory) / CHECKPOINT
    if not path.is_file():
        raise InputError(f"no checkpoint at {str(path)!r}; run with checkpoint_every=N and checkpoint_dir first")
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def run_explicit(problem: ExplicitDynamics, num_steps: int, *, d0: np.ndarray | None = None,
                 v0: np.ndarray | None = None, extra_state: Mapping[str, np.ndarray] | None = None,
                 output_every: int = 0, on_output: Callable[[ExplicitState], None] | None = None,
                 checkpoint_every: int = 0, checkpoint_dir: str | Path | None = None,
                 resume: str | Path | None = None) -> ExplicitResult:
    """Integrate to step ``num_steps`` (t = num_steps dt) by central differences.

    Args:
        problem: Mass, forces, constraints and dt.
        num_steps: Final step index N.
        d0, v0: Initial coefficients and velocities, shape ``(2 n,)`` (default zero).
        extra_state: Named arrays the force callable updates in place (e.g. damage
            variables); checkpointed with the state and restored in place on resume.
        output_every: Every so many steps (and at the end), call ``on_output(state)`` or,
            without it, keep a snapshot ``(step, time, d, v)`` in the result. The state's
            arrays are the driver's work buffers: copy what you keep.
        checkpoint_every: Write ``checkpoint_dir/checkpoint.npz`` every so many steps.
        checkpoint_dir: Directory of the checkpoint.
        resume: A checkpoint directory to continue from (``d0``/``v0`` are then ignored).
    """
    dt = float(problem.dt)
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"time step dt = {dt!r} must be positive; see stable_time_step")
    if int(num_steps) != num_steps or num_steps < 0:
        raise InputError(f"num_steps = {num_steps!r} must be a non-negative integer")
    if checkpoint_every and checkpoint_dir is None:
        raise InputError("checkpoint_every needs checkpoint_dir")
    mass = np.asarray(problem.mass, float)
    n2 = len(mass)
    extra = dict(extra_state or {})
    proj = _Projection(problem.constraints, mass)
    hist_t = np.empty(num_steps + 1)
    hist_e = np.empty((num_steps + 1, len(ENERGIES)))
    resumed = None
    if resume is not None:
        ck = load_checkpoint(resume)
        if ck["d"].shape != (n2,) or float(ck["dt"]) != dt:
            raise InputError(f"checkpoint in {str(resume)!r} has {ck['d'].size} unknowns and dt = "
                             f"{float(ck['dt']):.6g}; this problem has {n2} and dt = {dt:.6g}")
        step = int(ck["step"])
        if step > num_steps:
            raise InputError(f"checkpoint is at step {step}, beyond num_steps = {num_steps}")
        state = ExplicitState(step, float(ck["time"]), ck["d"].copy(), ck["v"].copy(), ck["a"].copy(),
                              ck["f_int"].copy(), ck["f_ext"].copy(), ck["energy"].copy())
        for k, arr in extra.items():
            if f"extra__{k}" not in ck:
                raise InputError(f"checkpoint has no extra state {k!r}; it holds "
                                 f"{sorted(s[7:] for s in ck if s.startswith('extra__'))}")
            arr[...] = ck[f"extra__{k}"]
        hist_t[:step + 1] = ck["history_time"]
        hist_e[:step + 1] = ck["history_energy"]
        resumed = step
    else:
        state = _initial_state(problem, proj, d0, v0)
        hist_t[0] = 0.0
        hist_e[0] = state.energy
    snapshots = []

    def output(s):
        if on_output is not None:
            on_output(s)
        else:
            snapshots.append((s.step, s.time, s.d.copy(), s.v.copy()))

    if output_every and resumed is None:
        output(state)
    t_wall = _time.perf_counter()
    # Work buffers, swapped rather than reallocated; the states handed to on_output are views
    # of them (copy what you keep).
    d, v, a = state.d.copy(), state.v.copy(), state.a.copy()
    f_int, f_ext, energy = state.f_int, state.f_ext, state.energy.copy()
    d_new, a_new, vh, dd = (np.empty(n2) for _ in range(4))
    no_dv = np.empty(0)
    zeros = np.zeros(n2)
    half = 0.5 * dt
    for step in range(state.step, num_steps):
        t_next = (step + 1) * dt
        _kick(v, a, half, vh)
        dv = no_dv
        if proj.G is not None:
            dv = proj.project(vh, proj.half_step_target(d, t_next, dt))
        _drift(d, vh, dt, d_new, dd)
        f_int_new = _vector(problem.internal_force(d_new), n2, "internal_force(d)")
        f_ext_new = zeros if problem.external_force is None else \
            _vector(problem.external_force(t_next), n2, "external_force(t)")
        _accelerate(f_ext_new, f_int_new, mass, vh, half, a_new, v)
        if proj.G is not None:
            # Constraint force over the step: the impulses of the half-step projection and of
            # the full-step one at its end (each carries half of it for a steady reaction).
            dv = dv + proj.project(v, proj.velocity_target(t_next, dt))
        inc = _energy_increments(v, mass, dd, f_int, f_int_new, f_ext, f_ext_new, dv)
        energy = np.array([inc[0], energy[1] + inc[1], energy[2] + inc[2], energy[3] + inc[3] / dt])
        d, d_new = d_new, d
        a, a_new = a_new, a
        f_int, f_ext = f_int_new, f_ext_new
        hist_t[step + 1] = t_next
        hist_e[step + 1] = energy
        done = step + 1
        if not np.all(np.isfinite(energy)):
            raise InputError(f"the solution blew up at step {done} (t = {t_next:.4g} s); reduce dt below "
                             "the stable step (stable_time_step / max_frequency)")
        if (output_every and (done % output_every == 0 or done == num_steps)) or \
                (checkpoint_every and done % checkpoint_every == 0):
            state = ExplicitState(done, t_next, d, v, a, f_int, f_ext, energy)
            if output_every and (done % output_every == 0 or done == num_steps):
                output(state)
            if checkpoint_every and done % checkpoint_every == 0:
                save_checkpoint(checkpoint_dir, state, dt, hist_t, hist_e, extra)
    wall = _time.perf_counter() - t_wall
    state = ExplicitState(num_steps, num_steps * dt, d, v, a, f_int.copy(), f_ext.copy(), energy)
    return ExplicitResult(state, dt, hist_t, hist_e, snapshots, resumed, wall)
