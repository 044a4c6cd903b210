"""The crack-tip study of the branching run measures a running tip and the stress around it."""
import numpy as np
import pytest

from verification import branching_tip as study


def test_rayleigh_speed_is_viktorovs_fraction_of_the_shear_speed():
    c_s = np.sqrt(2.5e10 / (2 * 1.25 * 2500.0))
    assert study.rayleigh_speed(2.5e10, 0.25, 2500.0) == pytest.approx(c_s * (0.862 + 0.285) / 1.25)


def test_the_hoop_stress_of_a_uniform_pull_peaks_ahead_of_the_tip():
    """Uniform sigma_yy: sigma_tt = sigma_yy cos^2 theta, largest at theta = 0, ratio cos^2 60 / ~1."""
    g = np.linspace(-5e-3, 5e-3, 101)
    x = np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)
    stress = np.tile([0.0, 1.0e6, 0.0], (len(x), 1))
    prof = study.hoop_profile(x, stress, np.ones(len(x), bool), np.zeros(len(x)), np.zeros(2), (2e-3, 4e-3))
    assert abs(prof["peak_deg"]) <= 7.5 and prof["damaged_share"] == 0.0
    assert 0.2 < prof["off_over_on"] < 0.35  # mean cos^2 over 45-75 deg against ~1 within 15 deg


def test_a_coarse_run_has_a_running_tip_slower_than_rayleigh_waves():
    m = study.measure(1.6e-3)
    s = study.summary(m)
    assert m["branches"] >= 1 and s["frames"] >= 3
    assert 0.05 < s["speed_over_cR"] < 1.0
    tips = [f["tip_mm"][0] for f in m["frames"] if f["tip_mm"] is not None]
    assert tips == sorted(tips)  # the farthest cracked particle never moves back
    assert s["end_upper_mm"] is not None and s["end_lower_mm"] is not None  # two branches at the end


def test_bad_spacings_are_refused_in_one_line(capsys, tmp_path):
    assert study.main(["--h", "fine", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'fine'" in err[0]


def test_the_study_writes_its_table_json_and_figure(tmp_path, capsys):
    assert study.main(["--h", "1.6e-3", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| 1.6 |" in out and "h = 1.6 mm:" in out
    assert (tmp_path / "tip.json").exists() and (tmp_path / "tips.png").stat().st_size > 10_000
