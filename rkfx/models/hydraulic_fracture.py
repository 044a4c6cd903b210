"""The hydro-mechanically coupled damage particle method (chapter 5) as a model for the Newmark stepper.

Unknowns ``[u (2 n, interleaved), p (n)]``: u of time order 2 (inertia, lumped mass rho V_I),
p of order 1. With the trapezoidal rule (``rkfx.solvers.newmark.trapezoidal``: beta_2 = 1/4,
beta_1 = 1/2, theta = 1/2) a step is eqs. (5.18)-(5.24):

    M u'' + f_int(u) - K_C p = F_ext,       K_C^T u' + S p' + K_H p = Q_ext,

with, at the SCNI points (and the MSCNI subcells, which take their particle's fields):

* f_int = int B^T (1 - D) C eps~ (5.25) with the damage D of the smeared strain eps~ from the
  committed history (``rkfx.fracture.damage.update``: Mazars' strain, linear softening,
  kappa_c regularized by the cell chord (4.28)); 1 - D is kept at or above ``residual`` (the
  seed's low residual strength, which keeps a failed band from leaving its particles' u free).
  The MSCNI subcell terms (3.56) take the committed damage of their particle (lagged a step,
  which keeps the Jacobian the exact derivative);
* K_C = int B^T alpha m N (5.27) with alpha = 1 - (1 - D) K / K_s (or the material's constant);
* K_H = int grad N^T k_f grad N (5.28) with the anisotropic permeability (5.8) of damaged
  particles, k_fC = w^3 / (12 mu_f L_s) (5.12), w = D L_s n . eps~ . n (5.13);
* S = int N^T (1/Q) N (5.29) plus the fluid pressure projection (5.30) with eps_f of (3.53) at
  intact particles and eps_f = 0 at damaged ones.

Newton (``rkfx.solvers.newton``) takes the symmetrized Jacobian (5.36): the tangent (5.34)-(5.35)
of f_int, -K_C, and K_H without its derivative with respect to u. The storage row is scaled by
-beta_2 dt / beta_1 as in (5.24). alpha, 1/Q and the projection of a step are those of the
committed damage (the capacity of a step is built once, at its start). The number of Newton
iterations of every accepted step is kept (``iterations``).

Pre-existing cracks (a notch) enter as particles damaged from the start (``initial_damage``):
D = 1 with their crack normal, fluid pressure prescribed on them by a ``Region`` condition.

A pre-existing fracture with frictional contact (``contact``, seed 5.3.3): the particles are cut
along it (``cut_triangulation``) and the RK approximation sees it by diffraction; its faces
carry the fluid pressure and the penalty frictional contact (5.38)-(5.39)
(``rkfx.fracture.contact``): f_int gains f_C, the Jacobian its derivative (unsymmetric where
the fracture slips) and the u-p block the pressure on the faces. The particles covering it
take its permeability (open: (5.8) with w = g_N; closed: k_f0 / 100) plus their own crack
band's enhancement; that permeability is not differentiated in the Jacobian.

With ``closure`` a closed crack carries compression across it (``rkfx.fracture.closure``): the
stress and tangent of a damaged particle whose n . eps . n < 0 gain D M (n . eps . n) v and
D M v (x) v; the seed's isotropic damage (off, the default) lets a band squeezed across its
crack give way.
"""
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from rkfx.approximation.shape_functions import RKApproximation
from rkfx.assembly.boundary import boundary_quadrature, collocation, part_nodes
from rkfx.assembly.operators import laplacian, mass, stiffness, strain_matrix
from rkfx.assembly.smeared_strain import lumped_mass, row_strains
from rkfx.conditions import Displacement, Flux, Pressure, Region, Traction
from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.closure import CrackClosure
from rkfx.fracture.contact import FractureContact, FrictionalContact, interface
from rkfx.fracture.history import DamageHistory
from rkfx.fracture.tracking import Tracking
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles
from rkfx.materials import crack_flow
from rkfx.models.hydro_damage import RESIDUAL_STIFFNESS, CrackBands, crack_permeability
from rkfx.models.poroelasticity import (PoroMaterial, biot_integration, boundary_loads, divergence_matrix,
                                        fpp_parameter, projection_rows)
from rkfx.solvers.fields import layout
from rkfx.solvers.model import Constraints


@dataclass(frozen=True)
class FracturingRock:
    """A saturated, fracturing porous solid (the seed's data of 5.3.2 and 5.3.3).

    Attributes:
        E, nu: Drained Young's modulus [Pa] and Poisson's ratio [-] (plane strain).
        rho_s, rho_w: Grain and fluid densities [kg/m^3].
        porosity: n_f [-].
        k_h: Hydraulic conductivity [m/s]; gamma_w: specific weight of the fluid [Pa/m]
            (mobility k_f0 = k_h / gamma_w).
        K_w, K_s: Bulk moduli of the fluid and of the grains [Pa].
        GF, ft: Fracture energy [N/m] and tensile strength [Pa].
        viscosity: mu_f of the fluid [Pa s] (the cubic law 5.12).
        alpha: A constant Biot coefficient in place of 1 - (1 - D) K / K_s (``None``: that law,
            which needs K_s >= K).
    """

    E: float
    nu: float
    rho_s: float
    rho_w: float
    porosity: float
    k_h: float
    gamma_w: float
    K_w: float
    K_s: float
    GF: float
    ft: float
    viscosity: float = 1e-3
    alpha: float | None = None

    def __post_init__(self):
        self.damage_material  # validates E, nu, GF, ft
        for name in ("rho_s", "rho_w", "k_h", "gamma_w", "K_w", "K_s", "viscosity"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} must be positive and finite")
        if not 0.0 < self.porosity < 1.0:
            raise InputError(f"porosity = {self.porosity!r} must lie in (0, 1)")
        if self.alpha is None and self.K_s < self.elastic_bulk_modulus:
            raise InputError(f"K_s = {self.K_s:g} is below the skeleton's bulk modulus K = {self.elastic_bulk_modulus:g}, "
                             "so alpha = 1 - K / K_s < 0; raise K_s or give a constant alpha")
        if self.alpha is not None and not self.porosity <= self.alpha <= 1.0:
            raise InputError(f"alpha = {self.alpha!r} must lie in [porosity, 1]")

    @property
    def damage_material(self) -> dm.DamageMaterial:
        return dm.DamageMaterial(self.E, self.nu, self.ft, self.GF)

    @property
    def elastic_bulk_modulus(self) -> float:
        return self.damage_material.elastic.bulk_modulus

    @property
    def mobility(self) -> float:
        """k_f0 = k_h / gamma_w [m^2/(Pa s)]."""
        return self.k_h / self.gamma_w

    @property
    def density(self) -> float:
        """Mixture density (1 - n_f) rho_s + n_f rho_w [kg/m^3]."""
        return (1.0 - self.porosity) * self.rho_s + self.porosity * self.rho_w

    def biot(self, damage: np.ndarray) -> np.ndarray:
        """alpha per particle."""
        if self.alpha is not None:
            return np.full(len(damage), self.alpha)
        return crack_flow.biot_coefficient(damage, self.elastic_bulk_modulus, self.K_s)

    def storage(self, alpha: np.ndarray) -> np.ndarray:
        """1/Q = n_f / K_w + (alpha - n_f) / K_s per particle [1/Pa]."""
        return crack_flow.storage_coefficient(alpha, self.porosity, self.K_w, self.K_s)

    def intact(self) -> PoroMaterial:
        """The undamaged rock as a ``PoroMaterial`` (for eps_f of the projection, 3.53-3.54)."""
        a = float(self.biot(np.zeros(1))[0])
        return PoroMaterial(self.E, self.nu, self.mobility, a, float(self.storage(np.array([a]))[0]))


def initial_damage(points: dm.DamageModel, cracked: np.ndarray, normal: Sequence[float]) -> dm.DamageState:
    """The undamaged state with the particles ``cracked`` (indices) fully damaged (D = 1) across
    the unit ``normal``: a pre-existing crack (notch) smeared over its particles."""
    state = dm.initial_state(points)
    idx = np.asarray(cracked, np.int64)
    if idx.size == 0:
        return state
    n = np.asarray(normal, float)
    if n.shape != (2,) or not np.isclose(np.hypot(*n), 1.0):
        raise InputError(f"crack normal {normal!r} must be a unit vector (n_x, n_y)")
    normals, chord, kappa_c = state.normal.copy(), state.chord.copy(), state.kappa_c.copy()
    # initiate() takes the normal from a stress: a uniaxial stress along n gives n.
    stress = np.column_stack([np.full(len(idx), n[0] ** 2), np.full(len(idx), n[1] ** 2),
                              np.full(len(idx), n[0] * n[1])])
    dm.initiate(points, idx, stress, normals, chord, kappa_c)
    normals[idx] = n
    damaged = state.damaged.copy()
    damaged[idx] = True
    kappa, d = state.kappa.copy(), state.damage.copy()
    kappa[idx] = kappa_c[idx] if points.regularized else points.kappa_c[idx]
    d[idx] = 1.0
    return dm.DamageState(kappa, d, normals, kappa_c, damaged, chord, state.dissipated.copy())


JACOBIANS = ("symmetric", "full")


class HydraulicFractureModel(DamageHistory):
    """The model of the module docstring on particles ``p`` with nodal domains ``domains``.

    Args:
        p, rk, domains: Particles, their RK approximation, nodal domains (SCNI cells).
        rock: The material.
        displacements, pressures: Essential conditions (collocated; ``Region`` pressures
            prescribe the notch).
        tractions, fluxes: Natural conditions on boundary parts.
        precracked: Particles of a pre-existing crack (notch), damaged from the start
            (``initial_damage``) across ``precrack_normal``; default none.
        residual: Least stiffness fraction 1 - D [-].
        eps_p: MSCNI subcell factor.
        jacobian: ``symmetric`` (5.36), or ``full`` with dK_H/dU P in the p-u block (5.33):
            the dependence of the crack permeability on the aperture w (5.13) through the
            smeared strain and the damage of loading particles.
        injection: ``(region, rate)``: fluid injected into the particles of a ``Region`` at
            ``rate(t)`` [m^3/s per unit thickness], spread over them by volume (a source in the
            storage equation, Q^ext); the alternative to prescribing the notch pressure.
        contact: The frictional contact law of a pre-existing fracture whose faces are the
            boundary part ``fracture`` (``cut_triangulation``'s name; the approximation ``rk``
            must carry its cracks); ``None``: no such fracture.
        damage_update: ``"implicit"`` (the seed's: the damage of every Newton iterate) or
            ``"impl-ex"`` (the damage of a step extrapolated from the two before it, the
            implicit update committed at its end; ``rkfx.fracture.history``).
        closure: A closed crack carries compression across it (``rkfx.fracture.closure``, with
            M = lambda + 2 mu); ``False``: the seed's isotropic damage in compression too.
        track: Particle tracking (``rkfx.fracture.tracking``): only its seeds, the damaged
            particles and the candidates (4.22) of the damaged ones may damage. Within every
            residual the particles that initiate admit their candidates at once and the
            damage is evaluated again, until no admitted particle initiates (the crack may grow
            by more than a tracking radius in a step). What a step's iterates admit stays
            admitted until the step is committed: a particle strained past its threshold
            while not allowed would otherwise damage at once in one iterate and not at all in
            the next, and Newton would cycle between the two. The pre-cracked particles admit
            their candidates from the start. ``None``: every
            particle may damage.
    """

    linear = False

    def __init__(self, p: Particles, rk: RKApproximation, domains: NodalDomains, rock: FracturingRock, *,
                 displacements: Sequence[Displacement] = (), pressures: Sequence[Pressure] = (),
                 tractions: Sequence[Traction] = (), fluxes: Sequence[Flux] = (),
                 precracked: np.ndarray | None = None, precrack_normal: Sequence[float] = (0.0, 1.0),
                 residual: float = RESIDUAL_STIFFNESS, eps_p: float = 1.0,
                 jacobian: str = "symmetric", track: Tracking | None = None,
                 injection: tuple[Region, Callable[[float], float]] | None = None,
                 contact: FrictionalContact | None = None, fracture: str = "crack",
                 damage_update: str = "implicit", closure: bool = False):
        if jacobian not in JACOBIANS:
            raise InputError(f"jacobian = {jacobian!r}; choose one of {', '.join(JACOBIANS)}")
        self.jacobian = jacobian
        self.use_damage_update(damage_update)
        if not 0.0 < residual < 1.0:
            raise InputError(f"residual = {residual!r} must lie in (0, 1)")
        if not (displacements or pressures):
            raise InputError("no essential conditions: prescribe displacements (and pressures)")
        n = p.num_nodes
        self.p, self.rk, self.domains, self.rock, self.residual_fraction = p, rk, domains, rock, residual
        self.n = n
        self.layout = layout(("u", 2, 2), ("p", 1, 1), nodes=n)
        self.share = None
        it = biot_integration(p, rk, domains, "scni+fpp", eps_p)
        self.integration = it
        self.nodal, self.volume = it.nodal, it.nodal.weights
        self._grad = it.nodal.gradients
        self._values = it.nodal.values.matrix()
        self._div = divergence_matrix(it.nodal)
        self._bt = strain_matrix(self._grad).T.tocsr()
        self._fpp = projection_rows(rk, domains, it)
        self.fracture = None if contact is None else FractureContact(interface(p, rk=rk, domains=domains, name=fracture),
                                                                     contact, p.x, self.volume)
        self._C = rock.damage_material.elasticity()
        self.closure = CrackClosure.for_material(self._C) if closure else None
        cells = domains if domains.subcell_vertices is not None else p  # grid cells, or median-dual cells of p
        self.points = dm.damage_model(rock.damage_material, self.volume, geometry=dm.cell_geometry(cells))
        self.committed = initial_damage(self.points, np.zeros(0, np.int64) if precracked is None else precracked,
                                        precrack_normal)
        self.track = track if track is not None and track.enabled else None
        self.allowed = None if self.track is None else self.track.seeds | self.committed.damaged
        self.parent = np.full(n, -1, np.int64)
        self._trial_tracking: tuple[np.ndarray, np.ndarray] | None = None
        if self.track is not None:
            self._admit(np.flatnonzero(self.committed.damaged), self.committed.normal, self.allowed, self.parent)
        self.trial: dm.DamageUpdate | None = None
        self.strain = np.zeros((n, 3))
        self._mass = np.r_[lumped_mass(self.volume, rock.density), np.zeros(n)]
        self._col = collocation(p, rk, [(displacements, 0, 2), (pressures, 2 * n, 1)], 3 * n)
        bq = boundary_quadrature(p, domains, rk)
        self._boundary_loads = boundary_loads(p, bq, tractions, fluxes)
        self._injection = None
        if injection is not None:
            region, rate = injection
            inside = part_nodes(p, region)
            fraction = np.zeros(n)  # of the injected fluid, per particle of the region (by volume)
            fraction[inside] = self.volume[inside] / self.volume[inside].sum()
            self._injection = (self._values.T @ fraction, rate)  # int N_I s dOmega per unit injected volume
        self._h = np.sqrt(domains.area)
        self._intact = rock.intact()
        self.iterations: list[int] = []
        self._count = 0
        self._capacity: tuple[float, dm.DamageState, sp.csr_matrix] | None = None
        self._k_stab: tuple[dm.DamageState, sp.csr_matrix] | None = None

    # ------------------------------------------------------------------ fields of a damage state

    def band_widths(self, state: dm.DamageState) -> np.ndarray:
        """L_s = V_I / A_I of the damaged particles (1 elsewhere, unused), shape ``(n,)`` [m]; a
        particle without chord along its crack has A_I = sqrt(V_I) from its initiation
        (``rkfx.fracture.damage.initiate``)."""
        w = np.ones(self.n)
        on = np.flatnonzero(state.damaged)
        w[on] = self.volume[on] / state.chord[on]
        return w

    def permeability(self, state: dm.DamageState, strain: np.ndarray) -> np.ndarray:
        """k_f (5.8) per particle, shape ``(n, 2, 2)`` [m^2/(Pa s)]: the crack bands' and, at the
        particles covering a pre-existing fracture, the fracture's at the last residual (open:
        (5.8) with w = g_N; closed: k_f0 / 100), their band's enhancement kept."""
        k = crack_permeability(self.rock.mobility, state.damage, CrackBands(_unit(state.normal),
                               self.band_widths(state)), strain, self.rock.viscosity)
        if self.fracture is not None:
            self.fracture.added_permeability(k, self.rock.mobility, self.rock.viscosity)
        return k

    def pressures(self, x: np.ndarray) -> np.ndarray:
        """p^h at the particles for the unknowns ``x`` [Pa], shape ``(n,)``."""
        return self._values @ x[2 * self.n:]

    def displacements(self, x: np.ndarray) -> np.ndarray:
        """u^h at the particles for the unknowns ``x`` [m], shape ``(n, 2)``."""
        return self._values @ x[:2 * self.n].reshape(-1, 2)

    def _loads(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """F^ext and Q^ext at t: boundary tractions and fluxes, and the injected fluid."""
        f, q = self._boundary_loads(t)
        if self._injection is not None:
            weights, rate = self._injection
            q = q + float(rate(t)) * weights
        return f, q

    # ------------------------------------------------------------------ model protocol

    def _stabilization(self) -> sp.csr_matrix:
        """The MSCNI subcell stiffness (3.56) with the committed damage's (1 - D) of each
        subcell's particle: lagged by a step, so that the Jacobian stays consistent."""
        if self._k_stab is None or self._k_stab[0] is not self.committed:
            it = self.integration
            frac = self.stiffness_fraction(self.committed.damage)
            # MSCNI's grad-grad quadratures less plain SCNI: the subcell terms alone.
            quads = [*it.gradient_quads, replace(self.nodal, weights=-self.nodal.weights)]
            owners = [*it.gradient_owners, it.nodes]
            self._k_stab = (self.committed, stiffness(quads, [frac[o][:, None, None] * self._C for o in owners]))
        return self._k_stab[1]

    def _split(self, x):
        return x[:2 * self.n], x[2 * self.n:]

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        u, P = self._split(x)
        eps = row_strains(self._grad, u)
        self.strain = eps
        self.trial = upd = self._damage(eps)
        st = upd.state
        frac = self.stiffness_fraction(st.damage)
        stress = frac[:, None] * (eps @ self._C.T)
        if self.closure is not None:
            stress += self.closure.stress(eps, _unit(st.normal), 1.0 - frac)
        it = self.integration
        f_int = self._bt @ (self.volume[:, None] * stress).ravel() + self._stabilization() @ u
        alpha = self.rock.biot(st.damage)
        self._coupling = (self._div.T @ sp.diags(alpha * self.volume) @ self._values).tocsr()
        if self.fracture is not None:
            f_int = f_int + self.fracture.forces(u, P)  # before the permeability: it reads the apertures
        k = self.permeability(st, eps)
        self._kh = laplacian(it.gradient_quads, it.at_points(k, None, gradients=True))
        self._P = P
        f_ext, q_ext = self._loads(t)
        return np.r_[f_int - self._coupling @ P - f_ext, self._kh @ P - q_ext]

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        """The symmetrized Jacobian's blocks (5.36): [[K_U, -K_C], [0, K_H]] at the last residual."""
        self._count += 1
        # (5.35) with 1 - D floored at the residual fraction, as in the stress.
        tangent = self.trial.tangent
        if self.closure is not None:
            st = self.trial.state
            tangent = tangent + self.closure.tangent(self.strain, _unit(st.normal),
                                                     1.0 - self.stiffness_fraction(st.damage))
        k_u = stiffness([self.nodal], [tangent]) + self._stabilization()
        k_up = -self._coupling
        if self.fracture is not None:
            k_u, k_up = k_u + self.fracture.stiffness(), k_up + self.fracture.pressure_coupling()
        k_pu = self._permeability_derivative() if self.jacobian == "full" else None
        return sp.bmat([[k_u, k_up], [k_pu, self._kh]], format="csr")

    def _permeability_derivative(self) -> sp.csr_matrix | None:
        """d(K_H P)/dU (5.33) at the last residual, shape ``(n, 2 n)``, or ``None`` where no
        crack conducts beyond the intact rock.

        Along the crack direction t of a damaged particle L, k_L = k_f0 + (k_fC - k_f0) t t with
        k_fC = w^3 / (12 mu_f L_s) where it exceeds k_f0; dk_fC/deps = (w^2 / (4 mu_f L_s)) dw/deps
        with dw/deps = L_s (D n n + (n . eps . n) dD/deps) on an opening band (n . eps . n > 0).
        """
        st, committed, eps = self.trial.state, self.committed, self.strain
        bands = CrackBands(_unit(st.normal), self.band_widths(st))
        w = crack_flow.crack_aperture(st.damage, bands.width, bands.normal, eps)
        kfc = crack_flow.fracture_permeability(w, bands.width, self.rock.viscosity)
        on = np.flatnonzero(kfc > self.rock.mobility)
        if on.size == 0:
            return None
        nrm, ls = bands.normal[on], bands.width[on]
        nn = np.column_stack([nrm[:, 0] ** 2, nrm[:, 1] ** 2, nrm[:, 0] * nrm[:, 1]])
        dwde = st.damage[on, None] * ls[:, None] * nn
        loading = np.flatnonzero((st.kappa[on] > committed.kappa[on]) & (st.damage[on] < 1.0))
        if loading.size:
            j = on[loading]
            mat = self.rock.damage_material
            slope = dm.damage_slope(st.kappa[j], self.points.kappa0[j], st.kappa_c[j])
            grad = dm.equivalent_strain_gradient(eps[j], mat.nu, mat.plane)
            dwde[loading] += (ls[loading] * crack_flow.normal_strain(eps[j], nrm[loading]))[:, None] * slope[:, None] * grad
        factor = np.zeros(self.n)
        factor[on] = w[on] ** 2 / (4.0 * self.rock.viscosity * ls)
        # Rows dw/deps . B_L over the displacement coefficients, for every particle (zero off ``on``).
        de = np.zeros((self.n, 3))
        de[on] = dwde
        b = self._bt.T.tocsr()
        rows = sp.diags(de[:, 0]) @ b[0::3] + sp.diags(de[:, 1]) @ b[1::3] + sp.diags(de[:, 2]) @ b[2::3]
        t = np.column_stack([-_unit(st.normal)[:, 1], _unit(st.normal)[:, 0]])
        total = None
        it = self.integration
        for q, owner in zip(it.gradient_quads, it.gradient_owners):
            gx, gy = q.gradients.matrix(0), q.gradients.matrix(1)
            g = np.column_stack([gx @ self._P, gy @ self._P])
            tq = t[owner]
            scale = q.weights * factor[owner] * (tq * g).sum(axis=1)
            if not np.any(scale):
                continue
            left = gx.T @ sp.diags(scale * tq[:, 0]) + gy.T @ sp.diags(scale * tq[:, 1])
            term = left @ rows[owner]
            total = term if total is None else total + term
        return None if total is None else total.tocsr()

    def mass(self) -> sp.csr_matrix:
        return sp.diags(self._mass, format="csr")

    def capacity(self, dt: float) -> sp.csr_matrix:
        """[[0, 0], [K_C^T, S + S_fpp(dt)]] of the committed damage (built once per step)."""
        if self._capacity is None or self._capacity[0] != dt or self._capacity[1] is not self.committed:
            st = self.committed
            alpha = self.rock.biot(st.damage)
            it = self.integration
            kc = (self._div.T @ sp.diags(alpha * self.volume) @ self._values).tocsr()
            ks = mass(it.quads, it.at_points(self.rock.storage(alpha), None))
            eps_f = fpp_parameter(self._intact, dt, self._h)
            eps_f[st.damaged] = 0.0  # no projection where the crack conducts (5.30)
            rows, weights, owners = self._fpp
            stab = sum((r.matrix().T @ sp.diags(eps_f[o] * w) @ r.matrix() for r, w, o in zip(rows, weights, owners)),
                       sp.csr_matrix((self.n, self.n)))
            n2 = 2 * self.n
            cap = sp.bmat([[sp.csr_matrix((n2, n2)), None], [kc.T, (ks + stab).tocsr()]], format="csr")
            self._capacity = (dt, self.committed, cap)
        return self._capacity[2]

    def constraints(self, t: float) -> Constraints:
        return Constraints(self._col.G, self._col.values(self.p.x, t))

    def equation_weights(self, co) -> np.ndarray:
        """-beta_2 dt / beta_1 = -1 / (du'/du) on the storage rows, as in (5.24)."""
        n = self.n
        return np.r_[np.ones(2 * n), np.full(n, -1.0 / co.dv[0])]

    def _damage(self, eps: np.ndarray) -> dm.DamageUpdate:
        """The damage of ``eps``: the trial with the tracking admissions, or the step's impl-ex
        extrapolation (``DamageHistory.step_damage``)."""
        return self.step_damage(eps, tangent_floor=self.residual_fraction)


def _unit(normal: np.ndarray) -> np.ndarray:
    """Normals with zero rows (intact particles) replaced by (0, 1): unused where D = 0."""
    n = np.array(normal, float)
    zero = np.hypot(n[:, 0], n[:, 1]) == 0
    n[zero] = (0.0, 1.0)
    return n

