"""The central-difference stepper on models of any layout: order of accuracy, essential
conditions, the model protocol it shares with the Newmark family, and bitwise resume with
the model's history and a recorder's arrays."""
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.solvers import newmark as nm
from rkfx.solvers.central_difference import CentralDifference, Constraint, ExplicitBase, ExplicitModel
from rkfx.solvers.fields import single
from rkfx.solvers.integrate import integrate


class Chain(ExplicitBase):
    """n masses in a line joined by springs k, one component per node (u along the line); a
    spring k0 ties every mass to the ground. History: the largest |u| each mass has reached,
    updated in place by the force."""

    def __init__(self, n, m=2.0, k=3.0, k0=0.0, essential=()):
        self.layout = single("u", 1, 2, n)
        self.m = np.full(n, m)
        main = np.full(n, k0)
        main[:-1] += k
        main[1:] += k
        self.K = sp.diags([main, np.full(n - 1, -k), np.full(n - 1, -k)], [0, 1, -1]).tocsr()
        self.essential = tuple(essential)
        self.peak = np.zeros(n)

    def lumped_mass(self):
        return self.m

    def internal_force(self, d):
        np.maximum(self.peak, np.abs(d), out=self.peak)
        return self.K @ d

    def external_force(self, t):
        return None

    def state(self):
        return {"peak": self.peak}


def unit_row(i, n):
    return sp.csr_matrix(([1.0], ([0], [i])), shape=(1, n))


def test_oscillator_is_second_order():
    """One mass on a spring (a layout of one unknown): x = cos(omega t)."""
    model = Chain(1, m=2.0, k0=8.0)
    assert isinstance(model, ExplicitModel) and model.layout.size == 1
    omega, t_end = 2.0, 2.0
    errors = []
    for steps in (40, 80, 160, 320):
        res = CentralDifference(t_end / steps).run(model, steps, d0=[1.0])
        errors.append(abs(res.state.d[0] - np.cos(omega * t_end)))
        assert res.state.time == pytest.approx(t_end)
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((rates > 1.85) & (rates < 2.5)), (errors, rates)


def test_chain_of_odd_size_with_a_clamp_and_a_prescribed_velocity():
    n, dt, steps = 7, 0.1, 200
    x0 = np.sin(np.linspace(0.0, 2.0, n))  # x0[0] = 0: the clamp holds from the start
    clamp = Constraint(unit_row(0, n))
    model = Chain(n, essential=[clamp])
    res = CentralDifference(dt).run(model, steps, d0=x0, output_every=100)
    assert res.state.d.shape == (n,) and res.state.d[0] == 0.0
    assert res.relative_energy_error() < 1e-3
    assert [s[0] for s in res.snapshots] == [0, 100, 200]
    # The same model follows the protocol of rkfx.solvers.model: Newmark's explicit variant
    # (beta = 0, gamma = 1/2, the same scheme) takes it to the same state.
    st = nm.explicit()
    ref = integrate(st, Chain(n, essential=[clamp]), np.arange(steps + 1) * dt,
                    start=st.start(Chain(n, essential=[clamp]), x0=x0)).state
    assert np.abs(ref.x - res.state.d).max() <= 1e-10 * np.abs(x0).max()
    assert np.abs(ref.v - res.state.v).max() <= 1e-9 * np.abs(res.state.v).max()
    # A prescribed velocity on the last mass: its motion follows exactly.
    push = Constraint(unit_row(n - 1, n), velocity=lambda t: np.array([0.1]))
    moved = CentralDifference(dt).run(Chain(n, essential=[clamp, push]), steps)
    assert moved.state.v[-1] == pytest.approx(0.1, abs=1e-14)
    assert moved.state.d[-1] == pytest.approx(0.1 * steps * dt, rel=1e-12)
    assert moved.relative_energy_error() < 1e-3
    with pytest.raises(InputError, match="prescribed velocity"):
        Chain(n, essential=[push]).constraints(0.0)


class Kept:
    """A recorder of the sampled displacements, checkpointed with the run."""

    def __init__(self, n, samples):
        self.rows, self.slot = np.zeros((samples, n)), np.zeros(1, np.int64)

    def record(self, s):
        self.rows[self.slot[0]] = s.d
        self.slot[0] += 1

    def arrays(self):
        return {"rows": self.rows, "slot": self.slot}

    def restore(self, arrays):
        self.rows[...], self.slot[...] = arrays["rows"], arrays["slot"]


def test_resume_restores_the_model_state_and_the_recorder_bitwise(tmp_path):
    n, dt = 5, 0.1
    x0 = np.linspace(-1.0, 1.0, n)
    pull = Constraint(unit_row(n - 1, n), displacement=lambda t: np.array([0.2 * np.sin(t)]))
    stepper = CentralDifference(dt)

    def fresh():
        return Chain(n, k0=1.0, essential=[pull]), Kept(n, 7)

    model, kept = fresh()
    full = stepper.run(model, 60, d0=x0, output_every=10, recorder=kept)
    assert full.state.d[-1] == pytest.approx(0.2 * np.sin(6.0), abs=1e-14)
    first, first_kept = fresh()
    stepper.run(first, 45, d0=x0, output_every=10, recorder=first_kept, checkpoint_every=20, checkpoint_dir=tmp_path)
    again, again_kept = fresh()
    rest = stepper.run(again, 60, output_every=10, recorder=again_kept, resume=tmp_path)
    assert rest.resumed_from == 40
    for name in ("d", "v", "a", "f_int", "energy"):
        assert np.array_equal(getattr(rest.state, name), getattr(full.state, name)), name
    assert np.array_equal(again.peak, model.peak) and np.array_equal(again_kept.rows, kept.rows)
    assert np.array_equal(rest.energy, full.energy)


def test_bad_models_and_steps_name_the_culprit():
    with pytest.raises(InputError, match="dt"):
        CentralDifference(0.0)
    model = Chain(3)
    model.layout = single("p", 1, 1, 3)
    with pytest.raises(InputError, match="time order 2"):
        CentralDifference(0.1).run(model, 1)
    model = Chain(3)
    model.m = np.ones(4)
    with pytest.raises(InputError, match="lumped mass"):
        CentralDifference(0.1).run(model, 1)
    with pytest.raises(InputError, match="no tangent"):
        Chain(3).tangent(np.zeros(3), 0.0)


class OneRank:
    """A ``RankShare`` of one rank that owns every unknown: its sums are the values themselves,
    so a model with it takes the distributed path of the stepper (energies settled in blocks)."""

    def __init__(self, n):
        self.owned, self.rank, self.size, self.sums = np.ones(n), 0, 1, 0

    def sum(self, values):
        self.sums += 1
        return np.array(values, float)

    def least(self, value):
        return int(value)


def test_energies_settled_in_blocks_on_ranks_are_the_per_step_energies():
    """On ranks the energy increments wait for one all-reduce per SETTLE_EVERY steps (and at
    outputs and the end): the history is the serial one bit for bit, the sums are few, and a
    blow-up is named at the step where it happened."""
    from rkfx.solvers.central_difference import SETTLE_EVERY

    n, dt, steps = 7, 0.1, 203
    x0 = np.sin(np.linspace(0.0, 2.0, n))
    clamp = Constraint(unit_row(0, n))
    serial = CentralDifference(dt).run(Chain(n, essential=[clamp]), steps, d0=x0, output_every=50)
    model = Chain(n, essential=[clamp])
    model.share = OneRank(n)
    ranks = CentralDifference(dt).run(model, steps, d0=x0, output_every=50)
    assert np.array_equal(ranks.energy, serial.energy) and np.array_equal(ranks.state.d, serial.state.d)
    assert np.array_equal(ranks.state.energy, serial.state.energy)
    assert model.share.sums <= 1 + steps // SETTLE_EVERY + 5  # the start, full blocks, outputs, the end
    # beyond the stable step the run blows up; the distributed path names the serial step
    messages = []
    for share in (None, OneRank(n)):
        unstable = Chain(n, k=3e4, essential=[clamp])
        if share is not None:
            unstable.share = share
        with pytest.raises(InputError, match="blew up") as err:
            CentralDifference(dt).run(unstable, 2000, d0=x0)
        messages.append(str(err.value))
    assert messages[0] == messages[1]
