"""The branching sensitivity study measures what the case's figure shows on a coarse plate."""
import pytest

from verification import branching_sensitivity as study


def test_measurements_of_a_coarse_run_add_up():
    m = study.measure(1.6e-3, {})
    assert m["branches"] >= 1 and m["side_by_side"] >= m["branches"] - 1
    assert m["crack"] > 0 and m["onset"] >= 0
    assert m["crack"] + m["onset"] == pytest.approx(m["dissipated"])
    assert m["kappa_c_over_kappa0"] > 1  # regularized: kappa_c above the threshold (4.28)
    assert m["x_two_mm"] is None or m["x_two_mm"] >= m["split_mm"]
    assert sum(m["onset_by_distance"]) == pytest.approx(m["onset"])
    assert m["flank_per_cracked"] >= 0 and (m["flank_opening"] is None or 0 <= m["flank_opening"] < 0.5)


def test_an_unknown_variant_is_refused_in_one_line(capsys, tmp_path):
    assert study.main(["--variants", "defaults,eps=3", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'eps=3'" in err[0] and "eps_p=0" in err[0]


def test_the_residual_stiffness_variant_reaches_the_damage_model():
    """residual is not a case parameter: the study sets it on the model (a cracked particle keeps
    that share of its stiffness), which changes the run."""
    plain, stiff = study.measure(1.6e-3, {}), study.measure(1.6e-3, study.VARIANTS["residual=1e-2"])
    assert stiff["dissipated"] > 0 and stiff["dissipated"] != plain["dissipated"]


def test_the_untracked_variants_switch_the_tracking_off():
    """tracked=False lets every particle damage: the spurious damage of Fig 4.16 spreads, so the
    run differs from the tracked one."""
    assert study.VARIANTS["nonlocal R=2mm untracked"]["tracked"] is False
    plain, free = study.measure(1.6e-3, {}), study.measure(1.6e-3, {"tracked": False})
    assert free["dissipated"] > 0 and free["dissipated"] != plain["dissipated"]


def test_the_crack_band_fem_is_measured_the_same_way():
    """The crack-band FEM baseline on the same plate gives every measurement of the particle
    runs, on its cells (no kappa_c ratio: the band has no chord)."""
    m = study.measure(1.6e-3, study.VARIANTS["crack-band FEM"])
    plain = study.measure(1.6e-3, {})
    assert set(m) == set(plain)
    assert m["particles"] > plain["particles"]  # triangles of size h outnumber the particles
    assert m["crack"] > 0 and m["crack"] + m["onset"] == pytest.approx(m["dissipated"])
    assert sum(m["onset_by_distance"]) == pytest.approx(m["onset"])
    assert m["kappa_c_over_kappa0"] is None and m["branches"] >= 1
