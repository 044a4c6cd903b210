"""The granular collapse case (``rkfx.cases.granular_collapse``): dry Drucker-Prager columns of
two aspect ratios on moving particles, by NSNI without and with the VC correction, against the
published run-outs."""
import numpy as np
import pytest

from rkfx.cases import granular_collapse as gc
from rkfx.errors import InputError
from verification.granular_runout import bui_final_height, bui_runout, lube_runout


@pytest.fixture(scope="module")
def small():
    return gc.run(aspects=[0.5, 3.0], across=7, t_end=0.25)


def _run(results, rule, aspect):
    return next(r for r in results.runs if r.info["rule"] == rule and r.info["aspect"] == aspect)


def test_the_published_runouts():
    assert lube_runout(0.5) == pytest.approx(0.6) and lube_runout(3.0) == pytest.approx(1.9 * 3.0 ** (2 / 3))
    assert np.isnan(bui_runout(0.5)) and bui_runout(1.0) == pytest.approx(3.25) and bui_runout(2.0) > lube_runout(2.0)
    assert bui_final_height(0.5) == 1.0 and bui_final_height(3.0) < 0.5


def test_the_front_is_the_deposit_not_a_particle_thrown_ahead():
    """The run-out ends at the first gap along x wider than a support; a particle thrown beyond
    it is counted apart, and a body without gaps reaches its farthest particle."""
    from types import SimpleNamespace
    x = np.c_[np.linspace(0.0, 0.3, 31), np.zeros(31)]  # spacing 0.01 m
    body = SimpleNamespace(x=x, support=np.full(31, 0.02))
    assert gc.front(body, 0.2) == pytest.approx(0.5) and gc.detached(body) == 0
    thrown = SimpleNamespace(x=np.vstack([x, [[0.45, 0.05]]]), support=np.full(32, 0.02))
    assert gc.front(thrown, 0.2) == pytest.approx(0.5) and gc.detached(thrown) == 1


def test_columns_collapse_without_creating_energy(small):
    """Without the VC correction both columns run to the end; the low one keeps its height at the
    wall (Bui et al. 2015: below a = 0.65) while its toe moves out, the tall one falls to under
    half its height; the kinetic energy stays below gravity's work all along."""
    low, tall = _run(small, "nsni-novc", 0.5), _run(small, "nsni-novc", 3.0)
    for r in (low, tall):
        assert r.info["completed"] == 1 and r.info["why"] == "ran to t_end"
        assert r.info["energy_created"] == 0 and 0 < r.info["kinetic_peak"] < r.info["gravity_work"]
        assert len(r.series["t"]) == len(r.series["front"]) > 50
        assert r.info["steps_with_search"] > 0 and r.info["torn_point_evaluations"] == 0
        assert np.isfinite(r.errors["runout_vs_lube"])
    assert low.info["final_height"] > 0.97 and 0.05 < low.info["runout"] < 0.6
    assert tall.info["final_height"] < 0.5 and tall.info["runout"] > 1.0


def test_the_corrected_rule_is_reported_beside(small):
    """The runs with the VC correction stand beside the others, whatever became of them: at the
    end, or stopped with the reason."""
    for aspect in (0.5, 3.0):
        r = _run(small, "nsni", aspect)
        assert r.method == f"rkpm-nsni a={aspect:g}"
        assert r.info["why"] == "ran to t_end" or r.info["why"].startswith("stopped: ")
        assert r.info["completed"] == int(r.info["why"] == "ran to t_end")


def test_a_resumed_run_ends_where_it_would(tmp_path):
    prm = dict(aspects=[0.5], rules=["nsni-novc"], across=7, t_end=0.05)
    whole = gc.run(**prm, checkpoint_every=40, work_dir=tmp_path / "a")
    again = gc.run(**prm, work_dir=tmp_path / "b", resume=tmp_path / "a")
    (a,), (b,) = whole.runs, again.runs
    assert np.array_equal(a.series["x"], b.series["x"]) and np.array_equal(a.series["front"], b.series["front"])


def test_bad_input_is_refused_in_one_line():
    prm = {k: v.default for k, v in gc.PARAMS.items()}
    for bad, match in ((dict(aspects=[0.0]), "aspects"), (dict(across=3), "across"), (dict(rules=["gauss"]), "rule"),
                       (dict(cfl=0.9), "cfl"), (dict(viscosity=-1.0), "viscosity"), (dict(eta=-1.0), "eta"),
                       (dict(phi=95.0), "phi")):
        with pytest.raises(InputError, match=match):
            gc.check(**{**prm, **bad})
    with pytest.raises(InputError, match="no FEM baseline"):
        gc.run(methods=("fem",), aspects=[0.5], across=5, t_end=0.01)
