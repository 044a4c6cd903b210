"""Crack closure (rkfx.fracture.closure): the law, and a failed band squeezed across its crack in
the chapter-5 models (RKPM and the crack-band FEM)."""
import numpy as np
import pytest

from rkfx.approximation.shape_functions import rk_approximation
from rkfx.conditions import Displacement, Pressure
from rkfx.errors import InputError
from rkfx.fracture.closure import CrackClosure
from rkfx.geometry.grid_cells import grid_domains
from rkfx.geometry.particles import graded
from rkfx.models.hydraulic_fracture import FracturingRock, HydraulicFractureModel

SIDES = ("left", "right", "bottom", "top")
ROCK = FracturingRock(2.1e11, 0.3, 3000.0, 1000.0, 0.2, 1e-8, 1e4, 2e9, 1e11, 2.7e3, 2.1e7, alpha=1.0)
SQUEEZE = 1e-4  # uniaxial strain across the band, eps_yy = -SQUEEZE


def _energy(law, e, n, d):
    """psi_c = D M <eps_nn>_-^2 / 2 of each point."""
    enn = n[:, 0] ** 2 * e[:, 0] + n[:, 1] ** 2 * e[:, 1] + n[:, 0] * n[:, 1] * e[:, 2]
    return 0.5 * d * law.modulus * np.minimum(enn, 0.0) ** 2


def test_the_closure_stress_and_tangent_derive_from_its_energy():
    rng = np.random.default_rng(3)
    law = CrackClosure(2.0e10)
    m = 400
    e = 1e-3 * rng.standard_normal((m, 3))
    a = rng.uniform(0, np.pi, m)
    n = np.column_stack([np.cos(a), np.sin(a)])
    d = rng.uniform(0, 1, m)
    s, c = law.stress(e, n, d), law.tangent(e, n, d)
    h = 1e-9
    for k in range(3):
        de = np.zeros(3)
        de[k] = h
        fd_s = (_energy(law, e + de, n, d) - _energy(law, e - de, n, d)) / (2 * h)
        assert np.allclose(fd_s, s[:, k], rtol=1e-6, atol=1e-6 * law.modulus * 1e-3)
        fd_c = (law.stress(e + de, n, d) - law.stress(e - de, n, d)) / (2 * h)
        enn = n[:, 0] ** 2 * e[:, 0] + n[:, 1] ** 2 * e[:, 1] + n[:, 0] * n[:, 1] * e[:, 2]
        away = np.abs(enn) > 1e-6  # off the kink at eps_nn = 0
        assert np.allclose(fd_c[away], c[away, :, k], rtol=1e-6, atol=1e-6 * law.modulus)
    enn = n[:, 0] ** 2 * e[:, 0] + n[:, 1] ** 2 * e[:, 1] + n[:, 0] * n[:, 1] * e[:, 2]
    assert np.all(s[enn > 0] == 0) and np.all(c[enn > 0] == 0)  # an open crack: the damage alone
    # A failed point squeezed across its crack carries sigma_nn = M eps_nn, no shear.
    one = law.stress(np.array([[0.0, -1e-3, 0.0]]), np.array([[0.0, 1.0]]), np.ones(1))
    assert np.allclose(one, [[0.0, -1e-3 * law.modulus, 0.0]])


def test_a_bad_closure_modulus_is_refused():
    with pytest.raises(InputError, match="closure modulus"):
        CrackClosure(-1.0)


def _band_plate(n, closure):
    """A square whose middle rows of particles are failed (D = 1, crack along x)."""
    h = 1.0 / n
    xs = -0.5 + h * np.arange(n + 1)
    xs[n // 2] = 0.0
    p = graded(xs, xs)
    band = np.flatnonzero(np.abs(p.x[:, 1]) < 1.5 * h - 1e-9)
    model = HydraulicFractureModel(p, rk_approximation(p.x, p.spacing, 1.5), grid_domains(xs, xs), ROCK,
                                   displacements=[Displacement(s) for s in SIDES], pressures=[Pressure(s) for s in SIDES],
                                   precracked=band, closure=closure)
    inner = np.flatnonzero(np.all(np.abs(p.x) < 0.5 - 2.6 * h, axis=1))
    return p, model, inner, h


@pytest.mark.parametrize("closure", [True, False])
def test_a_failed_band_squeezed_across_its_crack_carries_the_load_only_with_closure(closure):
    """Uniaxial strain across the band, drained: with closure the band carries (lambda + 2 mu)
    eps_yy like the rock around it, so the interior nodes are in equilibrium (measured 1.7e-15 of
    sigma h); without it the failed band gives way (a force of 0.5 sigma h at its rows)."""
    p, model, inner, h = _band_plate(16, closure)
    n = p.num_nodes
    u = np.column_stack([np.zeros(n), -SQUEEZE * p.x[:, 1]])
    r = model.residual(np.r_[u.ravel(), np.zeros(n)], 0.0)[:2 * n].reshape(-1, 2)
    scale = ROCK.damage_material.elasticity()[1, 1] * SQUEEZE * h
    imbalance = np.abs(r[inner]).max() / scale
    if closure:
        assert imbalance < 1e-9
    else:
        assert imbalance > 0.1


def test_the_closure_tangent_is_the_residual_derivative():
    """Around the squeezed band (no damage grows under this compression) the Jacobian's solid
    rows equal central differences of the residual (measured 2e-14 relative)."""
    p, model, inner, h = _band_plate(12, True)
    n = p.num_nodes
    rng = np.random.default_rng(1)
    u = np.column_stack([np.zeros(n), -SQUEEZE * p.x[:, 1]]).ravel()
    x = np.r_[u, 1e5 * rng.random(n)]
    model.residual(x, 0.0)
    k = model.tangent(x, 0.0)
    closed = np.flatnonzero(model.committed.damaged)
    assert closed.size > 0 and np.all(model.closure.normal_stiffness(
        model.strain, model.committed.normal, np.ones(n))[closed] > 0)
    v = np.r_[SQUEEZE * 1e-3 * rng.standard_normal(2 * n), np.zeros(n)]
    fd = (model.residual(x + v, 0.0) - model.residual(x - v, 0.0)) / 2
    kv = k @ v
    assert np.linalg.norm(fd[:2 * n] - kv[:2 * n]) < 1e-7 * np.linalg.norm(kv[:2 * n])


def test_the_fem_band_carries_the_squeeze_with_closure():
    """The crack-band FEM's closure, on the element's mean strain: a failed row of elements
    squeezed across its crack leaves the interior vertices in equilibrium (measured 2.6e-15 of
    sigma h) and gives way without it (1.0 sigma h); its tangent is the residual's derivative
    (1.7e-14 relative)."""
    pytest.importorskip("dolfinx_solver")
    import dolfinx_solver  # noqa: F401  (before dolfinx / petsc4py)
    from mpi4py import MPI

    from fem_baselines import hydraulic_fracture as fhf
    from fem_baselines.poroelasticity import rectangle_mesh
    from rkfx.conditions import Region

    n_el = 16
    h = 1.0 / n_el
    xs = -0.5 + h * np.arange(n_el + 1)
    xs[n_el // 2] = 0.0
    band = Region(lambda x: (x[:, 1] > -1e-9) & (x[:, 1] < h + 1e-9), "band")  # the row of elements above y = 0
    conditions = [Displacement(s) for s in SIDES] + [Pressure(s) for s in SIDES]
    out = {}
    for closure in (True, False):
        mesh = rectangle_mesh(xs, xs, "triangle", MPI.COMM_SELF)
        m = fhf.FemHydraulicFractureModel(mesh, ROCK, conditions, precracked=band, closure=closure)
        assert m.committed.damaged.sum() > 0
        vx = m.u_nodes
        u = np.column_stack([np.zeros(len(vx)), -SQUEEZE * vx[:, 1]]).ravel()
        x = np.r_[u, np.zeros(m.n_p)]
        r = m.residual(x, 0.0)[:m.n_u].reshape(-1, 2)
        inner = np.all(np.abs(vx) < 0.5 - 1.5 * h, axis=1)
        scale = ROCK.damage_material.elasticity()[1, 1] * SQUEEZE * h
        out[closure] = np.abs(r[inner]).max() / scale
        if closure:
            rng = np.random.default_rng(2)
            k = m.tangent(x, 0.0)
            v = np.r_[SQUEEZE * 1e-3 * rng.standard_normal(m.n_u), np.zeros(m.n_p)]
            fd = (m.residual(x + v, 0.0) - m.residual(x - v, 0.0)) / 2
            kv = k @ v
            assert np.linalg.norm(fd[:m.n_u] - kv[:m.n_u]) < 1e-7 * np.linalg.norm(kv[:m.n_u])
    assert out[True] < 1e-9 and out[False] > 0.1
