"""Steady states by pseudo-time continuation (``rkfx.solvers.steady``), checked on the drained
Liakopoulos column against its exact quadrature (``verification.drained_column``)."""
from types import SimpleNamespace

import numpy as np
import pytest

from rkfx.cases import liakopoulos
from rkfx.errors import InputError
from rkfx.solvers.steady import steady_state
from verification.drained_column import drained_column

SOIL = liakopoulos._soil(1.3e6, 0.4, 2000.0, 1000.0, 0.2975, 4.5e-13, 1e-3, 1e12, 2e9, 9.806, "seed")
W, L = 0.1, 1.0


def _column(method, ny):
    ys = np.linspace(0.0, L, ny)
    points = np.vstack([np.column_stack([np.full(ny, 0.5 * W), ys]), [[0.5 * W, L]]])
    if method == "fem":
        pytest.importorskip("dolfinx_solver")
        return ys, *liakopoulos.fem_column(SOIL, W, L, ny, points)
    return ys, *liakopoulos.rkpm_column(SOIL, W, L, ny, "nsni", points)


def test_the_reference_is_hydrostatic_and_closed_form_when_saturated():
    """With S_w = 1 the no-flow profile is p = -rho_w g y and the confined skeleton, loaded by
    alpha p alone, lifts the top by u = -alpha rho_w g L^2 / (2 M)."""
    law = SimpleNamespace(saturation=lambda s: np.ones_like(np.asarray(s, float)))
    soil = SimpleNamespace(medium=SOIL.medium, retention=law, gravity=SOIL.gravity, alpha=SOIL.alpha)
    ref = drained_column(soil, 2.0)
    g, rho_w = SOIL.gravity, SOIL.medium.rho_f
    assert np.abs(ref.p + rho_w * g * ref.y).max() <= 1e-10 * rho_w * g * 2.0
    modulus = SOIL.medium.material.elastic.constrained_modulus
    assert ref.top_displacement == pytest.approx(-SOIL.alpha * rho_w * g * 4.0 / (2.0 * modulus), rel=1e-10)


def test_rkpm_reaches_the_exact_drained_state_and_converges():
    """RKPM (NSNI) at 21, 41 and 81 rows: the profile within 3e-5 of the top suction at 21 rows,
    converging at second order; the top's settlement within 2e-4; about twenty steps."""
    ref = drained_column(SOIL, L)
    errors, settlement = [], []
    for ny in (21, 41, 81):
        ys, model, sample = _column("rkpm", ny)
        done = steady_state(model, 1.0)
        v = sample(done.state.x)
        errors.append(np.abs(v[:-1] - np.interp(ys, ref.y, ref.p)).max() / abs(ref.p[-1]))
        settlement.append(abs(v[-1] - ref.top_displacement) / abs(ref.top_displacement))
        assert done.run.steps <= 30 and done.run.cuts == 0 and done.change[-1] <= 1e-9
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert errors[0] < 3e-5 and np.all(rates > 1.5), (errors, rates)
    assert max(settlement) < 2e-4 and settlement[-1] < settlement[0] / 4, settlement


def test_fem_reaches_the_exact_drained_state():
    ref = drained_column(SOIL, L)
    ys, model, sample = _column("fem", 21)
    v = sample(steady_state(model, 1.0).state.x)
    assert np.abs(v[:-1] - np.interp(ys, ref.y, ref.p)).max() < 2e-5 * abs(ref.p[-1])
    assert abs(v[-1] - ref.top_displacement) < 1e-4 * abs(ref.top_displacement)


def test_a_march_that_does_not_settle_is_refused_in_one_line():
    _, model, _ = _column("rkpm", 21)
    with pytest.raises(InputError, match=r"no steady state after 3 steps .* raise max_steps or growth"):
        steady_state(model, 1.0, max_steps=3)
    for bad, match in ((dict(first_step=0.0), "first_step"), (dict(first_step=1.0, growth=1.0), "growth"),
                       (dict(first_step=1.0, rtol=2.0), "rtol"), (dict(first_step=1.0, max_steps=0), "max_steps")):
        with pytest.raises(InputError, match=match):
            steady_state(model, **bad)
