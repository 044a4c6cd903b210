"""The damage particle method's material layer (seed chapter 4): isotropic damage at the particles.

Each damage point (an SCNI particle, or any integration point) carries the scalar damage of
the continuum damage model (4.1) driven by its *smeared* strain: for SCNI particles that is
the cell-smoothed strain of eq. (4.21), ``strain_matrix(smoothed_gradients(...).cell) @ d``.
Everything here is vectorised over the points. The law at a point, Mazars' strain and D, is
compiled once in ``rkfx.materials.damage_law``: ``update`` runs the point updates of the explicit force
of ``rkfx.models.damage_dynamics`` (serially), and ``equivalent_strain`` and ``damage`` are array
forms of the same functions.

* Mazars' equivalent strain (4.6) from the principal strains of Voigt strains
  (eps_xx, eps_yy, gamma_xy), and its gradient for the consistent tangent.
* The linear-softening damage law (4.2) with the irreversible history variable
  kappa = max(kappa_old, eps_eq) (Kuhn-Tucker conditions 4.3-4.5).
* The dissipation-energy regularization (4.26)-(4.28): kappa_c = (G_F / f_t) A_L / V_L, with
  A_L the chord of the particle's nodal domain through x_L along the crack (perpendicular to
  the crack normal n_L, which is fixed at damage initiation along the major principal
  direction of the effective stress, ``initiate``). ``chord_lengths`` computes it exactly for
  the median-dual cells of ``rkfx.geometry.nodal_domains``.
* The smeared stress (4.20)/(4.30), sigma = (1 - D) C eps, its consistent tangent, and the
  dissipated energy.
* What the damage solvers share (``rkfx.cases.cracked_bar``, ``fem_baselines.crack_band``):
  ``failure_displacement``, u_T^max read off a load path (their stepping, with step cutting
  and dissipation control through snap-backs, is ``rkfx.solvers.quasi_static.march``).

Dissipation bookkeeping. Damage dissipates Y dD per unit volume with the energy release rate
Y = eps : C : eps / 2. In uniaxial tension, the state the energy scaling (4.27) is built on,
eps = kappa while damage grows, so the dissipation density is a function of kappa alone,

    phi(kappa) = int_{kappa0}^{kappa} E s^2 / 2 D'(s) ds = W(kappa) - E (1 - D) kappa^2 / 2
               = kappa0 (E min(kappa, kappa_c) - sigma(kappa)) / 2,

the work of the monotonic stress-strain curve minus the elastic energy still stored, with
sigma(kappa) = E (1 - D(kappa)) kappa on that curve. It is exact for any step size (no
quadrature in time) and reaches g_L = f_t kappa_c / 2 (4.27) at complete failure. ``update``
returns V_L (phi(kappa_new) - phi(kappa_old)) summed over the points. For multiaxial states
the same phi is used (Y evaluated at the equivalent strain); cases check it against the work
balance W_ext - W_elastic.

Out-of-plane strain in Mazars' norm: plane strain has eps_zz = 0, which adds nothing to (4.6);
plane stress has eps_zz = -nu / (1 - nu) (eps_xx + eps_yy), which counts when positive.
"""
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from rkfx.approximation.sparse_rows import ranges
from rkfx.materials import damage_law as law
from rkfx.materials.elasticity import ElasticMaterial, out_of_plane_ratio, principal_direction
from rkfx.errors import InputError
from rkfx.fracture.nonlocal_average import NonlocalAverage
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.geometry.particles import Particles


@dataclass(frozen=True)
class DamageMaterial:
    """Isotropic elastic-damage solid with linear softening (4.2).

    Attributes:
        E: Young's modulus [Pa].
        nu: Poisson's ratio [-].
        ft: Tensile strength f_t [Pa]; the damage threshold is kappa0 = f_t / E.
        GF: Fracture energy G_F [J/m^2 = N/m].
        plane: ``"strain"`` or ``"stress"``: the 2-D idealization of C and of eps_zz in (4.6)
            (``rkfx.materials.elasticity.ElasticMaterial``).
    """

    E: float
    nu: float
    ft: float
    GF: float
    plane: str = "strain"

    def __post_init__(self):
        for name, fix in (("E", "Young's modulus, e.g. E=2e6"), ("ft", "the tensile strength, e.g. ft=200"),
                          ("GF", "the fracture energy per crack area, e.g. GF=1.885")):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name} = {v!r} must be positive and finite ({fix})")
        ElasticMaterial(self.E, self.nu, self.plane)  # validates nu and plane
        if not self.ft / self.E < 1.0:
            raise InputError(f"ft / E = {self.ft / self.E:g} is not a small strain; check the units of ft and E")

    @property
    def kappa0(self) -> float:
        """Damage threshold kappa0 = f_t / E [-] (4.2)."""
        return self.ft / self.E

    @property
    def critical_opening(self) -> float:
        """Critical crack opening w_c = 2 G_F / f_t of the linear cohesive law (4.7) [m]."""
        return 2.0 * self.GF / self.ft

    @property
    def elastic(self) -> ElasticMaterial:
        """The undamaged solid (E, nu, plane)."""
        return ElasticMaterial(self.E, self.nu, self.plane)

    def elasticity(self) -> np.ndarray:
        """Elastic matrix C in Voigt form (eps_xx, eps_yy, gamma_xy), shape ``(3, 3)`` [Pa]."""
        return self.elastic.D()


# --------------------------------------------------------------------------- strain measures


def principal_strains(strain: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """In-plane principal strains and the major principal direction.

    Args:
        strain: Voigt strains (eps_xx, eps_yy, gamma_xy), shape ``(m, 3)``.

    Returns:
        ``(values, direction)``: principal strains (major first), shape ``(m, 2)``, and the
        unit major principal direction, shape ``(m, 2)``.
    """
    e = np.ascontiguousarray(strain, float).reshape(-1, 3)
    values = np.empty((len(e), 2))
    law.principal_strains_kernel(e, values)
    return values, principal_direction(e, "strain")


def equivalent_strain(strain: np.ndarray, nu: float = 0.0, plane: str = "strain") -> np.ndarray:
    """Mazars' equivalent strain sqrt(sum <eps_I>^2) over the three principal strains (4.6).

    Args:
        strain: Voigt strains (eps_xx, eps_yy, gamma_xy), shape ``(m, 3)``.
        nu: Poisson's ratio (enters eps_zz in plane stress only).
        plane: ``"strain"`` (eps_zz = 0) or ``"stress"``.

    Returns:
        Shape ``(m,)`` [-].
    """
    e = np.ascontiguousarray(strain, float).reshape(-1, 3)
    eq = np.empty(len(e))
    law.equivalent_strain_kernel(e, out_of_plane_ratio(nu, plane), eq)
    return eq


def equivalent_strain_gradient(strain: np.ndarray, nu: float = 0.0, plane: str = "strain") -> np.ndarray:
    """d eps_eq / d (eps_xx, eps_yy, gamma_xy), shape ``(m, 3)``; zero where eps_eq = 0.

    d eps_I / d eps = n_I (x) n_I, i.e. (n_x^2, n_y^2, n_x n_y) against engineering shear; where
    the principal strains coincide the sum sum <eps_I> n_I (x) n_I is still unique.
    """
    e = np.ascontiguousarray(strain, float).reshape(-1, 3)
    values, n1 = principal_strains(e)
    n2 = np.column_stack([-n1[:, 1], n1[:, 0]])
    pos = np.maximum(values, 0.0)
    grad = np.zeros_like(e)
    for k, n in enumerate((n1, n2)):
        grad += pos[:, k:k + 1] * np.column_stack([n[:, 0] ** 2, n[:, 1] ** 2, n[:, 0] * n[:, 1]])
    r = out_of_plane_ratio(nu, plane)
    if r:
        ezz = np.maximum(-r * (e[:, 0] + e[:, 1]), 0.0)
        grad[:, :2] -= (r * ezz)[:, None]
    eq = equivalent_strain(e, nu, plane)
    out = np.zeros_like(e)
    np.divide(grad, eq[:, None], out=out, where=eq[:, None] > 0)
    return out


# --------------------------------------------------------------------------- damage law


def damage(kappa: np.ndarray, kappa0: np.ndarray | float, kappa_c: np.ndarray | float) -> np.ndarray:
    """Linear-softening damage D(kappa) of (4.2): 0 below kappa0, 1 beyond kappa_c (broadcasts).

    Where kappa_c <= kappa0 the law has no softening branch and D jumps to 1 at kappa0
    (``rkfx.materials.damage_law.damage_at``).
    """
    kappa, kappa0, kappa_c = np.broadcast_arrays(*(np.asarray(a, float) for a in (kappa, kappa0, kappa_c)))
    out = np.empty(kappa.shape)
    law.damage_array_kernel(*(np.ascontiguousarray(a).reshape(-1) for a in (kappa, kappa0, kappa_c)),
                            out.reshape(-1))
    return out if out.ndim else out[()]


def damage_slope(kappa: np.ndarray, kappa0: np.ndarray | float, kappa_c: np.ndarray | float) -> np.ndarray:
    """dD/dkappa of (4.2): kappa0 kappa_c / (kappa^2 (kappa_c - kappa0)) on [kappa0, kappa_c), else 0."""
    kappa, kappa0, kappa_c = np.broadcast_arrays(*(np.asarray(a, float) for a in (kappa, kappa0, kappa_c)))
    out = np.zeros(kappa.shape)
    soft = (kappa >= kappa0) & (kappa < kappa_c)
    out[soft] = kappa0[soft] * kappa_c[soft] / (kappa[soft] ** 2 * (kappa_c[soft] - kappa0[soft]))
    return out


def dissipation_density(kappa: np.ndarray, kappa0: np.ndarray | float, kappa_c: np.ndarray | float,
                        E: float) -> np.ndarray:
    """Energy dissipated per unit volume up to the history kappa [J/m^3] (module docstring).

    phi = kappa0 (E min(kappa, kappa_c) - E (1 - D) kappa) / 2; phi = f_t kappa_c / 2 (4.27) once
    kappa >= kappa_c, and 0 below kappa0.
    """
    kappa, kappa0, kappa_c = np.broadcast_arrays(*(np.asarray(a, float) for a in (kappa, kappa0, kappa_c)))
    sigma = E * (1.0 - damage(kappa, kappa0, kappa_c)) * kappa
    return np.where(kappa > kappa0, 0.5 * kappa0 * (E * np.minimum(kappa, kappa_c) - sigma), 0.0)


def crack_opening(kappa: np.ndarray, kappa0: np.ndarray | float, kappa_c: np.ndarray | float) -> np.ndarray:
    """Crack opening over the critical opening, w / w_c = min(D kappa / kappa_c, 1), per point.

    The inelastic strain D kappa smeared over the band of the point, over the band's critical
    strain kappa_c; it equals the fraction phi(kappa) / g_L of the point's fracture energy
    spent. Use it to see cracks: D itself says little once kappa_c >> kappa0 (fine
    regularized models), as D = 0.5 already at kappa ~ 2 kappa0, where the stress has barely
    softened. 0 below kappa0 (and where kappa_c is NaN, i.e. before initiation), 1 once failed.
    """
    kappa, kappa0, kappa_c = np.broadcast_arrays(*(np.asarray(a, float) for a in (kappa, kappa0, kappa_c)))
    w = np.zeros(kappa.shape)
    on = (kappa > kappa0) & np.isfinite(kappa_c)
    w[on] = 1.0  # also where kappa_c <= kappa0: perfectly brittle, failed at once
    soft = on & (kappa < kappa_c)
    w[soft] = damage(kappa[soft], kappa0[soft], kappa_c[soft]) * kappa[soft] / kappa_c[soft]
    return w


def critical_strain(material: DamageMaterial, chord: np.ndarray, volume: np.ndarray) -> np.ndarray:
    """Regularized kappa_c = (G_F / f_t) A_L / V_L (4.28), shape like ``chord``.

    In 2-D ``chord`` is the length A_L [m] and ``volume`` the area V_L [m^2] of the nodal domain
    (both per unit thickness), so the bulk dissipation g_L V_L = f_t kappa_c V_L / 2 equals the
    fracture energy G_F A_L / 2 of half a crack segment (4.24), (4.26).
    """
    return material.GF / material.ft * np.asarray(chord, float) / np.asarray(volume, float)


# --------------------------------------------------------------------------- cell chords (A_L)


@dataclass(frozen=True)
class CellGeometry:
    """The nodal domains as unions of convex subcell quadrilaterals.

    Attributes:
        node: Node L of each subcell, shape ``(num_subcells,)``.
        vertices: Counter-clockwise vertices (x_L, m_k, g, m_k-1) of each subcell, shape
            ``(num_subcells, 4, 2)`` [m]: the node, the midpoint of triangle side k, the
            triangle's centroid and the midpoint of side k-1 (as in ``rkfx.geometry.nodal_domains``);
            for grid cells the node, a cell-side point, the cell corner, a cell-side point.
        num_nodes: Number of nodes.
    """

    node: np.ndarray
    vertices: np.ndarray
    num_nodes: int

    @cached_property
    def by_node(self) -> tuple[np.ndarray, np.ndarray]:
        """The subcells grouped by node: node L has the subcells ``order[ptr[L]:ptr[L + 1]]``."""
        ptr = np.zeros(self.num_nodes + 1, np.int64)
        np.cumsum(np.bincount(self.node, minlength=self.num_nodes), out=ptr[1:])
        return np.argsort(self.node, kind="stable"), ptr

    def subcells(self, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The subcells of ``nodes`` and the place in ``nodes`` of each subcell's node."""
        order, ptr = self.by_node
        count = ptr[nodes + 1] - ptr[nodes]
        return order[ranges(ptr[nodes], count)], np.repeat(np.arange(len(nodes)), count)


def cell_geometry(p: Particles | NodalDomains) -> CellGeometry:
    """Subcell quadrilaterals of the nodal domains.

    Args:
        p: ``Particles``: their median-dual cells (subcell 3t + k); or ``NodalDomains``
            carrying ``subcell_vertices`` (e.g. ``rkfx.geometry.grid_cells.grid_domains``): its subcells.

    Raises:
        InputError: ``NodalDomains`` without ``subcell_vertices``.
    """
    if isinstance(p, NodalDomains):
        if p.subcell_vertices is None:
            raise InputError("these nodal domains carry no subcell_vertices; pass the Particles for "
                             "median-dual cells, or build the domains with rkfx.geometry.grid_cells.grid_domains")
        return CellGeometry(p.subcell_node, p.subcell_vertices, len(p.area))
    tri = p.triangles
    v = p.x[tri]                                # (t, 3, 2)
    nxt = p.x[np.roll(tri, -1, axis=1)]         # vertex k + 1
    prv = p.x[np.roll(tri, 1, axis=1)]          # vertex k - 1
    g = np.broadcast_to(v.mean(axis=1, keepdims=True), v.shape)
    quads = np.stack([v, 0.5 * (v + nxt), g, 0.5 * (prv + v)], axis=2)  # (t, 3, 4, 2)
    return CellGeometry(tri.reshape(-1), quads.reshape(-1, 4, 2), p.num_nodes)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _reach(quads: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Distance from vertex 0 of each convex quad along ``direction`` to the quad's far sides
    (1 -> 2 and 2 -> 3); 0 where the ray leaves the quad at its vertex (points outside)."""
    rel = quads - quads[:, :1]
    scale = np.abs(rel).max(axis=(1, 2))
    reach = np.zeros(len(quads))
    for a, b in ((1, 2), (2, 3)):
        p, e = rel[:, a], rel[:, b] - rel[:, a]
        det = _cross(e, direction)
        ok = np.abs(det) > 1e-12 * scale
        safe = np.where(ok, det, 1.0)
        s = _cross(e, p) / safe
        lam = _cross(direction, p) / safe
        hit = ok & (lam >= -1e-9) & (lam <= 1.0 + 1e-9) & (s > 1e-12 * scale)
        reach = np.where(hit, np.maximum(reach, s), reach)
    return reach


def chord_lengths(geometry: CellGeometry, nodes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Length A_L of the chord of each node's domain through x_L perpendicular to ``normals``.

    The domain is star-shaped with respect to its node, which is a vertex of every subcell, so
    the chord is the distance from x_L to the domain boundary along +t plus that along -t,
    t = (-n_y, n_x); each is the exit distance of the ray from the one subcell it runs through
    (the larger of the two where it runs along a subcell side). Rays leaving the geometry at a
    boundary node contribute 0.

    Args:
        geometry: From ``cell_geometry``.
        nodes: Node indices, shape ``(k,)`` (distinct).
        normals: Crack normals n_L (unit), shape ``(k, 2)``.

    Returns:
        A_L, shape ``(k,)`` [m] (per unit thickness in 2-D).
    """
    nodes = np.asarray(nodes, np.int64).reshape(-1)
    n = np.asarray(normals, float).reshape(-1, 2)
    sub, where = geometry.subcells(nodes)
    t = np.column_stack([-n[:, 1], n[:, 0]])[where]
    total = np.zeros(len(nodes))
    for sign in (1.0, -1.0):
        far = np.zeros(len(nodes))
        np.maximum.at(far, where, _reach(geometry.vertices[sub], sign * t))
        total += far
    return total



def band_widths(geometry: CellGeometry, volume: np.ndarray, nodes: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Width L_s = V_L / A_L of the smeared crack band of each node (chapter 5: 5.12-5.13),
    its nodal volume over the chord of its domain along the crack (``chord_lengths``).

    Args:
        geometry: From ``cell_geometry``.
        volume: Nodal volumes V of all nodes, shape ``(num_nodes,)`` [m^2 per unit thickness].
        nodes: Node indices, shape ``(k,)`` (distinct).
        normals: Crack normals n_L (unit), shape ``(k, 2)``.

    Returns:
        L_s, shape ``(k,)`` [m]; a node whose chord is 0 (a degenerate cell) raises.
    """
    nodes = np.asarray(nodes, np.int64).reshape(-1)
    chord = chord_lengths(geometry, nodes, normals)
    if np.any(chord <= 0):
        bad = int(nodes[np.argmin(chord)])
        raise InputError(f"node {bad}: its nodal domain has no chord along the crack; check the nodal domains there")
    return np.asarray(volume, float)[nodes] / chord

# --------------------------------------------------------------------------- model and state


@dataclass(frozen=True)
class DamageModel:
    """The fixed data of the damage points.

    Attributes:
        material: Material constants.
        volume: V_L of each point, shape ``(m,)`` [m^2 per unit thickness in 2-D].
        kappa0: Damage threshold per point (weakened where requested), shape ``(m,)``.
        geometry: Cell geometry for the regularization (4.28) (points are the nodes of
            ``geometry``), or ``None`` for the unregularized model.
        kappa_c: Critical strain per point of the unregularized model, shape ``(m,)``, or
            ``None`` when regularized.
        band_factor: Regularized kappa_c = band_factor (G_F / f_t) A_L / V_L. 1 for particles
            (4.28): a crack runs between two particles' cells and each dissipates G_F A_L / 2.
            2 for a crack band one element wide (Bazant and Oh): kappa_c = 2 G_F / (f_t h_e)
            with the band width h_e = V_L / A_L, so that one failed element dissipates G_F A_L.
        residual: Residual stiffness eta of the explicit force (``rkfx.models.damage_dynamics``):
            the stress is max(1 - D, eta) C e, so a cracked particle keeps the fraction eta of
            its stiffness (0, the default: none, as in (4.30)). A study option: the history,
            damage and dissipation are the law's; the energy balance counts the stress it carries.
        nonlocal_average: The history driven by the nonlocal equivalent strain over a physical
            radius, with kappa_c = 2 G_F / (f_t b) of its band width b
            (``rkfx.fracture.nonlocal_average``; explicit dynamics only), or ``None``: local (4.6).
    """

    material: DamageMaterial
    volume: np.ndarray
    kappa0: np.ndarray
    geometry: CellGeometry | None
    kappa_c: np.ndarray | None
    band_factor: float = 1.0
    residual: float = 0.0
    nonlocal_average: NonlocalAverage | None = None

    def __post_init__(self):
        if not 0.0 <= self.residual < 1.0:
            raise InputError(f"residual stiffness = {self.residual!r} must lie in [0, 1) (0: none; 1e-3-1e-2 "
                             "keeps a cracked particle that share of its stiffness)")

    @property
    def num_points(self) -> int:
        return len(self.volume)

    @property
    def regularized(self) -> bool:
        return self.geometry is not None


def damage_model(material: DamageMaterial, volume: np.ndarray, kappa0_factor: np.ndarray | float = 1.0,
                 geometry: CellGeometry | None = None, kappa_c: np.ndarray | float | None = None,
                 regularized: bool = True, band_factor: float = 1.0) -> DamageModel:
    """Validated ``DamageModel`` (``band_factor``: see ``DamageModel``).

    Args:
        material: Material constants.
        volume: V_L per point, shape ``(m,)``.
        kappa0_factor: Multiplier of kappa0 per point (e.g. 0.999 in a weak section), scalar or
            shape ``(m,)``, in (0, 1].
        geometry: ``cell_geometry(p)``; needed when ``regularized`` (points = nodes of p).
        kappa_c: Constant critical strain (scalar or per point) when not ``regularized``.
        regularized: kappa_c from (4.28) at damage initiation, or the constant ``kappa_c``.
    """
    volume = np.ascontiguousarray(volume, float).reshape(-1)
    m = len(volume)
    if not np.all(volume > 0):
        raise InputError("every damage point needs a positive volume V_L; check the nodal domains")
    factor = np.broadcast_to(np.asarray(kappa0_factor, float), (m,)).copy()
    if not np.all((factor > 0) & (factor <= 1)):
        raise InputError(f"kappa0_factor must lie in (0, 1] (e.g. 0.999 for a weak section), got "
                         f"{factor[~((factor > 0) & (factor <= 1))][0]!r}")
    kappa0 = material.kappa0 * factor
    if regularized:
        if geometry is None:
            raise InputError("the regularized model (4.28) needs the cell geometry: pass geometry=cell_geometry(p)")
        if geometry.num_nodes != m:
            raise InputError(f"geometry has {geometry.num_nodes} nodes but {m} damage points were given")
        if not (np.isfinite(band_factor) and band_factor > 0):
            raise InputError(f"band_factor = {band_factor!r} must be positive (1 for particles, 2 for a crack band)")
        return DamageModel(material, volume, kappa0, geometry, None, float(band_factor))
    if kappa_c is None:
        raise InputError("the unregularized model needs a constant kappa_c (> kappa0 = ft / E)")
    kc = np.broadcast_to(np.asarray(kappa_c, float), (m,)).copy()
    if not np.all(kc > kappa0):
        raise InputError(f"kappa_c = {kc.min():g} must exceed kappa0 = ft / E = {material.kappa0:g}")
    return DamageModel(material, volume, kappa0, None, kc)


@dataclass(frozen=True)
class DamageState:
    """History of the damage points.

    Attributes:
        kappa: History variable kappa (max equivalent strain reached), shape ``(m,)``.
        damage: D(kappa), shape ``(m,)``.
        normal: Crack normal n_L fixed at initiation, shape ``(m, 2)`` (zero before).
        kappa_c: Critical strain in force, shape ``(m,)`` (NaN before initiation when regularized).
        damaged: Whether the point has initiated damage (kappa >= kappa0), shape ``(m,)``.
        chord: A_L at initiation (regularized model), shape ``(m,)`` [m] (NaN otherwise).
        dissipated: Energy dissipated so far per point, V_L phi(kappa), shape ``(m,)`` [J per
            unit thickness in 2-D].
    """

    kappa: np.ndarray
    damage: np.ndarray
    normal: np.ndarray
    kappa_c: np.ndarray
    damaged: np.ndarray
    chord: np.ndarray
    dissipated: np.ndarray


def initial_state(model: DamageModel) -> DamageState:
    """Undamaged state."""
    m = model.num_points
    kc = np.full(m, np.nan) if model.regularized else model.kappa_c.copy()
    return DamageState(np.zeros(m), np.zeros(m), np.zeros((m, 2)), kc, np.zeros(m, bool), np.full(m, np.nan),
                       np.zeros(m))


@dataclass(frozen=True)
class DamageUpdate:
    """The response of the damage points to a strain.

    Attributes:
        state: The trial state (commit it once the step has converged).
        stress: Smeared stress (1 - D) C eps (4.30), shape ``(m, 3)`` [Pa].
        tangent: d stress / d strain, shape ``(m, 3, 3)`` [Pa], or ``None``.
        dissipation: Energy dissipated since ``state`` [J per unit thickness in 2-D].
    """

    state: DamageState
    stress: np.ndarray
    tangent: np.ndarray | None
    dissipation: float


def initiate(model: DamageModel, points: np.ndarray, effective: np.ndarray, normal: np.ndarray,
             chord: np.ndarray, kappa_c: np.ndarray, at: np.ndarray | None = None) -> None:
    """Fix the crack of damage points at initiation, in place.

    The crack normal n_L is the major principal direction of the effective stress C eps
    (section 4.2.2); in the regularized model A_L is the chord of the point's cell across n_L
    and kappa_c = band_factor (G_F / f_t) A_L / V_L (4.28) with the material's f_t.

    Args:
        model: Fixed point data.
        points: Indices of the initiating points, shape ``(k,)`` (distinct).
        effective: Their effective stresses C eps, shape ``(k, 3)`` [Pa].
        normal: n_L of every point, shape ``(m, 2)``: rows ``points`` are written.
        chord: A_L of every point, shape ``(m,)`` [m]: written when regularized.
        kappa_c: Critical strains, shape ``(m,)``: written when regularized.
        at: Where the points' values go in ``normal``, ``chord`` and ``kappa_c`` when these hold
            a subset of the points (one rank's), shape ``(k,)``; default ``points``.
    """
    at = points if at is None else at
    normal[at] = principal_direction(effective)
    if model.regularized:
        c = chord_lengths(model.geometry, points, normal[at])
        # A point on a cell's boundary whose line across n_L leaves the cell at once (a particle
        # on a cut face, a notch reaching a boundary) has no chord; it takes the cell's size
        # sqrt(V_L), for kappa_c (4.28) and for the band width V_L / A_L of chapter 5 alike.
        chord[at] = np.where(c > 0, c, np.sqrt(model.volume[points]))
        if model.nonlocal_average is not None:  # a band of the average's physical width
            mat = model.material
            kappa_c[at] = 2.0 * mat.GF / (mat.ft * model.nonlocal_average.band_width)
        else:
            kappa_c[at] = model.band_factor * critical_strain(model.material, chord[at], model.volume[points])


def update(model: DamageModel, state: DamageState, strain: np.ndarray, tangent: bool = True,
           tangent_floor: float = 0.0, loading_tolerance: float = 0.0,
           allowed: np.ndarray | None = None) -> DamageUpdate:
    """Damage, stress and tangent for the strains ``strain`` from the converged ``state``.

    kappa = max(kappa_old, eps_eq(strain)) (4.3)-(4.5). A point crossing its threshold for the
    first time fixes its crack normal along the major principal direction of the effective
    stress C eps and, in the regularized model, its kappa_c = (G_F / f_t) A_L / V_L (4.28) with
    the material's f_t (the weakening factor only triggers localization) (``initiate``).
    eps_eq, kappa, D and the stress come from the compiled point updates of
    ``rkfx.materials.damage_law`` that the explicit force runs, with every point allowed to damage.

    Args:
        model: Fixed point data.
        state: Last converged state.
        strain: Smeared Voigt strains, shape ``(m, 3)``.
        tangent: Also form the consistent tangent (1 - D) C - D'(kappa) (C eps) (x) d eps_eq / d eps
            (the second term on loading points only).
        tangent_floor: Lower bound of (1 - D) in the tangent only (e.g. 1e-6), which keeps the
            Newton matrix regular once points have failed; the stress is not affected.
        loading_tolerance: Points with eps_eq > (1 - loading_tolerance) max(kappa_old, kappa0)
            count as loading in the tangent (with the slope at kappa0 if still below it). A
            small positive value makes a point sitting on its threshold (the first iterate of
            a step, or the peak) soften in the tangent, so that Newton's first prediction
            follows the softening branch rather than the secant one.
        allowed: Points that may damage further (particle tracking, ``rkfx.fracture.tracking``),
            shape ``(m,)`` bool; the others keep their history and respond elastically with
            their committed damage. ``None``: every point.

    A regularized kappa_c <= kappa0 (a cell too coarse for G_F) makes the point perfectly
    brittle; ``check_regularization`` rejects such converged states.
    """
    if model.nonlocal_average is not None:
        raise InputError("the nonlocal damage model runs in explicit dynamics only (rkfx.models.damage_dynamics); "
                         "build the quasi-static model without nonlocal_average")
    mat = model.material
    elastic = mat.elastic
    c = elastic.D()
    e = np.ascontiguousarray(strain, float).reshape(-1, 3)
    m = len(e)
    everywhere = np.ones(m, bool) if allowed is None else np.asarray(allowed, bool)
    eq, effective, crossing = np.empty(m), np.empty((m, 3)), np.empty(m, bool)  # crossing: unused here
    law.strain_kernel_serial(e, c, elastic.out_of_plane_ratio, everywhere, state.damaged, model.kappa0, eq,
                             effective, crossing)
    trial = np.maximum(state.kappa, eq) if allowed is None else np.where(everywhere, np.maximum(state.kappa, eq),
                                                                         state.kappa)
    # Points crossing their threshold now fix n_L and kappa_c; points within the loading
    # tolerance below it get prospective values for the tangent only.
    near = ~state.damaged & (trial >= (1.0 - loading_tolerance) * model.kappa0)
    if allowed is not None:
        near &= everywhere
    new = near & (trial >= model.kappa0)
    normal, kappa_c, chord = state.normal, state.kappa_c, state.chord
    if near.any():
        idx = np.flatnonzero(near)
        normal, kappa_c, chord = normal.copy(), kappa_c.copy(), chord.copy()
        initiate(model, idx, effective[idx], normal, chord, kappa_c)
        prospective = np.flatnonzero(near & ~new)
        kc_tangent = kappa_c.copy()
        normal[prospective], chord[prospective] = state.normal[prospective], state.chord[prospective]
        kappa_c[prospective] = state.kappa_c[prospective]
    active = state.damaged | new
    kappa, d, stress = state.kappa.copy(), np.zeros(m), np.empty((m, 3))
    law.damage_kernel_serial(eq, effective, everywhere, active, model.kappa0, kappa_c, kappa, d, stress)
    kc = np.where(active, kappa_c, np.inf)
    phi_new = dissipation_density(kappa, model.kappa0, kc, mat.E)
    phi_old = dissipation_density(state.kappa, model.kappa0, kc, mat.E)
    diss = model.volume * (phi_new - phi_old)
    new_state = DamageState(kappa, d, normal, kappa_c, active, chord, state.dissipated + diss)
    tan = None
    if tangent:
        tan = np.maximum(1.0 - d, tangent_floor)[:, None, None] * c
        kc_t = np.where(near, kc_tangent, kc) if near.any() else kc
        loading = (eq > (1.0 - loading_tolerance) * np.maximum(state.kappa, model.kappa0)) & (eq < kc_t)
        if allowed is not None:
            loading &= everywhere
        if loading.any():
            i = np.flatnonzero(loading)
            slope = damage_slope(np.maximum(eq[i], model.kappa0[i]), model.kappa0[i], kc_t[i])
            grad = equivalent_strain_gradient(e[i], mat.nu, mat.plane)
            tan[i] -= slope[:, None, None] * effective[i][:, :, None] * grad[:, None, :]
    return DamageUpdate(new_state, stress, tan, float(diss.sum()))


def check_regularization(model: DamageModel, state: DamageState) -> None:
    """Raise if a damaged point of a converged state has kappa_c <= kappa0 (4.28).

    Raises:
        InputError: Naming the point, its A_L and V_L, and the admissible cell size: kappa_c > kappa0
            needs V_L / A_L < E G_F / f_t^2.
    """
    bad = np.flatnonzero(state.damaged & ~(state.kappa_c > model.kappa0))
    if bad.size:
        i, mat = bad[0], model.material
        raise InputError(
            f"damage point {i}: kappa_c = {state.kappa_c[i]:.3g} <= kappa0 = {model.kappa0[i]:.3g} "
            f"(A_L = {state.chord[i]:.3g}, V_L = {model.volume[i]:.3g}); the cell is too coarse for G_F: refine "
            f"until V_L / A_L < E G_F / f_t^2 = {mat.E * mat.GF / mat.ft**2:.3g} or raise GF")


# --------------------------------------------------------------------------- load paths
# Shared by the damage solvers (rkfx.cases.cracked_bar, fem_baselines.crack_band): both drive
# a tip displacement through softening (rkfx.solvers.quasi_static.march) and read the same
# quantities off the curve.


def failure_displacement(u: np.ndarray, force: np.ndarray, rtol: float = 1e-6) -> float:
    """Tip displacement at which the force first vanishes (complete failure), u_T^max.

    The softening branch of the last two steps with F > rtol max F is extrapolated linearly to
    F = 0 (exact for the linear softening law (4.2) whatever the step size). Where the force
    was still rising before it vanished (a snap-back: the bar broke at once), it is the first
    displacement with F <= rtol max F. NaN if the force never vanishes.

    Args:
        u: Tip displacements, shape ``(k,)`` [m], starting at 0.
        force: Forces, shape ``(k,)`` [N].
    """
    u, force = np.asarray(u, float), np.asarray(force, float)
    small = force <= rtol * force.max()
    small[0] = False
    if not small.any():
        return float("nan")
    j = int(np.argmax(small))  # first vanishing step
    k = j - 1
    if k >= 1 and force[k] < force[k - 1]:
        return float(u[k] + force[k] * (u[k] - u[k - 1]) / (force[k - 1] - force[k]))
    return float(u[j])
