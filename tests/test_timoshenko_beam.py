"""Timoshenko's cantilever: the exact solution is one, and MSCNI converges to it at second order."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.integration.norms import relative_errors
from rkfx.models.elastostatics import solve_plane_strain
from verification.timoshenko_beam import TimoshenkoBeam


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_exact_solution_is_consistent(plane):
    beam = TimoshenkoBeam(plane=plane)
    rng = np.random.default_rng(0)
    x = np.column_stack([rng.uniform(0, beam.L, 50), rng.uniform(-beam.D / 2, beam.D / 2, 50)])
    # The gradient is the derivative of the displacement.
    step = 1e-5
    for j in range(2):
        dx = np.zeros(2)
        dx[j] = step
        fd = (beam.displacement(x + dx) - beam.displacement(x - dx)) / (2 * step)
        np.testing.assert_allclose(beam.gradient(x)[:, :, j], fd, rtol=1e-7, atol=1e-12)
    # The stress is the material's law of that gradient.
    g = beam.gradient(x)
    eps = np.column_stack([g[:, 0, 0], g[:, 1, 1], g[:, 0, 1] + g[:, 1, 0]])
    np.testing.assert_allclose(eps @ beam.material().D().T, beam.stress(x), rtol=1e-9, atol=1e-9 * beam.P)
    # Free top and bottom; the end shear has resultant P and no moment.
    y = np.linspace(-beam.D / 2, beam.D / 2, 2001)
    end = beam.traction(np.column_stack([np.full_like(y, beam.L), y]), np.tile([1.0, 0.0], (len(y), 1)))
    assert np.trapezoid(end[:, 1], y) == pytest.approx(beam.P, rel=1e-6)
    assert abs(np.trapezoid(end[:, 0] * y, y)) < 1e-9 * beam.P * beam.D
    top = beam.traction(np.array([[10.0, beam.D / 2]]), np.array([[0.0, 1.0]]))
    np.testing.assert_allclose(top, 0.0, atol=1e-9)
    e = beam.E if plane == "stress" else beam.E / (1 - beam.nu**2)
    assert beam.tip_deflection() > beam.P * beam.L**3 / (3 * e * beam.inertia)  # bending, plus shear


def test_mscni_converges_on_the_beam():
    beam = TimoshenkoBeam()
    h, l2, h1 = [], [], []
    for nx, ny in ((17, 5), (33, 9), (65, 17)):
        p = beam.nodes(nx, ny)
        sol = solve_plane_strain(p, beam.material(), beam.conditions(), rule="mscni")
        err = relative_errors(p, sol.rk, sol.coefficients, beam.displacement, beam.gradient)
        h.append(beam.L / (nx - 1))
        l2.append(err["l2"])
        h1.append(err["h1"])
    rate = lambda e: np.log(np.array(e[:-1]) / e[1:]) / np.log(np.array(h[:-1]) / h[1:])  # noqa: E731
    print(f"\nbeam L2 {np.round(l2, 6)} rates {np.round(rate(l2), 2)}; H1 {np.round(h1, 5)} rates {np.round(rate(h1), 2)}")
    assert np.all(rate(l2) >= 1.8) and np.all(rate(h1) >= 0.9)


def test_auto_solver_switches_to_cg_gamg_above_the_direct_limit():
    """solver="auto": MUMPS on a small beam, CG + GAMG (rigid-body modes, GAMG_THRESHOLD) above
    AUTO_DIRECT_MAX_DOFS, in a few iterations and with MUMPS's displacements to the solver's
    tolerance; the transformation method's saddle point stays direct; a bad name is refused."""
    pytest.importorskip("petsc4py")
    from rkfx.models.elastostatics import AUTO_DIRECT_MAX_DOFS, choose_solver  # noqa: PLC0415

    beam = TimoshenkoBeam()
    small = solve_plane_strain(beam.nodes(33, 9), beam.material(), beam.conditions())
    assert small.linear["solver"] == "mumps" and small.n_dofs <= AUTO_DIRECT_MAX_DOFS
    p = beam.nodes(161, 41)
    auto = solve_plane_strain(p, beam.material(), beam.conditions())
    direct = solve_plane_strain(p, beam.material(), beam.conditions(), solver="mumps")
    assert auto.n_dofs > AUTO_DIRECT_MAX_DOFS and auto.linear["solver"] == "cg-gamg"
    assert auto.linear["reason"] == "CONVERGED_RTOL" and 3 <= auto.linear["iterations"] <= 20
    scale = np.abs(direct.coefficients).max()
    assert np.abs(auto.coefficients - direct.coefficients).max() <= 1e-6 * scale
    assert choose_solver("auto", 10**6, "transformation", "mscni") == "mumps"
    assert choose_solver("auto", 10**6, "nitsche", "dni") == "mumps"
    with pytest.raises(InputError, match="unknown linear solver 'amg'"):
        solve_plane_strain(p, beam.material(), beam.conditions(), solver="amg")
