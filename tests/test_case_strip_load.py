"""Strip load on a consolidating half-space (seed 3.4.3)."""
import json
import warnings

import numpy as np
import pytest

from rkfx.cases import strip_load


@pytest.fixture(scope="module")
def seed():
    """31 x 31 graded nodes, Delta t_D = 0.025, to T_D = 1; RKPM only (FEM: see the CLI test)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # NI's near-singular modes
        return {r.method: r for r in strip_load.run(methods=("rkpm",), t_D_end=1.0).runs}


def test_axis_profile_and_history_match_the_exact_solution(seed):
    r = seed["rkpm-scni+fpp"]
    assert r.errors["l2_p_axis"] < 0.05
    assert r.errors["max_err_history"] < 0.02
    # The history rises above the undrained value q/2 (Mandel-Cryer) and decays.
    p = np.asarray(r.series["p_history"]) / 1.0e4
    assert p.max() > 0.56 and p[-1] < 0.3


def test_ni_is_less_accurate_than_scni_fpp(seed):
    assert seed["rkpm-ni"].errors["max_err_history"] > 3 * seed["rkpm-scni+fpp"].errors["max_err_history"]


def test_low_permeability_ni_oscillates_scni_fpp_does_not(seed):
    ni = seed["rkpm-ni (low k)"].errors["p_second_difference"]
    stab = seed["rkpm-scni+fpp (low k)"].errors["p_second_difference"]
    assert ni > 4 * stab


def test_node_lines_resolve_the_strip():
    xs = strip_load.node_lines(0.2, 5.0, 31, 0.04, uniform_to=0.2)
    assert len(xs) == 31 and np.isclose(xs[5], 0.2) and np.isclose(xs[-1], 5.0)
    assert np.all(np.diff(xs) > 0) and np.all(np.diff(xs)[5:] >= 0.04 - 1e-12)


def test_cli_quick(tmp_path):
    pytest.importorskip("dolfinx_solver")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert strip_load.main(["--quick", "--out", str(tmp_path)]) == 0
    data = json.loads((tmp_path / "results.json").read_text())
    methods = {r["method"] for r in data["runs"]}
    assert {"rkpm-scni+fpp", "fem-taylor-hood", "rkpm-ni (low k)"} <= methods
    assert (tmp_path / "drained.png").exists() and (tmp_path / "undrained_fields.png").exists()
