"""Unsaturated u-p poroelasticity with gravity in dolfinx: the FEM baseline of the Liakopoulos
column (the equations of ``rkfx.models.unsaturated_poroelasticity``, eqs. 6.15-6.16).

Taylor-Hood (P2-P1 or Q2-Q1) with the Galerkin forms

    F_u = int sigma''(u) : eps(v) - alpha S p div v - (rho_0 + n rho_w S) g . v
    F_p = int k k_rw (grad p - S rho_w g) . grad q  [+ int_face kappa <p>_+ q ds]
    c   = int q (alpha S div u' + p' / Q)

and their exact derivatives (d(1/Q)/dp by central differences, as in the RKPM model). The
coefficients S_w, k_rw, 1/Q and their slopes are the retention law's numpy functions
(``rkfx.materials.retention``) evaluated at the quadrature points of a quadrature space and
held there as Functions, so the physics is written once; the forms take the same quadrature
degree. The model reuses :class:`fem_baselines.poroelasticity.FemBiotModel` for the numbering,
the boundary conditions and the gathering into scipy CSR, and is stepped by ``rkfx.solvers``
like the RKPM model (``rate_force`` for the state-dependent capacity).
"""
from __future__ import annotations

from collections.abc import Sequence

import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py: orders MPI loading)

import basix.ufl
import numpy as np
import scipy.sparse as sp

import dolfinx
import dolfinx.fem
import ufl

from fem_baselines.elasticity import strain, stress_law
from fem_baselines.poroelasticity import FemBiotModel, _global_matrix, _global_vector
from rkfx.assembly.seepage_face import check_penalty
from rkfx.conditions import Condition
from rkfx.errors import InputError
from rkfx.models.plastic_points import PlasticPoints
from rkfx.models.unsaturated_poroelasticity import WEIGHTS, UnsaturatedSoil

#: Names of the coefficient Functions on the quadrature space (``UnsaturatedSoil.coefficients``).
COEFFICIENTS = ("S", "dS", "kr", "dkr", "iQ", "diQ")


class FemUnsaturatedModel(PlasticPoints, FemBiotModel):
    """The unsaturated u-p equations on a Taylor-Hood mesh, as a model of ``rkfx.solvers``.

    Args:
        mesh: A 2-D dolfinx mesh.
        soil: Constituents, retention law and gravity (g along -y).
        conditions: ``rkfx.conditions`` (Displacement, Pressure; Traction and Flux as loads).
        quadrature_degree: Of every form and of the coefficient space.
        seepage: ``(part, kappa)``: a seepage face on a boundary part with the one-sided outflow
            kappa <p>_+ [m/(Pa s)] of ``rkfx.assembly.seepage_face``, or ``None``.
        weight: The skeleton's body load, as in the RKPM model: rho_0 = -n rho_w (``"change"``,
            from the saturated state) or (1 - n) rho_s (``"full"``).
        facet_tags, physical_groups: Of a gmsh mesh (``fem_baselines.gmsh_mesh``), so that
            conditions may name its boundary groups.
        plasticity: A Drucker-Prager skeleton (the medium's E and nu, ``weight="full"``), as in
            the RKPM model: sigma'' at each quadrature point the return map of its committed
            stress by the step's strain increment (``rkfx.materials.drucker_prager``, the same
            numpy law on a quadrature space), the Jacobian its algorithmic tangent; history
            committed with each step. ``None``: elastic.
        ramp: The load factor lambda(t) on the skeleton's loads (weight, the pore pressure's
            force, the tractions), as in the RKPM model; ``None``: 1.
    """

    def __init__(self, mesh: dolfinx.mesh.Mesh, soil: UnsaturatedSoil, conditions: Sequence[Condition],
                 quadrature_degree: int = 4, seepage: tuple | None = None, weight: str = "change",
                 facet_tags=None, physical_groups=None, plasticity=None, ramp=None):
        if weight not in WEIGHTS:
            raise InputError(f"weight = {weight!r}: choose {' or '.join(WEIGHTS)}")
        m = soil.medium
        mat = m.material
        super().__init__(mesh, m.E, m.nu, m.k, mat.alpha, mat.S, "taylor-hood", conditions, facet_tags=facet_tags,
                         physical_groups=physical_groups)
        self.soil, self.linear = soil, False
        cell = mesh.topology.cell_name()
        W = dolfinx.fem.functionspace(mesh, basix.ufl.quadrature_element(cell, value_shape=(), degree=quadrature_degree))
        self.W = W
        self.uh, self.ph = dolfinx.fem.Function(self.V), dolfinx.fem.Function(self.Q)
        self.vu, self.vp = dolfinx.fem.Function(self.V), dolfinx.fem.Function(self.Q)
        self.coef = {name: dolfinx.fem.Function(W, name=name) for name in COEFFICIENTS}
        self._p_at = dolfinx.fem.Expression(self.ph, W.element.interpolation_points)
        self._pq = dolfinx.fem.Function(W)
        dx = ufl.dx(domain=mesh, metadata={"quadrature_degree": quadrature_degree})
        scalar = dolfinx.default_scalar_type
        const = lambda value: dolfinx.fem.Constant(mesh, scalar(value))  # noqa: E731
        alpha, n, rho, k = const(mat.alpha), const(m.porosity), const(m.rho_f), const(m.k)
        rho_0 = const(-m.porosity * m.rho_f if weight == "change" else (1.0 - m.porosity) * m.rho_s)
        g = dolfinx.fem.Constant(mesh, np.array([0.0, -soil.gravity], dtype=scalar))
        S, dS, kr, dkr, iQ, diQ = (self.coef[c] for c in COEFFICIENTS)
        sigma = stress_law(mesh, mat.elastic)
        u, p = self.uh, self.ph
        v, q = ufl.TestFunction(self.V), ufl.TestFunction(self.Q)
        du, dp = ufl.TrialFunction(self.V), ufl.TrialFunction(self.Q)
        flux = grad_p = ufl.grad(p) - S * rho * g
        form = dolfinx.fem.form
        self.plasticity, self.ramp = plasticity, ramp
        self._skeleton_forms(mesh, cell, quadrature_degree, weight, sigma, dx, const, alpha, n, rho, rho_0, g)
        F_p = k * kr * ufl.inner(flux, ufl.grad(q)) * dx
        J_pp = (k * kr * ufl.inner(ufl.grad(dp), ufl.grad(q)) + k * dkr * dp * ufl.inner(grad_p, ufl.grad(q))
                - k * kr * dS * dp * rho * ufl.inner(g, ufl.grad(q))) * dx
        self._c_p = form(q * (alpha * S * ufl.div(self.vu) + iQ * self.vp) * dx)
        self._C_x = form(q * (alpha * dS * ufl.div(self.vu) + diQ * self.vp) * dp * dx)
        self._C_vu = form(q * alpha * S * ufl.div(du) * dx)
        self._C_vp = form(q * iQ * dp * dx)
        self._face = None
        if seepage is not None:
            part, kappa = seepage
            check_penalty(kappa)
            ds = ufl.Measure("ds", domain=mesh, subdomain_data=self.boundary.tags([part], "seepage face"))(1)
            wet = ufl.conditional(ufl.gt(p, 0.0), 1.0, 0.0)
            outflow = const(kappa) * ufl.max_value(p, 0.0)
            self._face = form(outflow * ds)
            F_p = F_p + outflow * q * ds
            J_pp = J_pp + const(kappa) * wet * dp * q * ds
        self._F_p, self._J_pp = form(F_p), form(J_pp)
        self._kuu = _global_matrix(self._J_uu, self.comm) if self.plasticity is None else None
        self._q = [form(-k * kr * flux[j] * dx) for j in range(2)]

    def _skeleton_forms(self, mesh, cell, degree, weight, sigma, dx, const, alpha, n, rho, rho_0, g) -> None:
        """F_u and its Jacobian with the load factor (1 without a ramp), and with plasticity the
        stress and tangent held on quadrature spaces (Voigt: strain (xx, yy, gamma_xy), stress
        (xx, yy, xy))."""
        u, v, du, p = self.uh, ufl.TestFunction(self.V), ufl.TrialFunction(self.V), self.ph
        S, dS = self.coef["S"], self.coef["dS"]
        self._lam = lam = const(1.0)
        form = dolfinx.fem.form
        at_one = alpha * S * p * ufl.div(v) + (rho_0 + n * rho * S) * ufl.inner(g, v)
        self._F_load = form(at_one * dx)  # the skeleton's loads at lambda = 1
        loads = -lam * at_one
        self._J_up = form(lam * (-alpha * (S + dS * p) * ufl.div(v) - n * rho * dS * ufl.inner(g, v)) *
                          ufl.TrialFunction(self.Q) * dx)
        if self.plasticity is None:
            self._F_u = form((ufl.inner(sigma(u), strain(v)) + loads) * dx)
            self._J_uu = form(ufl.inner(sigma(du), strain(v)) * dx)
            return

        def space(shape):
            return dolfinx.fem.functionspace(mesh, basix.ufl.quadrature_element(cell, value_shape=shape, degree=degree))

        def voigt(w):
            e = strain(w)
            return ufl.as_vector([e[0, 0], e[1, 1], 2.0 * e[0, 1]])

        Wv, Wt = space((3,)), space((3, 3))
        self._eps_at = dolfinx.fem.Expression(voigt(u), Wv.element.interpolation_points)
        self._eps = dolfinx.fem.Function(Wv)
        self._sig = dolfinx.fem.Function(Wv)       # (xx, yy, xy) of the trial stress
        self._ct = dolfinx.fem.Function(Wt)
        self._F_u = form((ufl.inner(self._sig, voigt(v)) + loads) * dx)
        self._J_uu = form(ufl.inner(ufl.dot(self._ct, voigt(du)), voigt(v)) * dx)
        m = self.soil.medium
        self._plastic_points(self.plasticity, self.ramp, weight, m.E, m.nu, len(self._eps.x.array) // 3)

    # ------------------------------------------------------------------ state

    def _set(self, x: np.ndarray) -> None:
        """u_h, p_h and the coefficients at the quadrature points from the unknowns."""
        self.assign(x, self.uh, self.ph)
        self._pq.interpolate(self._p_at)
        values = self.soil.coefficients(self._pq.x.array)
        for name in COEFFICIENTS:
            self.coef[name].x.array[:] = values[name]

    def _blocks(self, uu, up, pu, pp) -> sp.csr_matrix:
        n_u, n_p = self._n_u, self.layout.size - self._n_u
        zero = lambda r, c: sp.csr_matrix((r, c))  # noqa: E731
        return sp.bmat([[uu if uu is not None else zero(n_u, n_u), up if up is not None else zero(n_u, n_p)],
                        [pu if pu is not None else zero(n_p, n_u), pp if pp is not None else zero(n_p, n_p)]],
                       format="csr")

    # ------------------------------------------------------------------ model

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        self._set(x)
        self._t_trial = t
        lam = self._factor(t)
        self._lam.value = lam
        if self.plasticity is not None:
            self._eps.interpolate(self._eps_at)
            stress = self._return_map(self._eps.x.array.reshape(-1, 3).copy())
            self._sig.x.array[:] = stress[:, [0, 1, 3]].ravel()
        r = np.r_[_global_vector(self._F_u, self.comm), _global_vector(self._F_p, self.comm)]
        loads = self.loads(t).copy()
        loads[:self._n_u] *= lam
        return r - loads

    def load_derivative(self) -> np.ndarray:
        """dr/dt at the last ``residual`` call: -lambda'(t) times the skeleton's loads at
        lambda = 1 (weight, pore pressure's force, tractions), as in the RKPM model."""
        if self.ramp is None:
            return np.zeros(self.layout.size)
        t = self._t_trial
        loads = _global_vector(self._F_load, self.comm) + self.loads(t)[:self._n_u]
        return -self._factor_slope(t) * np.r_[loads, np.zeros(self.layout.size - self._n_u)]

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        kuu = self._kuu
        if self.plasticity is not None:
            self._ct.x.array[:] = self._return_tangent().ravel()
            kuu = _global_matrix(self._J_uu, self.comm)
        return self._blocks(kuu, _global_matrix(self._J_up, self.comm), None,
                            _global_matrix(self._J_pp, self.comm))

    def rate_force(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        self._set(x)
        self.assign(v, self.vu, self.vp)
        return np.r_[np.zeros(self._n_u), _global_vector(self._c_p, self.comm)]

    def rate_tangents(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        dx = self._blocks(None, None, None, _global_matrix(self._C_x, self.comm))
        dv = self._blocks(None, None, _global_matrix(self._C_vu, self.comm), _global_matrix(self._C_vp, self.comm))
        return dx, dv

    def capacity(self, dt: float) -> None:
        return None

    def equation_weights(self, co) -> None:
        return None

    def flux_integral(self, x: np.ndarray) -> np.ndarray:
        """int q dA of Darcy's flux q = -k k_rw (grad p - S_w rho_w g) over the mesh, shape
        ``(2,)`` [m^3/s per m], summed over the ranks (collective)."""
        self._set(x)
        return np.array([self.comm.allreduce(dolfinx.fem.assemble_scalar(q)) for q in self._q])

    def seepage_outflow(self, x: np.ndarray) -> float:
        """int_face kappa <p>_+ ds [m^2/s per m] (0 without a face), summed over the ranks (collective)."""
        if self._face is None:
            return 0.0
        self._set(x)
        return float(self.comm.allreduce(dolfinx.fem.assemble_scalar(self._face)))

    def pressure_function(self, x: np.ndarray) -> dolfinx.fem.Function:
        """p_h of the unknowns ``x`` (a new Function)."""
        ph = dolfinx.fem.Function(self.Q)
        ph.x.array[:] = x[self.p_index]
        return ph
