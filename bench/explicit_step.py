"""Benchmark: wall time of one explicit central-difference step with the SCNI internal force.

For each size, a uniform grid on a 0.1 m square (Kalthoff's plate, seed 4.3.2) with steel
(E = 1.9e11 Pa, nu = 0.3, rho = 8000 kg/m^3): the smeared strain operator B~ (the smoothed
gradient rows and their transpose, ``rkfx.assembly.smeared_strain.smeared_strain``) is built once (``setup``:
RK rows, nodal domains, B~; not part of the step); then central differences
(``rkfx.solvers.central_difference.run_explicit``) take steps with the
linear elastic force f_int = B~^T V D B~ d, a roller on the symmetry plane (bottom) and a
prescribed velocity on the lower half of the left edge (the impact), both by the lumped-mass
projection. ``f_int`` is the two sparse products alone (operator cache-warm, so a lower
bound); ``step`` everything (force, projections, updates, energy bookkeeping).

The projection of 80 microseconds of Kalthoff's problem on 202,500 nodes (h = 0.1/449 m, dt
from the CFL condition with C = 0.5) is steps x time per step.

Usage: python bench/explicit_step.py [--nodes 1e4 1e5 202500] [--steps 20] [--courant 0.5]
The last line printed reads ``<N> nodes: <seconds> s per step`` for the largest N.
"""
import argparse
import math
import time

import numpy as np

E, NU, RHO, SIDE = 1.9e11, 0.3, 8000.0, 0.1
KALTHOFF_T, KALTHOFF_NODES, IMPACT_V = 80e-6, 202_500, 16.5


def measure(num_nodes: int, steps: int, courant: float) -> dict:
    from rkfx.conditions import Displacement, Velocity
    from rkfx.materials.elasticity import ElasticMaterial
    from rkfx.assembly.smeared_strain import constraint, elastic_force, lumped_mass, smeared_strain, stable_time_step
    from rkfx.solvers.central_difference import ExplicitDynamics, run_explicit
    from rkfx.geometry.nodal_domains import nodal_domains
    from rkfx.geometry.particles import structured
    from rkfx.approximation.shape_functions import rk_approximation

    side = int(round(math.sqrt(num_nodes)))
    p = structured(SIDE, SIDE, side, side)
    mat = ElasticMaterial(E, NU)
    t0 = time.perf_counter()
    rk = rk_approximation(p.x, p.spacing)
    dom = nodal_domains(p)
    op = smeared_strain(p, rk, dom)
    f_int = elastic_force(op, mat.D())
    mass = lumped_mass(dom.area, RHO)
    roller = constraint(p, rk, [Displacement("bottom", 0.0, (1,))])
    impact = constraint(p, rk, [Velocity("left", lambda x, t: np.where(x[:, 1] < 0.5 * SIDE, IMPACT_V, 0.0), (0,))])
    dt = stable_time_step(p.spacing, mat, RHO, courant)
    problem = ExplicitDynamics(mass, f_int, dt, constraints=[roller, impact])
    setup = time.perf_counter() - t0
    d = np.random.default_rng(0).standard_normal(2 * p.num_nodes) * 1e-9
    f_int(d)
    reps = max(3, steps)
    t0 = time.perf_counter()
    for _ in range(reps):
        f_int(d)
    force = (time.perf_counter() - t0) / reps
    run_explicit(problem, 2)  # first call: projections, allocation
    t0 = time.perf_counter()
    res = run_explicit(problem, steps)
    per_step = (time.perf_counter() - t0) / steps
    return {"nodes": p.num_nodes, "nnz": op.rows.indices.size, "setup": setup, "f_int": force, "step": per_step,
            "dt": dt, "energy_error": res.relative_energy_error()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", nargs="+", type=float, default=[1e4, 1e5, KALTHOFF_NODES])
    ap.add_argument("--steps", type=int, default=20, help="steps timed per size")
    ap.add_argument("--courant", type=float, default=0.5, help="C of dt = C min(h) / c_d")
    args = ap.parse_args(argv)
    from rkfx.memory import reuse_freed_memory
    from rkfx.warmup import warm_up

    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    measure(400, 3, args.courant)  # compile the step kernels
    rows = [measure(int(n), args.steps, args.courant) for n in sorted(args.nodes)]
    print(f"{'nodes':>10} {'nnz(grad N)':>12} {'setup [s]':>10} {'f_int [ms]':>11} {'step [ms]':>10} "
          f"{'dt [ns]':>8} {'ns/node/step':>13}")
    for r in rows:
        print(f"{r['nodes']:>10,d} {r['nnz']:>12,d} {r['setup']:>10.2f} {1e3 * r['f_int']:>11.2f} "
              f"{1e3 * r['step']:>10.2f} {1e9 * r['dt']:>8.2f} {1e9 * r['step'] / r['nodes']:>13.1f}")
    # Kalthoff: 450 x 450 nodes on 0.1 m, h = 0.1 / 449 m.
    from rkfx.materials.elasticity import ElasticMaterial
    from rkfx.assembly.smeared_strain import dilatational_wave_speed

    c_d = dilatational_wave_speed(ElasticMaterial(E, NU), RHO)
    h = SIDE / 449
    dt = args.courant * h / c_d
    steps = math.ceil(KALTHOFF_T / dt)
    big = [r for r in rows if r["nodes"] == KALTHOFF_NODES]
    print(f"\nKalthoff (seed 4.3.2): c_d = {c_d:.1f} m/s, h = {1e6 * h:.2f} um, dt = C h / c_d = "
          f"{1e9 * dt:.2f} ns (C = {args.courant}), {KALTHOFF_T * 1e6:.0f} us = {steps} steps")
    if big:
        print(f"projected wall time: {steps} steps x {1e3 * big[0]['step']:.2f} ms = "
              f"{steps * big[0]['step']:.0f} s (elastic SCNI force; a damage update adds its own cost)")
    last = rows[-1]
    print(f"{last['nodes']} nodes: {last['step']:.4f} s per step")


if __name__ == "__main__":
    main()
