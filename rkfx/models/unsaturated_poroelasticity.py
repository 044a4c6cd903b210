"""Unsaturated u-p poroelasticity with gravity on a nodal integration (eqs. 6.3-6.7, 6.14-6.16).

Small deformation, zero air pressure (suction s = -p), Bishop's stress with chi = S_w:

    div(sigma''(u) - alpha S_w(p) p I) + rho(S_w) g = 0                         (6.15, quasi-static)
    alpha S_w div u' + p' / Q(p) - div[k k_rw(p) (grad p - S_w rho_w g)] = 0    (6.16)

with rho = (1 - n) rho_s + n S_w rho_w (6.5), 1/Q of (6.7) and the retention law's S_w and k_rw
(``rkfx.materials.retention``). The coupling of the storage equation carries S_w as in
Zienkiewicz et al. (1999, eq. 2.9), the transpose of the stress term; (6.16) prints alpha
alone, which equals it while saturated.

By default (``weight="change"``) the displacement is measured from a saturated state (S_w = 1,
p = 0) in equilibrium with gravity (the initial effective stress balances rho_sat g), so only
rho - rho_sat = n rho_w (S_w - 1) loads the skeleton; with ``weight="full"`` the skeleton
starts unstressed and carries the whole weight rho(S_w) g, so that sigma'' = D eps(u) is the
effective stress itself (the initial state of a slope or a levee). A constant external force
f (``load``: tractions, e.g. a reservoir's water on a face) may be added, and a seepage face
(``seepage``) adds its one-sided outflow F(p) = N_face^T (w kappa <N_face p>_+)
(``rkfx.assembly.seepage_face``). The forms are those of ``rkfx.assembly.nodal_forms`` with the
coefficients at the nodes L: S_w, k_rw and 1/Q of p(x_L) = N_I(x_L) p_I. As a model of
``rkfx.solvers`` (u and p of time order 1, u quasi-static):

    r = [K u - C(S) p - f_g(S) - f,  A(k_rw) p - G(k_rw S) + F(p)]
    c(x, v) = [0,  D(S) u' + M(1/Q) p']                           (``rate_force``)

K = sum V B^c^T D B, C(S) = sum V alpha S (B^c)^T m N, D(S) = sum V alpha S N^T m^T B,
M = sum V N^T (1/Q) N, A(k) the Darcy form with k = k_f k_rw(p_L) per node including the
NSNI expansion terms (k frozen at the node's value there), and G the gravity flux
sum V (grad^c N)^T k S rho_w g. The Jacobian is exact except for d(1/Q)/dp, taken by central
differences (``rkfx.materials.retention.storage_slope``); its blocks are sums of weighted row
products on patterns found once (``rkfx.assembly.weighted_forms``). Essential conditions are
collocation rows at boundary nodes.

With ``plasticity`` the skeleton is Drucker-Prager: K u becomes sum V B^c^T sigma''(u) + the
elastic NSNI expansion terms, sigma'' the return map of each point's committed stress by its
strain increment, the Jacobian the return's algorithmic tangent; ``ramp`` scales the skeleton's
loads (gravity) by a factor lambda(t), the path a plastic state is loaded along.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.assembly import nodal_forms
from rkfx.assembly.operators import strain_matrix
from rkfx.assembly.seepage_face import SeepageFace
from rkfx.assembly.weighted_forms import WeightedForm, placed
from rkfx.errors import InputError
from rkfx.integration.nodal_stabilized import NodalIntegration
from rkfx.materials.drucker_prager import DruckerPrager
from rkfx.materials.retention import Retention, storage, storage_slope
from rkfx.models.explicit_poroelasticity import Constituents
from rkfx.models.plastic_points import PlasticPoints
from rkfx.parallel.unknowns import LocalUnknowns
from rkfx.solvers.fields import layout
from rkfx.solvers.model import Constraints, Stateless

#: Gravitational acceleration of §6.4.2 [m/s^2].
GRAVITY = 9.806

#: What the skeleton's body load is: the change of the mixture's weight from saturation, or all of it.
WEIGHTS = ("change", "full")


@dataclass(frozen=True)
class UnsaturatedSoil:
    """A soil of known constituents whose water saturation follows a retention law.

    Attributes:
        medium: The constituents (E, nu, rho_s, rho_f = rho_w, n, mobility k_f = k_in / mu_w,
            K_s, K_f = K_w) as when saturated.
        retention: S_w(s), k_rw(s) (``rkfx.materials.retention``).
        gravity: |g| [m/s^2]; g points in -y.
    """

    medium: Constituents
    retention: Retention
    gravity: float = GRAVITY

    def __post_init__(self):
        if not isinstance(self.retention, Retention):
            raise InputError(f"retention {self.retention!r} is not a retention law (saturation, saturation_slope, "
                             "relative_permeability, relative_permeability_slope)")
        if not (np.isfinite(self.gravity) and self.gravity >= 0):
            raise InputError(f"gravity = {self.gravity!r} must be >= 0 [m/s^2]")

    @property
    def alpha(self) -> float:
        return self.medium.material.alpha

    def coefficients(self, p: np.ndarray) -> dict[str, np.ndarray]:
        """S_w, k_rw, 1/Q and their derivatives in p at water pressures ``p`` [Pa]."""
        law, m = self.retention, self.medium
        s = -np.asarray(p, float)
        args = (m.porosity, self.alpha, m.K_f, m.K_s)
        return {"S": law.saturation(s), "dS": -law.saturation_slope(s),
                "kr": law.relative_permeability(s), "dkr": -law.relative_permeability_slope(s),
                "iQ": storage(law, p, *args), "diQ": storage_slope(law, p, *args)}


def _divergence(rows) -> sp.csr_matrix:
    b = strain_matrix(rows)
    return (b[0::3] + b[1::3]).tocsr()


class UnsaturatedBiotModel(PlasticPoints, Stateless):
    """The unsaturated u-p equations on one nodal rule (see the module docstring).

    Args:
        rule: The nodal integration of the (fixed) particles.
        soil: Constituents, retention law and gravity.
        constraints: Collocation rows G x = g of the essential conditions (constant), over
            the model's unknowns (with ``local``, the rank's own constraint rows over its local
            unknowns).
        local: On MPI ranks, the rank's local unknowns (``rkfx.parallel.unknowns``) and
            ``rule`` its own points' rows over the whole node set
            (``nodal_integration(..., points=)``): the model then lives on the local nodes and
            returns the contributions of its points (``share`` tells the steppers, which add
            them up). ``None``: the whole model.
        seepage: A seepage face (``rkfx.assembly.seepage_face``): outflow kappa <p>_+ through it
            (with ``local``, the rank's own points over the whole node set).
        weight: ``"change"`` (the skeleton carries rho - rho_sat) or ``"full"`` (all of rho).
        load: A constant external force over the whole model's vector (with ``local``, each
            rank adds its owned entries), or ``None``.
        plasticity: A Drucker-Prager skeleton (``rkfx.materials.drucker_prager``, the medium's E
            and nu) in place of the elastic one, with ``weight="full"``: sigma'' at each point
            is the return map of its committed stress by the strain increment of the step, and
            the Jacobian takes its algorithmic tangent; the NSNI expansion terms stay elastic
            (a stabilization). History: the points' strain, stress and equivalent plastic
            strain, committed with each step. ``None``: linear elastic.
        ramp: A load factor lambda(t) on the skeleton's loads, its weight, the pore
            pressure's force alpha S_w p and ``load`` (gravity scaled by lambda, the flow
            equation unchanged): the path along which a plastic skeleton takes its load.
            ``None``: 1.
    """

    def __init__(self, rule: NodalIntegration, soil: UnsaturatedSoil, constraints: Constraints,
                 local: LocalUnknowns | None = None, seepage: SeepageFace | None = None, weight: str = "change",
                 load: np.ndarray | None = None, plasticity: DruckerPrager | None = None,
                 ramp=None):
        if weight not in WEIGHTS:
            raise InputError(f"weight = {weight!r}: choose {' or '.join(WEIGHTS)}")
        self.local = local
        self.share = None if local is None else local.share
        if local is not None:
            rule = rule.localized(local.nodes)
            seepage = None if seepage is None else seepage.localized(local.nodes)
        self.seepage = seepage
        self._face = None if seepage is None else seepage.matrix()
        n = rule.values.num_cols
        self.n, self.rule, self.soil = n, rule, soil
        self.layout = layout(("u", 2, 1), ("p", 1, 1), nodes=n)
        self.linear = False
        if constraints.G.shape[1] != 3 * n:
            raise InputError(f"constraint rows have {constraints.G.shape[1]} columns; the model has {3 * n} unknowns")
        self._constraints = constraints
        m = soil.medium
        self.K = nodal_forms.stiffness(rule, m.material.elastic.D())
        self.N = rule.values.matrix().tocsr()
        self.NT = self.N.T.tocsr()
        self.V = rule.weights
        self.div_test = _divergence(rule.test)
        self.div_trial = _divergence(rule.trial)
        self.test = [rule.test.matrix(c).tocsr() for c in range(2)]
        self.trial = [rule.trial.matrix(c).tocsr() for c in range(2)]
        self.expansion = []  # (m_Lj, [d/dx, d/dy] rows of the j-th trial gradient)
        if rule.moments is not None:
            for j, rows in enumerate((rule.trial_x, rule.trial_y)):
                self.expansion.append((rule.moments[:, j], [rows.matrix(c).tocsr() for c in range(2)]))
        self.g = np.array([0.0, -soil.gravity])
        m = soil.medium
        self._plastic_points(plasticity, ramp, weight, m.E, m.nu, len(rule.weights))
        if plasticity is not None:
            self._plastic_skeleton(rule)
        # the skeleton's body load per unit volume is [rho_0 + n rho_w S_w] g
        self._rho_0 = -m.porosity * m.rho_f if weight == "change" else (1.0 - m.porosity) * m.rho_s
        whole = 3 * n if local is None else int(local.index.max(initial=-1)) + 1
        if load is not None and (np.ndim(load) != 1 or len(load) < whole):
            raise InputError(f"load has shape {np.shape(load)}; give the whole model's force vector")
        if load is not None and local is not None:
            owned = np.zeros(len(local.index), bool)
            owned[local.share.owned] = True
            load = np.where(owned, np.asarray(load, float)[local.index], 0.0)
        self._load = None if load is None else np.asarray(load, float)
        self._at = None
        self._forms()

    def _plastic_skeleton(self, rule: NodalIntegration) -> None:
        """The strain rows, and the elastic stabilization alone in ``K``."""
        b_test, b_trial = strain_matrix(rule.test), strain_matrix(rule.trial)
        self._b_test = [b_test[c::3].tocsr() for c in range(3)]
        self._b_trial = [b_trial[c::3].tocsr() for c in range(3)]
        self.K = nodal_forms.stabilization_stiffness(rule, self.soil.medium.material.elastic.D())

    def _forms(self) -> None:
        """The patterns of the Jacobian (``tangent``) and of the rate derivatives."""
        n, size = self.n, 3 * self.n
        on_p = lambda a: placed(a, size, 2 * n)  # noqa: E731
        N = on_p(self.N)
        self._components = [c for c in range(2) if self.g[c] != 0.0]
        pairs = [(placed(self.div_test, size), N)]                              # -C(S + S' p)
        pairs += [(placed(self.N, size, c, 2), N) for c in self._components]    # d f_g / dp
        pairs += [(on_p(self.test[j]), on_p(self.trial[j])) for j in range(2)]  # A(k)
        pairs += [(on_p(r), on_p(r)) for _, rows in self.expansion for r in rows]
        pairs += [(on_p(self.test[j]), N) for j in range(2)]                    # dk, dS of the flux
        pairs += [(on_p(r), N) for _, rows in self.expansion for r in rows]
        if self._face is not None:
            pairs += [(on_p(self._face), on_p(self._face))]                     # d(kappa <p>_+)/dp
        if self.plasticity is not None:                                         # B^T C_T B
            pairs += [(placed(bt, size), placed(br, size)) for bt in self._b_test for br in self._b_trial]
        self._tangent = WeightedForm(pairs, (size, size), constant=placed(sp.vstack([self.K, sp.csr_matrix((n, 2 * n))]),
                                                                           size))
        self._rate_x = WeightedForm([(N, N)], (size, size))
        self._rate_v = WeightedForm([(N, placed(self.div_trial, size)), (N, N)], (size, size))

    # ------------------------------------------------------------------ fields

    def pressures(self, x: np.ndarray) -> np.ndarray:
        """p^h at the integration points (the nodes, or a rank's own), shape ``(num_points,)`` [Pa]."""
        return self.N @ x[2 * self.n:]

    def saturation(self, x: np.ndarray) -> np.ndarray:
        """S_w at the integration points, shape ``(num_points,)``."""
        return self.soil.retention.saturation(-self.pressures(x))

    def darcy_flux(self, x: np.ndarray) -> np.ndarray:
        """Darcy's flux q = -k k_rw (grad p - S_w rho_w g) at the integration points, shape
        ``(num_points, 2)`` [m/s], with the trial gradients of the rule."""
        m = self.soil.medium
        P = x[2 * self.n:]
        c = self.soil.coefficients(self.N @ P)
        k = m.k * c["kr"]
        return np.column_stack([-k * (self.trial[j] @ P - c["S"] * m.rho_f * self.g[j]) for j in range(2)])

    def flux_integral(self, x: np.ndarray) -> np.ndarray:
        """int q dA over the domain by the rule, shape ``(2,)`` [m^3/s per m]; on MPI ranks the
        sum over every rank's points (collective)."""
        local = self.V @ self.darcy_flux(x)
        return local if self.share is None else np.array([self.share.total(v) for v in local])

    def seepage_pressures(self, x: np.ndarray) -> np.ndarray:
        """p^h at the seepage face's points (``seepage.points``; a rank's own), shape ``(num_points,)`` [Pa]."""
        return self._face @ x[2 * self.n:]

    def seepage_outflow(self, x: np.ndarray) -> float:
        """The outflow through the seepage face, int kappa <p>_+ ds [m^2/s per m] (0 without a
        face; on MPI ranks the sum over the ranks, collective)."""
        local = 0.0
        if self._face is not None:
            f = self.seepage
            local = float(f.weights @ (f.penalty * np.maximum(self._face @ x[2 * self.n:], 0.0)))
        return local if self.share is None else self.share.total(local)

    # ------------------------------------------------------------------ model

    def residual(self, x: np.ndarray, t: float) -> np.ndarray:
        n, V, soil = self.n, self.V, self.soil
        m = soil.medium
        u, P = x[:2 * n], x[2 * n:]
        pL = self.N @ P
        c = soil.coefficients(pL)
        k = m.k * c["kr"]
        grad = [t @ P for t in self.trial]
        lam = self._factor(t)
        loads = self.div_test.T @ (V * soil.alpha * c["S"] * pL)  # the skeleton's loads at lambda = 1
        body = V * (self._rho_0 + m.porosity * m.rho_f * c["S"])
        loads[1::2] += self.NT @ (body * self.g[1])
        if self.g[0]:
            loads[0::2] += self.NT @ (body * self.g[0])
        if self._load is not None:
            loads = loads + self._load[:2 * n]
        r_u = self.K @ u - lam * loads
        if self.plasticity is not None:
            sig = self._return_map(np.column_stack([b @ u for b in self._b_trial]))
            r_u = r_u + sum(b.T @ (V * sig[:, k]) for b, k in zip(self._b_test, (0, 1, 3)))
        self._loads_at = (t, loads)
        r_p = sum(self.test[j].T @ (V * k * (grad[j] - c["S"] * m.rho_f * self.g[j])) for j in range(2))
        second = []
        for mom, rows in self.expansion:
            d = [b @ P for b in rows]
            second.append(d)
            r_p = r_p + sum(rows[j].T @ (mom * k * d[j]) for j in range(2))
        face = None
        if self._face is not None:
            face = self._face @ P
            r_p = r_p + self._face.T @ (self.seepage.weights * self.seepage.penalty * np.maximum(face, 0.0))
        self._at = (pL, c, grad, second, face)
        r = np.r_[r_u, r_p]
        return r if self._load is None else r - lam * np.r_[np.zeros(2 * n), self._load[2 * n:]]

    def load_derivative(self) -> np.ndarray:
        """dr/dt at the last ``residual`` call: -lambda'(t) times the loads at lambda = 1 (the
        skeleton's weight, the pore pressure's force and ``load``; path following,
        ``rkfx.solvers.path_following``)."""
        t, loads = self._loads_at
        flow = np.zeros(self.n) if self._load is None else self._load[2 * self.n:]
        return -self._factor_slope(t) * np.r_[loads, flow]

    def tangent(self, x: np.ndarray, t: float) -> sp.csr_matrix:
        V, soil = self.V, self.soil
        m = soil.medium
        pL, c, grad, second, face = self._at
        k, dk = m.k * c["kr"], m.k * c["dkr"]
        lam = self._factor(t)
        w = [-lam * V * soil.alpha * (c["S"] + c["dS"] * pL)]
        w += [-lam * V * m.porosity * m.rho_f * c["dS"] * self.g[j] for j in self._components]
        w += [V * k] * 2
        w += [mom * k for mom, rows in self.expansion for _ in rows]
        w += [V * (dk * (grad[j] - c["S"] * m.rho_f * self.g[j]) - k * c["dS"] * m.rho_f * self.g[j]) for j in range(2)]
        w += [mom * dk * d[j] for (mom, _), d in zip(self.expansion, second) for j in range(2)]
        if face is not None:
            w += [self.seepage.weights * self.seepage.penalty * (face > 0.0)]
        if self.plasticity is not None:
            ct = self._return_tangent()
            w += [V * ct[:, i, j] for i in range(3) for j in range(3)]
        return self._tangent(w)

    def rate_force(self, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        n, V = self.n, self.V
        pL = self.N @ x[2 * n:]
        c = self.soil.coefficients(pL)
        div_v, pv = self.div_trial @ v[:2 * n], self.N @ v[2 * n:]
        self._rate_at = (c, div_v, pv)
        return np.r_[np.zeros(2 * n), self.NT @ (V * (self.soil.alpha * c["S"] * div_v + c["iQ"] * pv))]

    def rate_tangents(self) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        V, a = self.V, self.soil.alpha
        c, div_v, pv = self._rate_at
        return (self._rate_x([V * (a * c["dS"] * div_v + c["diQ"] * pv)]),
                self._rate_v([V * a * c["S"], V * c["iQ"]]))

    def mass(self) -> None:
        return None

    def capacity(self, dt: float) -> None:
        return None

    def constraints(self, t: float) -> Constraints:
        return self._constraints
