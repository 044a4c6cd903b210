"""Time stepping and nonlinear solves shared by every model: fields, the model protocol,
steppers, one Newton, checkpoints.

    fields         the unknowns of a model: named fields, components, time order, layout
    model          what a model gives a stepper: residual, tangent, mass, capacity,
                   essential conditions, history with trial/commit
    newton         the one nonlinear solve: Newton with optional backtracking line search
    newmark        Newmark for second-order fields with the generalized trapezoid for
                   first-order ones (eqs. 5.18-5.22; explicit when beta = theta = 0,
                   eqs. 6.37-6.41); the theta-method (backward Euler, Crank-Nicolson)
    central_difference  central differences with a lumped mass for explicit models:
                   projected essential conditions, prescribed velocities, energies
    quasi_static   load stepping with step cutting and dissipation control (snap-backs)
    path_following a displacement prescribed and the load factor found: past limit loads
    integrate      the time loop: step cutting, outputs, checkpoints and resume
    checkpoint     atomic checkpoint files
"""
