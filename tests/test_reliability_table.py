"""docs/reliability.md is the generated table of bad inputs, every row a one-line refusal that writes nothing."""
import pytest

from verification import bad_inputs


@pytest.fixture(scope="module")
def outcomes():
    return [bad_inputs.run_row(row) for row in bad_inputs.ROWS]


def test_there_are_enough_bad_inputs():
    rows = bad_inputs.ROWS
    assert len(rows) >= 40
    assert len({r.command for r in rows}) == len(rows), "a bad input is listed twice"


@pytest.mark.parametrize("i", range(len(bad_inputs.ROWS)))
def test_bad_input_is_refused_in_one_line_and_writes_nothing(outcomes, i):
    row, out = bad_inputs.ROWS[i], outcomes[i]
    if row.note:
        pytest.skip(f"{row.command}: {row.note}")
    assert bad_inputs.refused(out), f"{row.command}: exit {out.exit}, stderr {out.lines}, wrote {out.written}"


def test_docs_table_is_up_to_date(outcomes):
    text = bad_inputs.table(bad_inputs.ROWS, outcomes)
    assert bad_inputs.DOC.read_text() == text, "docs/reliability.md is stale: python -m verification.bad_inputs --write"
