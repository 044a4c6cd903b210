"""The explicit u-p stepper (beta1 = 1/2, beta2 = 0, theta = 0; eqs. 6.37-6.43) on a two-unknown
u-p system with a known solution: it converges to it at first order (forward Euler on p), the
stable-step estimate holds, and a larger step is refused in one line."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from rkfx.errors import InputError
from rkfx.solvers.explicit_up import ExplicitUP, stable_steps
from rkfx.solvers.fields import layout

M, K, C, MP, H, F = 2.0, 50.0, 3.0, 0.5, 4.0, 1.0


class TwoUnknowns:
    """m u'' + k u - c p = f,  m_p p' + c u' + h p = 0 (a one-node consolidating oscillator)."""

    def __init__(self, k=K, c=C, h=H):
        self.k, self.c, self.h = k, c, h

    layout = layout(("u", 1, 2), ("p", 1, 1), nodes=1)
    essential = ()

    def lumped_mass(self):
        return np.array([M, MP])

    def solid_force(self, u, p):
        return self.k * u - self.c * p

    def fluid_flux(self, v, p):
        return self.c * v + self.h * p

    def external_force(self, t):
        return np.array([F, 0.0])


def _reference(t_end):
    def rhs(t, y):
        u, v, p = y
        return [v, (F - K * u + C * p) / M, -(C * v + H * p) / MP]
    sol = solve_ivp(rhs, (0.0, t_end), [0.0, 0.0, 0.0], rtol=1e-12, atol=1e-14, dense_output=True)
    return sol.sol


def test_converges_at_first_order_to_the_exact_history():
    t_end = 2.0
    ref = _reference(t_end)
    errors = []
    for steps in (400, 800, 1600):
        run = ExplicitUP(t_end / steps).run(TwoUnknowns(), steps, record=lambda x, r, t: x.copy())
        exact = ref(run.times)[[0, 2]].T
        errors.append(np.abs(run.samples - exact).max() / np.abs(exact).max())
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(rates > 0.9), (errors, rates)
    assert errors[-1] < 5e-3


def test_the_stable_step_estimate_is_the_coupled_one():
    limits = stable_steps(TwoUnknowns())
    # undrained skeleton stiffness k + c^2 / m_p, and the diffusion eigenvalue h / m_p
    assert limits["wave"] == pytest.approx(2.0 / np.sqrt((K + C * C / MP) / M), rel=1e-6)
    assert limits["diffusion"] == pytest.approx(2.0 * MP / H, rel=1e-6)
    assert limits["governs"] == "diffusion"  # 0.25 s against 0.34 s
    with pytest.raises(InputError, match="the diffusion governs"):
        ExplicitUP(1.01 * limits["coupled"]).run(TwoUnknowns(), 10)
    with pytest.raises(InputError, match="time step"):
        ExplicitUP(-1.0)


@pytest.mark.parametrize("k, c, h", [(1.0, 3.0, 0.0), (1.0, 3.0, 1.0), (1.0, 3.0, 3.0), (1.0, 10.0, 10.0),
                                     (10.0, 1.0, 5.0), (1.0, 10.0, 100.0)])
def test_the_allowed_step_is_stable_undrained_and_where_the_two_limits_meet(k, c, h):
    model = TwoUnknowns(k, c, h)
    dt = 0.99 * stable_steps(model)["coupled"]
    run = ExplicitUP(dt).run(model, 5000, record=lambda x, r, t: x.copy())
    static = F / k  # drained equilibrium u = f / k, p = 0 (undrained, h = 0: oscillates about f / (k + c^2 / m_p))
    assert np.abs(run.samples).max() < 3.0 * max(static, c * static / MP)


def test_a_resumed_run_ends_where_an_uninterrupted_one_does(tmp_path):
    record = lambda x, r, t: x.copy()  # noqa: E731
    whole = ExplicitUP(0.005).run(TwoUnknowns(), 300, record=record, record_every=7)
    ExplicitUP(0.005).run(TwoUnknowns(), 140, record=record, record_every=7, checkpoint_every=70,
                          checkpoint_dir=tmp_path)
    resumed = ExplicitUP(0.005).run(TwoUnknowns(), 300, record=record, record_every=7, checkpoint_every=70,
                                    checkpoint_dir=tmp_path, resume=tmp_path)
    assert resumed.resumed_from == 140
    assert np.array_equal(resumed.x, whole.x) and np.array_equal(resumed.rate, whole.rate)
    assert np.array_equal(resumed.times, whole.times) and np.array_equal(resumed.samples, whole.samples)
    with pytest.raises(InputError, match="dt = "):
        ExplicitUP(0.004).run(TwoUnknowns(), 300, resume=tmp_path)


class StabilizedStorage:
    """Three nodes: m u'' + K u - C p = f, (M_p + S) p' + C^T u' + H p = 0, p_3 = 0 held, with S
    a pressure stabilization (symmetric, zero row sums, 20 times the storage: far from lumpable)."""

    layout = layout(("u", 1, 2), ("p", 1, 1), nodes=3)
    chain = np.array([[1.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    Kuu = 40.0 * chain + 10.0 * np.eye(3)
    Cup = np.array([[2.0, 0.5, 0.0], [0.5, 2.0, 0.5], [0.0, 0.5, 2.0]])
    Hpp = 3.0 * chain
    S = 20.0 * MP * chain
    F3 = np.array([F, 0.0, -0.5 * F])

    def __init__(self):
        from rkfx.solvers.central_difference import Constraint  # noqa: PLC0415
        g = np.zeros((1, 6))
        g[0, 5] = 1.0
        import scipy.sparse as sp  # noqa: PLC0415
        self.essential = [Constraint(sp.csr_matrix(g))]

    def lumped_mass(self):
        return np.r_[np.full(3, M), np.full(3, MP)]

    def pressure_stabilization(self, dt):
        import scipy.sparse as sp  # noqa: PLC0415
        return sp.csr_matrix(self.S)

    def solid_force(self, u, p):
        return self.Kuu @ u - self.Cup @ p

    def fluid_flux(self, v, p):
        return self.Cup.T @ v + self.Hpp @ p

    def external_force(self, t):
        return np.r_[self.F3, np.zeros(3)]


def test_a_pressure_stabilization_enters_the_storage_and_the_conditions_its_metric():
    """The stepper solves (M_p + S) p' = r (conjugate gradients) and holds p_3 = 0 in that
    metric, so it converges at first order to the history of the system reduced to the free
    pressures, (M_p + S)_ff p_f' = r_f; the lumped storage alone misses it by far."""
    m = StabilizedStorage()
    cap = (MP * np.eye(3) + m.S)[:2, :2]

    def rhs(t, y):
        u, v, p = y[:3], y[3:6], np.r_[y[6:], 0.0]
        return np.r_[v, (m.F3 - m.Kuu @ u + m.Cup @ p) / M, np.linalg.solve(cap, -(m.Cup.T @ v + m.Hpp @ p)[:2])]
    t_end = 1.0
    ref = solve_ivp(rhs, (0.0, t_end), np.zeros(8), rtol=1e-12, atol=1e-14, dense_output=True).sol
    errors = []
    for steps in (500, 1000, 2000):
        run = ExplicitUP(t_end / steps).run(m, steps, record=lambda x, r, t: x.copy())
        exact = np.c_[ref(run.times)[:3].T, ref(run.times)[6:].T, np.zeros(len(run.times))]
        assert np.abs(run.samples[:, 5]).max() < 1e-13
        errors.append(np.abs(run.samples - exact).max() / np.abs(exact).max())
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all(rates > 0.9) and errors[-1] < 5e-3, (errors, rates)
    lumped = StabilizedStorage()
    lumped.pressure_stabilization = lambda dt: None
    run = ExplicitUP(t_end / 2000).run(lumped, 2000, record=lambda x, r, t: x.copy())
    assert np.abs(run.samples - exact).max() / np.abs(exact).max() > 20 * errors[-1]


def test_a_storage_solve_that_does_not_converge_is_refused():
    from rkfx.solvers.explicit_up import _capacity_solver  # noqa: PLC0415
    m = StabilizedStorage()
    solve = _capacity_solver(m.S, np.full(3, MP), lambda v: v, lambda a, b: float(a @ b), max_iterations=1)
    with pytest.raises(InputError, match="did not converge in 1 conjugate-gradient iterations"):
        solve(np.array([1.0, -2.0, 0.5]))
