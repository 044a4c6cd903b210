"""The wave column (§6.4.1, Figs 6.5-6.6): NSNI within 5 % of the exact histories at 241 nodes
along the height and converging, DNI visibly worse, Taylor-Hood beside them."""
import json

import numpy as np
import pytest

from rkfx.cases import wave_column


@pytest.fixture(scope="module")
def seed():
    """The rules study at 241 nodes, the refinement 61/121/241 (RKPM only)."""
    return wave_column.run(methods=("rkpm",), refine_ny=[61, 121, 241])


def _runs(res, study):
    return {r.method: r for r in res.runs if r.info["study"] == study}


def test_nsni_within_5_percent_at_241_nodes(seed):
    e = _runs(seed, "rules")["rkpm-nsni"].errors
    assert e["u_top_l2"] < 0.05 and e["p_base_l2"] < 0.05, e


def test_dni_is_visibly_worse(seed):
    runs = _runs(seed, "rules")
    nsni, dni = runs["rkpm-nsni"].errors, runs["rkpm-dni"].errors
    assert dni["u_top_l2"] > 5 * nsni["u_top_l2"] and dni["p_base_l2"] > 3 * nsni["p_base_l2"]


def test_nsni_converges_at_a_rate_above_1_5(seed):
    ref = _runs(seed, "refinement")
    for n in (121, 241):
        e = ref[f"rkpm-nsni ny={n}"].errors
        assert e["rate_u_top_l2"] > 1.5 and e["rate_p_base_l2"] > 1.5, (n, e)


def test_the_wave_limit_governs_at_241_nodes(seed):
    info = _runs(seed, "rules")["rkpm-nsni"].info
    assert info["governs"] == "wave" and info["dt"] <= 0.9 * info["wave_limit"]


def test_cli_quick_with_fem_and_a_resume(tmp_path):
    pytest.importorskip("dolfinx_solver")
    out = tmp_path / "run"
    assert wave_column.main(["--quick", "--out", str(out), "--checkpoint-every", "200"]) == 0
    data = json.loads((out / "results.json").read_text())
    fem = next(r for r in data["runs"] if r["method"] == "fem-taylor-hood")
    assert fem["errors"]["p_base_l2"] < 0.01 and fem["errors"]["u_top_l2"] < 0.01
    assert (out / "histories.png").exists() and (out / "refinement.png").exists()
    again = tmp_path / "again"
    assert wave_column.main(["--quick", "--out", str(again), "--resume", str(out)]) == 0
    redo = json.loads((again / "results.json").read_text())
    for a, b in zip(data["runs"], redo["runs"]):
        assert a["method"] == b["method"] and np.array_equal(a["series"]["p_base"], b["series"]["p_base"])


def test_bad_parameters_exit_2(capsys):
    with pytest.raises(SystemExit) as e:
        wave_column.main(["--set", "courant=2"])
    assert e.value.code == 2 and "courant" in capsys.readouterr().err
    with pytest.raises(SystemExit) as e:
        wave_column.main(["--set", "fpp=maybe"])
    assert e.value.code == 2 and "fpp" in capsys.readouterr().err


def test_the_pressure_projection_converges_but_smears_the_column(seed):
    """With the fluid pressure projection of (6.49) in the storage rows (``fpp=true``) NSNI still
    converges at second order and within 5 % at 241 nodes, but its base pressure is several times
    further from the exact history than without (the projection slows the pressure's response
    at the fronts): why it is off by default here."""
    res = wave_column.run(methods=("rkpm",), rules=("nsni",), refine_ny=[121, 241], fpp=True)
    runs = _runs(res, "refinement")
    plain = _runs(seed, "refinement")["rkpm-nsni ny=241"].errors
    e = runs["rkpm-nsni ny=241"].errors
    assert e["u_top_l2"] < 0.05 and e["p_base_l2"] < 0.05 and e["rate_p_base_l2"] > 1.5, e
    assert e["p_base_l2"] > 3 * plain["p_base_l2"], (e, plain)
