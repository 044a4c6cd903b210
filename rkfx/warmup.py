"""Compile (or load from numba's cache) every kernel of the core on a tiny problem.

Benchmarks and cases call ``warm_up()`` before timing so that reported wall times measure
the method, not the just-in-time compiler (about 20 s on a fresh install, well under a
second afterwards).
"""
from functools import cache


@cache
def warm_up() -> None:
    import numpy as np

    from rkfx.approximation.diffraction import cracks
    from rkfx.fracture.damage import DamageMaterial, cell_geometry, damage_model, initial_state, update
    from rkfx.materials.elasticity import ElasticMaterial
    from rkfx.assembly.smeared_strain import lumped_mass, smeared_strain
    from rkfx.models.damage_dynamics import run_damage
    from rkfx.geometry.nodal_domains import nodal_domains
    from rkfx.assembly.operators import stiffness
    from rkfx.linalg.symmetry import is_symmetric
    from rkfx.geometry.grid_cells import grid_domains
    from rkfx.geometry.particles import graded, structured
    from rkfx.integration.quadrature import integration_rules, mscni_stabilization, smoothed_gradients
    from rkfx.approximation.shape_functions import evaluate, rk_approximation

    p = structured(1.0, 1.0, 5, 5)
    d = nodal_domains(p)
    for order, c in ((1, 1.5), (2, 2.5)):
        rk = rk_approximation(p.x, p.spacing, c, order)
        evaluate(rk, p.x, gradients=True)
    rk = rk_approximation(p.x, p.spacing)
    s = smoothed_gradients(p, rk, d)
    mscni_stabilization(p, rk, d, s, with_values=True)
    k = stiffness(integration_rules("dni", p, rk, d), ElasticMaterial(1.0, 0.3).D())
    is_symmetric(k)
    crack = cracks([np.array([[0.0, 0.4], [0.5, 0.4]])])
    evaluate(rk_approximation(p.x, p.spacing, 1.75, cracks=crack), p.x, gradients=True)
    model = damage_model(DamageMaterial(1.0, 0.3, 1e-3, 1e-3), d.area, geometry=cell_geometry(p))
    run_damage("warm-up", smeared_strain(p, rk, d), lumped_mass(d.area, 1.0), 1e-3, model, None, (), 2e-3)
    update(model, initial_state(model), np.tile([2e-3, 0.0, 0.0], (p.num_nodes, 1)))  # the quasi-static law
    xs = np.linspace(0.0, 1.0, 16)  # a grid with an interior: the lattice stencils of an MSCNI step
    g = graded(xs, xs)
    op = smeared_strain(g, rk_approximation(g.x, g.spacing, 2.0), grid_domains(xs, xs), eps_p=1.0)
    e, diff = op.strains(np.zeros(2 * g.num_nodes))
    op.force(e, diff)
    op.damaged_force(e, diff, ElasticMaterial(1.0, 0.3).D(), np.zeros(g.num_nodes))
