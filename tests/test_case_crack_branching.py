"""Dynamic crack branching (seed 4.3.3) on the quick refinements h = 1.6 and 0.8 mm to 80 µs: the crack
runs from the tip to the right and splits, the dissipation is objective with the regularization only,
the energy balances, and the command line writes its metrics and refuses bad input in one line."""
import json

import numba
import numpy as np
import pytest

from rkfx.cases import crack_branching as cb


@pytest.fixture(scope="module")
def quick():
    # One numba thread: the step kernels are per particle (results do not depend on the thread
    # count), and at ~6,500 particles two threads on a busy 2-core machine ran 2.4x slower than one.
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        return cb.run(methods=("rkpm",), **cb.QUICK)
    finally:
        numba.set_num_threads(threads)


def study(res, name):
    return {r.info["h_nominal"]: r for r in res.runs if r.info.get("study") == name}


def summary(res, name):
    return next(r for r in res.runs if r.info.get("study") == "summary" and r.info["of"] == name)


def test_grid_puts_the_crack_on_cell_faces():
    for h in (1.6e-3, 8e-4, 4e-4, 2e-4, 7e-4):
        xs, ys = cb.grid(h)
        assert len(xs) % 2 == 0 and len(ys) % 2 == 0
        # a1 and a2 are midlines between two grid lines, never on one.
        for c, a in ((xs, cb.A1), (ys, cb.A2)):
            i = np.searchsorted(c, a)
            assert np.isclose(0.5 * (c[i - 1] + c[i]), a)
        assert abs(xs[1] - h) < 0.05 * h and abs(ys[1] - h) < 0.05 * h


def test_traction_load_is_the_resultant_on_top_and_bottom():
    material = cb._check(3.2e10, 0.2, 2450.0, 2.72e6, 3.0, 1e6, "strain", 1e-6, 0.5, [1.6e-3], 1.75, 0.5, 3.5)
    xs, ys = cb.grid(1.6e-3)
    pl = cb.dyn.plate(xs, ys, [((0.0, cb.A2), (cb.A1, cb.A2))], [(False, True)], material, 2450.0, 1.75)
    f = cb.traction_force(pl, 1e6).reshape(-1, 2)
    top = pl.p.x[:, 1] > cb.A2
    # sigma * length on each edge, opposite; no horizontal load.
    assert f[top, 1].sum() == pytest.approx(1e6 * cb.LX, rel=1e-9)
    assert f[~top, 1].sum() == pytest.approx(-1e6 * cb.LX, rel=1e-9)
    assert np.abs(f[:, 0]).max() < 1e-9 * np.abs(f).max()


def test_crack_grows_from_the_tip_to_the_right_and_branches(quick):
    runs = study(quick, "rkpm-dpm")
    assert sorted(runs) == sorted(cb.QUICK["h"])
    for h, r in runs.items():
        assert r.errors["tip_x"] > cb.A1 + 0.03, (h, r.errors)
        tip = np.asarray(r.series["tip_x"], float)
        tip = tip[np.isfinite(tip)]
        assert tip.size and tip[0] < cb.A1 + 3 * h and np.all(np.diff(tip) >= 0)
        # Nothing fails behind the initial tip (the crack faces are free) or far off the crack line ahead of it.
        d = np.zeros(r.info["nx"] * r.info["ny"])
        d[np.asarray(r.series["damaged_index"], int)] = r.series["damaged_D"]
        grid = np.stack(np.meshgrid(np.linspace(0, cb.LX, r.info["nx"]), np.linspace(0, cb.LY, r.info["ny"])),
                        -1).reshape(-1, 2)
        failed = grid[d >= 0.9]
        assert failed[:, 0].min() > cb.A1 - 2 * h
    # At 0.8 mm the crack splits into two branches before it reaches the counting window.
    fine = runs[8e-4]
    assert fine.errors["branches"] == 2, fine.errors
    assert cb.A1 < fine.errors["branch_x"] < cb.BRANCH_WINDOW[0]


def test_dissipation_is_positive_monotone_and_the_energy_balances(quick):
    for name in ("rkpm-dpm", "rkpm-dpm-unregularized"):
        for r in study(quick, name).values():
            diss = np.asarray(r.series["dissipated"])
            assert diss[0] == 0.0 and diss[-1] > 0.05  # J/m: some centimetres of crack at G_F = 3 N/m
            assert np.all(np.diff(diss) >= -1e-9 * diss[-1])
            assert r.errors["dissipated_end"] == diss[-1]
            assert r.errors["energy_error"] < 1e-3
            # The traction's work went somewhere: external work exceeds the dissipation.
            assert np.asarray(r.series["external"])[-1] > diss[-1]


def test_dissipation_is_objective_with_regularization_only(quick):
    reg = summary(quick, "rkpm-dpm")
    unreg = summary(quick, "rkpm-dpm-unregularized")
    assert reg.errors["dissipation_change_fine"] < 0.5 * unreg.errors["dissipation_change_fine"], \
        (reg.errors, unreg.errors)
    coarse, fine = (study(quick, "rkpm-dpm-unregularized")[h].errors["dissipated_end"] for h in (1.6e-3, 8e-4))
    # Constant kappa_c: the band narrows and dissipates less on the finer grid.
    assert fine < 0.8 * coarse


def test_cli_writes_metrics_runs_fem_and_rejects_bad_input(tmp_path, capsys):
    out = tmp_path / "b"
    assert cb.main(["--method", "rkpm", "--set", "h=1.6e-3", "unregularized_h=1.6e-3", "nonlocal_h=8e-4",
                    "t_end=1e-5", "--out", str(out)]) == 0
    data = json.loads((out / "results.json").read_text())
    run = next(r for r in data["runs"] if r["method"] == "rkpm-dpm h=0.0016")
    assert {"branches", "branch_x", "tip_x", "dissipated_end", "energy_error"} <= set(run["errors"])
    assert {"time_us", "dissipated", "tip_x"} <= set(run["series"])
    summ = next(r for r in data["runs"] if r["info"].get("of") == "rkpm-dpm")
    assert "dissipation_change_fine" in summ["errors"] and set(summ["series"]["branches"]) == {"0.0016"}
    for f in ("cracks.png", "damage.png", "damage_unregularized.png", "cracks_nonlocal.png", "dissipation.png"):
        assert (out / f).is_file()
    # The crack-band finite elements: same metrics and figures.
    assert cb.main(["--method", "fem", "--set", "fem_h=1.6e-3", "t_end=2e-5", "--out", str(tmp_path / "f")]) == 0
    runs = json.loads((tmp_path / "f" / "results.json").read_text())["runs"]
    assert [r["method"] for r in runs] == ["fem-crack-band h=0.0016", "fem-crack-band"]
    assert {"branches", "branch_x", "tip_x", "dissipated_end", "dissipated_in_cracks"} <= set(runs[0]["errors"])
    assert runs[0]["errors"]["energy_error"] < 1e-3 and runs[0]["errors"]["dissipated_end"] > 0
    assert (tmp_path / "f" / "cracks_fem.png").is_file()
    capsys.readouterr()
    for bad in (["--set", "h=0.01"], ["--set", "GF=-1"], ["--set", "plane=membrane"], ["--set", "tol=0"],
                ["--set", "h=abc"], ["--set", "fem_h=0.05"], ["--resume", str(tmp_path / "nowhere")]):
        with pytest.raises(SystemExit) as err:
            cb.main(["--method", "rkpm", "--out", str(tmp_path / "x"), *bad])
        assert err.value.code == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
