"""u-p solves at scale: displacement conditions by Nitsche's method (with the pore pressure in
the total traction), and GMRES preconditioned by the Schur-complement field split (GAMG on the
displacements, the fixed-stress Schur approximation factorized) against MUMPS."""
import dolfinx_solver  # noqa: F401  (before petsc4py)
import numpy as np
import pytest
import scipy.sparse as sp

from rkfx.conditions import Displacement, Pressure
from rkfx.errors import InputError
from rkfx.geometry.particles import structured
from rkfx.linalg.linear_solver import DisplacementSplit, linear_solver
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from verification.mandel import Mandel

LX, LY, F = 20.0, 2.0, 40.0


def _mandel(nu, nx, ny):
    material = PoroMaterial(1.0e4, nu, 1.0e-4)
    exact = Mandel(material.E, nu, material.k, LX, LY, F)
    bcs = [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
           Displacement("top", lambda x, t: np.full(len(x), exact.plate_displacement(t)), (1,))]
    return material, exact, structured(LX, LY, nx, ny), bcs


@pytest.mark.parametrize("nu", [0.0, 0.3])
def test_nitsche_displacements_give_mandel_as_collocation_does(nu):
    """The profiles at t_D = 0.05 and 0.2 are as close to the exact solution with Nitsche's
    terms as with collocation; at nu = 0.3 the slab's sides move, so the pore pressure's part
    of the traction on the rollers is exercised."""
    material, exact, p, bcs = _mandel(nu, 61, 7)
    h = LX / 60
    t_out = np.array([0.05, 0.2]) * LX**2 / exact.c
    times = time_grid(t_out, 0.05 * h**2 / exact.c, 1.6, hold=5)
    x = np.linspace(0.0, LX, 201)
    pts = np.column_stack([x, np.zeros_like(x)])
    errors = {}
    for method in ("transformation", "nitsche"):
        sol = solve_biot(p, material, times, t_out, bcs, [Pressure("right")], bc_method=method)
        ph = sol.pressure(pts)
        errors[method] = [np.linalg.norm(ph[i] - exact.pressure(x, t)) / np.linalg.norm(exact.pressure(x, t))
                          for i, t in enumerate(t_out)]
    for col, nit in zip(errors["transformation"], errors["nitsche"]):
        assert nit < 0.02 and nit < 1.5 * col + 1e-3, errors


def test_fieldsplit_solves_as_mumps_in_a_few_iterations():
    material, exact, p, bcs = _mandel(0.0, 101, 11)
    times = 0.5 * (LX / 100) ** 2 / exact.c * np.arange(5)
    sols = {s: solve_biot(p, material, times, times[1:], bcs, [Pressure("right")], bc_method="nitsche", solver=s)
            for s in ("mumps", "fieldsplit")}
    a, b = sols["mumps"].P, sols["fieldsplit"].P
    assert np.abs(a - b).max() <= 1e-5 * np.abs(a).max()  # GMRES to a 1e-10 residual
    lin = sols["fieldsplit"].linear
    assert lin["solves"] == 4 and 4 * 2 <= lin["iterations"] <= 4 * 60, lin
    assert sols["mumps"].linear == {"solver": "mumps", "solves": 4, "iterations": 4}


def test_fieldsplit_refuses_what_it_cannot_precondition():
    material, exact, p, bcs = _mandel(0.0, 11, 3)
    with pytest.raises(InputError, match="bc_method='nitsche'"):
        solve_biot(p, material, [0.0, 1.0], [1.0], bcs, [Pressure("right")], solver="fieldsplit")
    a = sp.identity(6, format="csr")
    with pytest.raises(InputError, match="split=DisplacementSplit"):
        linear_solver(a, solver="fieldsplit")
    with pytest.raises(InputError, match="split= is for solver='fieldsplit'"):
        linear_solver(a, solver="mumps", split=DisplacementSplit(np.zeros((2, 2))))


def test_auto_takes_the_field_split_above_the_switch(monkeypatch):
    """solver="auto": MUMPS below ``U_P_AUTO_DIRECT_MAX_DOFS`` unknowns, the field split above
    with Nitsche's conditions in 2-D (the same pressures to GMRES's tolerance); collocated
    conditions and 3-D stay direct."""
    from rkfx.models import poroelasticity as up

    assert up.choose_solver("auto", 10 * up.U_P_AUTO_DIRECT_MAX_DOFS, "nitsche", 2) == "fieldsplit"
    assert up.choose_solver("auto", up.U_P_AUTO_DIRECT_MAX_DOFS, "nitsche", 2) == "mumps"
    assert up.choose_solver("auto", 10 * up.U_P_AUTO_DIRECT_MAX_DOFS, "transformation", 2) == "mumps"
    assert up.choose_solver("auto", 10 * up.U_P_AUTO_DIRECT_MAX_DOFS, "nitsche", 3) == "mumps"
    with pytest.raises(InputError, match="unknown u-p solver 'gmres'"):
        up.choose_solver("gmres", 10, "nitsche", 2)
    material, exact, p, bcs = _mandel(0.0, 61, 7)
    times = (LX / 60) ** 2 / exact.c * np.arange(4)
    run = lambda solver: solve_biot(p, material, times, times[1:], bcs, [Pressure("right")],  # noqa: E731
                                    bc_method="nitsche", solver=solver)
    direct = run("auto")
    monkeypatch.setattr(up, "U_P_AUTO_DIRECT_MAX_DOFS", 100)
    split = run("auto")
    assert direct.linear["solver"] == "mumps" and split.linear["solver"] == "fieldsplit"
    assert split.linear["iterations"] > split.linear["solves"]
    assert np.abs(split.P - direct.P).max() <= 1e-5 * np.abs(direct.P).max()
