"""Quasi-static load stepping (rkfx.solvers.quasi_static): a softening spring through its
snap-back, checkpoints and resume, bad input."""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.fracture import damage as dm
from rkfx.models.damage_bar import DamageBarModel, LoadCurve, elastic_limit, strip
from rkfx.errors import InputError, SolverError
from rkfx.solvers.checkpoint import load_arrays
from rkfx.solvers.fields import single
from rkfx.solvers.model import Constraints
from rkfx.solvers.quasi_static import DISSIPATION, QuasiStatic, march


class SofteningSpring:
    """Two springs in series, 0 - 1 softening by the linear damage law (4.2), 1 - 2 elastic;
    u_0 = 0 and u_2 = lam. With k_elastic < k kappa0 / (kappa_c - kappa0) the pair snaps back:
    the peak F = k kappa0 is reached at lam = kappa0 + k kappa0 / k_elastic, and the force
    vanishes at lam = kappa_c, after dissipating k kappa0 kappa_c / 2."""

    linear = False

    def __init__(self, k=1.0, kappa0=1.0, kappa_c=2.0, k_elastic=0.5):
        self.k, self.kappa0, self.kappa_c, self.k_elastic = k, kappa0, kappa_c, k_elastic
        self.layout = single("u", 1, 0, 3)
        self.kappa = 0.0
        self.trial = (0.0, 0.0, 0.0)

    def _law(self, kappa):
        return float(dm.damage(kappa, self.kappa0, self.kappa_c))

    def residual(self, x, t):
        e = x[1] - x[0]
        kappa = max(self.kappa, e)
        self.trial = (kappa, self._law(kappa), e)
        fa, fb = (1 - self.trial[1]) * self.k * e, self.k_elastic * (x[2] - x[1])
        return np.array([-fa, fa - fb, fb])

    def tangent(self, x, t):
        kappa, d, e = self.trial
        slope = (1 - d) * self.k
        if e >= self.kappa and self.kappa0 <= e < self.kappa_c:
            slope -= float(dm.damage_slope(e, self.kappa0, self.kappa_c)) * self.k * e
        kb = self.k_elastic
        return sp.csr_matrix([[slope, -slope, 0.0], [-slope, slope + kb, -kb], [0.0, -kb, kb]])

    def mass(self):
        return None

    def capacity(self, dt):
        return None

    def constraints(self, t):
        return Constraints(sp.csr_matrix([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]), np.array([0.0, t]),
                           np.array([0.0, 1.0]))

    def commit(self):
        self.kappa = self.trial[0]

    def state(self):
        return {"kappa": np.array(self.kappa)}

    def restore(self, arrays):
        self.kappa = float(arrays["kappa"])

    def history_increment(self):
        return self.trial[1] - self._law(self.kappa)

    def dissipation(self):
        phi = [dm.dissipation_density(kappa, self.kappa0, self.kappa_c, self.k) for kappa in (self.trial[0], self.kappa)]
        return float(phi[0] - phi[1])


class Curve:
    """Records (lam, F, control) per accepted step; raises ``Interrupt`` at step ``stop``."""

    def __init__(self, stop=None):
        self.rows, self.stop = [], stop

    def record(self, s):
        self.rows.append((s.lam, s.force, s.control == DISSIPATION))
        if s.step == self.stop:
            raise Interrupt

    def arrays(self):
        return {"rows": np.array(self.rows).reshape(-1, 3)}

    def restore(self, arrays):
        self.rows = [tuple(r) for r in arrays["rows"]]


class Interrupt(Exception):
    """A killed run."""


STEPPER = QuasiStatic(energy_step=0.05, max_increment=0.2)


def test_softening_spring_snaps_back_under_dissipation_control():
    spring, curve = SofteningSpring(), Curve()
    out = march(spring, np.linspace(0.2, 4.0, 20), STEPPER, recorder=curve)
    lam, force, arc = np.array(curve.rows).T
    assert out.arc_steps > 5 and arc.sum() == out.arc_steps
    # Peak k kappa0 = 1 at lam = 3, then the branch F = lam - 2 back to the failure at lam = 2.
    assert np.isclose(force.max(), 1.0, rtol=1e-9) and np.isclose(lam[np.argmax(force)], 3.0, rtol=1e-9)
    soft = arc.astype(bool)
    assert np.all(np.diff(lam[soft]) < 0)
    assert np.allclose(force[soft], lam[soft] - 2.0, atol=1e-8)
    assert dm.failure_displacement(np.r_[0.0, lam], np.r_[0.0, force]) == pytest.approx(2.0, rel=1e-8)
    # Broken, with all of the spring's fracture energy dissipated, and the targets reached.
    assert abs(out.force) < 1e-9 and out.lam == 4.0
    assert spring.kappa >= spring.kappa_c
    work = np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(lam)) + 0.5 * force[0] * lam[0]
    assert work == pytest.approx(1.0, rel=1e-6)


def test_without_dissipation_control_the_snap_back_is_a_one_line_error():
    with pytest.raises(SolverError, match="energy_step") as e:
        march(SofteningSpring(), np.linspace(0.2, 4.0, 20), QuasiStatic(max_increment=0.2))
    assert "\n" not in str(e.value)


def _resumed(make, targets, stepper, every, stop, tmp_path):
    """(uninterrupted, resumed) runs: model, recorder and result of each."""
    whole = make()
    full = march(whole[0], targets, stepper, recorder=whole[1], checkpoint_every=every,
                 checkpoint_dir=tmp_path / "whole")
    part = make(stop)
    with pytest.raises(Interrupt):
        march(part[0], targets, stepper, recorder=part[1], checkpoint_every=every, checkpoint_dir=tmp_path / "part")
    again = make()
    res = march(again[0], targets, stepper, recorder=again[1], checkpoint_every=every,
                checkpoint_dir=tmp_path / "again", resume=tmp_path / "part")
    assert res.resumed_from == every * (stop // every)
    return (whole, full), (again, res)


def _assert_same(a, b):
    assert a.keys() == b.keys()
    for key in set(a) - {"cursor__wall"}:  # everything but the wall time
        assert np.array_equal(a[key], b[key], equal_nan=True), key


def test_killed_spring_resumes_bit_for_bit_inside_the_snap_back(tmp_path):
    targets = np.linspace(0.2, 4.0, 20)
    probe = Curve()
    march(SofteningSpring(), targets, STEPPER, recorder=probe)
    first_arc = next(i for i, r in enumerate(probe.rows) if r[2]) + 1
    (whole, full), (again, res) = _resumed(lambda stop=None: (SofteningSpring(), Curve(stop)), targets, STEPPER, 3,
                                           first_arc + 4, tmp_path)
    assert np.isfinite(load_arrays(tmp_path / "part")["cursor__stall"])
    assert np.array_equal(full.x, res.x) and np.array_equal(full.mu, res.mu) and full.lam == res.lam
    assert whole[1].rows == again[1].rows
    assert (full.steps, full.cuts, full.arc_steps) == (res.steps, res.cuts, res.arc_steps)
    _assert_same(load_arrays(tmp_path / "whole"), load_arrays(tmp_path / "again"))


def test_killed_bar_resumes_bit_for_bit(tmp_path):
    """The unregularized 32-node bar snaps back: kill it in its dissipation-controlled stretch."""
    material = dm.DamageMaterial(2.0e6, 0.0, 200.0, 1.885, "stress")
    s = strip(100.0, 10.0, 32)
    weak = (s.extent[:, 0] <= 50.0 + 1e-7) & (s.extent[:, 1] >= 50.0 - 1e-7)
    points = dm.damage_model(material, s.volume, np.where(weak, 0.999, 1.0), kappa_c=1.41375e-3, regularized=False)
    u_peak = elastic_limit(s, points)
    targets = np.r_[0.98 * u_peak, u_peak * 1.0001, np.linspace(0.98 * u_peak, 0.0192, 41)[1:]]
    stepper = QuasiStatic(energy_step=material.GF * s.H / 50.0)

    class Bar(LoadCurve):
        def __init__(self, model, stop):
            super().__init__(model, s.thickness, s.H, [0.01])
            self.stop = stop

        def record(self, state):
            super().record(state)
            if state.step == self.stop:
                raise Interrupt

    def make(stop=None):
        model = DamageBarModel(s, points)
        return model, Bar(model, stop)

    (whole, full), (again, res) = _resumed(make, targets, stepper, 10, 75, tmp_path)
    assert full.arc_steps > 10
    assert np.isfinite(load_arrays(tmp_path / "part")["cursor__stall"])  # it stopped in the stretch
    assert np.array_equal(full.x, res.x) and np.array_equal(full.mu, res.mu)
    _assert_same(whole[1].arrays(), again[1].arrays())
    _assert_same(whole[0].state(), again[0].state())
    assert whole[1].curve["force"][-1] < 1e-6 * max(whole[1].curve["force"])


def test_bad_input_names_the_culprit():
    spring, targets = SofteningSpring(), np.linspace(0.2, 4.0, 20)
    cases = [
        (lambda: QuasiStatic(energy_step=-1.0), "energy_step"),
        (lambda: QuasiStatic(min_fraction=0.0), "min_fraction"),
        (lambda: march(spring, targets[::-1]), "increasing"),
        (lambda: march(spring, [0.0, 1.0]), "positive"),
        (lambda: march(spring, targets, checkpoint_every=2), "checkpoint_dir"),
        (lambda: march(spring, targets, checkpoint_every=-1), "checkpoint_every"),
    ]
    for call, name in cases:
        with pytest.raises(InputError, match=name) as e:
            call()
        assert "\n" not in str(e.value)


def test_resume_refuses_a_checkpoint_of_other_targets(tmp_path):
    targets = np.linspace(0.2, 2.0, 5)
    march(SofteningSpring(), targets, STEPPER, checkpoint_every=2, checkpoint_dir=tmp_path)
    with pytest.raises(InputError, match="other load targets"):
        march(SofteningSpring(), targets * 1.5, STEPPER, resume=tmp_path)
    with pytest.raises(InputError, match="no checkpoint"):
        march(SofteningSpring(), targets, STEPPER, resume=tmp_path / "missing")


def test_dissipation_control_needs_the_models_dissipation():
    class NoDissipation(SofteningSpring):
        dissipation = None

    with pytest.raises(InputError, match=r"dissipation\(\)"):
        march(NoDissipation(), [1.0], STEPPER)
