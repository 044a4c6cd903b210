"""The steppers on small models with exact solutions: orders of accuracy, constraints,
Newton's reports, step cutting and bitwise resume."""
import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from rkfx.errors import InputError, SolverError
from rkfx.solvers import newmark as nm
from rkfx.solvers.fields import single
from rkfx.solvers.integrate import integrate, time_grid
from rkfx.solvers.model import Constraints, Stateless, no_constraints
from rkfx.solvers.newton import DIVERGED, MAX_ITERATIONS, NewtonOptions


class Oscillator(Stateless):
    """m x'' + k x + k3 x^3 = 0 for n uncoupled unknowns (k3 = 0: linear, x = cos(omega t))."""

    def __init__(self, n=1, m=2.0, k=8.0, k3=0.0):
        self.layout = single("x", 1, 2, n)
        self.m, self.k, self.k3 = m, k, k3
        self.linear = k3 == 0.0

    def residual(self, x, t):
        return self.k * x + self.k3 * x**3

    def tangent(self, x, t):
        return sp.diags(self.k + 3 * self.k3 * x**2)

    def mass(self):
        return sp.identity(self.layout.size) * self.m

    def capacity(self, dt):
        return None

    def constraints(self, t):
        return no_constraints(self.layout.size)


class Diffusion(Stateless):
    """C x' + K x = 0: three coupled first-order unknowns (a lumped 1-D consolidation), with an
    optional prescribed x_0(t) = sin(t)."""

    C = np.diag([1.0, 2.0, 1.5])
    K = np.array([[3.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])

    def __init__(self, prescribed=False):
        self.layout = single("p", 1, 1, 3)
        self.linear = True
        self.prescribed = prescribed

    def residual(self, x, t):
        return self.K @ x

    def tangent(self, x, t):
        return sp.csr_matrix(self.K)

    def mass(self):
        return None

    def capacity(self, dt):
        return sp.csr_matrix(self.C)

    def constraints(self, t):
        if not self.prescribed:
            return no_constraints(3)
        return Constraints(sp.csr_matrix(([1.0], ([0], [0])), shape=(1, 3)), np.array([np.sin(t)]),
                           np.array([np.cos(t)]))


class NonlinearStorage(Stateless):
    """(1 + x^2) x' + x = 0 through ``rate_force``: ln x + x^2 / 2 = ln x0 + x0^2 / 2 - t."""

    def __init__(self):
        self.layout = single("x", 1, 1, 1)
        self.linear = False

    def residual(self, x, t):
        return x.copy()

    def tangent(self, x, t):
        return sp.identity(1, format="csr")

    def mass(self):
        return None

    def capacity(self, dt):
        return None

    def rate_force(self, x, v):
        self._at = (x.copy(), v.copy())
        return (1.0 + x**2) * v

    def rate_tangents(self):
        x, v = self._at
        return sp.diags(2.0 * x * v), sp.diags(1.0 + x**2)

    def constraints(self, t):
        return no_constraints(1)

    @staticmethod
    def exact(x0, t):
        from scipy.optimize import brentq
        c = np.log(x0) + 0.5 * x0**2 - t
        return brentq(lambda x: np.log(x) + 0.5 * x**2 - c, 1e-12, x0)


class Final:
    def __init__(self):
        self.x = []

    def record(self, s):
        self.x.append(s.x.copy())

    def arrays(self):
        return {"x": np.array(self.x)}

    def restore(self, a):
        self.x = list(a["x"])


def run(stepper, model, t_end, steps, x0, v0=None):
    times = np.linspace(0.0, t_end, steps + 1)
    s0 = stepper.start(model, x0=x0, v0=v0)
    return integrate(stepper, model, times, start=s0).state


def rates(errors):
    e = np.asarray(errors)
    return np.log2(e[:-1] / e[1:])


@pytest.mark.parametrize("stepper, order", [(nm.trapezoidal(), 2.0), (nm.explicit(), 2.0),
                                            (nm.Newmark(beta=0.25, gamma=0.6), 1.0)])
def test_oscillator_orders(stepper, order):
    model = Oscillator()
    omega = np.sqrt(model.k / model.m)
    errs = [abs(run(stepper, model, 2.0, n, [1.0]).x[0] - np.cos(omega * 2.0)) for n in (80, 160, 320, 640)]
    r = rates(errs)
    assert np.all(r > order - 0.15), (errs, r)
    assert np.all(r < order + 0.5), (errs, r)


@pytest.mark.parametrize("theta, order", [(1.0, 1.0), (0.5, 2.0), (0.0, 1.0)])
def test_first_order_rates(theta, order):
    model = Diffusion()
    x0 = np.array([1.0, -0.5, 2.0])
    exact = sla.expm(-np.linalg.solve(Diffusion.C, Diffusion.K) * 1.0) @ x0
    v0 = -np.linalg.solve(Diffusion.C, Diffusion.K @ x0)  # consistent rates for theta < 1
    steps = (80, 160, 320, 640) if theta == 0 else (10, 20, 40, 80)
    errs = [np.abs(run(nm.theta_method(theta), model, 1.0, n, x0, v0).x - exact).max() for n in steps]
    r = rates(errs)
    assert np.all(r > order - 0.1), (errs, r)
    assert errs[-1] < (1e-4 if order == 2 else 2e-2)


@pytest.mark.parametrize("theta", [1.0, 0.5, 0.0])
def test_prescribed_value_is_met_exactly(theta):
    model = Diffusion(prescribed=True)
    v0 = np.array([1.0, 0.0, 0.0])
    s = run(nm.theta_method(theta), model, 0.7, 35, [0.0, 0.0, 0.0], v0)
    assert s.x[0] == pytest.approx(np.sin(0.7), abs=1e-12)


def test_duffing_trapezoid_second_order():
    model = Oscillator(k3=20.0)
    st = nm.trapezoidal(rtol=1e-13)
    ref = run(st, model, 1.0, 5120, [1.0]).x[0]
    errs = [abs(run(st, model, 1.0, n, [1.0]).x[0] - ref) for n in (40, 80, 160, 320)]
    assert np.all(rates(errs) > 1.85), errs


@pytest.mark.parametrize("theta, order", [(1.0, 1.0), (0.5, 2.0)])
def test_state_dependent_capacity_orders(theta, order):
    model = NonlinearStorage()
    x0 = 1.5
    v0 = [-x0 / (1.0 + x0**2)]
    exact = NonlinearStorage.exact(x0, 1.0)
    errs = [abs(run(nm.theta_method(theta, rtol=1e-13), model, 1.0, n, [x0], v0).x[0] - exact)
            for n in (10, 20, 40, 80)]
    r = rates(errs)
    assert np.all(np.abs(r - order) < 0.15), (errs, r)


def test_state_dependent_capacity_needs_implicit_rates():
    model = NonlinearStorage()
    with pytest.raises(InputError, match="rate_force"):
        run(nm.theta_method(0.0), model, 0.1, 2, [1.0], [-0.5])


def test_linear_model_reuses_one_factorization():
    model = Diffusion()
    out = integrate(nm.backward_euler(), model, np.linspace(0, 1, 21),
                    start=nm.backward_euler().start(model, x0=[1.0, 0.0, 0.0]))
    assert out.factorizations == 1 and out.newton_iterations == 20


class Stiff(Oscillator):
    """A Duffing spring whose Newton diverges at a large step (k3 huge)."""

    def __init__(self):
        super().__init__(k3=1e6)


def test_step_cutting_and_failure_message():
    model = Stiff()
    st = nm.Newmark(newton=NewtonOptions(max_iterations=6))
    out = integrate(st, model, [0.0, 0.5], start=st.start(model, x0=[1.0]), max_cuts=12)
    assert out.cuts > 0 and out.state.t == 0.5
    with pytest.raises(SolverError, match=r"Newton failed at step 1 \(t = .* after 0 cuts\), iteration \d+: "
                                          rf"({MAX_ITERATIONS}|{DIVERGED}) \(residual"):
        integrate(st, model, [0.0, 0.5], start=st.start(model, x0=[1.0]), max_cuts=0)


def test_resume_is_bitwise(tmp_path):
    model = Oscillator(n=3, k3=5.0)
    st = nm.trapezoidal()
    times = np.linspace(0, 1.0, 41)
    x0 = [1.0, 0.5, -0.2]
    full = Final()
    integrate(st, model, times, start=st.start(model, x0=x0), recorder=full)
    first = Final()
    integrate(st, model, times[:25], start=st.start(model, x0=x0), recorder=first, checkpoint_every=8,
              checkpoint_dir=tmp_path)
    rest = Final()
    out = integrate(st, model, times, recorder=rest, resume=tmp_path)
    assert out.resumed_from == 24
    assert np.array_equal(np.array(rest.x), np.array(full.x))


def test_bad_input_names_the_culprit():
    with pytest.raises(InputError, match="theta"):
        nm.Newmark(theta=1.5)
    with pytest.raises(InputError, match="beta"):
        nm.Newmark(beta=-1.0)
    with pytest.raises(InputError, match="increasing"):
        integrate(nm.trapezoidal(), Oscillator(), [0.0, 0.0])
    with pytest.raises(InputError, match="output times"):
        time_grid([0.0], 0.1)


def test_resume_is_reported_and_a_garbled_checkpoint_named(tmp_path, caplog):
    import logging

    from rkfx.solvers.checkpoint import load_arrays, save_arrays

    save_arrays(tmp_path / "run", {"state__step": np.int64(24), "x": np.ones(3)})
    with caplog.at_level(logging.INFO, logger="rkfx"):
        assert load_arrays(tmp_path / "run")["x"].sum() == 3
    assert "run continues from step 24" in caplog.text
    path = tmp_path / "run" / "checkpoint.npz"
    path.write_bytes(path.read_bytes()[:40])  # truncated, as by a full disk
    with pytest.raises(InputError, match=r"checkpoint.npz is unreadable .*delete .*run"):
        load_arrays(tmp_path / "run")


class SlowlyLoaded(Oscillator):
    """m x'' + k x + k3 x^3 = F t: a stiff Duffing spring loaded slowly, quasi-static on the scale
    of its period (the steps are 1e4 periods)."""

    def __init__(self):
        super().__init__(m=1e-6, k=1.0, k3=50.0)
        self.linear = False

    def residual(self, x, t):
        return super().residual(x, t) - t


def test_damped_newmark_is_first_order_and_damps_what_the_trapezoid_keeps():
    model = Oscillator()
    omega = np.sqrt(model.k / model.m)
    errs = [abs(run(nm.damped(), model, 2.0, n, [1.0]).x[0] - np.cos(omega * 2.0)) for n in (160, 320, 640, 1280)]
    assert np.all(rates(errs) > 0.85), errs
    # Steps of 100 periods: the trapezoid keeps the amplitude (1), the damped scheme kills it.
    dt = 100 * 2 * np.pi / omega
    kept = run(nm.trapezoidal(), model, 20 * dt, 20, [1.0])
    damped = run(nm.damped(), model, 20 * dt, 20, [1.0])
    assert abs(kept.x[0]) > 0.9 and abs(damped.x[0]) < 0.1  # measured: 0.865 per step
    with pytest.raises(InputError, match="gamma = 0.5"):
        nm.damped(gamma=0.5)


def test_newton_from_the_last_step_finds_the_same_solution_in_fewer_iterations():
    """guess="previous": the same trapezoidal steps of a slowly loaded stiff spring, Newton
    started from x_n instead of the predictor, which the undamped stiff mode carries off."""
    times = np.linspace(0.0, 2.0, 21)
    out = {}
    for guess in ("predictor", "previous"):
        st = nm.trapezoidal(guess=guess, rtol=1e-12)
        rec = Final()
        res = integrate(st, SlowlyLoaded(), times, start=st.start(SlowlyLoaded(), x0=[0.0], a0=[0.0]), recorder=rec)
        out[guess] = (np.array(rec.x), res.newton_iterations)
    assert np.allclose(out["previous"][0], out["predictor"][0], rtol=1e-9, atol=1e-12)
    assert out["previous"][1] < out["predictor"][1], out
    with pytest.raises(InputError, match="guess"):
        nm.Newmark(guess="zero")


class Loaded(Oscillator):
    """m x'' + k x + k3 x^3 = 1: a weakly nonlinear spring under a load applied at once."""

    def __init__(self):
        super().__init__(m=1e-6, k=1.0, k3=1e-7)
        self.linear = False

    def residual(self, x, t):
        return super().residual(x, t) - 1.0


def test_newton_converges_relative_to_the_predictor_residual():
    """||F|| <= rtol ||F_0||, F_0 at the predictor: the first update leaves k3 x^3 ~ 1e-7 of the
    load, within rtol = 1e-6 of the start, so one iteration is enough."""
    st = nm.trapezoidal(rtol=1e-6)
    res = integrate(st, Loaded(), [0.0, 1.0], start=st.start(Loaded(), x0=[0.0], a0=[0.0]))
    assert res.newton_iterations == 1
    assert abs(res.state.x[0] - 1.0) < 1e-5  # static up to the tiny mass's response


def test_until_ends_the_run_at_its_event_and_a_resume_ends_there_too(tmp_path):
    model = Oscillator(k3=5.0)
    st = nm.trapezoidal()
    times = np.linspace(0, 2.0, 81)

    def crossed(s):  # x = cos(...) first falls below zero
        return s.x[0] < 0.0

    rec = Final()
    out = integrate(st, model, times, start=st.start(model, x0=[1.0]), recorder=rec, until=crossed,
                    checkpoint_every=1000, checkpoint_dir=tmp_path)
    assert out.ended_early and out.state.x[0] < 0.0 and rec.x[-2] >= 0.0 < out.state.step < len(times) - 1
    full = Final()
    integrate(st, model, times, start=st.start(model, x0=[1.0]), recorder=full)
    assert np.array_equal(np.array(rec.x), np.array(full.x)[:len(rec.x)])
    # the checkpoint is written at the event, and resuming from it ends there at once
    again = integrate(st, model, times, recorder=Final(), until=crossed, resume=tmp_path)
    assert again.ended_early and again.state.step == out.state.step and again.substeps == 0
    # without the test, the resumed run goes on to the end
    assert integrate(st, model, times, recorder=Final(), resume=tmp_path).state.step == len(times) - 1
