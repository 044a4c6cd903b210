"""Runnable benchmarks: ``python -m rkfx.cases.<name> [--quick] [--method rkpm|fem|both]
[--set NAME=VALUE ...] [--out DIR]``.

Each case module states its problem, parameters and units in its docstring and offers a pure
``run(...)``, a ``plot(results, out)`` and ``main(argv=None)``; the command-line interface,
results file (``DIR/results.json``, default ``results/<name>/``) and summary table they share
live in ``rkfx.cases._cli``. Before any work the command line calls the case's ``check`` (its
documented parameter ranges) and ``memory_need`` (an estimate of its peak memory, refused when
the machine cannot hold it), see ``rkfx.cases._preflight``.

    plate_with_hole   Kirsch plate with a circular hole under remote tension (plane strain):
                      RKPM (MSCNI / SCNI / DNI) and FEM (P1 / P2) on the same gmsh mesh, errors
                      and rates against the exact solution, stress concentration at the hole.
    mandel            Mandel's problem (seed 3.4.2): u-p variants, Taylor-Hood and Q1-Q1, the
                      Mandel-Cryer effect and the early-time oscillation study.
    terzaghi          Terzaghi's consolidation (seed 3.4.1): first-step profiles, refinement.
    strip_load        strip load on a consolidating half-space (seed 3.4.3), graded nodes.
    cracked_bar       damage particle method on a bar in tension (seed 4.3.1): regularized vs
                      unregularized, crack-band FEM, Gauss vs SCNI stress.
    kalthoff          Kalthoff's impact (seed 4.3.2): dynamic mixed-mode crack growth.
    crack_branching   a crack under tension that branches (seed 4.3.3).
    sneddon           Sneddon's pressurized crack (seed 5.3.1): a smeared RKPM crack against the
                      discrete FEM slit on the same fixed square.
    injection         fluid injection into a notched saturated plate (seed 5.3.2): hydraulic
                      fracture by the coupled damage particle method.
    wave_column       waves in a saturated u-p column (seed 6.4.1): explicit RKPM on NSNI and
                      DNI, Taylor-Hood with the trapezoid, the exact Laplace-domain solution.
    liakopoulos       unsaturated drainage of a sand column (seed 6.4.2): implicit RKPM u-p on
                      NSNI with the retention law against Taylor-Hood on the same grid.
    levee             a levee's initial state (seed 6.4.3, stage 1): steady seepage under gravity
                      through a seepage face, RKPM on gmsh nodes beside Taylor-Hood.
    granular_collapse dry granular columns collapsing on moving particles (chapter 6's large
                      deformation): run-outs against Lube et al. (2005), NSNI with and without
                      the VC correction.
    cryer             Cryer's poroelastic sphere (3-D, seed 3.3.2): RKPM SCNI + FPP on gmsh
                      tetrahedra against the exact solution, NI's early oscillation, Taylor-Hood.
"""
