"""rkfx: reproducing kernel particle methods for geomechanics.

The numerical core needs only numpy, scipy and numba. Its subpackages, in the order of the
data path (see docs/core.md):

    geometry        node sets and their nodal domains
        particles        nodes, spacing, background triangulation, named boundaries
        particles3d      3-D nodes with a tetrahedralization: tensor grids, jittered grids
        gmsh_nodes       particles from gmsh models and .geo files, 2-D and 3-D (needs gmsh)
        gmsh_solids      the 3-D benchmark solids as gmsh models: sphere octant, box, L-block
        gmsh_plates      2-D squares with embedded pre-existing fractures as gmsh models
        nodal_domains    conforming median-dual cells, subcells, boundary segments
        grid_cells       rectangular Voronoi cells of tensor grids, with slits along cell faces
        nodal_cells3d    3-D cells: median-dual cells of tetrahedra, box cells of grids (13 points)
        cells            the default nodal cells of a particle set, in either dimension
    approximation   the RK approximation
        kernel           cubic B-spline kernel
        neighbours       cell-list search of the supports covering a point (neighbours3d in 3-D)
        shape_functions  RK shape functions and direct gradients (eqs. 3.17-3.25); 3-D kernels in
                         shape_functions3d, reached through the same ``evaluate``
        diffraction      pre-existing cracks: diffraction of the kernel supports round crack tips
        sparse_rows      rows of shape-function values and gradients, and their combinations
    integration     integration rules as sparse rows
        quadrature       Gauss, DNI, SCNI and MSCNI rules (eqs. 3.55-3.56)
        nodal_rules3d    DNI, SCNI and MSCNI on 3-D cells (facet-smoothed gradients, 13-point rule)
        norms            error norms
    assembly        operators and conditions
        operators        B^T D B w products: stiffness, diffusion, mass, loads
        boundary         boundary integration, collocated conditions, Nitsche terms
        smeared_strain   the smeared strain of explicit SCNI, lumped mass, stable step (eq. 4.31-4.35)
        local_strain     one rank's share of the smeared strain: strains at its particles, forces on its nodes
        matrix_strain    strains B d and forces B^T (Sigma V) of a given matrix (FEM cells), whole or a rank's share
    materials       constitutive laws
        elasticity       the elastic law: 2-D (plane strain or stress) and 3-D, principal directions
        damage_law       Mazars' strain and the softening law compiled, shared by statics and dynamics
        crack_flow       flow in damaged particles: aperture, cubic law, anisotropic permeability (ch. 5)
    fracture        the damage particle method (chapter 4)
        damage           damage points: regularization by the cell chord (4.28), trial updates
        tracking         candidate damage particles along crack segments (eq. 4.22)
        history          trial and committed damage of implicit models, with tracking admissions
        contact          pre-existing fractures: penalty frictional contact (5.38)-(5.39), their flow
        closure          crack closure: a closed smeared crack carries compression across it
    models          what the steppers advance
        elastostatics    elastostatics in 2-D and 3-D
        poroelasticity   equal-order u-p Biot model: NI/SCNI with pressure projection (chapter 3),
                         in 2-D and 3-D
        damage_bar       the damaging bar under displacement control (chapter 4)
        damage_dynamics  the damage particle method in explicit dynamics, runs kept on disk
        damage_ranks     the same over MPI ranks: each rank steps its own particles
        hydro_damage     the u-p fields of damaged particles (chapter 5)
        hydraulic_fracture  the coupled u-p damage model with inertia for the Newmark stepper (chapter 5)
    solvers         fields, the model protocol, steppers, one Newton, checkpoints
    linalg          linear solves: factorizations through PETSc (``rkfx.linalg.petsc``) or SciPy
    parallel        work over MPI ranks
        partition        recursive coordinate bisection of the nodes into parts
        ownership        a rank's owned nodes and ghosts, the numbering with contiguous parts
        rows             a rank's contributions sent to the owners of their rows
        halo             ghost copies refreshed by a neighbour-only exchange
        ghost_counts     the halo of any partition counted serially (for the scaling model)
        ranks            serial work under MPI: rank 0 runs it, the others sleep until they get the result
        threads          numba threads per rank: each rank its share of its node's cores
    conditions      boundary and region conditions: one vocabulary, values of x and t
    errors          errors naming the culprit and the fix
    warmup          compile the kernels before timing

``rkfx.linalg.petsc`` (imported on purpose) hands the sparse operators to PETSc;
``rkfx.cases`` holds the runnable benchmarks (``python -m rkfx.cases.<name>``).
"""
__version__ = "0.1.0"
