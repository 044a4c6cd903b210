"""Two-dimensional steady unsaturated seepage: the rectangular dam's exact discharge
(``verification.rectangular_dam``) with RKPM and FEM, and seepage faces
(``rkfx.assembly.seepage_face``) on exact columns and on the dam."""
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.assembly.seepage_face import seepage_face
from rkfx.cases._confined_column import column_discretization
from rkfx.errors import InputError
from rkfx.models.explicit_poroelasticity import collocation_rows
from rkfx.models.unsaturated_poroelasticity import UnsaturatedBiotModel
from rkfx.solvers.model import Constraints
from rkfx.solvers.steady import steady_state
from verification.rectangular_dam import Dam, dam_discharge, discharge, fem_dam, levee_sand, rkpm_dam, seepage_penalty

SOIL = levee_sand()
GAMMA_W = SOIL.medium.rho_f * SOIL.gravity
K = SOIL.medium.k


def test_the_exact_discharge_has_the_closed_form_when_saturated():
    """k_rw = 1: Phi(p) = p and Q = k gamma (H^2 - (H - T)^2)|_{H_2}^{H_1} / (2 L), Dupuit's
    discharge plus the suction zones' share."""
    law = SimpleNamespace(relative_permeability=lambda s: np.ones_like(np.asarray(s, float)))
    soil = SimpleNamespace(medium=SOIL.medium, retention=law, gravity=SOIL.gravity)
    dam = Dam()
    closed = K * GAMMA_W * ((dam.head_up ** 2 - (dam.head_up - dam.height) ** 2)
                            - (dam.head_down ** 2 - (dam.head_down - dam.height) ** 2)) / (2.0 * dam.length)
    assert dam_discharge(soil, dam) == pytest.approx(closed, rel=1e-10)
    # the sand's k_rw < 1 in the suction zones: less than saturated, more than Dupuit's share
    dupuit = K * GAMMA_W * (dam.head_up ** 2 - dam.head_down ** 2) / (2.0 * dam.length)
    assert dupuit < dam_discharge(SOIL, dam) < closed


def test_rkpm_discharge_converges_at_second_order():
    """NSNI at 6, 11 and 21 rows: 5.2e-3, 1.3e-3, 3.1e-4 of the exact discharge (rates 2.0, 2.05)."""
    dam = Dam()
    exact = dam_discharge(SOIL, dam)
    errors = []
    for ny in (6, 11, 21):
        q, done = discharge(rkpm_dam(SOIL, dam, ny), dam)
        errors.append(abs(q - exact) / exact)
        assert done.run.cuts == 0 and done.run.steps <= 25
    rates = np.log2(np.array(errors[:-1]) / errors[1:])
    assert errors[0] < 6e-3 and np.all(rates > 1.8), (errors, rates)


def test_fem_discharge_converges_at_third_order():
    pytest.importorskip("dolfinx_solver")
    dam = Dam()
    exact = dam_discharge(SOIL, dam)
    errors = [abs(discharge(fem_dam(SOIL, dam, ny), dam)[0] - exact) / exact for ny in (6, 11)]
    assert errors[0] < 3e-5 and np.log2(errors[0] / errors[1]) > 2.8, errors


def _column(method, head, W=0.2, L=1.0, ny=11):
    """A column W x L, p = gamma head at its base, its top a seepage face: the model, the
    face's penalty and the model's face points' pressures (a function of the state)."""
    h = L / (ny - 1)
    kappa = seepage_penalty(SOIL, h)
    if method == "fem":
        pytest.importorskip("dolfinx_solver")
        from fem_baselines.poroelasticity import rectangle_mesh
        from fem_baselines.unsaturated import FemUnsaturatedModel
        from rkfx.conditions import Displacement, Pressure
        mesh = rectangle_mesh(np.linspace(0.0, W, int(round(W / h)) + 1), np.linspace(0.0, L, ny), "quadrilateral")
        model = FemUnsaturatedModel(mesh, SOIL, [Displacement("bottom"), Pressure("bottom", GAMMA_W * head)],
                                    seepage=("top", kappa))
        return model, kappa, None
    d = column_discretization(W, L, int(round(W / h)) + 1, ny)
    n = d.particles.num_nodes
    G = sp.vstack([collocation_rows(d.rk, d.bottom, c, n, 0, 3 * n) for c in (0, 1)]
                  + [collocation_rows(d.rk, d.bottom, None, n, 2 * n, 3 * n)]).tocsr()
    g = np.r_[np.zeros(2 * len(d.bottom)), np.full(len(d.bottom), GAMMA_W * head)]
    edges = d.particles.boundary_edges
    face = seepage_face(d.rk, edges[np.isin(edges, d.top).all(axis=1)], kappa)
    model = UnsaturatedBiotModel(d.rule, SOIL, Constraints(G, g), seepage=face)
    return model, kappa, lambda x: face.matrix() @ x[2 * n:]


@pytest.mark.parametrize("method", ["rkpm", "fem"])
def test_an_artesian_column_discharges_through_its_seepage_face(method):
    """Base head 1.5 L: saturated upward flow leaving through the top, p linear with the top at
    q / kappa, so q (1 + k / (kappa L)) = k gamma (H / L - 1) exactly; the face's outflow
    carries all of it. FEM holds it to round-off; RKPM to 1.4e-5 (measured), the error of
    collocating the base pressure at the nodes only (its test functions keep a small integral
    along the base, so even the linear field leaves a residual there)."""
    W, L, head = 0.2, 1.0, 1.5
    model, kappa, face_p = _column(method, head, W, L)
    x = steady_state(model, 0.01).state.x
    q = K * GAMMA_W * (head / L - 1.0) / (1.0 + K / (kappa * L))
    tol = 1e-8 if method == "fem" else 5e-5
    assert model.flux_integral(x)[1] / (W * L) == pytest.approx(q, rel=tol)
    assert model.seepage_outflow(x) / W == pytest.approx(q, rel=tol)
    if face_p is not None:
        assert np.allclose(face_p(x), q / kappa, rtol=tol)


@pytest.mark.parametrize("method", ["rkpm", "fem"])
def test_a_column_below_its_face_stays_hydrostatic_and_dry(method):
    """Base head 0.5 L: the water table stays inside, the face is dry (p < 0) and lets nothing
    through; the steady state is the no-flow profile (RKPM's flux 1.3e-6 of k gamma W L,
    measured, its error on the curved unsaturated profile)."""
    W, L = 0.2, 1.0
    model, _, face_p = _column(method, 0.5, W, L)
    x = steady_state(model, 0.01).state.x
    assert model.seepage_outflow(x) == 0.0
    tol = 1e-10 if method == "fem" else 1e-5
    assert np.abs(model.flux_integral(x)).max() < tol * K * GAMMA_W * W * L
    if face_p is not None:
        assert face_p(x).max() < -0.4 * GAMMA_W * L


def test_a_dam_without_tailwater_seeps_out_of_its_downstream_face():
    """H_2 = 0, the whole downstream face a seepage face: all the water leaves through it (FEM's
    outflow equals its discharge to round-off, RKPM's within 1 %), and RKPM and FEM agree on the
    discharge to 1e-3 at 11 rows (measured 4e-5), below that of a face held at suction."""
    pytest.importorskip("dolfinx_solver")
    dam = Dam(head_down=0.0, seepage=True)
    found = {}
    for method, build in (("rkpm", rkpm_dam), ("fem", fem_dam)):
        model = build(SOIL, dam, 11)
        q, done = discharge(model, dam)
        found[method] = q
        out = model.seepage_outflow(done.state.x)
        assert out == pytest.approx(q, rel=1e-9 if method == "fem" else 1e-2), (method, out, q)
    assert found["rkpm"] == pytest.approx(found["fem"], rel=1e-3)
    assert found["fem"] < dam_discharge(SOIL, Dam(head_down=0.0))


def test_a_bad_seepage_face_is_refused_in_one_line():
    d = column_discretization(0.2, 1.0, 3, 11)
    with pytest.raises(InputError, match="penalty"):
        seepage_face(d.rk, d.particles.boundary_edges[:2], 0.0)
    with pytest.raises(InputError, match="no boundary segments"):
        seepage_face(d.rk, np.zeros((0, 2), np.int64), 1.0)
