"""Benchmark: time to accuracy on Mandel's problem, RKPM SCNI+FPP against Taylor-Hood.

Seed parameters (E = 1e4, nu = 0, k = 1e-4, Lx = 20, Ly = 2, F = 40: c = 1, p0+ = 1). Every
resolution uses the same uniform time steps, Delta T_D = 2.5e-5 up to T_D = 0.05 (2,000 steps;
both solvers factorize once), so that backward Euler's error (~3e-5) stays below most of
the spatial errors compared. Error: the larger of the relative L2 errors of p along y = 0 at
T_D = 0.02 and 0.05. Wall time: assembly plus all time steps (kernels and forms compiled
before timing).

For every RKPM run the Taylor-Hood wall time at the same error is interpolated (log-log) from
the Taylor-Hood runs; the ratio RKPM / TH at matched error is printed (goal <= 1).

Usage: python bench/mandel_time_to_accuracy.py [--nx 21 41 81 161]
"""
import argparse

import numpy as np

import dolfinx_solver  # noqa: F401  (MPI before petsc4py)
from fem_baselines import poroelasticity as fb
from rkfx.conditions import Displacement, Pressure, split
from rkfx.geometry.particles import structured
from rkfx.models.poroelasticity import PoroMaterial, solve_biot
from rkfx.solvers.integrate import time_grid
from rkfx.memory import reuse_freed_memory
from rkfx.warmup import warm_up
from verification.mandel import Mandel

E, NU, K, LX, LY, F = 1.0e4, 0.0, 1.0e-4, 20.0, 2.0, 40.0
T_D = np.array([0.02, 0.05])
DT_D = 2.5e-5


def conditions(exact):
    """Rollers left and bottom, the rigid plate's displacement on top, drained right side: both solvers'."""
    return [Displacement("left", components=(0,)), Displacement("bottom", components=(1,)),
            Displacement("top", lambda xx, t: np.full(len(xx), exact.plate_displacement(t)), (1,)),
            Pressure("right")]


def rkpm(nx, ny, material, bcs, times, outputs, x):
    p = structured(LX, LY, nx, ny)
    kinds = split(bcs)
    sol = solve_biot(p, material, times, outputs, kinds[Displacement], kinds[Pressure], variant="scni+fpp")
    return sol.pressure(np.column_stack([x, 0 * x])), sol.wall_time_s, sol.n_dofs


def taylor_hood(nx, ny, material, bcs, times, outputs, x):
    mesh = fb.rectangle_mesh(np.linspace(0, LX, nx), np.linspace(0, LY, ny), "triangle")
    res = fb.solve_biot(mesh, E, NU, K, 1.0, 0.0, "taylor-hood", bcs, times, np.column_stack([x, 0 * x]), outputs)
    return res.p, res.wall_time_s, res.n_dofs


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nx", nargs="+", type=int, default=[21, 41, 81, 161])
    args = ap.parse_args(argv)
    material = PoroMaterial(E, NU, K)
    exact = Mandel(E, NU, K, LX, LY, F)
    outputs = T_D * LX**2 / exact.c
    times = time_grid(outputs, DT_D * LX**2 / exact.c)
    x = np.linspace(0.0, LX, 401)
    p_exact = np.array([exact.pressure(x, t) for t in outputs])
    bcs = conditions(exact)
    reuse_freed_memory()  # large temporaries reuse freed pages (rkfx.memory)
    warm_up()
    for solve in (rkpm, taylor_hood):  # compile forms / kernels outside the timings
        solve(11, 3, material, bcs, times[:3], times[2:3], x)
    rows = {"rkpm": [], "th": []}
    print(f"{len(times) - 1} time steps for every run\n")
    print(f"{'method':<14} {'nodes':>12} {'dofs':>8} {'wall [s]':>9} {'rel L2(p)':>10}")
    for nx in args.nx:
        ny = (nx - 1) // 10 + 1
        for key, solve in (("rkpm", rkpm), ("th", taylor_hood)):
            p_h, wall, dofs = solve(nx, ny, material, bcs, times, outputs, x)
            err = max(np.linalg.norm(a - b) / np.linalg.norm(b) for a, b in zip(p_h, p_exact))
            rows[key].append((err, wall))
            name = "RKPM SCNI+FPP" if key == "rkpm" else "Taylor-Hood"
            print(f"{name:<14} {f'{nx} x {ny}':>12} {dofs:>8} {wall:>9.2f} {err:>10.2e}", flush=True)
    th = np.array(sorted(rows["th"]))  # by error
    print("\nwall time at matched error (Taylor-Hood interpolated in log-log):")
    ratios = []
    for err, wall in rows["rkpm"]:
        if th[0, 0] <= err <= th[-1, 0]:
            t_th = np.exp(np.interp(np.log(err), np.log(th[:, 0]), np.log(th[:, 1])))
            ratios.append(wall / t_th)
            print(f"  error {err:.2e}: RKPM {wall:.2f} s, TH {t_th:.2f} s, ratio {wall / t_th:.2f}")
        else:
            print(f"  error {err:.2e}: RKPM {wall:.2f} s, outside the Taylor-Hood error range "
                  f"[{th[0, 0]:.2e}, {th[-1, 0]:.2e}]")
    if ratios:
        print(f"\nRKPM / TH wall time at matched error: {min(ratios):.2f} .. {max(ratios):.2f} (goal <= 1)")


if __name__ == "__main__":
    main()
