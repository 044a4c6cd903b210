"""The nonlocal equivalent strain (rkfx.fracture.nonlocal_average) and the damage model that uses it."""
from dataclasses import replace

import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.fracture import damage as dm
from rkfx.fracture.nonlocal_average import nonlocal_average
from rkfx.assembly.smeared_strain import smeared_strain
from rkfx.models.damage_dynamics import DamageForce, damage_field
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded
from rkfx.approximation.shape_functions import rk_approximation

MATERIAL = dm.DamageMaterial(E=1.0e4, nu=0.25, ft=1.0, GF=0.05, plane="strain")


@pytest.fixture(scope="module")
def square():
    xs = ys = np.linspace(0.0, 1.0, 21)
    p = graded(xs, ys)
    domains = grid_domains(xs, ys)
    return p, domains


def test_rows_average_constants_and_interior_linear_fields(square):
    """Each row sums to 1 (a constant field stays), and the symmetric bell reproduces a linear
    field at particles whose disc lies inside the square."""
    p, domains = square
    avg = nonlocal_average(p.x, domains.area, 0.2, 1.0)
    rows = np.arange(p.num_nodes)
    out = np.zeros(p.num_nodes)
    avg.average(np.full(p.num_nodes, 3.0), rows, out)
    np.testing.assert_allclose(out, 3.0, rtol=1e-14)
    linear = 1.0 + 2.0 * p.x[:, 0] - p.x[:, 1]
    avg.average(linear, rows, out)
    inside = np.all((p.x > 0.2 + 1e-9) & (p.x < 0.8 - 1e-9), axis=1)
    assert inside.sum() > 100
    np.testing.assert_allclose(out[inside], linear[inside], rtol=1e-12)
    # Near an edge the average is pulled inwards: no particle reproduces a field it cannot see.
    assert not np.allclose(out[~inside], linear[~inside], rtol=1e-6)
    # Only the requested rows are written.
    out[:] = -1.0
    avg.average(linear, np.array([5, 7]), out)
    assert np.count_nonzero(out != -1.0) == 2


def test_rows_built_for_some_particles_are_the_whole_builds_rows(square):
    """A rank builds the rows of its own particles only (points=): their share equals the
    share of the whole build entry for entry, crack cuts included; the partial rows refuse to
    average until a share is taken, and a share of other particles is refused."""
    p, domains = square
    crack = np.array([[[0.0, 0.5], [0.5, 0.5]]])
    whole = nonlocal_average(p.x, domains.area, 0.2, 1.0, crack)
    mine = np.flatnonzero(p.x[:, 0] > 0.4)
    part = nonlocal_average(p.x, domains.area, 0.2, 1.0, crack, points=mine)
    a, b = whole.restricted(mine), part.restricted(mine)
    for name in ("indptr", "indices", "weights"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert np.count_nonzero(b.weights == 0.0) > 0  # pairs across the crack are cut
    with pytest.raises(InputError, match="restricted"):
        part.average(np.zeros(p.num_nodes), mine, np.zeros(p.num_nodes))
    with pytest.raises(InputError, match="other particles"):
        part.restricted(np.array([0, 1]))
    with pytest.raises(InputError, match="ascending"):
        nonlocal_average(p.x, domains.area, 0.2, 1.0, points=mine[::-1])


def test_a_lone_strained_particle_does_not_initiate_on_its_own_strain(square):
    """The history follows the average: a strain above kappa0 at one particle only, averaged with
    unstrained neighbours, stays below the threshold; a uniform one crosses it everywhere, with
    kappa_c = 2 G_F / (f_t b) of the band width b = band_factor R."""
    p, domains = square
    op = smeared_strain(p, rk_approximation(p.x, p.spacing, 1.75), domains)
    local = dm.damage_model(MATERIAL, domains.area, geometry=dm.cell_geometry(domains))
    model = replace(local, nonlocal_average=nonlocal_average(p.x, domains.area, 0.2, 1.5))
    centre = int(np.argmin(np.linalg.norm(p.x - [0.5, 0.5], axis=1)))
    force = DamageForce(op, model, damage_field(model))
    force._eq[:] = 0.0
    force._eq[centre] = 3.0 * MATERIAL.kappa0
    force._average()
    assert not force._crossing.any()
    assert 0 < force._eq[centre] < MATERIAL.kappa0
    d = np.zeros(2 * p.num_nodes)
    d[1::2] = 1.5 * MATERIAL.kappa0 * p.x[:, 1]  # eps_yy = 1.5 kappa0 everywhere
    field = damage_field(model)
    DamageForce(op, model, field)(d)
    assert field.damaged.all()
    np.testing.assert_allclose(field.kappa_c, 2.0 * MATERIAL.GF / (MATERIAL.ft * 0.3), rtol=1e-14)


def test_the_quasi_static_update_refuses_the_nonlocal_model(square):
    p, domains = square
    model = dm.damage_model(MATERIAL, domains.area, geometry=dm.cell_geometry(domains))
    model = replace(model, nonlocal_average=nonlocal_average(p.x, domains.area, 0.2, 1.0))
    with pytest.raises(InputError, match="explicit dynamics only"):
        dm.update(model, dm.initial_state(model), np.zeros((p.num_nodes, 3)))


@pytest.mark.parametrize("radius, factor, match", [(0.0, 1.0, "positive length"), (0.05, 1.0, "1.5 particle"),
                                                   (0.2, -1.0, "band_factor")])
def test_bad_radius_or_band_factor_is_refused_in_one_line(square, radius, factor, match):
    p, domains = square
    with pytest.raises(InputError, match=match):
        nonlocal_average(p.x, domains.area, radius, factor)


def test_the_band_factor_solves_its_equation_on_the_measured_table():
    """b / R from the 1-D measurements: the ratio r = kappa_c / kappa0 = 2 l / (b R) it implies reads
    b back off the table; b grows with l / R; a radius whose band leaves kappa_c < 2 kappa0 is refused."""
    from rkfx.fracture.nonlocal_average import _RATIOS, _WIDTHS, band_factor

    for r, b in zip(_RATIOS, _WIDTHS):
        assert band_factor(r * b / 2.0) == pytest.approx(b, rel=1e-9)
    factors = [band_factor(v) for v in (1.5, 3.0, 6.5, 20.0, 60.0)]
    assert all(a < b for a, b in zip(factors, factors[1:]))
    with pytest.raises(InputError, match="kappa_c < 2 kappa0"):
        band_factor(1.0)


def test_released_energy_is_the_work_of_a_uniform_softening():
    """Under a uniform uniaxial strain the average is the local strain, and the released energy
    sum V Y dD of small steps approaches the closed form V phi(kappa) of the local law (nu = 0)."""
    xs = ys = np.linspace(0.0, 1.0, 11)
    p = graded(xs, ys)
    domains = grid_domains(xs, ys)
    op = smeared_strain(p, rk_approximation(p.x, p.spacing, 1.75), domains, eps_p=0.0)
    material = dm.DamageMaterial(E=1.0e4, nu=0.0, ft=1.0, GF=1.5e-4, plane="strain")  # kappa_c = 10 kappa0
    local = dm.damage_model(material, domains.area, geometry=dm.cell_geometry(domains))
    model = replace(local, nonlocal_average=nonlocal_average(p.x, domains.area, 0.2, 1.5))
    field = damage_field(model)
    force = DamageForce(op, model, field)
    kappa_c = 2.0 * material.GF / (material.ft * 0.3)
    d = np.zeros(2 * p.num_nodes)
    for s in np.linspace(0.0, 0.5 * kappa_c, 2001)[1:]:
        d[1::2] = s * p.x[:, 1]
        force(d)
    phi = dm.dissipation_density(field.kappa, model.kappa0, field.kappa_c, material.E) * model.volume
    assert field.damaged.all() and field.damage.min() > 0.5
    np.testing.assert_allclose(field.dissipation(model), phi, rtol=1e-4)
    assert field.dissipated(model) == pytest.approx(phi.sum(), rel=1e-4)
    assert "released" in field.arrays  # checkpointed with the history


def test_released_energy_closes_the_work_of_a_fracture_run():
    """On the branching plate (coarse, short), the released energy is what the internal work
    leaves after the energy still stored, (1 - D) of each particle's cell and MSCNI energy."""
    from rkfx.cases import _dynamic_fracture as dyn
    from rkfx.cases import crack_branching as cb

    prm = {k: p.default for k, p in cb.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], prm["plane"])
    pl, track, model, f = cb.setup(1.6e-3, material, prm, nonlocal_radius=3.2e-3)
    r = dyn.simulate("nonlocal", pl, model, track, [], 5e-5, external_force=lambda t: f)
    e, diff = pl.op.strains(r.displacement)
    c = np.ascontiguousarray(material.elasticity())
    stored = 0.5 * float(r.displacement @ pl.op.damaged_force((1 - r.damage)[:, None] * (e @ c.T), diff, c, r.damage))
    released = r.history[-1, 1]
    assert np.count_nonzero(r.damage >= 1.0) > 10, "the run must break particles"
    assert released == pytest.approx(r.history[-1, 4] - stored, rel=5e-3)
    np.testing.assert_allclose(r.dissipation.sum(), released, rtol=1e-12)
    # The run's own stored-energy column is the same energy, and its released work the same sum.
    assert r.column("stored")[-1] == pytest.approx(stored, rel=1e-9)
    assert r.released[-1] == pytest.approx(released, rel=5e-3)


def test_the_local_law_releases_more_than_its_closed_form():
    """With the local law the history's released energy (internal work - stored) closes the
    work as for the nonlocal one, and exceeds the law's sum V_L phi(kappa_L), which counts only
    what Mazars' norm sees (docs/fracture.md)."""
    from rkfx.cases import _dynamic_fracture as dyn
    from rkfx.cases import crack_branching as cb

    prm = {k: p.default for k, p in cb.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], prm["plane"])
    pl, track, model, f = cb.setup(1.6e-3, material, prm)
    r = dyn.simulate("local", pl, model, track, [], 5e-5, external_force=lambda t: f)
    e, diff = pl.op.strains(r.displacement)
    c = np.ascontiguousarray(material.elasticity())
    stored = 0.5 * float(r.displacement @ pl.op.damaged_force((1 - r.damage)[:, None] * (e @ c.T), diff, c, r.damage))
    assert r.column("stored")[-1] == pytest.approx(stored, rel=1e-9)
    assert r.released[-1] == pytest.approx(r.history[-1, 4] - stored, rel=1e-9)
    assert r.released[-1] > 1.1 * r.history[-1, 1] > 0
    assert np.all(np.diff(r.released) > -1e-6 * r.released[-1])  # released energy only grows


def test_the_band_table_is_what_the_one_dimensional_bar_measures():
    """The b / R table of band_factor is verification.nonlocal_band's measurement at h / R = 1/20
    (one point re-measured), with the bar's energy balanced."""
    from rkfx.fracture.nonlocal_average import _RATIOS, _WIDTHS
    from verification.nonlocal_band import run

    m = run(10.0, 0.05)
    assert m["converged"] and abs(m["balance"]) < 1e-3
    assert m["b_eff_over_R"] == pytest.approx(_WIDTHS[list(_RATIOS).index(10.0)], abs=1e-4)


@pytest.mark.parametrize("radius, match", [(5e-4, "below 1.5 spacings"), (2e-2, "over 25 spacings"),
                                           (-1.0, "positive length")])
def test_a_case_refuses_a_nonlocal_radius_outside_its_range_in_one_line(radius, match):
    from rkfx.cases import crack_branching as cb

    prm = {k: p.default for k, p in cb.PARAMS.items()} | {"nonlocal_radius": radius}
    with pytest.raises(InputError, match=match) as err:
        cb.check(**prm)
    assert "\n" not in str(err.value)


def test_a_band_too_wide_for_the_fracture_energy_is_refused():
    from rkfx.cases._dynamic_fracture import check_nonlocal

    with pytest.raises(InputError, match="kappa_c < 2 kappa0"):
        check_nonlocal(2e-3, [4e-4], E=1.9e11, ft=9.5e8, GF=2e3)  # l = 0.42 mm against R = 2 mm
