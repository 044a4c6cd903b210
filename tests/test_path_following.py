"""Path following past a limit load (rkfx.solvers.path_following): a softening spring whose load
falls past its peak is traced exactly, a load step ends on the requested load, and a killed run
resumes to the uninterrupted path."""
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.solvers.model import Constraints, Stateless
from rkfx.solvers.path_following import PathFollowing, follow

K, X0, F = 2.0e3, 0.01, 5.0


class Springs(Stateless):
    """A softening spring f(x1) = K x1 exp(-x1/X0) under the load t F, and a second unknown
    held at 0 by an essential condition (its multiplier balances the spring K x1 pulling on it)."""

    def __init__(self):
        self.layout = SimpleNamespace(size=2)

    def residual(self, x, t):
        self._x = x
        return np.array([K * x[0] * np.exp(-x[0] / X0) - t * F, K * x[1] - K * x[0]])

    def tangent(self, x, t):
        e = np.exp(-x[0] / X0)
        return sp.csr_matrix([[K * e * (1.0 - x[0] / X0), 0.0], [-K, K]])

    def load_derivative(self):
        return np.array([-F, 0.0])

    def constraints(self, t):
        return Constraints(sp.csr_matrix([[0.0, 1.0]]), np.zeros(1))


def exact(d):
    """The load factor in equilibrium with the spring at x1 = d."""
    return K * d * np.exp(-d / X0) / F


def test_the_load_falls_past_the_peak_as_the_spring_softens():
    """Load control ends at the peak K X0 / e; displacement control goes on down the softening branch."""
    targets = np.linspace(0.0, 4 * X0, 17)[1:]
    run = follow(Springs(), np.array([1.0, 0.0]), targets, np.zeros(2))
    assert run.ended == "targets" and run.message == ""
    d, t = run.path.T
    assert np.allclose(d[1:][np.isin(d[1:], targets)], targets)
    assert np.abs(t - exact(d)).max() < 1e-9 * exact(X0)
    assert t.argmax() not in (0, len(t) - 1) and t[-1] < 0.5 * t.max()  # past the peak, down the branch


def test_a_load_step_ends_on_the_requested_load():
    """until_load: the step that would pass t = 0.8 t_peak becomes a load step to it, on the
    rising branch."""
    peak = exact(X0)
    run = follow(Springs(), np.array([1.0, 0.0]), np.linspace(0.0, 4 * X0, 9)[1:], np.zeros(2),
                 until_load=0.8 * peak)
    assert run.ended == "load"
    assert abs(run.t - 0.8 * peak) < 1e-12 * peak
    assert run.d < X0 and abs(exact(run.d) - run.t) < 1e-9 * peak


def test_until_ends_the_path_after_the_first_step_it_holds():
    run = follow(Springs(), np.array([1.0, 0.0]), np.linspace(0.0, 4 * X0, 17)[1:], np.zeros(2),
                 until=lambda s, path: s.d >= 2 * X0 and len(path) == s.step + 1)
    assert run.ended == "until" and abs(run.d - 2 * X0) < 1e-15


class _Killed(Exception):
    pass


class Kept:
    """The recorder: (d, t) of the accepted steps; kills the run at ``kill``."""

    def __init__(self, kill=None):
        self.rows, self.kill = [], kill

    def record(self, s):
        self.rows.append((s.d, s.t))
        if s.step == self.kill:
            raise _Killed

    def arrays(self):
        return {"rows": np.array(self.rows).reshape(-1, 2)}

    def restore(self, a):
        self.rows = [tuple(r) for r in a["rows"]]


def test_a_killed_run_resumes_to_the_uninterrupted_path(tmp_path):
    targets = np.linspace(0.0, 4 * X0, 17)[1:]
    whole = follow(Springs(), np.array([1.0, 0.0]), targets, np.zeros(2), recorder=Kept())
    with pytest.raises(_Killed):
        follow(Springs(), np.array([1.0, 0.0]), targets, np.zeros(2), recorder=Kept(kill=7), checkpoint_every=3,
               checkpoint_dir=tmp_path)
    kept = Kept()
    resumed = follow(Springs(), np.array([1.0, 0.0]), targets, np.zeros(2), recorder=kept, resume=tmp_path)
    assert resumed.resumed_from == 6
    assert np.array_equal(resumed.path, whole.path) and np.array_equal(resumed.x, whole.x)
    assert len(kept.rows) == whole.steps


@pytest.mark.parametrize("change, culprit", [
    (dict(targets=[0.02, 0.01]), "strictly one way"),
    (dict(control=np.zeros(2)), "control nonzero"),
    (dict(model=SimpleNamespace(layout=SimpleNamespace(size=2))), "load_derivative"),
    (dict(checkpoint_every=2), "checkpoint_dir"),
])
def test_bad_input_names_the_culprit(change, culprit):
    args = dict(model=Springs(), control=np.array([1.0, 0.0]), targets=[0.01, 0.02], x0=np.zeros(2)) | change
    with pytest.raises(InputError, match=culprit):
        follow(**args)


def test_bad_settings_name_the_culprit():
    with pytest.raises(InputError, match="rtol"):
        PathFollowing(rtol=0.0)
    with pytest.raises(InputError, match="min_fraction"):
        PathFollowing(min_fraction=2.0)
