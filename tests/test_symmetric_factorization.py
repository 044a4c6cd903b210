"""Symmetric systems on request factorized as L D L^T: the detection, the solution, and the u-p steps."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rkfx.linalg.symmetry import is_symmetric

petsc = pytest.importorskip("rkfx.linalg.petsc")


def _saddle_point(seed: int = 1) -> sp.csr_matrix:
    """[[K, B^T], [B, -C]]: symmetric indefinite, a tiny (1e-12) lower-right block."""
    rng = np.random.default_rng(seed)
    n, m = 300, 80
    k = sp.random(n, n, 0.02, random_state=seed)
    k = k + k.T + 10 * sp.eye(n)
    b = sp.random(m, n, 0.03, random_state=seed + 1)
    return sp.bmat([[k, b.T], [b, -sp.diags(rng.uniform(1e-12, 2e-12, m))]], format="csr")


def test_symmetry_is_judged_against_the_rows_scales():
    a = _saddle_point()
    assert is_symmetric(a)
    residue = a.tolil()
    residue[0, 7] = 1e-19  # round-off left on one side of a cancellation
    assert is_symmetric(residue.tocsr())
    skew = a.tolil()
    skew[0, 7] += 1e-9 * abs(a[0]).max()
    assert not is_symmetric(skew.tocsr())
    assert not is_symmetric(sp.random(4, 5, 0.5, random_state=0, format="csr"))


def test_symmetric_saddle_point_is_solved_by_ldlt_as_by_lu():
    a = _saddle_point()
    b = np.random.default_rng(2).standard_normal(a.shape[0])
    assert not petsc.LinearSolver(a).symmetric  # LU unless asked
    ls = petsc.LinearSolver(a, symmetric=True)
    assert ls.symmetric and ls.ksp.getPC().getType() == "cholesky"
    x = ls.solve(b)
    ls.destroy()
    reference = spla.spsolve(a.tocsc(), b)
    assert np.abs(x - reference).max() <= 1e-9 * np.abs(reference).max()
    skew = a.tolil()
    skew[0, 7] += 1e-3
    ls = petsc.LinearSolver(skew.tocsr(), symmetric=True)
    assert not ls.symmetric and ls.ksp.getPC().getType() == "lu"
    ls.destroy()


def test_up_steps_with_collocated_conditions_are_symmetric(monkeypatch):
    """Backward Euler on the Biot model: the storage rows weighted by -1/(du'/du) and the
    constraint rows by the matching weights make every step's matrix symmetric."""
    from rkfx.conditions import Displacement, Pressure  # noqa: PLC0415
    from rkfx.geometry.particles import structured  # noqa: PLC0415
    from rkfx.models.poroelasticity import PoroMaterial, solve_biot  # noqa: PLC0415
    from rkfx.solvers.integrate import time_grid  # noqa: PLC0415

    seen = []
    init = petsc.LinearSolver.__init__

    def spy(self, a, *args, **kwargs):
        init(self, a, *args, **kwargs)
        seen.append(is_symmetric(a))

    monkeypatch.setattr(petsc.LinearSolver, "__init__", spy)
    times = time_grid([1.0e3], 10.0, 2.0)
    fixed = [Displacement("bottom"), Displacement("left", components=(0,)), Displacement("right", components=(0,))]
    solve_biot(structured(1.0, 2.0, 5, 9), PoroMaterial(E=1.0e6, nu=0.25, k=1.0e-6), times, [times[-1]], fixed,
               [Pressure("top")], variant="scni+fpp")
    assert seen and all(seen), seen
