"""The parameters every case declares: units in their docs, aliases on the command line."""
import re

import pytest

from rkfx.cases import _cli
from rkfx.cases._cli import Param, ParameterError, build_parser, fingerprint, parse_params

CASES = ["mandel", "terzaghi", "strip_load", "plate_with_hole", "cracked_bar", "kalthoff", "crack_branching",
         "sneddon", "injection"]
UNIT = re.compile(r"\[[^\]]+\]")  # [Pa], [m], [-] (dimensionless), [count], [stress], ...


@pytest.mark.parametrize("case", CASES)
def test_every_parameter_doc_names_its_unit(case):
    module = __import__(f"rkfx.cases.{case}", fromlist=["PARAMS"])
    missing = [k for k, v in module.PARAMS.items() if not isinstance(v.default, (str, bool))
               and not (isinstance(v.default, list) and v.default and isinstance(v.default[0], str))
               and not UNIT.search(v.doc)]
    assert not missing, f"{case}: parameters without a unit in brackets: {missing}"


SPECS = {"h": Param([8e-4, 4e-4], "particle spacings [m]", aliases=("spacing",)),
         "steps": Param(10, "load steps [count]")}


def test_an_alias_sets_its_parameter(capsys):
    params = parse_params(SPECS, ["spacing=1e-3,5e-4"])
    assert params == {"h": [1e-3, 5e-4], "steps": 10}
    assert "alias of h" in capsys.readouterr().err


def test_unknown_names_stay_one_line_errors():
    with pytest.raises(ParameterError, match=r"unknown parameter 'nodes'; valid names: h, steps"):
        parse_params(SPECS, ["nodes=3"])


def test_help_lists_the_aliases_and_the_fingerprint_uses_the_parameter_name():
    assert "alias spacing" in build_parser("demo", "demo", SPECS).epilog
    stamp = fingerprint("demo", SPECS, parse_params(SPECS, ["spacing=1e-3"]), "rkpm")
    assert stamp["params"] == {"h": [1e-3], "steps": 10}


@pytest.mark.parametrize("case", CASES)
def test_no_alias_hides_a_parameter(case):
    module = __import__(f"rkfx.cases.{case}", fromlist=["PARAMS"])
    assert not set(_cli.alias_names(module.PARAMS)) & set(module.PARAMS)


def test_a_converting_alias_gives_its_parameter_the_value_in_its_own_terms(capsys):
    from rkfx.cases import kalthoff

    params = parse_params(kalthoff.PARAMS, ["nodes=150,250"])
    assert params["h"] == pytest.approx([0.1 / 149, 0.1 / 249]) and kalthoff.columns(params["h"]) == [150, 250]
    assert "alias of h" in capsys.readouterr().err
    assert parse_params(kalthoff.PARAMS)["h"] == kalthoff.spacings([150, 250, 350, 450])


def test_a_resume_reads_runs_stored_under_an_alias(tmp_path):
    from rkfx.cases import kalthoff

    params = parse_params(kalthoff.PARAMS)
    stamp = fingerprint("kalthoff", kalthoff.PARAMS, params, "rkpm")
    old = {**stamp, "params": {("nodes" if k == "h" else k): ([150, 250, 350, 450] if k == "h" else v)
                               for k, v in stamp["params"].items()}}
    (tmp_path / "checkpoints").mkdir()
    (tmp_path / "checkpoints" / _cli.FINGERPRINT).write_text(__import__("json").dumps(old))
    assert _cli.check_resume(tmp_path, stamp, False, kalthoff.PARAMS)
    with pytest.raises(ParameterError, match=r"h = .* \(now "):
        _cli.check_resume(tmp_path, {**stamp, "params": {**stamp["params"], "h": [1e-3]}}, False, kalthoff.PARAMS)


def test_a_resume_reads_runs_stored_before_a_parameter_existed(tmp_path):
    """Runs stored before ``closure`` was a blanton parameter resume at its default (their
    behaviour) and are refused, naming it, with another value."""
    from rkfx.cases import blanton

    stamp = fingerprint("blanton", blanton.PARAMS, parse_params(blanton.PARAMS), "rkpm")
    old = {**stamp, "params": {k: v for k, v in stamp["params"].items() if k != "closure"}}
    (tmp_path / "checkpoints").mkdir()
    (tmp_path / "checkpoints" / _cli.FINGERPRINT).write_text(__import__("json").dumps(old))
    assert _cli.check_resume(tmp_path, stamp, False, blanton.PARAMS)
    with pytest.raises(ParameterError, match=r"closure = False \(now True\)"):
        _cli.check_resume(tmp_path, {**stamp, "params": {**stamp["params"], "closure": True}}, False, blanton.PARAMS)


def test_none_empties_a_list_and_an_empty_value_stays_an_error():
    """``--set nonlocal_h=none`` skips a study; ``--set h=`` is still refused in one line."""
    assert _cli.coerce("nonlocal_h", "none", [8e-4]) == []
    assert _cli.coerce("nonlocal_h", " None ", [8e-4]) == []
    with pytest.raises(_cli.ParameterError, match="comma-separated list"):
        _cli.coerce("h", "", [8e-4])
