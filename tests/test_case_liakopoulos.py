"""Liakopoulos' drainage column (§6.4.2, Figs 6.8-6.9): RKPM on NSNI against the Taylor-Hood
baseline on the same grid and step times, the RKPM refinement, the CLI with a resume."""
import json

import numpy as np
import pytest

from rkfx.cases import liakopoulos


@pytest.fixture(scope="module")
def quick():
    pytest.importorskip("dolfinx_solver")
    return liakopoulos.run(ny=21, refine_ny=[41], output_min=[5.0, 30.0, 60.0, 120.0])


def _run(res, method):
    return next(r for r in res.runs if r.method == method)


def test_rkpm_profiles_within_5_percent_of_fem(quick):
    e = _run(quick, "rkpm-nsni").errors
    for m in (5, 30, 60, 120):
        assert e[f"profile_{m}min"] < 0.05, e
    assert e["settlement_end"] < 0.05 and e["probes_max"] < 0.05


def test_the_column_drains_from_the_top(quick):
    s = _run(quick, "fem-taylor-hood").series
    top = np.asarray(s["profiles"])[:, -1]
    assert np.all(np.diff(top) < 0) and top[-1] < -5e3  # suction grows at the top, several kPa by 2 h
    assert np.all(np.abs(np.asarray(s["profiles"])[:, 0]) < 1e-6)  # drained base
    settle = np.asarray(s["settlement"])
    assert np.all(np.diff(settle) >= -1e-12) and settle[-1] > 1e-4


def test_refinement_stays_at_the_fem_result(quick):
    coarse, fine = _run(quick, "rkpm-nsni").errors, _run(quick, "rkpm-nsni ny=41").errors
    assert fine["profile_120min"] < 0.01 and coarse["profile_120min"] < 0.01


def test_explicit_step_count_is_reported(quick):
    assert quick.params["explicit_steps_needed"] > 1e7 and 1500 < quick.params["c_fast"] < 2500


def test_cli_with_a_resume(tmp_path):
    pytest.importorskip("dolfinx_solver")
    out = tmp_path / "run"
    args = ["--set", "ny=21", "--set", "refine_ny=21", "--set", "output_min=5,10", "--checkpoint-every", "20"]
    assert liakopoulos.main([*args, "--out", str(out)]) == 0
    data = json.loads((out / "results.json").read_text())
    assert (out / "drainage.png").exists() and (out / "steady.png").exists()
    again = tmp_path / "again"
    assert liakopoulos.main([*args, "--out", str(again), "--resume", str(out)]) == 0
    redo = json.loads((again / "results.json").read_text())
    for a, b in zip(data["runs"], redo["runs"]):
        assert a["method"] == b["method"] and a["series"].keys() == b["series"].keys()
        assert all(np.array_equal(a["series"][k], b["series"][k]) for k in a["series"])


@pytest.mark.parametrize("setting, word", [("retention=vg", "retention"), ("ny=20", "ny"), ("rule=gauss", "rule"),
                                           ("probes=1.5", "probe"), ("max_step=0", "max_step"),
                                           ("steady=sometimes", "steady")])
def test_bad_parameters_exit_2(capsys, setting, word):
    with pytest.raises(SystemExit) as e:
        liakopoulos.main(["--set", setting])
    assert e.value.code == 2 and word in capsys.readouterr().err
