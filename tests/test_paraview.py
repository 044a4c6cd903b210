"""ParaView output: particle and nodal-cell series, the FEM writer, and a case's --vtk files read back."""
import json

import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.geometry.particles import structured
from rkfx.output.paraview import FieldSeries, nodal_cells, pvd_times as times_of

pv = pytest.importorskip("pyvista")


def _read(pvd, t):
    reader = pv.get_reader(str(pvd))
    reader.set_active_time_value(t)
    return reader, reader.read()[0]


def test_particle_and_cell_series_read_back(tmp_path):
    p = structured(2.0, 1.0, 5, 4)
    series = FieldSeries(tmp_path, "run", p.x, cells=nodal_cells(p))
    stress = np.column_stack([p.x[:, 0], p.x[:, 1], -p.x[:, 0]])
    for t in (0.25, 1.0):
        series.write(t, displacement=t * p.x, pressure=t * p.x[:, 0], stress=stress)
    reader, mesh = _read(series.pvd, 1.0)
    assert reader.time_values == [0.25, 1.0]
    assert mesh.n_points == p.num_nodes
    np.testing.assert_allclose(mesh.points[:, :2], p.x)
    np.testing.assert_allclose(mesh.point_data["pressure"], p.x[:, 0])
    np.testing.assert_allclose(mesh.point_data["displacement"][:, :2], p.x)
    s = mesh.point_data["stress"]  # symmetric tensor xx, yy, zz, xy, yz, xz
    np.testing.assert_allclose(s[:, [0, 1, 3]], stress)
    assert not s[:, [2, 4, 5]].any()
    _, cells = _read(tmp_path / "run_cells.pvd", 0.25)
    assert cells.area == pytest.approx(2.0)  # the nodal cells tile the domain
    np.testing.assert_allclose(np.sort(np.unique(cells.cell_data["pressure"])), np.unique(0.25 * p.x[:, 0]))


def test_series_refuses_a_field_of_the_wrong_size(tmp_path):
    p = structured(1.0, 1.0, 3, 3)
    series = FieldSeries(tmp_path, "run", p.x)
    with pytest.raises(InputError, match="'pressure'.*per particle"):
        series.write(0.0, pressure=np.zeros(4))
    with pytest.raises(InputError, match="4 components"):
        series.write(0.0, pressure=np.zeros((9, 4)))


def test_index_lists_every_written_step_as_it_goes(tmp_path):
    p = structured(1.0, 1.0, 3, 3)
    series = FieldSeries(tmp_path, "run", p.x)
    series.write(0.5, pressure=np.zeros(9))
    np.testing.assert_allclose(times_of(series.pvd), [0.5])  # complete after one step
    series.write(2.0, pressure=np.ones(9))
    np.testing.assert_allclose(times_of(series.pvd), [0.5, 2.0])


def test_fem_series_writes_vertex_and_cell_fields(tmp_path):
    import dolfinx_solver  # noqa: F401
    from dolfinx import fem, mesh as dmesh
    from mpi4py import MPI

    from fem_baselines.paraview import FemSeries

    m = dmesh.create_unit_square(MPI.COMM_SELF, 3, 3)
    u = fem.Function(fem.functionspace(m, ("Lagrange", 2, (2,))))
    d = fem.Function(fem.functionspace(m, ("DG", 0)))
    with FemSeries(tmp_path, "fem-p2", m) as series:
        for t in (1.0, 3.0):
            u.interpolate(lambda x: np.vstack([t * x[0], x[1] ** 2]))
            d.x.array[:] = t
            series.write(t, displacement=u, damage=d)
    reader, mesh = _read(tmp_path / "fem-p2.pvd", 3.0)
    assert reader.time_values == [1.0, 3.0]
    np.testing.assert_allclose(mesh.point_data["displacement"][:, 0], 3.0 * mesh.points[:, 0], atol=1e-12)
    np.testing.assert_allclose(mesh.point_data["displacement"][:, 1], mesh.points[:, 1] ** 2, atol=1e-12)
    np.testing.assert_allclose(mesh.cell_data["damage"], 3.0)


def test_terzaghi_vtk_files_hold_the_documented_fields_at_the_output_times(tmp_path):
    from rkfx.cases import terzaghi

    out = tmp_path / "terzaghi"
    terzaghi.main(["--quick", "--vtk", "--out", str(out), "--set", "variants=scni+fpp", "fem=taylor-hood",
                   "refine_ny=21", "t_end=5", "t_out=2"])
    times = json.loads((out / "results.json").read_text())["runs"][0]["series"]["t"]
    vtk = out / "vtk"
    np.testing.assert_allclose(times_of(vtk / "rkpm-scni+fpp_particles.pvd"), times)
    np.testing.assert_allclose(times_of(vtk / "fem-taylor-hood.pvd"), times)
    _, rk = _read(vtk / "rkpm-scni+fpp_particles.pvd", times[-1])
    assert {"displacement", "pressure", "strain", "effective_stress"} <= set(rk.point_data.keys())
    assert rk.n_points == 7 * 21
    eps, sig = rk.point_data["strain"], rk.point_data["effective_stress"]  # tensors: xx, yy, zz, xy, yz, xz
    np.testing.assert_allclose(sig[:, 3], 2 * 500.0 * eps[:, 3], atol=1e-9 * np.abs(sig).max())  # G = E/2 at nu = 0
    np.testing.assert_allclose(sig[:, 1], 1.0e3 * eps[:, 1], atol=1e-9 * np.abs(sig).max())
    p0 = json.loads((out / "results.json").read_text())["params"]["p0"]
    assert np.median(rk.point_data["pressure"]) == pytest.approx(p0, rel=0.02)  # undrained below the top
    _, fe = _read(vtk / "fem-taylor-hood.pvd", times[-1])
    assert {"displacement", "pressure"} <= set(fe.point_data.keys())
    assert np.median(fe.point_data["pressure"]) == pytest.approx(p0, rel=0.02)
    # A second run in the same folder moves the earlier ParaView files aside with the results.
    terzaghi.main(["--quick", "--out", str(out), "--set", "variants=scni", "fem=taylor-hood", "refine_ny=21"])
    assert (out / "previous" / "vtk" / "rkpm-scni+fpp_particles.pvd").is_file() and not (out / "vtk").exists()


def test_vtk_is_refused_in_one_line_by_a_case_without_paraview_output(tmp_path, capsys):
    from rkfx.cases import _cli

    def run(methods, a=1.0):
        return _cli.Results("demo", {"a": a})

    with pytest.raises(SystemExit) as stop:
        _cli.main("demo", "demo case", {"a": _cli.Param(1.0, "a value [-]")}, run,
                  argv=["--vtk", "--out", str(tmp_path)])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "--vtk" in err and "demo" in err and len(err.splitlines()) == 1


RK = ("displacement", "pressure", "strain", "effective_stress")
DAMAGE = ("damage", "crack_opening", "displacement", "velocity")
# case, --set values, {file: (point fields, cell fields)} of its --quick --vtk output
CASE_FILES = {
    "mandel": (["variants=scni+fpp", "early_variants=scni+fpp", "fem=taylor-hood"],
               {"rkpm-scni+fpp_particles.pvd": (RK, ()), "rkpm-scni+fpp_cells.pvd": ((), RK),
                "fem-taylor-hood.pvd": (("displacement", "pressure"), ())}),
    "strip_load": (["variants=scni+fpp", "low_variants=ni", "fem=q1q1-fpp"],
                   {"rkpm-scni+fpp_particles.pvd": (RK, ()), "rkpm-ni-low-k_cells.pvd": ((), RK),
                    "fem-q1q1-fpp.pvd": (("displacement", "pressure"), ())}),
    "plate_with_hole": ([], {"rkpm-mscni-level0_particles.pvd": (("displacement", "strain", "stress"), ()),
                             "rkpm-mscni-level0_cells.pvd": ((), ("displacement", "strain", "stress")),
                             "fem-p2-level0.pvd": (("displacement",), ())}),
    "sneddon": (["crack_particles=9", "bands=strip", "fem_degrees=1", "fem_levels=1"],
                {"rkpm-strip-n9_particles.pvd": (RK + ("damage", "crack_opening"), ()),
                 "fem-p1-level0.pvd": (("displacement",), ())}),
    "cracked_bar": (["nodes=16"], {"rkpm-scni_n16_particles.pvd": (("stress", "damage"), ()),
                                   "rkpm-scni_n16_cells.pvd": ((), ("stress", "damage")),
                                   "fem-crack-band_n16.pvd": ((), ("stress", "damage"))}),
    "kalthoff": (["nodes=60", "unregularized_nodes=60", "no_tracking_nodes=60", "fem_nodes=60", "nonlocal_h=none",
                  "t_end=2e-5"],
                 {"rkpm-dpm_n60_particles.pvd": (DAMAGE, ()), "rkpm-dpm_n60_cells.pvd": ((), DAMAGE),
                  "fem-crack-band_n60.pvd": (("displacement", "velocity"), ("damage", "crack_opening"))}),
    "crack_branching": (["h=8e-4", "unregularized_h=8e-4", "fem_h=8e-4", "nonlocal_h=none", "t_end=1e-5",
                         "--method", "both"],
                        {"rkpm-dpm_h0.0008_particles.pvd": (DAMAGE, ()),
                         "fem-crack-band_h0.0008.pvd": (("displacement", "velocity"), ("damage",))}),
    "injection": (["h=0.05"], {"rkpm_h0.05_particles.pvd": (("displacement", "pressure", "damage", "crack_opening",
                                                              "strain", "permeability"), ()),
                               "rkpm_h0.05_cells.pvd": ((), ("pressure", "damage"))}),
    "cryer": (["variants=scni+fpp", "early_variants=scni+fpp", "rkpm_levels=0.1", "fem_levels=0.1"],
              {"rkpm-scni+fpp_particles.pvd": (RK, ()), "rkpm-scni+fpp_cells.pvd": (RK, ()),
               "fem-taylor-hood.pvd": (("displacement", "pressure"), ())}),
}


@pytest.mark.parametrize("case", sorted(CASE_FILES))
def test_case_vtk_files_hold_the_documented_fields(case, tmp_path, capsys):
    """Each case's --quick --vtk output opens in pyvista with the fields its docstring names, at
    increasing times, and the nodal cells tile the model; its terminal output fits 100 columns."""
    import importlib

    pytest.importorskip("dolfinx_solver")
    sets, files = CASE_FILES[case]
    method = sets[sets.index("--method"):] if "--method" in sets else []
    sets = [s for s in sets if s not in method]
    module = importlib.import_module(f"rkfx.cases.{case}")
    out = tmp_path / case
    assert module.main(["--quick", "--vtk", "--out", str(out), *method, *(["--set", *sets] if sets else [])]) == 0
    printed = capsys.readouterr()
    table = printed.out.split("\nresults: ")[0]  # the file paths below it are as long as they are
    assert max(map(len, table.splitlines())) <= 100
    assert "done [" in printed.err  # a line per finished model
    for name, (point, cell) in files.items():
        pvd = out / "vtk" / name
        times = times_of(pvd)
        assert len(times) >= 1 and np.all(np.diff(times) > 0), (name, times)
        _, mesh = _read(pvd, times[-1])
        assert set(point) <= set(mesh.point_data.keys()), (name, mesh.point_data.keys())
        assert set(cell) <= set(mesh.cell_data.keys()), (name, mesh.cell_data.keys())
        for data in (mesh.point_data, mesh.cell_data):
            if "damage" in data:
                assert 0.0 <= data["damage"].min() and data["damage"].max() <= 1.0
            for key in data.keys():
                assert np.isfinite(data[key]).all(), (name, key)
    if case == "kalthoff":  # the impacted edge moves at v0: velocities are u^h, not RK coefficients
        _, parts = _read(out / "vtk" / "rkpm-dpm_n60_particles.pvd", times_of(out / "vtk" / "rkpm-dpm_n60_particles.pvd")[-1])
        edge = (parts.points[:, 0] < 1e-12) & (parts.points[:, 1] < 0.02)
        np.testing.assert_allclose(parts.point_data["velocity"][edge, 0], 16.5, rtol=1e-6)
    cells = next(out.glob("vtk/*_cells.pvd"), None)
    if cells is not None and case not in ("plate_with_hole", "cryer"):  # rectangles: the cells tile the box
        _, mesh = _read(cells, times_of(cells)[-1])
        lo, hi = np.asarray(mesh.bounds[::2][:2]), np.asarray(mesh.bounds[1::2][:2])
        assert mesh.area == pytest.approx(np.prod(hi - lo), rel=1e-9)


def test_render_draws_a_field_off_screen_and_names_the_missing_one(tmp_path):
    from rkfx.output.render import render

    p = structured(1.0, 1.0, 9, 9)
    series = FieldSeries(tmp_path, "run", p.x, cells=nodal_cells(p))
    series.write(1.0, damage=(p.x[:, 0] > 0.5).astype(float))
    png = render(tmp_path / "run_cells.pvd", "damage", tmp_path / "damage.png", segments=[((0, 0.5), (0.5, 0.5))])
    image = pv.read(str(png))
    rgb = np.asarray(image.point_data[image.point_data.keys()[0]])[:, :3].astype(float)
    assert rgb.std(axis=0).max() > 20  # not one flat colour: the damaged half shows
    with pytest.raises(InputError, match="no field 'pressure'; choose from damage"):
        render(tmp_path / "run_cells.pvd", "pressure", tmp_path / "x.png")


def test_3d_particles_and_tetrahedra_read_back_and_render(tmp_path):
    """3-D particles: vectors and Voigt tensors (xx, yy, zz, yz, xz, xy) as ParaView's symmetric
    tensors, the tetrahedra carrying the fields as point data; the solid renders from (-1, -1, -1)."""
    from rkfx.geometry.particles3d import box
    from rkfx.output.render import render

    p = box(1.0, 1.0, 1.0, 4, 4, 4)
    series = FieldSeries(tmp_path, "solid", p.x, cells=p.tetrahedra)
    voigt = np.column_stack([p.x, 10 + p.x])  # xx, yy, zz, yz, xz, xy
    series.write(0.5, displacement=0.1 * p.x, pressure=p.x.sum(axis=1), stress=voigt)
    _, mesh = _read(series.pvd, 0.5)
    np.testing.assert_allclose(mesh.points, p.x)
    np.testing.assert_allclose(mesh.point_data["displacement"], 0.1 * p.x)
    np.testing.assert_allclose(mesh.point_data["stress"], voigt[:, [0, 1, 2, 5, 3, 4]])  # xx yy zz xy yz xz
    _, solid = _read(tmp_path / "solid_cells.pvd", 0.5)
    assert solid.volume == pytest.approx(1.0) and solid.n_cells == len(p.tetrahedra)
    np.testing.assert_allclose(solid.point_data["pressure"], p.x.sum(axis=1))
    png = render(tmp_path / "solid_cells.pvd", "pressure", tmp_path / "p.png", view="iso-")
    image = pv.read(str(png))
    rgb = np.asarray(image.point_data[image.point_data.keys()[0]])[:, :3].astype(float)
    assert rgb.std(axis=0).max() > 20
    with pytest.raises(InputError, match="view 'top'"):
        render(tmp_path / "solid_cells.pvd", "pressure", tmp_path / "q.png", view="top")
