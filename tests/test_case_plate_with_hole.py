"""The plate-with-a-hole case: geometry, CLI contract, and accuracy bounds that can fail.

Bounds were measured on the quick mesh (h = 0.5 m, 276 nodes; E = 1e3, nu = 0.3, T = 1,
a = 1, L = 5) and given a margin of about 2x:

    method       L2 err    H1 err   sigma_xx(0, a)
    rkpm-mscni   6.7e-4    1.74e-2  3.000
    rkpm-scni    3.3e-3    5.07e-2  2.80
    rkpm-dni     3.0e-2    0.587    2.94
    fem-p1       5.9e-3    4.93e-2  2.26   (cell value of P1)
    fem-p2       9.6e-4    5.15e-3  2.89
"""
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh")
pytest.importorskip("dolfinx_solver")
pytest.importorskip("matplotlib")

from rkfx.cases import _cli  # noqa: E402
from rkfx.cases import plate_with_hole as case  # noqa: E402
from rkfx.geometry.gmsh_nodes import from_geo, from_gmsh  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
GEO = ROOT / "cases" / "geometry" / "plate_with_hole.geo"
PARTS = {"left", "bottom", "right", "top", "hole"}


def test_geo_file_gives_the_quarter_plate():
    exact_area = 5.0**2 - math.pi * 1.0**2 / 4
    for h in (0.5, 0.25):
        p = from_geo(GEO, mesh_size=h)
        assert set(p.boundary_names) == PARTS
        # The polygonal hole is inscribed in the circle: slightly more area, by O(h_hole^2).
        assert 0.0 < p.area() - exact_area < 1e-2
        r = np.linalg.norm(p.x[p.boundary_nodes("hole")], axis=1)
        np.testing.assert_allclose(r, 1.0, atol=1e-12)
        assert np.abs(p.x[p.boundary_nodes("left"), 0]).max() < 1e-12
        assert np.abs(p.x[p.boundary_nodes("top"), 1] - 5.0).max() < 1e-12
        assert p.spacing.max() <= 1.2 * h


def test_geo_file_and_case_mesh_agree():
    """The .geo file is the documented twin of the case's gmsh-API geometry: same mesh."""
    p_geo = from_geo(GEO)  # lc = 0.5 in the file
    gmsh.initialize(interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        case.mesh_plate(1.0, 5.0, 0.5)
        p_api = from_gmsh(gmsh.model)
    finally:
        gmsh.finalize()
    assert p_geo.num_nodes == p_api.num_nodes
    assert set(p_geo.boundary_names) == set(p_api.boundary_names) == PARTS
    np.testing.assert_allclose(np.sort(p_geo.x, axis=0), np.sort(p_api.x, axis=0), atol=1e-12)


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("pwh")
    code = case.main(["--quick", "--out", str(out), "--set", "rules=mscni,scni,dni"])
    data = json.loads((out / "results.json").read_text())
    return code, out, data, {r["method"]: r for r in data["runs"]}


def test_quick_results_schema(quick):
    code, out, data, _ = quick
    assert code == 0
    assert data["case"] == "plate_with_hole"
    assert set(case.PARAMS) <= set(data["params"])
    assert data["params"]["rules"] == ["mscni", "scni", "dni"]
    assert [r["method"] for r in data["runs"]] == ["rkpm-mscni", "rkpm-scni", "rkpm-dni", "fem-p1", "fem-p2"]
    for r in data["runs"]:
        assert {"method", "wall_time_s", "n_dofs", "series", "errors"} <= set(r)
        assert isinstance(r["n_dofs"], int) and r["n_dofs"] > 0
        assert math.isfinite(r["wall_time_s"]) and r["wall_time_s"] > 0
        assert all(isinstance(v, float) and math.isfinite(v) for v in r["errors"].values())
        assert len(r["series"]["y_axis"]) == len(r["series"]["sxx_axis"])
        assert len(r["series"]["node_error"]) == r["info"]["nodes"]
    assert data["runs"][0]["n_dofs"] == data["runs"][3]["n_dofs"]  # same nodes for RKPM and P1
    for name in ("sigma_xx_axis.png", "convergence.png", "error_field.png"):
        assert (out / name).stat().st_size > 10_000


def test_quick_accuracy(quick):
    _, _, _, runs = quick
    e = {m: r["errors"] for m, r in runs.items()}
    assert e["rkpm-mscni"]["l2"] < 1.5e-3
    assert e["rkpm-mscni"]["h1"] < 3.5e-2
    assert e["rkpm-scni"]["h1"] < 0.1
    assert e["fem-p1"]["l2"] < 1.2e-2 and e["fem-p1"]["h1"] < 0.1
    assert e["fem-p2"]["l2"] < 2e-3 and e["fem-p2"]["h1"] < 1e-2
    # Stress concentration sigma_xx(0, a) = 3T.
    assert e["rkpm-mscni"]["sxx_hole_err"] < 0.1
    assert e["fem-p2"]["sxx_hole_err"] < 0.1
    # DNI lacks integration consistency and stability: it must come out far worse.
    assert e["rkpm-dni"]["l2"] > 10 * e["rkpm-mscni"]["l2"]
    assert e["rkpm-dni"]["h1"] > 10 * e["rkpm-mscni"]["h1"]
    assert e["rkpm-mscni"]["h1"] < e["rkpm-scni"]["h1"] < e["rkpm-dni"]["h1"]


def test_two_level_rates():
    """Rates between h = 0.5 and 0.25 (measured: MSCNI 2.48 / 1.32, P1 1.82 / 0.96, P2 1.89 / 1.88)."""
    res = case.run(h=0.5, levels=2)
    fine = {r.method: r.errors for r in res.runs if r.info["level"] == 1}
    assert set(fine) == {"rkpm-mscni", "fem-p1", "fem-p2"}
    assert fine["rkpm-mscni"]["rate_l2"] > 1.8 and fine["rkpm-mscni"]["rate_h1"] > 0.9
    assert fine["fem-p1"]["rate_l2"] > 1.6 and fine["fem-p1"]["rate_h1"] > 0.85
    # P2: the polygonal hole limits both rates to 2.
    assert fine["fem-p2"]["rate_l2"] > 1.7 and fine["fem-p2"]["rate_h1"] > 1.7


@pytest.mark.parametrize("setting, names", [
    ("nu=0.7", ["nu"]),
    ("bogus=1", ["bogus", "valid names", "support_factor"]),
    ("levels=two", ["levels", "integer"]),
    ("rules=mscni,foo", ["rules", "foo"]),
    ("h=-1", ["h"]),
    ("L=0.5", ["L"]),
    ("a=6", ["a = 6", "lower a"]),
])
def test_bad_parameters_exit_2_with_one_line(setting, names, tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        case.main(["--quick", "--out", str(tmp_path / "o"), "--set", setting])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    for n in names:
        assert n in err
    assert not (tmp_path / "o").exists()


def test_cli_process_exit_code(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "rkfx.cases.plate_with_hole", "--set", "bogus=1"],
                          capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "unknown parameter 'bogus'" in proc.stderr
    assert proc.stdout == ""


def test_parameter_coercion():
    specs = {"x": _cli.Param(1.0, ""), "n": _cli.Param(2, ""), "s": _cli.Param("a", ""),
             "b": _cli.Param(False, ""), "l": _cli.Param(["p"], ""), "k": _cli.Param([1, 2], "")}
    p = _cli.parse_params(specs, ["x=3e-2", "n=7", "s=hello", "b=yes", "l=u, v", "k=4,5,6"], {"n": 5})
    assert p == {"x": 0.03, "n": 7, "s": "hello", "b": True, "l": ["u", "v"], "k": [4, 5, 6]}
    assert _cli.parse_params(specs, [], {"n": 5})["n"] == 5
    for bad in ("x=nan", "n=1.5", "b=maybe", "k=1,x", "x", "zz=1"):
        with pytest.raises(_cli.ParameterError):
            _cli.parse_params(specs, [bad])
