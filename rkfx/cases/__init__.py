"""Runnable benchmarks: ``python -m rkfx.cases.<name> [--quick] [--method rkpm|fem|both]
[--set NAME=VALUE ...] [--out DIR]``.

Each case module states its problem, parameters and units in its docstring and offers a pure
``run(...)``, a ``plot(results, out)`` and ``main(argv=None)``; the command-line interface,
results file (``DIR/results.json``, default ``results/<name>/``) and summary table they share
live in ``rkfx.cases._cli``.

    plate_with_hole   Kirsch plate with a circular hole under remote tension (plane strain):
                      RKPM (MSCNI / SCNI / DNI) and FEM (P1 / P2) on the same gmsh mesh, errors
                      and rates against the exact solution, stress concentration at the hole.
"""
