"""The time-to-accuracy table shared by the cases (rkfx.cases._accuracy)."""
import pytest

from rkfx.cases._accuracy import matched
from rkfx.cases._cli import Run


def test_the_other_methods_cost_is_interpolated_in_log_log():
    runs = [Run("rkpm h=0.1", 10.0, 100, errors={"e": 0.02}, info={"refinement": True}),
            Run("fem h=0.2", 1.0, 50, errors={"e": 0.04}, info={"refinement": True}),
            Run("fem h=0.1", 4.0, 200, errors={"e": 0.01}, info={"refinement": True})]
    (row,) = matched(runs, "e")
    assert row["error"] == 0.02 and row["level_of"] == "rkpm" and row["rkpm_wall_s"] == 10.0
    assert row["fem_wall_s"] == pytest.approx(2.0) and row["fem_dofs"] == 100  # halfway in log-log
    assert row["wall_ratio"] == pytest.approx(5.0)


def test_rows_need_the_other_method_on_both_sides_and_skip_unselected_or_exact_runs():
    runs = [Run("rkpm h=0.1", 10.0, 100, errors={"e": 0.02}),
            Run("rkpm h=0.05", 30.0, 400, errors={"e": 0.005}),
            Run("rkpm h=0.025", 90.0, 1600, errors={"e": 0.0}),  # the reference itself: no error
            Run("fem h=0.2", 1.0, 50, errors={"e": 0.04}),
            Run("fem h=0.1", 4.0, 200, errors={"e": 0.01}),
            Run("fem h=0.05", 9.0, 800, errors={"e": 0.003}, info={"skip": True})]
    rows = matched(runs, "e", lambda r: not r.info.get("skip"))
    # rkpm 0.005 lies below the FEM curve (0.01-0.04); fem 0.01 lies within RKPM's (0.005-0.02).
    assert [(r["level_of"], r["error"]) for r in rows] == [("rkpm", 0.02), ("fem", 0.01)]
    assert rows[1]["rkpm_wall_s"] == pytest.approx(10.0 * (30.0 / 10.0) ** 0.5)
    assert matched(runs[:2], "e") == []  # one method only
