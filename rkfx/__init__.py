"""rkfx: reproducing kernel particle methods for geomechanics.

The numerical core (this package's top-level modules) needs only numpy, scipy and numba:

    particles        nodes, spacing, background triangulation, named boundaries
    gmsh_nodes       particles from gmsh models and .geo files (needs gmsh)
    nodal_domains    conforming median-dual cells, subcells, boundary segments
    grid_cells       rectangular Voronoi cells of tensor grids, with slits along cell faces
    shape_functions  RK shape functions and direct gradients (eqs. 3.17-3.25)
    quadrature       Gauss, DNI, SCNI and MSCNI rules as sparse rows (eqs. 3.55-3.56)
    operators        B^T D B w products: stiffness, diffusion, mass, loads
    boundary         boundary integration and essential conditions
    elasticity       the 2-D elastic law (plane strain or stress), principal directions
    elastostatics    plane-strain solver
    poroelasticity   equal-order u-p Biot solver: NI/SCNI with pressure projection (chapter 3)
    damage           damage particle method: Mazars strain, damage law, energy regularization (ch. 4)
    damage_law       Mazars' strain and the softening law compiled, shared by statics and dynamics
    cracks           pre-existing cracks: diffraction of the kernel supports round crack tips
    explicit         explicit models: smeared strain B~ (SCNI, MSCNI), lumped mass, stable step
    crack_tracking   candidate damage particles along crack segments (eq. 4.22)
    explicit_damage  damage particle method in explicit dynamics: compiled update, runs kept on disk
    linear_solver    factorized systems through PETSc when installed, else SciPy
    ranks            serial work under MPI: rank 0 runs it, every rank gets the result
    warmup           compile the kernels before timing

``rkfx.petsc`` (imported on purpose) hands the sparse operators to PETSc; ``rkfx.cases``
holds the runnable benchmarks (``python -m rkfx.cases.<name>``).
"""
__version__ = "0.1.0"
