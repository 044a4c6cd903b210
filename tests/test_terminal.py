"""Terminal output of the cases: tables within 100 columns, wrapped parameters, summary
headings, and a line per model naming its warnings."""
import warnings

import pytest

from rkfx.cases import _terminal
from rkfx.cases._cli import Results, Run


def _wide() -> Results:
    params = {f"parameter_{k}": [0.125 * k, 1e-9 * k, 3] for k in range(12)} | {"label": "x" * 40}
    runs = [Run(f"rkpm-variant-{k} n={50 * k}", 1.5 * k, 1000 * k,
                errors={f"a_rather_long_error_name_{j}": 1e-3 * j * k for j in range(9)},
                info={"study": "levels", "nodes": 50 * k, "h": 0.1 / k}) for k in range(1, 4)]
    runs.append(Run("rkpm-variant", 9.0, 3000, errors={"spread": 0.01},
                    info={"study": "summary", "of": "rkpm-variant", "over": "n=50,100,150 (wall: their sum)"}))
    return Results("demo", params, runs)


def test_tables_fit_100_columns_and_keep_every_value():
    text = _terminal.summary_table(_wide())
    lines = text.splitlines()
    assert max(map(len, lines)) <= _terminal.WIDTH
    assert "[...]" not in text and "parameter_11=1.375,1.1e-08,3" in text.replace("\n    ", " ")
    for j in range(9):  # every error column is in one of the continuation tables
        assert sum(f"a_rather_long_error_name_{j}" in line for line in lines) == 1
    assert sum(line.startswith("rkpm-variant-2 n=100") for line in lines) >= 2  # the method is repeated


def test_a_summary_row_says_what_it_aggregates():
    text = _terminal.summary_table(_wide())
    assert "study levels:" in text
    assert "summary of rkpm-variant over n=50,100,150 (wall: their sum):" in text


def test_a_model_names_its_warnings_once_and_says_when_it_is_done(capsys):
    with _terminal.model_run("rkpm-ni (low k)"):
        for _ in range(3):
            warnings.warn("system matrix has 2 null pivot(s)", RuntimeWarning)
    err = capsys.readouterr().err.splitlines()
    assert err[0] == "warning [rkpm-ni (low k)]: system matrix has 2 null pivot(s)"
    assert len(err) == 2 and err[1].startswith("done [rkpm-ni (low k)] in ")


def test_a_failed_model_prints_its_warnings_but_no_done_line(capsys):
    with pytest.raises(ValueError), _terminal.model_run("m"):
        warnings.warn("careful", RuntimeWarning)
        raise ValueError("stop")
    assert capsys.readouterr().err.splitlines() == ["warning [m]: careful"]


def test_progress_is_the_bare_iterable_without_a_terminal():
    steps = range(5)
    assert _terminal.progress(steps, "x", 5) is steps  # pytest's stderr is not a terminal
    bar = _terminal.step_progress("x", 5)
    bar(3)
    bar.close()
    assert bar.bar is None
