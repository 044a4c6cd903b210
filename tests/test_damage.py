"""The damage particle method's material layer (seed 4.1-4.2): Mazars' strain, the damage law,
irreversibility, dissipation, cell chords A_L and the regularized kappa_c (4.28)."""
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.spatial import Delaunay

from rkfx.fracture import damage as dm
from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import particles, structured

MAT = dm.DamageMaterial(E=2.0e6, nu=0.0, ft=200.0, GF=1.885)


def rotated(eps_xx, eps_yy, theta):
    """Voigt strain (engineering shear) of principal strains rotated by theta."""
    c, s = np.cos(theta), np.sin(theta)
    r = np.array([[c, -s], [s, c]])
    e = r @ np.diag([eps_xx, eps_yy]) @ r.T
    return np.array([e[0, 0], e[1, 1], 2 * e[0, 1]])


# --------------------------------------------------------------------------- Mazars (4.6)


@pytest.mark.parametrize("theta", [0.0, 0.3, np.pi / 2, 2.0])
def test_mazars_is_the_norm_of_the_positive_principal_strains(theta):
    strains = np.array([rotated(1e-4, 0.0, theta), rotated(1e-4, -3e-4, theta), rotated(2e-4, 2e-4, theta),
                        rotated(-1e-4, -2e-4, theta), rotated(3e-4, 4e-4, theta)])
    expected = [1e-4, 1e-4, np.sqrt(8e-8), 0.0, 5e-4]
    assert np.allclose(dm.equivalent_strain(strains), expected, rtol=1e-12, atol=1e-18)
    values, direction = dm.principal_strains(strains[:1])
    assert np.allclose(values, [[1e-4, 0.0]], atol=1e-18)
    assert abs(abs(direction[0] @ [np.cos(theta), np.sin(theta)]) - 1) < 1e-12


def test_mazars_pure_shear_and_plane_stress_out_of_plane_strain():
    assert np.isclose(dm.equivalent_strain(np.array([[0.0, 0.0, 2e-4]]))[0], 1e-4)
    # Uniaxial compression in plane stress: eps_zz = -nu / (1 - nu) (eps_xx + eps_yy) > 0 counts.
    eps = np.array([[-1.0, 0.25, 0.0]])
    assert np.isclose(dm.equivalent_strain(eps, nu=0.2, plane="stress")[0], np.hypot(0.25, 0.1875))
    assert np.isclose(dm.equivalent_strain(eps, nu=0.2, plane="strain")[0], 0.25)


@pytest.mark.parametrize("plane", ["strain", "stress"])
def test_mazars_gradient_matches_finite_differences(plane):
    rng = np.random.default_rng(1)
    eps = rng.normal(size=(20, 3)) * 1e-4
    grad = dm.equivalent_strain_gradient(eps, 0.25, plane)
    step = 1e-10
    for k in range(3):
        de = np.zeros(3)
        de[k] = step
        fd = (dm.equivalent_strain(eps + de, 0.25, plane) - dm.equivalent_strain(eps - de, 0.25, plane)) / (2 * step)
        assert np.allclose(grad[:, k], fd, rtol=1e-5, atol=1e-9)


def mazars_oracle(e, nu, plane):
    """Mazars' eps_eq (4.6) in plain numpy: the test oracle of the compiled law."""
    mean = 0.5 * (e[:, 0] + e[:, 1])
    radius = np.hypot(0.5 * (e[:, 0] - e[:, 1]), 0.5 * e[:, 2])
    ezz = -nu / (1 - nu) * (e[:, 0] + e[:, 1]) if plane == "stress" else np.zeros(len(e))
    parts = np.maximum(np.column_stack([mean + radius, mean - radius, ezz]), 0.0)
    return np.sqrt(np.sum(parts**2, axis=1))


def damage_oracle(kappa, k0, kc):
    """D(kappa) of (4.2) in plain numpy: the test oracle of the compiled law."""
    kappa, k0, kc = np.broadcast_arrays(*(np.asarray(a, float) for a in (kappa, k0, kc)))
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = 1.0 - k0 / kappa * (kc - kappa) / (kc - k0)
    return np.where(kappa < k0, 0.0, np.where(kc > k0, np.clip(soft, 0.0, 1.0), 1.0))


@pytest.mark.parametrize("plane", ["strain", "stress"])
def test_compiled_law_matches_the_numpy_oracle(plane):
    rng = np.random.default_rng(7)
    eps = rng.normal(size=(500, 3)) * 1e-4
    assert np.allclose(dm.equivalent_strain(eps, 0.2, plane), mazars_oracle(eps, 0.2, plane), rtol=1e-13, atol=0)
    k0 = 1e-4
    kappa = np.r_[rng.uniform(0.0, 30 * k0, 500), k0, 20 * k0]
    for kc in (20 * k0, 0.5 * k0):
        assert np.allclose(dm.damage(kappa, k0, kc), damage_oracle(kappa, k0, kc), rtol=1e-14, atol=0)
    # The smeared stress of update is (1 - D) C eps with D of the oracle.
    model = dm.damage_model(dm.DamageMaterial(1.0, 0.2, 1e-4, 1e-5, plane), np.ones(500), kappa_c=20 * k0,
                            regularized=False)
    up = dm.update(model, dm.initial_state(model), eps, tangent=False)
    d = damage_oracle(mazars_oracle(eps, 0.2, plane), k0, 20 * k0)
    assert np.allclose(up.state.damage, d, rtol=1e-12, atol=1e-15)
    assert np.allclose(up.stress, (1 - d)[:, None] * eps @ model.material.elasticity().T, rtol=1e-12, atol=1e-18)


# --------------------------------------------------------------------------- damage law (4.2)


def test_damage_law_limits_and_linear_softening():
    k0, kc = MAT.kappa0, 20 * MAT.kappa0
    kappa = np.array([0.0, 0.5 * k0, k0, 2 * k0, 0.5 * (k0 + kc), kc, 3 * kc])
    d = dm.damage(kappa, k0, kc)
    assert d[0] == d[1] == d[2] == 0.0 and d[-2] == 1.0 and d[-1] == 1.0
    # On [kappa0, kappa_c] the stress E (1 - D) kappa falls linearly from f_t to 0 (Fig 4.3).
    soft = kappa[2:6]
    assert np.allclose(MAT.E * (1 - dm.damage(soft, k0, kc)) * soft, MAT.ft * (kc - soft) / (kc - k0))
    # A law without a softening branch (kappa_c <= kappa0) is perfectly brittle.
    assert np.array_equal(dm.damage([0.5 * k0, k0, 2 * k0], k0, 0.5 * k0), [0.0, 1.0, 1.0])


def test_damage_slope_matches_finite_differences():
    k0, kc = 1e-4, 3e-3
    kappa = np.linspace(1.1 * k0, 0.95 * kc, 30)
    h = 1e-12
    fd = (dm.damage(kappa + h, k0, kc) - dm.damage(kappa - h, k0, kc)) / (2 * h)
    assert np.allclose(dm.damage_slope(kappa, k0, kc), fd, rtol=1e-5)
    assert np.all(dm.damage_slope([0.5 * k0, 2 * kc], k0, kc) == 0)


def test_dissipation_density_is_the_integral_of_the_energy_release_rate():
    """phi(kappa) = int E s^2 / 2 D'(s) ds; g_L = f_t kappa_c / 2 at failure (4.27)."""
    k0, kc = MAT.kappa0, 15 * MAT.kappa0
    for kappa in (0.5 * k0, 2 * k0, 0.6 * kc, kc, 2 * kc):
        exact, _ = quad(lambda s: 0.5 * MAT.E * s**2 * dm.damage_slope(s, k0, kc), k0, min(kappa, kc),
                        epsabs=1e-14) if kappa > k0 else (0.0, 0)
        assert np.isclose(dm.dissipation_density(kappa, k0, kc, MAT.E), exact, rtol=1e-9, atol=1e-15)
    assert np.isclose(dm.dissipation_density(kc, k0, kc, MAT.E), 0.5 * MAT.ft * kc)


def uniaxial_model(kappa_c=2e-3, volume=(2.0,)):
    return dm.damage_model(MAT, np.asarray(volume, float), kappa_c=kappa_c, regularized=False)


def test_crack_opening_is_the_spent_fraction_of_the_fracture_energy():
    """w / w_c = D kappa / kappa_c = phi(kappa) / g_L: small while D is already large."""
    k0, kc = MAT.kappa0, 65 * MAT.kappa0  # kappa_c / kappa0 of the 0.2 mm branching model
    kappa = np.array([0.5 * k0, 2 * k0, 10 * k0, 0.6 * kc, kc, 2 * kc])
    w = dm.crack_opening(kappa, k0, kc)
    assert np.allclose(w, dm.dissipation_density(kappa, k0, kc, MAT.E) / (0.5 * MAT.ft * kc), rtol=1e-12)
    assert w[0] == 0.0 and w[-2] == w[-1] == 1.0
    assert dm.damage(10 * k0, k0, kc) > 0.9 and w[2] < 0.15  # D says failed, the band has barely opened
    # Before initiation (kappa_c NaN) and when perfectly brittle (kappa_c <= kappa0).
    assert dm.crack_opening(2 * k0, k0, np.nan) == 0.0 and dm.crack_opening(2 * k0, k0, 0.5 * k0) == 1.0


def test_irreversibility_under_unloading_and_reloading():
    model = uniaxial_model()
    k0 = MAT.kappa0
    state = dm.initial_state(model)
    up = dm.update(model, state, np.array([[5 * k0, 0.0, 0.0]]))
    state = up.state
    d1 = state.damage[0]
    assert 0 < d1 < 1 and np.isclose(state.kappa[0], 5 * k0) and state.damaged[0]
    assert np.allclose(state.normal[0], [1.0, 0.0])
    # Unloading: kappa and D stay, the stress returns along the secant (1 - D) E eps, no dissipation.
    for eps in (3 * k0, 0.5 * k0, -k0):
        down = dm.update(model, state, np.array([[eps, 0.0, 0.0]]))
        assert down.state.kappa[0] == state.kappa[0] and down.state.damage[0] == d1
        assert np.isclose(down.stress[0, 0], (1 - d1) * MAT.E * eps) and down.dissipation == 0.0
        assert np.allclose(down.tangent[0], (1 - d1) * MAT.elasticity())
    # Reloading beyond the history damages further and dissipates.
    again = dm.update(model, state, np.array([[8 * k0, 0.0, 0.0]]))
    assert again.state.damage[0] > d1 and again.dissipation > 0
    total = uniaxial_model().volume[0] * dm.dissipation_density(8 * k0, k0, 2e-3, MAT.E)
    assert np.isclose(up.dissipation + again.dissipation, total)


def test_consistent_tangent_matches_finite_differences():
    model = dm.damage_model(dm.DamageMaterial(1.0e3, 0.2, 1.0, 0.05), np.ones(3), kappa_c=0.02, regularized=False)
    state = dm.initial_state(model)
    eps = np.array([[3e-3, 1e-3, 2e-3], [4e-3, -1e-3, 0.0], [1e-3, 2.5e-3, -1e-3]])
    state = dm.update(model, state, 0.9 * eps).state  # damaged, now loading further
    tan = dm.update(model, state, eps).tangent
    h = 1e-9
    for k in range(3):
        de = np.zeros(3)
        de[k] = h
        fd = (dm.update(model, state, eps + de).stress - dm.update(model, state, eps - de).stress) / (2 * h)
        assert np.allclose(tan[:, :, k], fd, rtol=1e-5, atol=1e-6)


def test_failed_points_carry_no_stress_and_the_floor_only_touches_the_tangent():
    model = uniaxial_model(kappa_c=1e-3)
    up = dm.update(model, dm.initial_state(model), np.array([[2e-3, 0.0, 0.0]]), tangent_floor=1e-6)
    assert up.state.damage[0] == 1.0 and up.stress[0, 0] == 0.0
    assert np.allclose(up.tangent[0], 1e-6 * MAT.elasticity())
    assert np.isclose(up.dissipation, 2.0 * 0.5 * MAT.ft * 1e-3)


# --------------------------------------------------------------------------- A_L and kappa_c (4.28)


def square_cell(a=1.0):
    """A square cell of half-width a around the origin, as four quadrant quads."""
    quads = []
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        q = np.array([[0, 0], [sx * a, 0], [sx * a, sy * a], [0, sy * a]], float)
        quads.append(q if sx * sy > 0 else q[[0, 3, 2, 1]])
    return dm.CellGeometry(np.zeros(4, np.int64), np.array(quads), 1)


@pytest.mark.parametrize("angle", [0.0, 0.2, np.pi / 4, 1.0, np.pi / 2, 2.5, np.pi])
def test_chord_of_a_square_cell(angle):
    n = np.array([[np.cos(angle), np.sin(angle)]])
    t = np.array([-n[0, 1], n[0, 0]])
    expected = 2 * 1.5 / np.abs(t).max()
    assert np.isclose(dm.chord_lengths(square_cell(1.5), [0], n)[0], expected, rtol=1e-12)


@pytest.mark.parametrize("angle", [0.0, 0.1, np.pi / 6, 0.7, np.pi / 2, 2.0])
def test_chord_of_the_regular_hexagon_of_an_equilateral_mesh(angle):
    """Around an interior node of equilateral triangles the median-dual cell is the regular
    hexagon with apothem h/2 (its sides bisect the edges): chord h / cos(phi), phi the angle of
    the chord to the nearest edge direction."""
    h = 1.0
    i, j = np.meshgrid(np.arange(-3, 4), np.arange(-3, 4))
    x = np.column_stack([(i + 0.5 * j).ravel() * h, (j * np.sqrt(3) / 2).ravel() * h])
    p = particles(x, Delaunay(x).simplices)
    centre = int(np.argmin(np.linalg.norm(x, axis=1)))
    n = np.array([[np.cos(angle), np.sin(angle)]])
    t_angle = angle + np.pi / 2
    phi = (t_angle + np.pi / 6) % (np.pi / 3) - np.pi / 6
    assert np.isclose(dm.chord_lengths(dm.cell_geometry(p), [centre], n)[0], h / np.cos(phi), rtol=1e-12)


def test_chords_of_the_diagonal_split_grid():
    """Interior median-dual cell of a diagonal-split square grid: a hexagon with vertices at
    the centroids (2h/3, h/3), (h/3, 2h/3), ...; boundary rays leaving the domain count 0."""
    h = 0.5
    p = structured(2.0, 2.0, 5, 5)
    g = dm.cell_geometry(p)
    centre = int(np.argmin(np.linalg.norm(p.x - 1.0, axis=1)))
    # Crack normals and their chords: across x, across y, chord along (1, 1), chord along (-1, 1).
    normals = {"n = e_x": [1, 0], "n = e_y": [0, 1], "t = (1, 1)": [1, -1], "t = (-1, 1)": [1, 1]}
    got = [dm.chord_lengths(g, [centre], np.array([v], float) / np.linalg.norm(v))[0] for v in normals.values()]
    assert np.allclose(got, [h, h, np.sqrt(2) * h, 2 * np.sqrt(2) * h / 3])
    bottom = int(np.argmin(np.linalg.norm(p.x - [1.0, 0.0], axis=1)))
    assert np.isclose(dm.chord_lengths(g, [bottom], np.array([[1.0, 0.0]]))[0], 0.5 * h)
    # Several nodes at once, in any order.
    both = dm.chord_lengths(g, [bottom, centre], np.array([[1.0, 0.0], [1.0, 0.0]]))
    assert np.allclose(both, [0.5 * h, h])


def test_regularized_kappa_c_scales_with_chord_over_volume():
    """kappa_c = (G_F / f_t) A_L / V_L (4.28): on a grid of spacing h, A_L / V_L = 1 / h for a
    crack across the bar, so kappa_c h is the same at every spacing and g_L V_L = G_F A_L / 2."""
    values = []
    for n in (9, 17, 33):
        p = structured(1.0, 1.0, n, n)
        d = nodal_domains(p)
        model = dm.damage_model(MAT, d.area, geometry=dm.cell_geometry(p))
        centre = int(np.argmin(np.linalg.norm(p.x - 0.5, axis=1)))
        eps = np.zeros((p.num_nodes, 3))
        eps[centre] = rotated(2 * MAT.kappa0, 0.0, 0.0)
        state = dm.update(model, dm.initial_state(model), eps).state
        assert state.damaged.sum() == 1 and np.allclose(state.normal[centre], [1.0, 0.0])
        h = 1.0 / (n - 1)
        assert np.isclose(state.chord[centre], h) and np.isclose(d.area[centre], h * h)
        values.append(state.kappa_c[centre] * h)
        g_l = 0.5 * MAT.ft * state.kappa_c[centre]
        assert np.isclose(g_l * d.area[centre], MAT.GF * state.chord[centre] / 2)
    assert np.allclose(values, MAT.GF / MAT.ft)


def test_crack_normal_follows_the_major_principal_stress():
    p = structured(1.0, 1.0, 9, 9)
    d = nodal_domains(p)
    model = dm.damage_model(MAT, d.area, geometry=dm.cell_geometry(p))
    centre = int(np.argmin(np.linalg.norm(p.x - 0.5, axis=1)))
    eps = np.zeros((p.num_nodes, 3))
    eps[centre] = rotated(3 * MAT.kappa0, -MAT.kappa0, np.pi / 4)
    state = dm.update(model, dm.initial_state(model), eps).state
    assert np.isclose(abs(state.normal[centre] @ [1, 1]) / np.sqrt(2), 1.0)
    # The chord runs along (-1, 1): 2 sqrt(2) h / 3 (see the diagonal-split test).
    assert np.isclose(state.chord[centre], 2 * np.sqrt(2) / 3 / 8)


def test_too_coarse_cells_are_rejected_with_the_size_limit():
    coarse = dm.DamageMaterial(E=2.0e6, nu=0.0, ft=200.0, GF=1e-4)
    p = structured(1.0, 1.0, 3, 3)
    d = nodal_domains(p)
    model = dm.damage_model(coarse, d.area, geometry=dm.cell_geometry(p))
    state = dm.update(model, dm.initial_state(model), np.tile([1e-2, 0.0, 0.0], (p.num_nodes, 1))).state
    with pytest.raises(InputError, match="too coarse for G_F"):
        dm.check_regularization(model, state)


@pytest.mark.parametrize("kwargs, name", [({"GF": -1.0}, "GF"), ({"E": 0.0}, "E"), ({"ft": np.nan}, "ft"),
                                          ({"nu": 0.5}, "nu"), ({"plane": "shell"}, "plane")])
def test_bad_material_names_the_parameter(kwargs, name):
    args = {"E": 2e6, "nu": 0.0, "ft": 200.0, "GF": 1.885, **kwargs}
    with pytest.raises(InputError, match=name):
        dm.DamageMaterial(**args)


def test_model_input_checks():
    with pytest.raises(InputError, match="kappa_c"):
        dm.damage_model(MAT, np.ones(2), kappa_c=0.5 * MAT.kappa0, regularized=False)
    with pytest.raises(InputError, match="geometry"):
        dm.damage_model(MAT, np.ones(2))
    with pytest.raises(InputError, match="kappa0_factor"):
        dm.damage_model(MAT, np.ones(2), kappa0_factor=1.5, kappa_c=1.0, regularized=False)


def test_failure_displacement_of_a_linear_softening_curve():
    u = np.r_[0.0, 0.5, 1.0, np.linspace(1.0, 3.3, 12)[1:]]
    force = np.clip(np.minimum(u, (3.0 - u) / 2.0), 0.0, None)
    assert np.isclose(dm.failure_displacement(u, force), 3.0)
    # A sudden break (the force still rising before it vanishes): the first zero.
    assert dm.failure_displacement([0.0, 1.0, 2.0, 2.1], [0.0, 1.0, 2.0, 0.0]) == 2.1
    assert np.isnan(dm.failure_displacement([0.0, 1.0], [0.0, 1.0]))


def test_a_point_without_chord_takes_its_cell_size():
    """A corner cell's line along the crack can leave the domain at once on both sides (chord 0);
    kappa_c (4.28) then takes A_L = sqrt(V_L), the cell's size, instead of refusing the cell."""
    p = structured(1.0, 1.0, 5, 5)
    d = nodal_domains(p)
    model = dm.damage_model(MAT, d.area, geometry=dm.cell_geometry(p))
    corner = int(np.argmin(np.linalg.norm(p.x, axis=1)))
    n = np.array([[1.0, 1.0]]) / np.sqrt(2.0)
    assert dm.chord_lengths(model.geometry, [corner], n)[0] == 0.0
    m = model.num_points
    normal, chord, kappa_c = np.zeros((m, 2)), np.full(m, np.nan), np.full(m, np.nan)
    dm.initiate(model, np.array([corner]), np.array([[1.0, 1.0, 1.0]]), normal, chord, kappa_c)
    assert np.allclose(np.abs(normal[corner]), n[0])
    assert np.isclose(chord[corner], np.sqrt(d.area[corner]))
    assert kappa_c[corner] > model.kappa0[corner]
