"""Explicit crack-band FEM for Kalthoff's impact problem (fem_baselines.crack_band_dynamics)."""
import dolfinx_solver  # noqa: F401  (must precede dolfinx / petsc4py)

import numpy as np
import pytest

from fem_baselines import crack_band_dynamics as cbd
from rkfx.fracture import damage as dm
from rkfx.errors import InputError

H = 0.005          # coarse mesh: ~500 nodes
A1, A2 = 0.05, 0.025
ELASTIC = dict(ft=1e11, GF=1e12)   # damage threshold never reached, band check passes


@pytest.fixture(scope="module")
def plate():
    return cbd.cracked_plate_mesh(H)


@pytest.fixture(scope="module")
def damaged_run():
    return cbd.kalthoff_crack_band(H, 30e-6)


def test_mesh_has_slit_open_except_at_tip(plate):
    on_line = np.isclose(plate.x[:, 1], A2) & (plate.x[:, 0] <= A1 + 1e-12)
    xs, counts = np.unique(np.round(plate.x[on_line, 0], 12), return_counts=True)
    assert xs[-1] == pytest.approx(A1) and counts[-1] == 1            # one tip node
    assert np.all(counts[:-1] == 2) and len(xs) >= round(A1 / H)      # faces duplicated, mouth too
    upper, lower, tip = cbd.slit_sides(plate, A1, A2)
    assert len(upper) == len(lower) == len(xs) - 1 and len(tip) == 1
    # no cell touches both faces
    cells_up = np.isin(plate.triangles, upper).any(axis=1)
    cells_lo = np.isin(plate.triangles, lower).any(axis=1)
    assert not np.any(cells_up & cells_lo)


def test_rigid_opening_of_slit_costs_no_strain(plate):
    """Translate the upper face nodes and everything above the slit left of the tip region
    rigidly: cells along both faces stay unstrained."""
    ops = cbd.fem_operators(plate, 8000.0)
    upper, _, _ = cbd.slit_sides(plate, A1, A2)
    moved = np.zeros(plate.num_nodes, bool)
    moved[upper] = True
    moved |= plate.x[:, 1] > A2 + 1e-12
    d = np.zeros(2 * plate.num_nodes)
    d[1::2] = moved * 1e-3            # opening u_y = 1 mm of the upper side
    strain = np.abs(ops.B @ d).reshape(-1, 3).max(axis=1)
    far = plate.centroids[:, 0] < A1 - 2 * H       # away from the ligament ahead of the tip
    assert strain[far].max() < 1e-12
    assert strain[~far].max() > 1e-6              # the ligament ahead of the tip is stretched


def test_lumped_mass_and_strain_operator(plate):
    rho = 8000.0
    ops = cbd.fem_operators(plate, rho)
    assert ops.mass[0::2].sum() == pytest.approx(rho * 0.01, rel=1e-12)
    assert np.allclose(ops.mass[0::2], ops.mass[1::2]) and np.all(ops.mass > 0)
    assert ops.area.sum() == pytest.approx(0.01, rel=1e-12)
    d = np.zeros(2 * plate.num_nodes)
    d[0::2] = 0.01 * plate.x[:, 0] - 0.5 * plate.x[:, 1]
    d[1::2] = 0.02 * plate.x[:, 1] + 0.53 * plate.x[:, 0]
    assert np.allclose((ops.B @ d).reshape(-1, 3), [0.01, 0.02, 0.03], atol=1e-12)


def test_triangle_chords():
    """The chords through the centroids that set the crack band width (either orientation)."""
    tri = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]] * 2 + [[[0.0, 0.0], [0.0, 1.0], [1.0, 0.0]]])
    geometry = cbd.triangle_geometry(tri)
    normals = np.array([[0.0, 1.0], [1.0, 0.0], [1.0, -1.0]]) * [[1.0], [1.0], [np.sqrt(0.5)]]
    got = dm.chord_lengths(geometry, np.arange(3), normals)  # chords perpendicular to the normals
    # horizontal chord through (1/3, 1/3): x from 0 to 2/3; the 45-degree one from (0, 0) to (1/2, 1/2)
    assert np.allclose(got, [2 / 3, 2 / 3, np.sqrt(0.5)])


def test_elastic_run_conserves_energy_and_impact_edge_moves_at_v0():
    r = cbd.kalthoff_crack_band(H, 15e-6, **ELASTIC)
    run = r.run
    assert run.energy_error < 1e-2
    assert np.all(r.damage == 0) and r.dissipated[-1] == 0 and np.all(np.isnan(run.initiation_time))
    impact = (np.abs(r.x[:, 0]) < 1e-12) & (r.x[:, 1] < A2 - 1e-12)
    t = run.steps * run.dt
    u, v = run.displacement.reshape(-1, 2), run.velocity.reshape(-1, 2)
    assert np.allclose(v[impact, 0], 16.5)
    assert np.allclose(u[impact, 0], 16.5 * t, rtol=1e-10)
    bottom = np.abs(r.x[:, 1]) < 1e-12
    assert np.all(u[bottom, 1] == 0)
    kinetic, internal, external = (run.column(c) for c in ("kinetic", "internal", "external"))
    assert kinetic[-1] > 0 and internal[-1] > 0
    # the impact nodes start at v0 (their kinetic energy is the initial one); the work of the
    # prescribed motion balances the energy
    assert kinetic[0] + external[-1] == pytest.approx(kinetic[-1] + internal[-1], rel=1e-3)


def test_damage_starts_at_crack_tip_and_dissipation_grows(damaged_run):
    r = damaged_run
    onset = r.run.initiation_time
    first = np.flatnonzero(onset == np.nanmin(onset))
    dist = np.hypot(*(r.centroids[first] - [A1, A2]).T)
    assert dist.max() < 2 * H
    assert r.dissipated[-1] > 0 and np.all(np.diff(r.dissipated) >= 0)
    assert r.damage.max() > 0.5
    assert r.run.energy_error < 2e-2


def test_checkpoint_resume_reproduces_run(tmp_path, damaged_run):
    steps = damaged_run.run.steps
    t_end = 30e-6
    # a checkpoint mid-run (after damage started), then resume from it as if killed there
    ck = tmp_path / "ck"
    cbd.kalthoff_crack_band(H, t_end, checkpoint_every=(steps * 3) // 4, work_dir=ck)
    (ck / "fem-crack-band_h0.005" / "result.npz").unlink()
    resumed = cbd.kalthoff_crack_band(H, t_end, resume=ck)
    assert resumed.run.resumed_from == (steps * 3) // 4
    for name in ("displacement", "damage", "history", "initiation_time"):
        np.testing.assert_array_equal(getattr(resumed.run, name), getattr(damaged_run.run, name), err_msg=name)


def test_unregularized_uses_given_kappa_c():
    kappa0 = 9.5e8 / 1.9e11
    r = cbd.kalthoff_crack_band(H, 25e-6, regularized=False, kappa_c=20 * kappa0)
    assert r.dissipated[-1] > 0


@pytest.mark.parametrize("kwargs, match", [
    (dict(h=0.0), "h = 0.0 must be positive"),
    (dict(h=0.02), "too coarse"),
    (dict(h=H, GF=1e3), "band too wide"),
    (dict(h=H, regularized=False), "needs kappa_c"),
    (dict(h=H, regularized=False, kappa_c=1e-3), "needs kappa_c > kappa0"),
    (dict(h=H, kappa_c=0.1), "only used with regularized=False"),
    (dict(h=H, rho=-1.0), "rho"),
    (dict(h=H, t_end=0.0), "t_end"),
    (dict(h=H, samples=0), "samples"),
    (dict(h=H, courant=1.5), "courant"),
    (dict(h=H, ft=-1.0), "ft"),
    (dict(h=H, a1=0.2), "inside the plate"),
])
def test_bad_inputs(kwargs, match):
    with pytest.raises(InputError, match=match):
        cbd.kalthoff_crack_band(**kwargs)


def test_crack_band_dissipates_g_f_per_crack_length(damaged_run):
    """Bazant-Oh scaling: a failed cell dissipates G_F times its chord along the crack."""
    r = damaged_run
    done = np.flatnonzero(r.damage == 1.0)
    assert done.size
    geometry = cbd.triangle_geometry(r.x[r.triangles])
    chord = dm.chord_lengths(geometry, done, r.run.normal[done])
    e = r.x[r.triangles[done, 1:]] - r.x[r.triangles[done, :1]]
    area = 0.5 * np.abs(e[:, 0, 0] * e[:, 1, 1] - e[:, 0, 1] * e[:, 1, 0])
    kappa_c = 2 * 2e4 / 9.5e8 * chord / area
    phi = dm.dissipation_density(r.run.kappa[done], 9.5e8 / 1.9e11, kappa_c, 1.9e11)
    assert np.allclose(phi * area, 2e4 * chord, rtol=1e-12)


def test_edge_traction_is_the_resultant_on_top_and_bottom():
    m = cbd.cracked_plate_mesh(0.004, width=0.1, height=0.04, a1=0.05, a2=0.02)
    f = cbd.edge_traction(m, 1e6).reshape(-1, 2)
    top, bottom = np.isclose(m.x[:, 1], 0.04), np.isclose(m.x[:, 1], 0.0)
    # sigma * width on each edge, outward; nothing on the slit faces or the sides.
    assert f[top, 1].sum() == pytest.approx(1e6 * 0.1, rel=1e-12)
    assert f[bottom, 1].sum() == pytest.approx(-1e6 * 0.1, rel=1e-12)
    assert np.abs(f[~(top | bottom)]).max() == 0 and np.abs(f[:, 0]).max() == 0


def test_branching_plate_balances_energy_and_cracks_from_the_tip():
    r = cbd.branching_crack_band(0.002, 40e-6)
    run = r.run
    assert run.energy_error < 1e-3
    kinetic, internal, external = (run.column(c) for c in ("kinetic", "internal", "external"))
    # The traction's work = kinetic energy + internal work, which holds the dissipation.
    assert external[-1] == pytest.approx(kinetic[-1] + internal[-1], rel=1e-3)
    assert internal[-1] > r.dissipated[-1] > 0
    onset = run.initiation_time
    first = np.flatnonzero(onset == np.nanmin(onset))
    assert np.hypot(*(r.centroids[first] - [0.05, 0.02]).T).max() < 2 * 0.002
    with pytest.raises(InputError, match="sigma"):
        cbd.branching_crack_band(0.002, sigma=0.0)


def test_resume_reads_a_finished_run_back_without_meshing(tmp_path, monkeypatch):
    first = cbd.branching_crack_band(0.004, 5e-6, work_dir=tmp_path)

    def no_mesh(*args, **kwargs):
        raise AssertionError("meshed again")

    monkeypatch.setattr(cbd, "cracked_plate_mesh", no_mesh)
    again = cbd.branching_crack_band(0.004, 5e-6, resume=tmp_path)
    np.testing.assert_array_equal(again.run.history, first.run.history)
    np.testing.assert_array_equal(again.triangles, first.triangles)
    np.testing.assert_array_equal(again.centroids, first.centroids)
    assert (again.num_nodes, again.num_cells, again.h) == (first.num_nodes, first.num_cells, first.h)


def test_resume_of_a_run_without_saved_mesh_meshes_and_writes_to_the_new_work_dir(tmp_path):
    first = cbd.branching_crack_band(0.004, 5e-6, work_dir=tmp_path / "a")
    (tmp_path / "a" / "fem-crack-band_h0.004" / cbd.MESH_FILE).unlink()   # as written by an older rkfx
    again = cbd.branching_crack_band(0.004, 5e-6, resume=tmp_path / "a", work_dir=tmp_path / "b")
    np.testing.assert_array_equal(again.run.history, first.run.history)
    assert (tmp_path / "b" / "fem-crack-band_h0.004" / cbd.MESH_FILE).is_file()
