"""Longer verification studies (``make test-slow``): finer refinements than the default suite."""
import numpy as np
import pytest

from conftest import l_shape
from rkfx.conditions import Displacement
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.models.elastostatics import solve_plane_strain
from rkfx.integration.norms import relative_errors
from verification.manufactured import SineField

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("rule, support_factor", [("mscni", 1.5), ("scni", 2.5)])
def test_rates_on_the_l_shape_over_five_levels(rule, support_factor):
    """Non-convex domain, 5 gmsh refinements down to ~25,000 nodes: pairwise rates."""
    material = ElasticMaterial(1.0, 0.3)
    field = SineField(material.lame_lambda, material.shear_modulus)
    h, l2, h1 = [], [], []
    for size in (0.2, 0.1, 0.05, 0.025, 0.0125):
        p = l_shape(size)
        bcs = [Displacement(s, lambda x, t: field.displacement(x)) for s in p.boundary_names]
        sol = solve_plane_strain(p, material, bcs, body_force=field.body_force, rule=rule,
                                 support_factor=support_factor)
        err = relative_errors(p, sol.rk, sol.coefficients, field.displacement, field.gradient)
        h.append(np.sqrt(p.area() / p.num_nodes))
        l2.append(err["l2"])
        h1.append(err["h1"])
    h, l2, h1 = map(np.array, (h, l2, h1))
    r_l2 = np.log(l2[:-1] / l2[1:]) / np.log(h[:-1] / h[1:])
    r_h1 = np.log(h1[:-1] / h1[1:]) / np.log(h[:-1] / h[1:])
    print(f"\n{rule}: L2 {l2} rates {np.round(r_l2, 2)}\n  H1 {h1} rates {np.round(r_h1, 2)}")
    assert np.all(r_l2 >= 1.8) and np.all(r_h1 >= 0.9)


def test_plate_with_hole_default_study(tmp_path):
    """The demo's full 4-level study: MSCNI rates and the stress concentration converge."""
    import json

    from rkfx.cases import plate_with_hole

    plate_with_hole.main(["--method", "rkpm", "--out", str(tmp_path)])
    runs = json.loads((tmp_path / "results.json").read_text())["runs"]
    errs = [r["errors"] for r in runs if r["method"] == "rkpm-mscni"]
    assert len(errs) == 4
    assert errs[-1]["rate_l2"] >= 1.8 and errs[-1]["rate_h1"] >= 0.9
    assert errs[-1]["sxx_hole_err"] < 0.01
