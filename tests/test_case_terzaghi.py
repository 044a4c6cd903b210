"""Terzaghi's problem (seed 3.4.1): the acceptance criteria of the Chapter 3 case."""
import json

import pytest

from rkfx.cases import terzaghi


@pytest.fixture(scope="module")
def seed():
    """7 x 21 nodes, first step of 1 s, the four RKPM variants; refinement 21/41/81."""
    return terzaghi.run(methods=("rkpm",))


def runs(res, study):
    return {r.method: r for r in res.runs if r.info["study"] == study}


def test_scni_fpp_first_step_within_5_percent_away_from_the_drained_layer(seed):
    assert runs(seed, "variants")["rkpm-scni+fpp"].errors["first_step_max_dev_away"] <= 0.05


@pytest.mark.parametrize("variant", ["rkpm-ni", "rkpm-scni"])
def test_unstabilized_variants_oscillate(seed, variant):
    assert runs(seed, "variants")[variant].errors["first_step_max_dev_away"] > 0.5


def test_error_decreases_over_21_41_81_nodes(seed):
    ref = runs(seed, "refinement")
    errors = [ref[f"rkpm-scni+fpp ny={n}"].errors["first_step_l2"] for n in (21, 41, 81)]
    assert errors[0] > errors[1] > errors[2]


def test_consolidation_over_time_matches_the_series():
    res = terzaghi.run(methods=("rkpm",), variants=["scni+fpp"], t_end=2.0e7, t_out=[1.0e6, 5.0e6], refine_ny=[])
    errors = res.runs[0].errors
    assert errors["l2_t1e+06"] < 0.03 and errors["l2_t5e+06"] < 0.02 and errors["l2_t2e+07"] < 0.02, errors


def test_cli_quick(tmp_path):
    pytest.importorskip("dolfinx_solver")
    assert terzaghi.main(["--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "results.json").read_text())
    run = next(r for r in data["runs"] if r["method"] == "rkpm-scni+fpp")
    assert {"z", "t", "p"} <= set(run["series"]) and run["series"]["t"][-1] == data["params"]["t_end"]
    assert (tmp_path / "first_step.png").exists() and (tmp_path / "refinement.png").exists()


def test_bad_parameters_exit_2(capsys):
    with pytest.raises(SystemExit) as e:
        terzaghi.main(["--set", "t_end=0.5"])
    assert e.value.code == 2 and "t_end" in capsys.readouterr().err
