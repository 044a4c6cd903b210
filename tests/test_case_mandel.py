"""Mandel's problem (seed 3.4.2): the acceptance criteria of the Chapter 3 case."""
import json

import numpy as np
import pytest

from rkfx.cases import mandel


@pytest.fixture(scope="module")
def seed():
    """The seed's resolution, SCNI+FPP and NI, Taylor-Hood beside them."""
    pytest.importorskip("dolfinx_solver")
    return {r.method: r for r in mandel.run(methods=("rkpm", "fem"), t_D=[0.01, 0.1, 0.5],
                                             variants=["scni+fpp"], early_variants=["ni", "scni+fpp"],
                                             fem=["taylor-hood"]).runs}


@pytest.mark.parametrize("method", ["rkpm-scni+fpp", "fem-taylor-hood"])
@pytest.mark.parametrize("t_d", [0.01, 0.1, 0.5])
def test_pressure_along_the_axis_within_3_percent(seed, method, t_d):
    assert seed[method].errors[f"l2_p_TD{t_d:g}"] <= 0.03


def test_mandel_cryer_effect(seed):
    r = seed["rkpm-scni+fpp"]
    early = np.asarray(r.series["history_t_D"]) < 0.05
    assert np.asarray(r.series["history_p"])[early].max() > 1.05  # p0+ = 1
    assert r.errors["cryer_peak"] > 1.1


def test_early_time_stable_with_scni_fpp_and_oscillating_with_ni(seed):
    assert seed["rkpm-scni+fpp"].errors["early_dtD0.01_overshoot"] <= 0.05
    assert seed["rkpm-ni"].errors["early_dtD0.01_overshoot"] > 0.20


def test_other_parameters_still_match_the_exact_solution():
    """nu = 0.2, a different load, permeability and size: no formula may assume the seed's values."""
    res = mandel.run(methods=("rkpm",), nu=0.2, E=2.0e4, k=3.0e-4, F=25.0, Lx=10.0, Ly=1.0, nx=81, ny=9,
                     t_D=[0.01, 0.1, 0.5], variants=["scni+fpp"], early_variants=[])
    errors = res.runs[0].errors
    assert all(errors[f"l2_p_TD{t:g}"] <= 0.03 for t in (0.01, 0.1, 0.5)), errors
    assert res.params["c"] != 1.0 and res.params["p0"] != 1.0


def test_nitsche_and_the_field_split_give_the_collocated_profiles():
    """--set bc_method=nitsche solver=fieldsplit: the same pressure errors as the defaults to 1e-4."""
    pytest.importorskip("dolfinx_solver")
    kw = dict(methods=("rkpm",), nx=41, ny=5, t_D=[0.01, 0.1], variants=["scni+fpp"], early_variants=[])
    a = mandel.run(**kw).runs[0].errors
    b = mandel.run(**kw, bc_method="nitsche", solver="fieldsplit").runs[0].errors
    for key in ("l2_p_TD0.01", "l2_p_TD0.1"):
        assert abs(a[key] - b[key]) <= 1e-4, (a, b)


def test_cli_quick_writes_results_and_figures(tmp_path):
    pytest.importorskip("dolfinx_solver")
    assert mandel.main(["--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "results.json").read_text())
    assert data["case"] == "mandel"
    run = next(r for r in data["runs"] if r["method"] == "rkpm-scni+fpp")
    assert {"x", "t_D", "p", "p_exact"} <= set(run["series"])
    assert len(run["series"]["p"]) == len(run["series"]["t_D"]) == 2
    assert len(run["series"]["p"][0]) == len(run["series"]["x"])
    assert (tmp_path / "profiles.png").stat().st_size > 10_000
    assert (tmp_path / "early_time.png").stat().st_size > 10_000


@pytest.mark.parametrize("arg, word", [("bogus=1", "bogus"), ("nu=0.5", "Poisson"), ("k=-1", "mobility"),
                                       ("variants=foo", "variant"), ("nx=2", "nx"), ("bc_method=weak", "bc_method"),
                                       ("solver=fieldsplit", "nitsche"), ("solver=cg", "solver")])
def test_bad_parameters_exit_2_with_one_line(arg, word, capsys):
    with pytest.raises(SystemExit) as e:
        mandel.main(["--quick", "--method", "rkpm", "--set", arg])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and word in err


def test_checkpointed_run_resumes_to_the_same_results(tmp_path):
    """A run that checkpoints, then an invocation resumed from it: every run (RKPM and FEM)
    reads its finished state back and the results are identical."""
    out = tmp_path / "first"
    pytest.importorskip("dolfinx_solver")
    args = ["--quick", "--method", "both", "--set", "variants=scni+fpp", "early_variants=scni+fpp", "fem=q1q1-fpp"]
    assert mandel.main(args + ["--checkpoint-every", "4", "--out", str(out)]) == 0
    assert (out / "checkpoints" / "fingerprint.json").is_file()
    assert sorted(p.name for p in (out / "checkpoints").iterdir() if p.is_dir()) == [
        f"{m}-{study}" for m in ("fem-q1q1-fpp", "rkpm-scni+fpp")
        for study in ("early-dtD0.01", "early-dtD0.1", "early-dtD1", "profiles")]
    again = tmp_path / "again"
    assert mandel.main(args + ["--resume", str(out), "--out", str(again)]) == 0
    a, b = (json.loads((d / "results.json").read_text()) for d in (out, again))
    assert [r["errors"] for r in a["runs"]] == [r["errors"] for r in b["runs"]]
