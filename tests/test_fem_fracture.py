"""A pre-existing fracture in the crack-band u-p FEM (fem_baselines.fracture_faces, seed 5.3.3).

The mesh is the particle set cut along the fracture (the RKPM case's vertices): its faces pair
up node to node, and the u-p model with the contact law, drained, reaches the exact state that
is linear on each side and jumps by what the law balances (stick, and slip at the friction
limit), as the RKPM model does in tests/test_contact.py.
"""
import dolfinx_solver  # noqa: F401  (before dolfinx)

import numpy as np
import pytest
from mpi4py import MPI

from fem_baselines.fracture_faces import fracture_faces, nodal_interface, touching
from fem_baselines.hydraulic_fracture import FemHydraulicFractureModel
from fem_baselines.poroelasticity import triangle_mesh
from rkfx.conditions import Displacement, Pressure
from rkfx.errors import InputError
from rkfx.fracture.contact import SLIP, STICK, FrictionalContact
from rkfx.geometry.particles import cut_triangulation, structured
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.hydraulic_fracture import FracturingRock
from rkfx.solvers.integrate import integrate
from rkfx.solvers.newmark import damped

SEGMENT = np.array([[0.0, 0.0], [1.0, 1.0]])
N_C = np.array([1.0, -1.0]) / np.sqrt(2.0)  # the right-hand normal of the segment: n_C of the faces
T_C = np.array([-N_C[1], N_C[0]])
LAW = FrictionalContact(k_N=1e3, k_T=5e2, mu=0.7)
# light and permeable, so 0.5 s is quasi-static and drained; no damage at these strains
ROCK = FracturingRock(1e4, 0.25, 1e-3, 1e-3, 0.2, 1e4, 1e4, 1e4, 1e12, 1e3, 1e3)


# The outer sides as markers: the face copies at the fracture's ends lie a gap (1e-8 h) off the
# sides, beyond the bounding-box tolerance of the side names.
SIDES = [lambda x: x[:, 1] < 1e-6, lambda x: x[:, 0] > 1 - 1e-6, lambda x: x[:, 1] > 1 - 1e-6,
         lambda x: x[:, 0] < 1e-6]


@pytest.fixture(scope="module")
def cut_square():
    p, _ = cut_triangulation(structured(1.0, 1.0, 13, 13), [SEGMENT])
    return p


def test_the_faces_of_a_cut_pair_up_node_to_node(cut_square):
    f = fracture_faces(cut_square, "crack", SEGMENT)
    assert f.num_pairs == 13  # every vertex of the diagonal, its ends on the boundary included
    np.testing.assert_allclose(f.weights.sum(), np.sqrt(2.0), rtol=1e-9)
    np.testing.assert_allclose(f.normal, np.broadcast_to(N_C, f.normal.shape))
    assert np.all((f.plus - f.minus) @ N_C > 0) and np.abs(f.plus - f.minus).max() < 1e-8
    rows = nodal_interface(f, cut_square.x, cut_square.x)
    u = np.zeros((cut_square.num_nodes, 2))
    u[(cut_square.x @ N_C) > 0] = [3.0, 1.0]  # the + side moved: the jump at every pair
    np.testing.assert_allclose(rows.jump_normal @ u.ravel(), np.dot([3.0, 1.0], N_C))
    np.testing.assert_allclose(rows.jump_tangent @ u.ravel(), np.dot([3.0, 1.0], T_C))
    tri = cut_square.x[cut_square.triangles]
    assert touching(f, tri).size == 2 * 12 + 2 * 11  # the triangles along both faces
    with pytest.raises(InputError, match="no boundary part 'fault'"):
        fracture_faces(cut_square, "fault", SEGMENT)


def _stress(s_n: float, tau: float) -> np.ndarray:
    """sigma with sigma n_C = -s_n n_C + tau t_C and sigma_tt = -0.4 s_n, as a 2 x 2 tensor."""
    return -s_n * np.outer(N_C, N_C) + tau * (np.outer(N_C, T_C) + np.outer(T_C, N_C)) - 0.4 * s_n * np.outer(T_C, T_C)


@pytest.mark.parametrize("state", ["stick", "slip"])
def test_a_confined_fractured_rock_drains_to_the_exact_state(cut_square, state):
    """The boundary prescribes the displacement that is linear on each side with the jump the
    law balances; the pore pressure of loading drains away and the FEM reaches the exact state
    (P1 holds it exactly)."""
    p = cut_square
    s_n = 2.0
    tau = 0.5 if state == "stick" else LAW.mu * s_n
    slid = tau / LAW.k_T if state == "stick" else 10 * tau / LAW.k_T  # slip: far beyond what sticking allows
    jump = -s_n / LAW.k_N * N_C + slid * T_C
    sig = _stress(s_n, tau)
    e = np.linalg.solve(ElasticMaterial(ROCK.E, ROCK.nu).voigt(2), [sig[0, 0], sig[1, 1], sig[0, 1]])
    grad = np.array([[e[0], e[2] / 2], [e[2] / 2, e[1]]])

    def exact(x, t=1.0):
        return min(t / 0.05, 1.0) * (x @ grad.T + ((x @ N_C) > 0)[:, None] * jump[None, :])

    model = FemHydraulicFractureModel(triangle_mesh(p.x, p.triangles, MPI.COMM_SELF), ROCK,
                                      [Displacement(s, exact) for s in SIDES] + [Pressure(s) for s in SIDES],
                                      contact=LAW, fracture=fracture_faces(p, "crack", SEGMENT))
    run = integrate(damped(0.9, 1.0), model, np.linspace(0.0, 0.5, 21))
    u = run.state.x[:model.n_u].reshape(-1, 2)
    want = exact(model.u_nodes)
    # Slip is history: while the loading's pore pressure drains, the faces slide a little
    # differently (3.7e-7 of u left over, the same after twice the drainage time); stick is exact.
    assert np.abs(u - want).max() <= (1e-7 if state == "stick" else 1e-6) * np.abs(want).max()
    assert np.abs(run.state.x[model.n_u:]).max() <= 1e-6 * s_n
    f = model.fracture
    np.testing.assert_allclose(f.trial.pressure, s_n, rtol=1e-6)
    np.testing.assert_allclose(np.abs(f.trial.shear), tau, rtol=1e-6 if state == "stick" else 1e-3)
    if state == "stick":
        assert (f.status() == STICK).all()
    else:  # slid to the limit while loading; the drainage after it unloads most points into stick
        # (shear 2e-4 below the limit)
        assert np.isin(f.status(), [STICK, SLIP]).all() and (f.status() == SLIP).any()
        np.testing.assert_allclose(f.slip, slid - tau / LAW.k_T, rtol=1e-4)
    # the elements along the faces carry the closed fracture's k_f0 / 100, the others the rock's
    k = model.permeability(model.committed, model.strain)
    cover = f.cover
    assert cover.size == 46 and np.allclose(k[cover], 0.01 * ROCK.mobility * np.eye(2))
    assert np.allclose(np.delete(k, cover, axis=0), ROCK.mobility * np.eye(2))
    saved = model.state()
    model.fracture.slip[:] = 1.0
    model.restore(saved)
    np.testing.assert_array_equal(model.fracture.slip, saved["contact_slip"])


def test_the_contact_needs_its_faces_and_p1(cut_square):
    mesh = triangle_mesh(cut_square.x, cut_square.triangles, MPI.COMM_SELF)
    sides = [Displacement(SIDES[3], 0.0), Pressure(SIDES[3])]
    with pytest.raises(InputError, match="needs both contact="):
        FemHydraulicFractureModel(mesh, ROCK, sides, contact=LAW)
    with pytest.raises(InputError, match="P1"):
        FemHydraulicFractureModel(mesh, ROCK, sides, contact=LAW, fracture=fracture_faces(cut_square, "crack", SEGMENT),
                                  element="taylor-hood", mass="consistent")
