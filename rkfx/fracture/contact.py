"""Frictional contact on pre-existing fractures: the penalty law (5.38)-(5.39) on the RK jump.

A pre-existing fracture Gamma_C is a cut of the particle set (``rkfx.geometry.particles.cut_triangulation``)
seen by the RK shape functions through diffraction (``rkfx.approximation.diffraction``): the
displacement jumps across it, [u] = u^+ - u^-, with the unit normal n_C pointing from the - side
to the + side: the right-hand normal of the fracture's polyline, so that t_C = (-n_y, n_x) runs
along the polyline (from its first point to its last) and the + side lies to its right. Its normal and tangential parts are the aperture
g_N = [u] . n_C and the slip g_T = [u] . t_C. The faces carry the total traction

    sigma n_C = -t_N n_C + t_T t_C,     t_N = p + k_N <-g_N>            (5.38)

(t_N compressive positive, p the fluid pressure on the fracture, <x> = max(x, 0)): an open
fracture (g_N > 0) is loaded by the fluid pressure alone; a closed one adds the penalty
k_N |g_N|, the effective contact pressure t_N - p. The shear resists slip by Coulomb friction on
that effective pressure,

    t_T = k_T (g_T - s)                 if |k_T (g_T - s)| <= mu_C (t_N - p)   (stick)
    t_T = mu_C (t_N - p) sign(g_T - s)  otherwise                           (slip)   (5.39)

with s the committed plastic slip (the return mapping of penalty-regularized Coulomb friction;
(5.39) is its first step from s = 0). Slipping moves s to g_T - t_T / k_T; an open fracture
keeps no shear (s = g_T), so on closing it sticks where it closes.

The faces' virtual work enters the momentum residual as

    f_C = int_Gamma [N]^T (-t_N n_C + t_T t_C) dGamma,

with the quadrature of the SCNI boundary segments of the faces (``interface``): the same points
and weights as the smoothed gradients' boundary terms, so a displacement linear on each side
with a jump that the law balances is reproduced exactly (tests/test_contact.py).

Flow (seed 5.3.3): the particles whose supports reach the fracture take, from the fracture point
nearest to them, either the anisotropic permeability (5.8) of an open fracture with w = g_N
(k_fC = w^3 / (12 mu_f L_F) along t_C, k_f0 across) or, closed, k_f0 / 100. L_F, the width
over which the fracture's flow is smeared, is the covering particles' volume over the
fracture's length, so that the band carries the cubic law's w^3 / (12 mu_f) per unit pressure
gradient.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from rkfx.approximation.shape_functions import RKApproximation, evaluate
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles
from rkfx.materials import crack_flow

OPEN, STICK, SLIP = 0, 1, 2  # the state of a fracture point
STATES = ("open", "stick", "slip")
CLOSED_PERMEABILITY = 0.01  # of the host rock's, at particles covering a closed fracture (seed 5.3.3)


@dataclass(frozen=True)
class FrictionalContact:
    """The penalty frictional contact law (5.38)-(5.39).

    Attributes:
        k_N, k_T: Normal and tangential penalties [Pa/m].
        mu: Friction coefficient mu_C [-] (the seed's 0.7).
    """

    k_N: float
    k_T: float
    mu: float = 0.7

    def __post_init__(self):
        for name in ("k_N", "k_T"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"contact penalty {name} = {v!r} must be positive and finite; e.g. 10 E / h")
        if not (np.isfinite(self.mu) and self.mu >= 0):
            raise InputError(f"friction coefficient mu = {self.mu!r} must be finite and >= 0 (the seed's 0.7)")


@dataclass(frozen=True)
class ContactResponse:
    """The law's response at the fracture points, shape ``(m,)`` each.

    Attributes:
        pressure: Effective contact pressure t_N - p = k_N <-g_N> [Pa].
        shear: t_T [Pa].
        slip: The plastic slip s after this response [m].
        status: OPEN, STICK or SLIP.
        d_pressure: d(t_N - p)/d g_N [Pa/m].
        d_shear_normal, d_shear_slip: d t_T / d g_N and d t_T / d g_T [Pa/m].
    """

    pressure: np.ndarray
    shear: np.ndarray
    slip: np.ndarray
    status: np.ndarray
    d_pressure: np.ndarray
    d_shear_normal: np.ndarray
    d_shear_slip: np.ndarray


def respond(law: FrictionalContact, g_n: np.ndarray, g_t: np.ndarray, slip: np.ndarray) -> ContactResponse:
    """The contact tractions of (5.38)-(5.39) for apertures ``g_n``, slips ``g_t`` and committed
    plastic slips ``slip`` (module docstring), with their derivatives."""
    closed = g_n <= 0.0  # at zero aperture the faces touch: the penalties act (Newton from a closed start)
    pressure = law.k_N * np.where(closed, -g_n, 0.0)
    trial = law.k_T * (g_t - slip)
    limit = law.mu * pressure
    # A point at the friction limit (a committed slip returns it there exactly, up to round-off)
    # slides: Newton from the last step's state then starts from the tangent of continued slip.
    sliding = closed & ((np.abs(trial) > limit) | ((limit > 0) & (np.abs(trial) >= limit * (1.0 - 1e-9))))
    sticking = closed & ~sliding
    sign = np.sign(trial)
    shear = np.where(sticking, trial, np.where(sliding, limit * sign, 0.0))
    new_slip = np.where(sliding, g_t - shear / law.k_T, np.where(closed, slip, g_t))
    status = np.where(sliding, SLIP, np.where(sticking, STICK, OPEN)).astype(np.int8)
    return ContactResponse(pressure=pressure, shear=shear, slip=new_slip, status=status,
                           d_pressure=np.where(closed, -law.k_N, 0.0),
                           d_shear_normal=np.where(sliding, -law.mu * law.k_N * sign, 0.0),
                           d_shear_slip=np.where(sticking, law.k_T, 0.0))


@dataclass(frozen=True)
class Interface:
    """Quadrature of a pre-existing fracture with the rows of the RK jump.

    Attributes:
        points: Quadrature points on the + face, shape ``(m, 2)`` [m].
        weights: Lengths, shape ``(m,)`` [m].
        normal: n_C (from the - side to the + side), shape ``(m, 2)``; tangent: t_C = (-n_y, n_x),
            along the fracture's polyline.
        jump_normal, jump_tangent: Rows of g_N and g_T over the interleaved displacement
            coefficients, shape ``(m, 2 n)``.
        mean: Rows of (p^+ + p^-) / 2 over the nodal values of an equal-order field, shape ``(m, n)``.
        plus, minus: Nodes owning the + and - face segments of each point, shape ``(m,)``.
    """

    points: np.ndarray
    weights: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    jump_normal: sp.csr_matrix
    jump_tangent: sp.csr_matrix
    mean: sp.csr_matrix
    plus: np.ndarray
    minus: np.ndarray

    @property
    def num_points(self) -> int:
        return len(self.weights)

    def covering(self) -> np.ndarray:
        """Nodes whose shape functions reach the fracture (from either face), sorted."""
        return np.unique(np.r_[self.jump_normal.indices // 2, self.mean.indices])


def interface(p: Particles, domains: NodalDomains, rk: RKApproximation, name: str = "crack") -> Interface:
    """The fracture whose faces are the boundary part ``name`` of ``p`` (as ``cut_triangulation``
    names them), integrated on the SCNI boundary segments of its faces: each segment of the +
    face (outward normal -n_C) is paired with the segment of the - face opposite it; shape
    functions are evaluated at each face's own segment midpoints, so each side sees its own
    particles."""
    if name not in p.boundary_names:
        raise InputError(f"no boundary part {name!r} for the fracture; the parts are "
                         f"{', '.join(sorted(p.boundary_names))} (cut_triangulation names the faces)")
    if rk.cracks is None:
        raise InputError("the RK approximation has no cracks: build it with the cracks cut_triangulation returns")
    b = domains.boundary
    faces = np.flatnonzero(b.tag == p.boundary_names[name])
    mid, outward = b.midpoint[faces], b.normal[faces]
    # n_C of each face segment: the right-hand normal of the nearest crack segment (polyline order).
    seg = rk.cracks.segments
    d = seg[:, 1] - seg[:, 0]
    along = np.clip(np.einsum("msk,sk->ms", mid[:, None] - seg[None, :, 0], d) / np.sum(d * d, axis=1), 0.0, 1.0)
    gap = np.linalg.norm(mid[:, None] - seg[None, :, 0] - along[..., None] * d, axis=-1)
    d = d[np.argmin(gap, axis=1)]
    n_c = np.column_stack([d[:, 1], -d[:, 0]]) / np.linalg.norm(d, axis=1)[:, None]
    on_plus = np.einsum("ij,ij->i", outward, n_c) < 0.0  # the + face looks back along -n_C
    plus, minus = np.flatnonzero(on_plus), np.flatnonzero(~on_plus)
    h = p.spacing[b.node[faces]]
    dist, opposite = cKDTree(mid[minus]).query(mid[plus]) if minus.size else (np.full(plus.size, np.inf), None)
    bad = np.flatnonzero(dist > 1e-3 * h[plus])
    if plus.size != minus.size or bad.size or len(np.unique(opposite)) != plus.size:
        where = mid[plus[bad[0]]] if bad.size else mid[0]
        raise InputError(f"fracture face segment near {where} has no opposite segment on the other face; "
                         "split the particles with cut_triangulation so both faces carry the same edges")
    minus = minus[opposite]
    normal = n_c[plus]
    pts_plus, pts_minus = mid[plus], mid[minus]
    weights = b.length[faces][plus]
    tangent = np.column_stack([-normal[:, 1], normal[:, 0]])
    up, um = evaluate(rk, pts_plus).matrix(), evaluate(rk, pts_minus).matrix()
    jump = (up - um).tocsr()
    n = rk.num_nodes
    return Interface(points=pts_plus, weights=weights, normal=normal, tangent=tangent,
                     jump_normal=directional_rows(jump, normal, n), jump_tangent=directional_rows(jump, tangent, n),
                     mean=(0.5 * (up + um)).tocsr(), plus=b.node[faces][plus], minus=b.node[faces][minus])


def directional_rows(rows: sp.csr_matrix, direction: np.ndarray, n: int) -> sp.csr_matrix:
    """Rows of (sum_I R_qI u_I) . d_q over interleaved displacement coefficients, shape ``(m, 2 n)``."""
    coo = rows.tocoo()
    r = np.r_[coo.row, coo.row]
    c = np.r_[2 * coo.col, 2 * coo.col + 1]
    v = np.r_[coo.data * direction[coo.row, 0], coo.data * direction[coo.row, 1]]
    return sp.csr_matrix((v, (r, c)), shape=(rows.shape[0], 2 * n))


class FractureContact:
    """A pre-existing fracture with frictional contact and history (trial/commit of the slip).

    ``forces(u, p)`` evaluates the trial response from the committed slip; ``commit()`` keeps it.
    """

    def __init__(self, fracture: Interface, law: FrictionalContact, x: np.ndarray | None = None,
                 volume: np.ndarray | None = None, carriers: np.ndarray | None = None):
        """``x`` and ``volume`` (the coordinates and volumes of the points that carry the flow:
        particles, or elements' centroids and areas) give the fracture's flow (``permeability``);
        ``carriers`` are the indices of those that carry the fracture's (default: the nodes
        whose shape functions reach it, ``Interface.covering``)."""
        self.interface, self.law = fracture, law
        self.cover = self.nearest = None
        self.band_width = 0.0
        if x is not None and volume is not None:
            self.cover = fracture.covering() if carriers is None else np.unique(np.asarray(carriers, np.int64))
            if self.cover.size == 0:
                raise InputError("no point carries the fracture's flow: give the elements or particles next to it")
            self.nearest = cKDTree(fracture.points).query(x[self.cover])[1]
            self.band_width = float(volume[self.cover].sum() / fracture.weights.sum())
        self.slip = np.zeros(fracture.num_points)
        self.trial: ContactResponse | None = None
        self._jumps = (np.zeros(fracture.num_points), np.zeros(fracture.num_points))
        self._pressure = np.zeros(fracture.num_points)

    def forces(self, u: np.ndarray, p: np.ndarray | None = None) -> np.ndarray:
        """f_C for the displacement coefficients ``u`` (2 n, interleaved) and the pressure
        coefficients ``p`` (n; ``None``: no fluid), shape ``(2 n,)``."""
        f = self.interface
        g_n, g_t = f.jump_normal @ u, f.jump_tangent @ u
        self._jumps = (g_n, g_t)
        self._pressure = np.zeros(f.num_points) if p is None else f.mean @ p
        self.trial = r = respond(self.law, g_n, g_t, self.slip)
        t_n = self._pressure + r.pressure
        return f.jump_normal.T @ (-f.weights * t_n) + f.jump_tangent.T @ (f.weights * r.shear)

    def stiffness(self) -> sp.csr_matrix:
        """d f_C / d u at the last ``forces``, shape ``(2 n, 2 n)`` (unsymmetric where slipping)."""
        f, r = self.interface, self.trial
        jn, jt = f.jump_normal, f.jump_tangent
        w = f.weights
        return (jn.T @ sp.diags(-w * r.d_pressure) @ jn + jt.T @ sp.diags(w * r.d_shear_slip) @ jt
                + jt.T @ sp.diags(w * r.d_shear_normal) @ jn).tocsr()

    def pressure_coupling(self) -> sp.csr_matrix:
        """d f_C / d p, shape ``(2 n, n)``: the fluid pressure on both faces."""
        f = self.interface
        return (f.jump_normal.T @ sp.diags(-f.weights) @ f.mean).tocsr()

    def commit(self) -> None:
        if self.trial is not None:
            self.slip = self.trial.slip.copy()

    def state(self) -> dict[str, np.ndarray]:
        return {"contact_slip": self.slip.copy()}

    def restore(self, arrays) -> None:
        self.slip = np.array(arrays["contact_slip"], float)

    def permeability(self, mobility: float, viscosity: float) -> tuple[np.ndarray, np.ndarray]:
        """The covering particles (indices) and their permeability from the fracture at the
        last ``forces`` (module docstring), shape ``(m, 2, 2)`` [m^2/(Pa s)]."""
        if self.cover is None:
            raise InputError("the fracture's flow needs the particles: FractureContact(..., x=, volume=)")
        w = np.maximum(self._jumps[0][self.nearest], 0.0)
        is_open = w > 0.0
        k0 = np.where(is_open, mobility, CLOSED_PERMEABILITY * mobility)
        k_fc = np.where(is_open, crack_flow.fracture_permeability(w, np.full(len(w), self.band_width), viscosity), 0.0)
        return self.cover, crack_flow.permeability_tensor(k0, k_fc, self.interface.normal[self.nearest])

    def added_permeability(self, k: np.ndarray, mobility: float, viscosity: float) -> np.ndarray:
        """The permeabilities ``k`` (per carrier point, shape ``(n, 2, 2)``) with the fracture's:
        at the carriers the host's isotropic k_f0 gives way to the fracture's tensor, their own
        crack bands' enhancement kept. Modifies and returns ``k``."""
        cover, k_fracture = self.permeability(mobility, viscosity)
        k[cover] += k_fracture - mobility * np.eye(2)
        return k

    def aperture(self) -> np.ndarray:
        """g_N at the last ``forces`` [m]."""
        return self._jumps[0]

    def status(self) -> np.ndarray:
        """OPEN / STICK / SLIP at the last ``forces``."""
        return self.trial.status if self.trial is not None else np.full(self.interface.num_points, OPEN, np.int8)
