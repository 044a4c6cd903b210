"""Linear solves: factorizations reused by the steppers, through PETSc (imported on purpose) or SciPy."""
