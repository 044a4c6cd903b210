"""RK u-p solver: boundary fluxes, gravity, operators and input checks."""
import numpy as np
import pytest

from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import structured
from rkfx.conditions import Displacement, Flux, Pressure
from rkfx.models.poroelasticity import NodalFields, PoroMaterial, biot_operators, fpp_parameter, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.approximation.shape_functions import rk_approximation

H = 4.0
MATERIAL = PoroMaterial(E=1.0e6, nu=0.25, k=1.0e-6)
COLUMN = structured(1.0, H, 5, 17)
FIXED = [Displacement("bottom"), Displacement("left", components=(0,)), Displacement("right", components=(0,))]
DRAINED_TOP = [Pressure("top")]
AXIS = np.column_stack([np.full(9, 0.5), np.linspace(0.0, H, 9)])
LONG = time_grid([1.0e8], 10.0, 2.0, hold=2)  # to steady state


@pytest.mark.parametrize("variant, rtol", [("scni+fpp", 1e-6), ("ni", 1e-2)])
def test_inflow_through_the_bottom_gives_a_linear_steady_pressure(variant, rtol):
    """Outward flux q.n = -v at the bottom, p = 0 on top: Darcy gives p = v (H - z) / k.

    SCNI is integration-consistent, so the linear field is exact; NI is only close.
    """
    v = 1.0e-7
    sol = solve_biot(COLUMN, MATERIAL, LONG, [LONG[-1]], FIXED, DRAINED_TOP,
                     fluxes=[Flux("bottom", lambda x, t, n: np.full(len(x), -v))], variant=variant)
    p = sol.pressure(AXIS)[0]
    assert np.allclose(p, v * (H - AXIS[:, 1]) / MATERIAL.k, rtol=rtol, atol=rtol * v * H / MATERIAL.k)


def test_gravity_gives_hydrostatic_pressure_and_settles_under_self_weight():
    rho_f, rho, g = 1000.0, 2000.0, 9.81
    sol = solve_biot(COLUMN, MATERIAL, LONG, [LONG[-1]], FIXED, DRAINED_TOP, gravity=(0.0, -g), density=rho,
                     fluid_density=rho_f)
    p = sol.pressure(AXIS)[0]
    assert np.allclose(p, rho_f * g * (H - AXIS[:, 1]), rtol=1e-6, atol=1e-6 * rho_f * g * H)
    # Drained oedometric settlement of the top under the buoyant weight: (rho - rho_f) g H^2 / (2 K_v);
    # the displacement is quadratic in depth, so a linear basis is within O(h^2) (0.07% here).
    kv = MATERIAL.elastic.constrained_modulus
    u_top = sol.displacement(np.array([[0.5, H]]))[0, 0, 1]
    assert u_top == pytest.approx(-(rho - rho_f) * g * H**2 / (2 * kv), rel=3e-3)


def test_fpp_parameter_vanishes_in_the_drained_limit():
    h = np.array([0.1])
    c = MATERIAL.consolidation_coefficient
    assert fpp_parameter(MATERIAL, 1e-9 * h[0] ** 2 / c, h)[0] == pytest.approx(
        2.0 / MATERIAL.oedometric_storage_modulus * (1 + np.tanh(2.0)) / 2, rel=1e-6)
    assert fpp_parameter(MATERIAL, 0.5 * h[0] ** 2 / c, h)[0] == 0.0


def test_projection_rows_annihilate_constants():
    """S of eq. (3.60) has constants in its kernel (Pi reproduces them)."""
    p = structured(2.0, 1.0, 9, 5)
    rk = rk_approximation(p.x, p.spacing)
    for variant in ("scni+fpp", "ni+fpp"):
        ops = biot_operators(p, rk, nodal_domains(p), MATERIAL, variant)
        s = ops.stabilization(np.ones(p.num_nodes))
        assert np.abs(s @ np.ones(p.num_nodes)).max() < 1e-12 * abs(s).max()
        assert abs(s).max() > 0


def test_bad_input():
    with pytest.raises(InputError, match="mobility"):
        PoroMaterial(1.0, 0.2, k=0.0)
    with pytest.raises(InputError, match="Biot coefficient"):
        PoroMaterial(1.0, 0.2, k=1.0, alpha=1.5)
    with pytest.raises(InputError, match="unknown variant"):
        solve_biot(COLUMN, MATERIAL, np.array([0.0, 1.0]), [1.0], FIXED, variant="gauss")
    with pytest.raises(InputError, match="output time"):
        solve_biot(COLUMN, MATERIAL, np.array([0.0, 1.0]), [0.5], FIXED)
    with pytest.raises(InputError, match="no essential boundary conditions"):
        solve_biot(COLUMN, MATERIAL, np.array([0.0, 1.0]), [1.0])


def test_a_condition_on_u_y_takes_u_y_from_a_full_vector_value():
    """Value functions may return both components; a u_y condition must use the second."""
    from rkfx.assembly.boundary import collocation

    p = structured(1.0, 1.0, 4, 4)
    rk = rk_approximation(p.x, p.spacing)
    bc = Displacement("top", lambda x, t: np.column_stack([np.full(len(x), 7.0), np.full(len(x), -3.0)]), (1,))
    col = collocation(p, rk, [([bc], 0, 2)], 3 * p.num_nodes)
    assert np.all(col.values(p.x, 0.0) == -3.0)
    assert np.all(col.G.indices % 2 == 1)  # only u_y coefficients


class _Killed(Exception):
    pass


def _killed_after(count):
    """A progress wrapper that stops the run after ``count`` steps, as a kill would."""
    def wrap(steps):
        for i, s in enumerate(steps):
            if i == count:
                raise _Killed
            yield s
    return wrap


def test_a_killed_run_resumes_to_the_same_result(tmp_path):
    times = time_grid([2.0e4, 1.0e5], 1.0e3, 1.5, hold=2)
    top = [Displacement("top", lambda x, t: np.full(len(x), -1e-4 * min(t / 1e4, 1.0)), (1,))]
    args = (COLUMN, MATERIAL, times, [2.0e4, 1.0e5], FIXED + top, DRAINED_TOP)
    full = solve_biot(*args)
    with pytest.raises(_Killed):
        solve_biot(*args, checkpoint_every=3, checkpoint_dir=tmp_path, progress=_killed_after(7))
    resumed = solve_biot(*args, checkpoint_every=3, checkpoint_dir=tmp_path, resume=tmp_path)
    assert np.array_equal(resumed.P, full.P) and np.array_equal(resumed.U, full.U)
    again = solve_biot(*args, resume=tmp_path)  # the finished run's last checkpoint
    assert np.array_equal(again.P, full.P)
    with pytest.raises(InputError, match="same times"):
        solve_biot(COLUMN, MATERIAL, times * 2, [4.0e4], FIXED + top, DRAINED_TOP, resume=tmp_path)


def test_nodal_fields_equal_to_the_constants_change_nothing():
    rk = rk_approximation(COLUMN.x, COLUMN.spacing, 1.5)
    d = nodal_domains(COLUMN)
    n = COLUMN.num_nodes
    mat = PoroMaterial(E=1.0e6, nu=0.25, k=1.0e-6, alpha=0.8, S=1e-7)
    fields = NodalFields(D=np.tile(mat.elastic.D(), (n, 1, 1)), k=np.tile(mat.k * np.eye(2), (n, 1, 1)),
                         alpha=np.full(n, 0.8), S=np.full(n, 1e-7))
    a = biot_operators(COLUMN, rk, d, mat, "scni+fpp")
    b = biot_operators(COLUMN, rk, d, mat, "scni+fpp", fields=fields)
    for name in ("Kuu", "Kup", "Ks", "Kh"):
        x, y = getattr(a, name), getattr(b, name)
        assert abs(x - y).max() <= 1e-12 * abs(x).max(), name
    with pytest.raises(InputError, match="nodal field k has shape"):
        biot_operators(COLUMN, rk, d, mat, "scni+fpp", fields=NodalFields(k=np.ones(3)))


def test_a_permeability_per_particle_layers_the_column():
    """Two layers, k on top and k/4 below: under a steady inflow v the pressure gradient is
    four times steeper in the lower layer (series flow). The particles at z = H/2 belong to
    the top layer, so the layers meet at the lower side of their cells, z_i = H/2 - h/2, and
    p = v ((H - z_i) / k + 4 z_i / k) at the bottom (within the RK smoothing of the kink)."""
    v = 1.0e-7
    k = np.where(COLUMN.x[:, 1] >= H / 2 - 1e-9, MATERIAL.k, MATERIAL.k / 4)
    z_i = H / 2 - H / 32
    sol = solve_biot(COLUMN, MATERIAL, LONG, [LONG[-1]], FIXED, DRAINED_TOP, fields=NodalFields(k=k),
                     fluxes=[Flux("bottom", lambda x, t, n: np.full(len(x), -v))])
    p = sol.pressure(np.array([[0.5, 0.0], [0.5, 0.75 * H]]))[0]
    assert p[0] == pytest.approx(v * ((H - z_i) + 4 * z_i) / MATERIAL.k, rel=0.03)
    assert p[1] == pytest.approx(v * H / 4 / MATERIAL.k, rel=1e-3)
