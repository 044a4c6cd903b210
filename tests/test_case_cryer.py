"""Cryer's sphere (3-D): the acceptance criteria of the 3-D u-p case at its quick size (713 nodes)."""
import json

import numpy as np
import pytest

from rkfx.cases import cryer


@pytest.fixture(scope="module")
def quick():
    pytest.importorskip("dolfinx_solver")
    res = cryer.run(mesh_size=0.1, t_D=[0.01, 0.05, 0.1, 0.3], early_variants=["ni", "scni+fpp"],
                    rkpm_levels=[0.15, 0.1], fem_levels=[0.2, 0.14])
    return res, {r.method: r for r in res.runs}


def test_centre_pressure_history_within_3_percent(quick):
    _, runs = quick
    for method in ("rkpm-scni+fpp", "fem-taylor-hood"):
        assert runs[method].errors["history_max"] <= 0.03, (method, runs[method].errors)


def test_mandel_cryer_peak_above_the_initial_pressure(quick):
    res, runs = quick
    r = runs["rkpm-scni+fpp"]
    assert res.params["peak_exact"] == pytest.approx(1.5754, abs=1e-3)  # nu = 0, exact
    assert r.errors["peak"] > 1.5 and abs(r.errors["peak_error"]) <= 0.03
    assert abs(r.errors["peak_T"] - res.params["peak_T_exact"]) <= 0.01
    centre = np.asarray(r.series["centre"])
    assert centre[0] > 1.0 and centre.max() > centre[0] + 0.4  # it rises well above p0 before it falls
    assert centre[-1] < 0.8


def test_ni_oscillates_early_and_scni_fpp_does_not(quick):
    _, runs = quick
    assert runs["rkpm-ni"].errors["early_first_overshoot"] > 0.2
    assert runs["rkpm-scni+fpp"].errors["early_first_overshoot"] <= 0.1
    assert runs["rkpm-ni"].errors["history_max"] > 5 * runs["rkpm-scni+fpp"].errors["history_max"]


def test_radial_profiles_follow_the_exact_solution(quick):
    _, runs = quick
    for t in (0.05, 0.1, 0.3):
        assert runs["rkpm-scni+fpp"].errors[f"l2_p_TD{t:g}"] <= 0.02


def test_refinement_reduces_the_error(quick):
    res, _ = quick
    levels = {r.method: r.errors["history_max"] for r in res.runs if r.info.get("refinement")}
    assert levels["rkpm-scni+fpp h=0.1"] < levels["rkpm-scni+fpp h=0.15"]
    assert levels["fem-taylor-hood h=0.14"] < levels["fem-taylor-hood h=0.2"]


def test_bad_parameters_are_refused_in_one_line():
    with pytest.raises(cryer.InputError, match="mesh size 0.8 must lie in"):
        cryer.check(**{**{k: p.default for k, p in cryer.PARAMS.items()}, "mesh_size": 0.8})
    with pytest.raises(cryer.InputError, match="unknown RKPM variant 'gauss'"):
        cryer.check(**{**{k: p.default for k, p in cryer.PARAMS.items()}, "variants": ["gauss"]})


def test_cli_quick_writes_results_and_figures(tmp_path):
    pytest.importorskip("dolfinx_solver")
    assert cryer.main(["--quick", "--method", "rkpm", "--set", "rkpm_levels=0.15", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "results.json").read_text())
    assert data["case"] == "cryer" and data["params"]["nodes"] == 713
    assert {p.name for p in tmp_path.glob("*.png")} >= {"history.png", "profiles.png", "early_time.png"}
