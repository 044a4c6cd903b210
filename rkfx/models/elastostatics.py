"""Elastostatics with RK shape functions, in 2-D (plane strain or stress) and 3-D: assemble,
constrain, solve through PETSc.

One driver, ``solve_elasticity``, for both dimensions: 2-D particles (``rkfx.geometry.particles``)
take the median-dual cells and the rules of ``rkfx.integration.quadrature``, 3-D particles
(``rkfx.geometry.particles3d``) the cells of ``rkfx.geometry.nodal_cells3d`` and the rules of
``rkfx.integration.nodal_rules3d``; ``solve_plane_strain`` is the 2-D entry. The boundary
conditions are those of ``rkfx.conditions``: ``Displacement`` (imposed by Nitsche's method or the
transformation method, ``rkfx.assembly.boundary``) and ``Traction``.
"""
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from rkfx.assembly.boundary import (BC_METHODS, boundary_quadrature, nitsche_terms, traction_load,
                                    transformation_constraints)
from rkfx.conditions import Condition, Displacement, Traction, split
from rkfx.materials.elasticity import ElasticMaterial
from rkfx.linalg.linear_solver import SOLVERS, linear_solver
from rkfx.errors import InputError
from rkfx.geometry.cells import nodal_cells
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.assembly.operators import add_into, load_vector, stiffness
from rkfx.geometry.particles import Particles
from rkfx.integration.nodal_rules3d import RULES_3D, integration_rules_3d
from rkfx.integration.quadrature import NODAL_RULES, integration_rules, scni, subcell_rule
from rkfx.parallel.ownership import numbering
from rkfx.parallel.partition import rcb
from rkfx.memory import ordinary_pages
from rkfx.parallel.rows import owned_block, owned_entries, renumbered
from rkfx.approximation.shape_functions import RKApproximation, evaluate, rk_approximation


# solver="auto" solves directly up to this many unknowns and by CG + GAMG above, for a
# symmetric positive definite system (Nitsche's method and a stable rule). On Timoshenko's beam
# (bench/beam_scale.py, MSCNI) MUMPS and CG + GAMG take 0.06 s each at 2.2k unknowns, 0.25 s
# and 0.14 s at 8.5k, 1.2 s and 0.52 s at 33k, 10.8 s and 2.2 s at 132k: below the switch both
# are fast and the direct solve is the robust one; above it the fill of LU costs time and memory.
AUTO_DIRECT_MAX_DOFS = 10_000
SOLVER_CHOICES = ("auto", *(s for s in SOLVERS if s != "fieldsplit"))  # fieldsplit: for u-p blocks


def choose_solver(solver: str, n_dofs: int, bc_method: str, rule: str) -> str:
    """The linear solver ``solver="auto"`` stands for (see ``AUTO_DIRECT_MAX_DOFS``); any other
    choice is returned as it is. The transformation method's multipliers make a saddle point
    and direct nodal integration a nearly singular matrix: both are solved directly."""
    if solver not in SOLVER_CHOICES:
        raise InputError(f"unknown linear solver {solver!r}; choose one of {', '.join(SOLVER_CHOICES)}")
    if solver != "auto":
        return solver
    spd = bc_method == "nitsche" and rule != "dni"
    return "cg-gamg" if spd and n_dofs > AUTO_DIRECT_MAX_DOFS else "mumps"


@dataclass(frozen=True)
class ElasticSolution:
    """RK coefficients of the displacement and what is needed to evaluate it.

    Attributes:
        rk: The approximation.
        coefficients: Nodal coefficients d_I (not nodal values), shape ``(num_nodes, g)`` [m],
            g = 2 or 3.
        n_dofs: Number of displacement unknowns.
        timings: Wall times of the stages [s].
        linear: The linear solve: ``solver``, its ``iterations`` (1 for a direct solve) and
            PETSc's ``reason`` for stopping.
    """

    rk: RKApproximation
    coefficients: np.ndarray
    n_dofs: int
    timings: dict[str, float] = field(default_factory=dict)
    linear: dict = field(default_factory=dict)

    def displacement(self, points: np.ndarray) -> np.ndarray:
        """u^h at points, shape ``(m, g)`` [m]."""
        return evaluate(self.rk, points).matrix(0) @ self.coefficients

    def gradient(self, points: np.ndarray) -> np.ndarray:
        """Direct gradient of u^h at points, shape ``(m, g, g)`` with [i, j] = du_i/dx_j."""
        rows = evaluate(self.rk, points, gradients=True)
        return np.stack([rows.matrix(1 + j) @ self.coefficients for j in range(self.rk.dim)], axis=2)


def solve_plane_strain(p: Particles, material: ElasticMaterial, conditions: Sequence[Displacement | Traction] = (),
                       **options) -> ElasticSolution:
    """Solve 2-D elasticity (the material's plane strain or plane stress) on 2-D particles ``p``:
    ``solve_elasticity`` with its options."""
    if p.x.shape[1] != 2:
        raise InputError(f"solve_plane_strain takes 2-D particles; these have {p.x.shape[1]} coordinates: use "
                         "solve_elasticity")
    return solve_elasticity(p, material, conditions, **options)


def solve_elasticity(p, material: ElasticMaterial, conditions: Sequence[Displacement | Traction] = (),
                     *, body_force: Callable[[np.ndarray], np.ndarray] | None = None,
                     rule: str = "mscni", bc_method: str = "nitsche", support_factor: float = 1.5,
                     order: int = 1, nitsche_penalty: float = 100.0, comm=None,
                     solver: str = "auto", distributed: bool | None = None, domains=None) -> ElasticSolution:
    """Solve linear elasticity on ``p``: 2-D (the material's plane strain or stress) or 3-D.

    Args:
        p: Particles with named boundary parts (``Particles`` or ``Particles3D``).
        material: Elastic constants.
        conditions: The boundary conditions, one list of ``rkfx.conditions.Displacement``
            (prescribed displacements, value(x, t) at t = 0 or a constant) and
            ``rkfx.conditions.Traction`` (value(x, t, n) at t = 0 or a constant vector) on
            named or marked boundary parts; the rest of the boundary is traction-free.
        body_force: b(x) [N/m^3] for x of shape ``(m, g)``, returning ``(m, g)``.
        rule: Integration rule: ``gauss1|gauss2|gauss4|dni|scni|mscni`` (3-D: ``dni|scni|mscni``).
        bc_method: ``transformation`` or ``nitsche``.
        support_factor, order: RK support a_I = c h_I and basis degree.
        nitsche_penalty: Dimensionless Nitsche parameter.
        comm: MPI communicator for the PETSc solve (default COMM_WORLD).
        solver: ``auto`` (MUMPS up to ``AUTO_DIRECT_MAX_DOFS`` unknowns, CG + GAMG with the
            rigid-body modes above, for Nitsche's method and a stable rule) | ``mumps`` |
            ``gmres-ilu`` | ``cg-gamg``. The solve's iterations and reason: ``.linear``.
        distributed: Assemble by owned rows (``_solve_by_owned_rows``): each rank integrates
            over the cells of its part of an RCB partition only. ``None`` (default): when
            ``comm`` has more than one rank and the rule is nodal (``scni``, ``mscni``); the
            other rules are assembled whole on every rank, as with ``False``.
        domains: The nodal cells (default: ``nodal_cells(p)``, the median-dual cells, or in 3-D
            the box cells of a tensor grid).
    """
    displacements, tractions = _displacements_and_tractions(conditions)
    if bc_method not in BC_METHODS:
        raise InputError(f"unknown bc_method {bc_method!r}; choose one of {', '.join(BC_METHODS)}")
    g = p.x.shape[1]
    if g == 3 and rule not in RULES_3D:
        raise InputError(f"rule {rule!r} is not available in 3-D; choose one of {', '.join(RULES_3D)}")
    if distributed is None:
        distributed = comm is not None and comm.size > 1 and rule in NODAL_RULES
    elif distributed and rule not in NODAL_RULES:
        raise InputError(f"distributed=True needs a nodal rule ({', '.join(NODAL_RULES)}), not {rule!r}; "
                         "choose one, or distributed=False")
    solver = choose_solver(solver, g * p.num_nodes, bc_method, rule)
    times = {}
    t0 = time.perf_counter()
    rk = rk_approximation(p.x, p.spacing, support_factor, order)
    terms = dict(material=material, displacements=displacements, tractions=tractions, body_force=body_force,
                 rule=rule, bc_method=bc_method, nitsche_penalty=nitsche_penalty)
    linear = {"solver": solver}
    if distributed:
        coefficients = _solve_by_owned_rows(p, rk, terms, comm, solver, times, t0, linear, domains)
        return ElasticSolution(rk, coefficients, g * p.num_nodes, times, linear)
    domains = nodal_cells(p) if domains is None else domains
    k, f, gm, gv = elastic_terms(p, rk, domains, **terms)
    _check_rigid_modes(p, gm)
    if bc_method == "nitsche":
        system, rhs = k, f
    else:
        system = sp.bmat([[k, gm.T], [gm, None]], format="csr")
        rhs = np.concatenate([f, gv])
    times["assemble"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    # GAMG aggregates node blocks and keeps the rigid modes (one rank: its rows are every node's).
    gamg = solver == "cg-gamg" and bc_method == "nitsche" and (comm is None or comm.size == 1)
    ls = linear_solver(system, comm, solver, coordinates=p.x if gamg else None)
    del k, system  # PETSc holds its own copy
    x = ls.solve(rhs)
    linear.update(iterations=ls.iterations, reason=ls.reason)
    ls.destroy()
    times["solve"] = time.perf_counter() - t0
    return ElasticSolution(rk, x[:g * p.num_nodes].reshape(-1, g), g * p.num_nodes, times, linear)



@ordinary_pages()  # its arrays are temporaries (rkfx.memory)
def elastic_terms(p: Particles, rk: RKApproximation, domains: NodalDomains, material: ElasticMaterial,
                  displacements: Sequence[Displacement], tractions: Sequence[Traction],
                  body_force: Callable[[np.ndarray], np.ndarray] | None, rule: str, bc_method: str,
                  nitsche_penalty: float, nodes: np.ndarray | None = None
                  ) -> tuple[sp.csr_matrix, np.ndarray, sp.csr_matrix, np.ndarray]:
    """The stiffness K (g n, g n) and load f (g n,), with the Nitsche terms for ``nitsche``, and
    the collocation rows G (k, g n) and values g (k,) of the displacement conditions (g = 2 or 3).

    ``nodes`` (indices, a nodal rule only) integrates over those nodes' cells and boundary
    half-segments (facets in 3-D) and collocates at those of them on Gamma_u: a rank's share,
    whose K and f summed over a partition's parts (and G stacked) are the whole ones.
    """
    dim = p.x.shape[1]
    d = material.voigt(dim)
    if dim == 3:
        quads = integration_rules_3d(rule, p, rk, domains, nodes=nodes)
        k = stiffness(quads, d)
    elif rule == "mscni":  # its stiffness is the subcell rule's (eps_p = 1; subcell_rule)
        k = stiffness([subcell_rule(rk, domains, nodes=nodes)], d)
        quads = [scni(p, rk, domains, nodes=nodes)] if body_force is not None else []
    else:
        quads = integration_rules(rule, p, rk, domains, nodes=nodes)
        k = stiffness(quads, d)
    segments = None if nodes is None else np.flatnonzero(np.isin(domains.boundary.node, nodes))
    bq = boundary_quadrature(p, domains, rk, segments=segments)
    f = traction_load(p, bq, tractions)
    if body_force is not None:
        q = quads[0]
        f += load_vector(q.values, q.weights, body_force(q.points))
    g, gv = transformation_constraints(p, rk, displacements, nodes=nodes)
    if bc_method == "nitsche":
        kn, fn = nitsche_terms(p, bq, d, displacements, nitsche_penalty)
        k, f = add_into(k, kn), f + fn
    return k, f, g, gv


def _solve_by_owned_rows(p: Particles, rk: RKApproximation, terms: dict, comm, solver: str, times: dict,
                         t0: float, linear: dict, domains=None) -> np.ndarray:
    """The coefficients, shape ``(n, g)``, on every rank, from a system assembled by owned rows.

    The nodes are split by RCB (``rkfx.parallel.partition``); each rank builds the nodal
    domains around its nodes and integrates over its nodes' cells only (``nodal_domains`` and
    ``elastic_terms`` with ``nodes``), renumbers its contributions so that
    each rank's unknowns are contiguous (its nodes' displacements, then the multipliers of the
    collocation rows at its nodes), sends the rows owned elsewhere to their owners
    (``rkfx.parallel.rows``) and hands its block of rows to a preallocated PETSc matrix.
    ``times`` gets the stages' wall times, assembly counted from ``t0``; ``linear`` the
    solve's iterations and stopping reason.
    """
    rank, size = (0, 1) if comm is None else (comm.rank, comm.size)
    dim = p.x.shape[1]
    part = rcb(p.x, size)
    num = numbering(part, size)
    owned = num.old_of_new[num.ranges[rank]:num.ranges[rank + 1]]
    cells = nodal_cells(p, nodes=owned) if domains is None else domains
    k, f, g, gv = elastic_terms(p, rk, cells, nodes=owned, **terms)
    _check_rigid_modes(p, g, comm)
    mine = g.shape[0] if terms["bc_method"] == "transformation" else 0
    multipliers = np.array(comm.allgather(mine) if size > 1 else [mine])
    starts = np.zeros(size + 1, np.int64)
    np.cumsum(dim * np.diff(num.ranges) + multipliers, out=starts[1:])
    # Global unknown of every (node, component) and of this rank's multipliers.
    first = starts[part] + dim * (num.new_of_old - num.ranges[part])
    unknown = np.concatenate([(first[:, None] + np.arange(dim)).ravel(),
                              starts[rank] + dim * len(owned) + np.arange(mine)])
    if mine:
        k = sp.bmat([[k, g.T], [g, None]], format="csr")
        f = np.concatenate([f, gv])
    total = int(starts[-1])
    contribution = renumbered(k, unknown, total)
    del k  # the largest arrays go as soon as their successor stands
    rhs = np.zeros(total)
    rhs[unknown] = f
    block = owned_block(contribution, starts, comm)
    del contribution
    b = owned_entries(rhs, starts, comm)
    times["assemble"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    gamg = solver == "cg-gamg" and not mine  # displacement rows only: node blocks and rigid modes for GAMG
    ls = linear_solver(block, comm, solver, owned_rows=True, coordinates=p.x[owned] if gamg else None)
    del block  # PETSc holds its own copy
    x = ls.solve(b)
    linear.update(iterations=ls.iterations, reason=ls.reason)
    ls.destroy()
    times["solve"] = time.perf_counter() - t0
    return x[unknown[:dim * p.num_nodes]].reshape(-1, dim)


def _displacements_and_tractions(conditions: Sequence[Condition]) -> tuple[list, list]:
    """The Displacement and Traction conditions of ``conditions``; any other kind raises."""
    if isinstance(conditions, Displacement | Traction):
        conditions = [conditions]
    by_kind = split(conditions)
    other = [c for kind, cs in by_kind.items() if kind not in (Displacement, Traction) for c in cs]
    if other:
        raise InputError(f"solve_elasticity takes rkfx.conditions.Displacement and Traction conditions, not "
                         f"{other[0]!r}; drop it (a Velocity belongs to explicit dynamics: smeared_strain.constraint)")
    return by_kind[Displacement], by_kind[Traction]


def _check_rigid_modes(p: Particles, g: sp.csr_matrix, comm=None) -> None:
    """Raise if the prescribed displacements leave a rigid-body mode free (K would be singular).
    With ``comm``, ``g`` is this rank's share of the rows (all ranks' rows are checked).

    RK shape functions reproduce linear fields, so coefficients equal to the rigid motions'
    nodal values are exactly the rigid modes; each must violate some constraint row.
    """
    x = p.x - p.x.mean(axis=0)
    dim = x.shape[1]
    names = ["x-translation", "y-translation", "z-translation"][:dim]
    # Rotations about the axes normal to each coordinate plane (i, j): u_i = -x_j, u_j = x_i.
    planes = [(0, 1)] if dim == 2 else [(1, 2), (0, 2), (0, 1)]
    names += ["rotation"] if dim == 2 else ["rotation about x", "rotation about y", "rotation about z"]
    modes = np.zeros((dim * p.num_nodes, len(names)))
    for c in range(dim):
        modes[c::dim, c] = 1.0
    for k, (i, j) in enumerate(planes, start=dim):
        modes[i::dim, k], modes[j::dim, k] = -x[:, j], x[:, i]
    seen = g @ modes if g.shape[0] else np.zeros((0, len(names)))
    if comm is not None and comm.size > 1:
        seen = np.vstack(comm.allgather(seen))
    sv = np.linalg.svd(seen, compute_uv=False) if len(seen) else np.zeros(0)
    scale = np.abs(modes).max()
    if len(sv) < len(names) or sv[-1] <= 1e-10 * scale * max(sv[0], 1.0):
        free = [name for k, name in enumerate(names)
                if not np.any(np.abs(seen[:, k]) > 1e-12 * scale)] or ["a combination of rigid motions"]
        raise InputError(f"the displacement conditions leave {', '.join(free)} free, so the stiffness is "
                         "singular; prescribe more components (e.g. a roller on a second boundary)")
