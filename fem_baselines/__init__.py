"""dolfinx finite-element baselines run beside the RKPM solvers on the same geometry."""
