"""Convergence of 3-D MSCNI on a manufactured elastic solution, unstructured gmsh tetrahedra of a
cube and of a non-convex L-shaped block, three refinements (mesh sizes 0.2, 0.1, 0.05).

Rates are pairwise, against h = (V / N)^(1/3). The support is a = 1.75 h_I (h_I the mean edge
length at the node): at 1.5 h_I the L2 rate of the coarsest pairs dips to 1.76-1.77 on these
pre-asymptotic levels (it reaches 1.90 from 7,434 to 20,785 nodes), see docs/three_d.md.
"""
import numpy as np
import pytest

from rkfx.conditions import Displacement
from rkfx.geometry.gmsh_nodes import from_gmsh_3d, scratch_model
from rkfx.geometry.gmsh_solids import box, l_block
from rkfx.integration.norms import relative_errors
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_elasticity
from verification.manufactured import SineField3D

MATERIAL = ElasticMaterial(E=1.0, nu=0.3)
FIELD = SineField3D(MATERIAL.lame_lambda, MATERIAL.shear_modulus)
SIZES = (0.2, 0.1, 0.05)
SUPPORT = 1.75


def study(builder):
    rows = []
    for size in SIZES:
        with scratch_model("convergence3d") as m:
            builder(mesh_size=size, model=m)
            p = from_gmsh_3d(m)
        bcs = [Displacement(name, lambda x, t: FIELD.displacement(x)) for name in p.boundary_names]
        sol = solve_elasticity(p, MATERIAL, bcs, body_force=FIELD.body_force, rule="mscni", support_factor=SUPPORT)
        err = relative_errors(p, sol.rk, sol.coefficients, FIELD.displacement, FIELD.gradient)
        rows.append(((p.volume() / p.num_nodes) ** (1 / 3), p.num_nodes, err["l2"], err["h1"]))
    h, n, l2, h1 = map(np.array, zip(*rows))
    rate = lambda e: np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])  # noqa: E731
    return n, l2, h1, rate(l2), rate(h1)


@pytest.mark.parametrize("builder", [box, l_block], ids=["cube", "l_block"])
def test_mscni_converges_at_second_order_in_l2(builder):
    n, l2, h1, r_l2, r_h1 = study(builder)
    print(f"\n{builder.__name__}: nodes {n}\n  L2 {l2} rates {np.round(r_l2, 2)}\n  H1 {h1} rates {np.round(r_h1, 2)}")
    assert np.all(r_l2 >= 1.8), r_l2
    assert r_h1[-1] >= 0.9, r_h1
    assert l2[-1] <= 0.02 and h1[-1] <= 0.1
