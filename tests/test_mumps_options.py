"""MUMPS controls given as PETSc options under the solvers' prefix (``-rkfx_mat_mumps_icntl_<i>``)
reach the factorization, as ``rkfx.linalg.petsc.make_ksp`` documents."""
import dolfinx_solver  # noqa: F401  (before petsc4py)
import numpy as np
import scipy.sparse as sp
from petsc4py import PETSc

from rkfx.linalg.linear_solver import linear_solver


def test_a_prefixed_mumps_control_reaches_the_factorization():
    a = (sp.random(300, 300, 0.03, random_state=0) + 10.0 * sp.eye(300)).tocsr()
    b = np.arange(300.0)
    options = PETSc.Options()
    options["rkfx_mat_mumps_icntl_7"] = 2  # the AMF ordering instead of the default choice
    try:
        ls = linear_solver(a)
        x = ls.solve(b)
        ordering = ls.ksp.getPC().getFactorMatrix().getMumpsIcntl(7)
        ls.destroy()
    finally:
        options.delValue("rkfx_mat_mumps_icntl_7")
    assert ordering == 2
    assert np.abs(a @ x - b).max() <= 1e-10 * np.abs(b).max()
