"""Benchmark: wall time of Kalthoff's impact problem by the damage particle method through 80 µs.

The regularized model of ``rkfx.cases.kalthoff`` with tracking on at ``--nodes`` particles per
side (450: 450 x 451 = 202,950 particles, h = 0.1 / 449 m, the seed's finest model has
202,500). Reported: the set-up (grid, RK rows with the crack, cells, B~), the time stepping
(central differences with the damage update of every particle, tracking, projections and
energy bookkeeping; JIT compilation excluded by a warm-up run), steps and time per step, and
the split of one step between the two sparse products over the subcell rows (the strains:
cell strains and MSCNI differences; the force), the damage kernels and the rest, measured on
the final state. For the two products: the bytes each must move, the bandwidth that makes,
its ratio to the machine's STREAM triad (``bench/stream.py``, measured in the same process),
and their time on one thread, which tells a memory-bound product (no faster on two threads)
from a compute-bound one (twice as fast). On the uniform grid the interior products run as
lattice stencils (``rkfx.assembly.lattice_stencil``); ``--sparse`` runs the same rows through
the sparse products instead, for comparison (the same results bit for bit).

Usage: python bench/kalthoff_speed.py [--nodes 450] [--t-end 8e-5] [--sparse]
The last line reads ``<N> particles: <seconds> s for <T> us``.
"""
import argparse
import dataclasses
import time

import numba
import numpy as np
from stream import bandwidth


def product_bytes(rows, num_subcells: int, num_nodes: int) -> int:
    """The bytes one sparse product over ``rows`` (the subcell rows or their transpose) moves
    at the least: its indices, values and row pointers once, the three strains or loads of
    each subcell once, the two coefficients or forces of each node once (the gathers hit the
    caches)."""
    return rows.indices.nbytes + rows.data.nbytes + rows.indptr.nbytes + 24 * num_subcells + 16 * num_nodes


def stencil_bytes(stab, num_nodes: int) -> tuple[int, int]:
    """The bytes the strains and the force move at the least with lattice stencils
    (``rkfx.assembly.lattice_stencil``): strains read d (16 B a node) and write its two
    components apart and read them back (32 B), write the cell strains (24 B a particle) and
    the differences (24 B a subcell) reading A_C / A_L (8 B); the force reads the nodal
    stresses, damage and volume (40 B a particle), the differences, A_C / A_L and eps_p A_C
    (40 B a subcell), writes the loads slot by slot and reads them back (48 B a subcell) and
    writes the force (16 B a node); the sparse rows and nodes move what a sparse product does."""
    st, rows = stab.stencil, stab.rows
    m = len(stab.owner)
    sparse_entries = int(np.sum(rows.indptr[st.sparse_rows + 1] - rows.indptr[st.sparse_rows]))
    t = stab.rows_t
    node_entries = int(np.sum(t.indptr[st.sparse_nodes + 1] - t.indptr[st.sparse_nodes]))
    strains = 48 * num_nodes + 24 * num_nodes + 32 * m + 20 * sparse_entries
    force = 40 * num_nodes + 88 * m + 16 * num_nodes + 20 * node_entries
    return strains, force


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nodes", type=int, default=450, help="particles per side")
    ap.add_argument("--t-end", type=float, default=80e-6, help="end time [s]")
    ap.add_argument("--sparse", action="store_true", help="sparse products instead of the lattice stencils")
    args = ap.parse_args(argv)

    from rkfx.fracture import damage as dm
    from rkfx.cases import _dynamic_fracture as dyn
    from rkfx.cases import kalthoff as k
    from rkfx.models.damage_dynamics import DamageForce, damage_field
    from rkfx.memory import reuse_freed_memory
    from rkfx.warmup import warm_up

    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    k.run(methods=("rkpm",), h=k.spacings([40]), unregularized_h=[], no_tracking_h=[], fem_h=[], nonlocal_h=[],
          t_end=5e-6)  # compile the step kernels
    prm = {name: spec.default for name, spec in k.PARAMS.items()}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
    t0 = time.perf_counter()
    pl, track, model = k.setup(args.nodes, material, prm)
    conditions = k.model_conditions(pl, prm["v0"])
    setup = time.perf_counter() - t0
    if args.sparse:
        pl = dataclasses.replace(pl, op=dataclasses.replace(
            pl.op, stabilization=dataclasses.replace(pl.op.stabilization, stencil=None)))
    run = dyn.simulate("bench", pl, model, track, conditions, args.t_end)
    n = pl.p.num_nodes
    # Split of one step, on the final damage state.
    field = damage_field(model, track, pl.dt)
    for name, arr in field.arrays.items():
        if name in ("damage", "kappa", "normal"):
            arr[...] = getattr(run, name)
    field.damaged[:] = run.damage > 0
    field.allowed[:] = True
    force = DamageForce(pl.op, model, field, track, pl.dt)
    d = np.random.default_rng(0).standard_normal(2 * n) * 1e-9
    reps = 20
    t = time.perf_counter()
    for _ in range(reps):
        e, diff = pl.op.strains(d)
    t_strain = (time.perf_counter() - t) / reps
    c, damage = force.c, field.damage
    t = time.perf_counter()
    for _ in range(reps):
        pl.op.damaged_force(e, diff, c, damage)
    t_force = (time.perf_counter() - t) / reps
    t = time.perf_counter()
    for _ in range(reps):
        force(d)
    t_all = (time.perf_counter() - t) / reps
    per_step = run.wall_time_s / run.steps
    stab = pl.op.stabilization
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    t = time.perf_counter()
    for _ in range(reps // 4):
        e, diff = pl.op.strains(d)
    t_strain_1 = (time.perf_counter() - t) / (reps // 4)
    t = time.perf_counter()
    for _ in range(reps // 4):
        pl.op.damaged_force(e, diff, c, damage)
    t_force_1 = (time.perf_counter() - t) / (reps // 4)
    numba.set_num_threads(threads)
    stream = bandwidth(mib=256, reps=5)["triad"]
    m = len(stab.owner)
    if stab.stencil is None:
        b_strain, b_force = product_bytes(stab.rows, m, n), product_bytes(stab.rows_t, m, n)
    else:
        b_strain, b_force = stencil_bytes(stab, n)
        rows_cover, nodes_cover = stab.stencil.coverage
        print(f"lattice stencils: {100 * rows_cover:.1f}% of the subcell rows, {100 * nodes_cover:.1f}% of the "
              f"nodes' forces (the rest sparse); sparse products would move "
              f"{product_bytes(stab.rows, m, n) / 1e6:.0f} + {product_bytes(stab.rows_t, m, n) / 1e6:.0f} MB")
    print(f"particles {n:,} (grid {len(pl.xs)} x {len(pl.ys)}), subcells {len(stab.owner):,}, "
          f"nnz(grad N over subcells) {stab.rows.indices.size:,}, h = {1e6 * pl.h:.1f} um, dt = {1e9 * pl.dt:.2f} ns")
    print(f"set-up {setup:.1f} s; {run.steps} steps in {run.wall_time_s:.1f} s = {1e3 * per_step:.1f} ms per step")
    print(f"one step: strains {1e3 * t_strain:.1f} ms, force {1e3 * t_force:.1f} ms, damage force in all "
          f"{1e3 * t_all:.1f} ms (kernels and tracking {1e3 * (t_all - t_strain - t_force):.1f} ms), "
          f"rest of the step {1e3 * (per_step - t_all):.1f} ms")
    for name, b, t2, t1 in (("strains", b_strain, t_strain, t_strain_1), ("force", b_force, t_force, t_force_1)):
        print(f"{name}: {b / 1e6:.0f} MB per step, {b / t2 / 1e9:.1f} GB/s = {b / t2 / 1e9 / stream:.2f} of the "
              f"stream triad ({stream:.1f} GB/s); {1e3 * t1:.1f} ms on 1 thread, {1e3 * t2:.1f} ms on {threads}")
    cracked = int((run.opening >= 0.5).sum())
    print(f"dissipated {run.history[-1, 1]:.0f} J/m, cracked particles (w / w_c >= 0.5) {cracked}, "
          f"energy balance error {run.energy_error:.1e}")
    print(f"{n} particles: {run.wall_time_s + setup:.1f} s for {1e6 * args.t_end:.0f} us")


if __name__ == "__main__":
    main()
