"""An elastic-plastic solid at finite deformation on moving RK particles (eqs. 6.8-6.13, 6.22-6.29, 6.50-6.79).

The updated-Lagrangian form of chapter 6 without the fluid: the particles move with the
material, the RK approximation and its nodal integration are rebuilt in the current
configuration after every step (``rkfx.approximation.semi_lagrangian``,
``rkfx.integration.nodal_stabilized``), and the stress is advanced by its Jaumann rate and a
Drucker-Prager return map. The model is an ``ExplicitBase`` model of
``rkfx.solvers.central_difference`` (d = the displacement coefficients since the start; its
internal force is called once per step with the new d and commits the step):

1. du = d - d_n; the velocity-gradient increment at each particle L from the trial gradients
   of the rule at x^n, dL = sum_I du_I (x) grad N_I(x_L), and the particle's move
   dx_L = sum_I N_I(x_L) du_I.
2. The stress: rotated by the spin of dL (6.13), then ``DruckerPrager.update`` with the strain
   increment sym(dL) (6.12). The volume V_L *= det(I + dL), kept within a factor
   ``max_dilation`` of V_L^0: beyond it the volume a particle gains is the void opened where
   grains part (the tension cut-off), not material; the mass m_L = rho V_L^0 stays.
3. NSNI only: the stress gradients tau_,x and tau_,y of the assumed stress (6.76) are the
   implicit gradients (6.29) of the particle stresses, sum_J N^∇_J(x_L) sigma_J, in the
   current configuration: no history, bounded by how the stress varies between particles.
4. The particles move, the approximation is rebuilt there (incremental neighbour search) and
   the internal force is evaluated in the new configuration (boundary segments stretched
   beyond the supports of their ends are left out of the corrected rules' boundary integral:
   grains have parted there):

       f_I = sum_L V_L B_I^c(x_L)^T sigma_L + sum_L [m_Lx B_I,x^T tau_,x + m_Ly B_I,y^T tau_,y]
             - sum_L N_I(x_L) F_L^wall,

   with the corrected test gradients of the rule, its second moments, and the wall forces of
   ``rkfx.assembly.rigid_walls``.

With ``viscosity`` beta > 0 a viscous stress 2 eta D (eta = beta rho c h_L, c the elastic
wave speed, h_L = sqrt(V_L), D the rate of deformation of the last step) is added to sigma in
the force: an artificial viscosity that vanishes with the particle spacing. ``eta`` [Pa s]
adds a fixed viscosity to it, the same at every spacing: a Kelvin-Voigt regularization of the
material itself (on the column collapse the run-out converges with it, 0.498 / 0.495 / 0.487
at 21 / 41 / 81 particles across, the finest at half the step; docs/large_deformation.md).

The lumped mass of coefficient I is the particle mass m_I (a constant; the row sums of the
moving approximation would change from step to step), and gravity is m_I g.

Status (measured on the collapse of a dry column, docs/large_deformation.md): with the sheet
rows of ``rkfx.approximation.semi_lagrangian`` SNNI and NSNI without the VC correction run the
collapse to the end at 21-81 particles across, far too mobile without viscosity and nearly to
rest near the published run-out with beta = 0.1 (not a converged result: eta falls with h);
the VC-corrected rules still fail (non-symmetric systems).
"""
from collections.abc import Mapping, Sequence

import numpy as np

from rkfx.approximation.semi_lagrangian import evaluate_moving, moved, moving_rk
from rkfx.assembly.rigid_walls import Wall, WallContact, wall_forces
from rkfx.errors import InputError, point_str
from rkfx.integration.nodal_stabilized import RULES, boundary_rule, nodal_cells, nodal_integration
from rkfx.materials import jaumann
from rkfx.materials.drucker_prager import DruckerPrager
from rkfx.solvers.central_difference import ExplicitBase
from rkfx.solvers.fields import single

#: omega sqrt(V) / c of the fastest mode at the smallest particle: on the column collapse's
#: grid the measured omega_max dt = 0.59 at dt = 0.3 h / c, at the corner (V^0 / 1.25 = h^2 / 7.5).
OMEGA_V = 0.59 / 0.3 * np.sqrt(1.0 / 7.5)


def _gradients(rows, du: np.ndarray) -> np.ndarray:
    """L[:, c, k] = sum_I rows_k(I) du[I, c] for gradient rows with components (d/dx, d/dy)."""
    return np.transpose(rows @ du, (0, 2, 1))


def _divergence(rows, stress: np.ndarray) -> np.ndarray:
    """sum_L rows(I, L)^T (sigma_xx, sigma_xy; sigma_xy, sigma_yy)_L, per coefficient ``(n, 2)``:
    ``stress`` (m, 4) already weighted."""
    bx, by = rows.matrix(0).T, rows.matrix(1).T
    return np.column_stack([bx @ stress[:, 0] + by @ stress[:, 3], bx @ stress[:, 3] + by @ stress[:, 1]])


class LagrangianPlasticity(ExplicitBase):
    """The explicit model of a Drucker-Prager solid on moving particles (module docstring).

    Args:
        x: Initial particle positions, shape ``(n, 2)`` [m].
        volume: Their volumes (areas) V_L^0, shape ``(n,)`` [m^2].
        support: RK support radii a_I, shape ``(n,)`` or a scalar [m].
        boundary: Particle pairs along the boundary with the body on their left, ``(k, 2)``;
            they move with the particles (the corrected rules integrate N_I n over them).
        soil: The Drucker-Prager law.
        density: rho [kg/m^3].
        dt: The time step of the run [s] (the walls' penalty and friction use it); refused
            beyond ``stable_step``, the linear limit of elasticity and viscosity together at the
            smallest particle [s].
        rule: A nodal rule of ``rkfx.integration.nodal_stabilized.RULES``.
        walls: Rigid walls (``rkfx.assembly.rigid_walls.Wall``).
        gravity: (g_x, g_y) [m/s^2].
        stress: Initial effective stress, shape ``(n, 4)`` [Pa] (default 0).
        skin: Verlet skin of the neighbour search [m] (default half the smallest support / 2).
        kappa: Wall penalty in units of m / dt^2.
        max_dilation: Bound on V_L / V_L^0 and V_L^0 / V_L (see the module docstring).
        viscosity: beta of the artificial viscosity eta = beta rho c h_L (module docstring).
        eta: A fixed viscosity [Pa s] added to it.
    """

    def __init__(self, x: np.ndarray, volume: np.ndarray, support, boundary: np.ndarray, soil: DruckerPrager,
                 density: float, dt: float, *, rule: str = "nsni", walls: Sequence[Wall] = (),
                 gravity=(0.0, -9.81), stress: np.ndarray | None = None, skin: float | None = None,
                 kappa: float = 0.1, max_dilation: float = 1.25, viscosity: float = 0.0,
                 eta: float = 0.0):
        x = np.array(x, dtype=np.float64)
        n = len(x)
        if rule not in RULES:
            raise InputError(f"unknown nodal integration rule {rule!r}; choose one of {', '.join(RULES)}")
        if not (np.isfinite(density) and density > 0):
            raise InputError(f"density = {density!r} must be positive [kg/m^3]")
        if not (np.isfinite(dt) and dt > 0):
            raise InputError(f"dt = {dt!r} must be a positive time step [s]")
        self.volume = np.array(np.broadcast_to(np.asarray(volume, float), (n,)))
        if not np.all(self.volume > 0):
            bad = int(np.flatnonzero(~(self.volume > 0))[0])
            raise InputError(f"particle {bad} has volume {self.volume[bad]!r}; particle volumes must be positive")
        self.support = np.ascontiguousarray(np.broadcast_to(np.asarray(support, float), (n,)))
        self.boundary = np.asarray(boundary, dtype=np.int64).reshape(-1, 2)
        self.soil, self.density, self.dt, self.rule_name = soil, float(density), float(dt), rule
        self.walls, self.kappa = tuple(walls), float(kappa)
        self.gravity = np.asarray(gravity, float)
        self.skin = float(0.25 * self.support.min() if skin is None else skin)
        if not (np.isfinite(max_dilation) and max_dilation > 1.0):
            raise InputError(f"max_dilation = {max_dilation!r} must be a ratio > 1 (e.g. 1.25)")
        self.volume0, self.max_dilation = self.volume.copy(), float(max_dilation)
        if not (np.isfinite(viscosity) and viscosity >= 0.0):
            raise InputError(f"viscosity = {viscosity!r} must be >= 0 (a fraction of rho c h)")
        if not (np.isfinite(eta) and eta >= 0.0):
            raise InputError(f"eta = {eta!r} must be a viscosity >= 0 [Pa s]")
        self.viscosity, self.eta, self.rate = float(viscosity), float(eta), None
        self._rho_c = density * np.sqrt((soil.bulk_modulus + 4.0 * soil.shear_modulus / 3.0) / density)
        # The explicit step's linear limit at the smallest particle (V_L down to V_L^0 /
        # max_dilation), elasticity and viscosity together: omega dt <= 2 (sqrt(1 + xi^2) - xi)
        # with xi = nu / 2 omega, nu = eta_L / (rho V_L) the viscous rate (alone: dt <= 2 / nu)
        # and omega = OMEGA_V c / sqrt(V_L) (alone: dt <= 2 / omega). OMEGA_V is calibrated on
        # the column of bench/column_collapse.py: the largest eigenvalue of M^-1 K at the start
        # is omega_max dt = 0.59 at dt = 0.3 h / c, at the top corner (V^0 = h^2 / 6), so a step
        # beyond about h / c is refused. With a fixed eta that column ran to the end at 0.28
        # and 0.56 of the viscous limit (21 and 41 across) and turned the corner inside out
        # within 39 steps at 1.1. Necessary, not sufficient: at 81 across a run at 0.60 of
        # this limit (0.45 of the viscous one) failed near the free top, a local failure of the
        # flow, and ran at half the step.
        self.stable_step = self._linear_limit(density)
        if dt > self.stable_step:
            raise InputError(f"dt = {dt:.3g} s is beyond the explicit limit of elasticity and viscosity at the "
                             f"smallest particle, {self.stable_step:.3g} s; reduce dt (or eta, viscosity)")
        self.particle_mass = self.density * self.volume
        self.layout = single("u", 2, 2, n)
        self.essential = ()
        self.x = x
        self.stress = np.zeros((n, 4)) if stress is None else np.array(stress, float)
        if self.stress.shape != (n, 4):
            raise InputError(f"initial stresses of shape {self.stress.shape} for {n} particles: give (n, 4) "
                             "(xx, yy, zz, xy)")
        self.plastic_strain = np.zeros(n)
        self.d_last = np.zeros(2 * n)
        self.counters = np.zeros(3, np.int64)  # steps, steps with a search, rows searched
        self.torn = np.zeros(2, np.int64)  # evaluation points given Shepard rows and sheet rows
        self.yielded = np.zeros(n, bool)
        self.contact: WallContact | None = None
        self._rebuild(fresh=True)

    def _linear_limit(self, density: float) -> float:
        """The linear limit of the explicit step at the smallest particle (see ``__init__``)."""
        small = self.volume0 / self.max_dilation
        c = self._rho_c / density
        omega = OMEGA_V * c / np.sqrt(small)
        nu = (self.eta + self.viscosity * self._rho_c * np.sqrt(small)) / (density * small)
        xi = nu / (2.0 * omega)
        return float(np.min(2.0 / omega * (np.sqrt(1.0 + xi * xi) - xi)))

    # -- the approximation in the current configuration

    def _rebuild(self, fresh: bool = False) -> None:
        cells = nodal_cells(self.x, self.volume)
        if fresh or cells.reach > self.rk.reach:
            self.rk = moving_rk(self.x, self.support, self.skin, reach=1.5 * cells.reach, torn=self.torn)
            searched = self.rk.searched
        else:
            self.rk = moved(self.rk, self.x)
            searched = self.rk.searched
        if not fresh:
            self.counters += [1, searched > 0, searched]
        edges = None
        if len(self.boundary):
            # A boundary segment stretched beyond its end's support is no longer a surface of the
            # body but a gap between parted grains: its points are covered by no one.
            a, b = self.boundary[:, 0], self.boundary[:, 1]
            length = np.linalg.norm(self.x[b] - self.x[a], axis=1)
            edges = boundary_rule(self.x, self.boundary[length < np.minimum(self.support[a], self.support[b])])
        self.rule = nodal_integration(self.rk, cells, edges, self.rule_name)
        self.implicit = evaluate_moving(self.rk, implicit=True) if self.rule.moments is not None else None

    # -- the explicit model

    def lumped_mass(self) -> np.ndarray:
        return np.repeat(self.particle_mass, 2)

    def external_force(self, t: float) -> np.ndarray:
        return (self.particle_mass[:, None] * self.gravity[None, :]).ravel()

    def internal_force(self, d: np.ndarray) -> np.ndarray:
        du = (d - self.d_last).reshape(-1, 2)
        if np.any(du):
            self._advance(du)
            self.d_last = d.copy()
        r = self.rule
        total = self.stress
        if self.rate is not None:
            if self.viscosity > 0.0:
                total = total + (self._rho_c * self.rate) * (self.viscosity * np.sqrt(self.volume))[:, None]
            if self.eta > 0.0:
                total = total + self.eta * self.rate
        f = _divergence(r.test, r.weights[:, None] * total)
        if r.moments is not None:
            tau = self.implicit @ self.stress  # (n, 3, 4): [sigma, d sigma / dx, d sigma / dy] at the particles
            for k, rows in enumerate((r.trial_x, r.trial_y)):
                f += _divergence(rows, r.moments[:, k:k + 1] * tau[:, 1 + k])
        self.contact = None
        if self.walls:
            dx = r.values @ du
            self.contact = wall_forces(self.walls, self.x, dx[:, 0], self.particle_mass, self.dt, self.kappa)
            f -= r.values.matrix().T @ self.contact.force
        return f.ravel()

    def _advance(self, du: np.ndarray) -> None:
        r = self.rule
        L = _gradients(r.trial, du)
        if self.viscosity > 0.0 or self.eta > 0.0:
            d = jaumann.strain_increment(L, 1.0 / self.dt)
            self.rate = np.column_stack([2.0 * d[:, 0], 2.0 * d[:, 1], np.zeros(len(d)), d[:, 2]])
        rotated = jaumann.rotated(self.stress, L, 1.0)
        step = self.soil.update(rotated, jaumann.strain_increment(L, 1.0), self.plastic_strain)
        self.stress, self.plastic_strain, self.yielded = step.stress, step.plastic_strain, step.yielded
        jac = (1.0 + L[:, 0, 0]) * (1.0 + L[:, 1, 1]) - L[:, 0, 1] * L[:, 1, 0]
        if not np.all(jac > 0):
            bad = int(np.flatnonzero(~(jac > 0))[0])
            raise InputError(f"particle {bad} at {point_str(self.x[bad])} was turned inside out in one step "
                             f"(det F = {jac[bad]:.3g}); reduce the time step")
        self.volume = np.clip(self.volume * jac, self.volume0 / self.max_dilation, self.volume0 * self.max_dilation)
        self.x = self.x + (r.values @ du)[:, 0]
        self._rebuild()

    # -- history

    def state(self) -> dict[str, np.ndarray]:
        return {"x": self.x, "volume": self.volume, "stress": self.stress,
                "plastic_strain": self.plastic_strain, "d_last": self.d_last, "counters": self.counters,
                "torn": self.torn}

    def restore(self, arrays: Mapping[str, np.ndarray]) -> None:
        for key in self.state():
            setattr(self, key, np.array(arrays[key]))
        if self.torn.shape == (1,):  # a checkpoint written before sheet rows were counted
            self.torn = np.array([self.torn[0], 0], np.int64)
        self._rebuild(fresh=True)

    @property
    def neighbour_rebuilds(self) -> dict[str, int]:
        """Steps run, steps that searched some rows again, and rows searched in all."""
        steps, searches, rows = map(int, self.counters)
        return {"steps": steps, "steps_with_search": searches, "rows_searched": rows,
                "torn_point_evaluations": int(self.torn[0]), "sheet_point_evaluations": int(self.torn[1])}
