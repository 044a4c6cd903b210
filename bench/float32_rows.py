"""Benchmark: what float32 storage of the shape-function rows would cost in accuracy.

Before the rows are stored in float32 (half their bytes: the largest arrays of an operator
build, ``docs/verification.md``), this measures the error that the rounding alone adds: every
value of the smoothed-gradient rows (SCNI cells, MSCNI subcells and differences) is rounded to
float32 and used in float64 from then on. Three variants:

* ``float64``: the rows as built;
* ``float32``: every value rounded;
* ``float32, zero-sum``: rounded, then the largest entry of each row set to minus the sum of
  the others, so that each row still sums to zero in float64 (a gradient row of a partition of
  unity reproduces constants exactly; rounding breaks that by about 1e-7 of its largest
  entry, and a rigid translation u then strains by 1e-7 u / h).

Problems: Timoshenko's beam (``verification.timoshenko_beam``, MSCNI, Nitsche, CG + GAMG) on
``--beam`` grids: the nodal L2 error and the tip deflection error against the exact solution;
and Kalthoff's regularized, tracked model (``rkfx.cases.kalthoff``) at ``--kalthoff``
particles per side through ``--t-end``: crack angle, dissipation, cracked particles and the
energy balance error.

Usage: python bench/float32_rows.py [--beam 257x65 1025x257] [--kalthoff 250] [--t-end 8e-5]
"""
import argparse
import contextlib
import time

import numpy as np

VARIANTS = ("float64", "float32", "float32, zero-sum")


def rounded(rows, variant: str):
    """``rows`` with their values rounded as ``variant`` says (a new SparseRows)."""
    from rkfx.approximation.sparse_rows import SparseRows  # noqa: PLC0415

    if rows is None or variant == "float64":
        return rows
    data = rows.data.astype(np.float32).astype(np.float64)
    if variant == "float32, zero-sum":
        for c in range(data.shape[1]):
            col = data[:, c]
            total = np.add.reduceat(col, rows.indptr[:-1]) if col.size else np.zeros(0)
            lengths = np.diff(rows.indptr)
            row = np.repeat(np.arange(rows.num_rows), lengths)
            # the largest |entry| of each row: the first of the entries sorted by (row, -|value|)
            order = np.lexsort((-np.abs(col), row))
            first = order[rows.indptr[:-1][lengths > 0]]
            col[first] -= total[lengths > 0]
    return SparseRows(rows.indptr, rows.indices, data, rows.num_cols)


@contextlib.contextmanager
def rows_as(variant: str):
    """Build the smoothed-gradient rows of implicit and explicit operators rounded as ``variant``."""
    import rkfx.assembly.smeared_strain as smeared  # noqa: PLC0415
    import rkfx.integration.quadrature as quadrature  # noqa: PLC0415

    built, sub_built = quadrature.smoothed_gradients, smeared.subcell_gradients

    def smoothed(*args, **kwargs):
        s = built(*args, **kwargs)
        return type(s)(rounded(s.cell, variant), s.node_values, rounded(s.cell_minus_subcell, variant), s.nodes,
                       s.subcells)

    def subcells(*args, **kwargs):
        cell, sub, order = sub_built(*args, **kwargs)
        return rounded(cell, variant), rounded(sub, variant), order

    # smeared_strain checks that the subcell strains average to the cell strains to 1e-9;
    # rounded rows do so only to ~1e-7 (the step reads the subcell rows alone).
    tol = smeared._PARTITION_TOL
    quadrature.smoothed_gradients, smeared.subcell_gradients = smoothed, subcells
    smeared._PARTITION_TOL = tol if variant == "float64" else 1e-6
    try:
        yield
    finally:
        quadrature.smoothed_gradients, smeared.subcell_gradients = built, sub_built
        smeared._PARTITION_TOL = tol


def beam(nx: int, ny: int, variant: str) -> dict:
    import dolfinx_solver  # noqa: F401, PLC0415
    from rkfx.approximation.shape_functions import evaluate  # noqa: PLC0415
    from rkfx.models.elastostatics import solve_plane_strain  # noqa: PLC0415
    from verification.timoshenko_beam import TimoshenkoBeam  # noqa: PLC0415

    b = TimoshenkoBeam()
    p = b.nodes(nx, ny)
    with rows_as(variant):
        sol = solve_plane_strain(p, b.material(), b.conditions(), rule="mscni", solver="cg-gamg")
    uh = evaluate(sol.rk, p.x).matrix(0) @ sol.coefficients
    ue = b.displacement(p.x)
    tip = np.flatnonzero((np.abs(p.x[:, 0] - b.L) < 1e-9) & (np.abs(p.x[:, 1]) < 1e-9))
    return {"nodes": p.num_nodes, "l2": float(np.linalg.norm(uh - ue) / np.linalg.norm(ue)),
            "tip": float(uh[tip[0], 1] / b.tip_deflection() - 1), "iterations": sol.linear["iterations"]}


def kalthoff(n: int, t_end: float, variant: str) -> dict:
    from rkfx.cases import _dynamic_fracture as dyn  # noqa: PLC0415
    from rkfx.cases import kalthoff as k  # noqa: PLC0415
    from rkfx.fracture import damage as dm  # noqa: PLC0415

    prm = {name: spec.default for name, spec in k.PARAMS.items()} | {"t_end": t_end}
    material = dm.DamageMaterial(prm["E"], prm["nu"], prm["ft"], prm["GF"], "strain")
    with rows_as(variant):
        pl, track, model = k.setup(n, material, prm)
    t0 = time.perf_counter()
    r = dyn.simulate(variant, pl, model, track, k.model_conditions(pl, prm["v0"]), t_end)
    angle = dyn.crack_angle(pl.p.x, r.opening, np.array([k.A1, k.A2]), prm["angle_radius"])
    return {"particles": pl.p.num_nodes, "angle": angle, "dissipated": float(r.history[-1, 1]),
            "cracked": int((r.opening >= dyn.CRACKED).sum()), "energy_error": r.energy_error,
            "wall": time.perf_counter() - t0}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--beam", nargs="*", default=["257x65", "1025x257"], help="nx x ny grids of the beam")
    ap.add_argument("--kalthoff", nargs="*", type=int, default=[250], help="Kalthoff particles per side")
    ap.add_argument("--t-end", type=float, default=80e-6, help="Kalthoff end time [s]")
    args = ap.parse_args(argv)
    from rkfx.memory import reuse_freed_memory  # noqa: PLC0415
    from rkfx.warmup import warm_up  # noqa: PLC0415

    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    for grid in args.beam:
        nx, ny = (int(v) for v in grid.split("x"))
        for variant in VARIANTS:
            r = beam(nx, ny, variant)
            print(f"beam {r['nodes']:,} nodes, {variant:18s}: nodal L2 error {r['l2']:.6e}, tip error {r['tip']:+.6e}, "
                  f"{r['iterations']} CG iterations", flush=True)
    for n in args.kalthoff:
        for variant in VARIANTS:
            r = kalthoff(n, args.t_end, variant)
            print(f"kalthoff {r['particles']:,} particles, {variant:18s}: angle {r['angle']:.2f} deg, dissipated "
                  f"{r['dissipated']:.2f} J/m, {r['cracked']} cracked, energy balance error {r['energy_error']:.2e} "
                  f"({r['wall']:.0f} s)", flush=True)


if __name__ == "__main__":
    main()
