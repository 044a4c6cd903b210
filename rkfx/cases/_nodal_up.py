"""RKPM u-p discretizations of a particle set, serial or split over MPI ranks: what the cases on
nodal rules share.

``nodal_discretization``: linear RK on the particles (support a = ``support`` spacings, a skin
of half a spacing), their median-dual areas as square cells, and any rule of
``rkfx.integration.nodal_stabilized.RULES``. On a communicator of several ranks the nodes are
split by RCB: each rank's rule covers its own nodes' cells only, and ``rank_unknowns`` gives
its local u-p unknowns (own nodes, then the ghosts its rows touch), ``owned`` the rank's share
of a node set, ``split_over_ranks`` a model's conditions and probes over the local unknowns and
``whole_unknowns`` a model's size over all ranks. ``edge_load``: the force of
a traction on boundary edges.
"""
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from rkfx.approximation.semi_lagrangian import MovingRK, evaluate_moving, moving_rk
from rkfx.geometry.nodal_domains import nodal_domains
from rkfx.geometry.particles import Particles
from rkfx.integration.nodal_stabilized import NodalIntegration, boundary_rule, nodal_cells, nodal_integration
from rkfx.parallel.ownership import Numbering, numbering
from rkfx.parallel.partition import rcb
from rkfx.parallel.unknowns import LocalUnknowns, local_unknowns


class NodalDiscretization(NamedTuple):
    """Particles, approximation and rule; on MPI ranks the rank's own nodes (whose cells its
    rule covers) and the partition's numbering."""

    particles: Particles
    rk: MovingRK
    rule: NodalIntegration
    own: np.ndarray | None = None
    numbering: Numbering | None = None


def nodal_discretization(p: Particles, spacing: float, rule: str = "nsni", comm=None,
                         support: float = 2.0) -> NodalDiscretization:
    """The discretization of particles ``p`` of nominal ``spacing`` h [m] (a = ``support`` h,
    skin h / 2)."""
    cells = nodal_cells(p.x, nodal_domains(p).area)
    rk = moving_rk(p.x, support * spacing, 0.5 * spacing, reach=cells.reach)
    num = own = None
    if comm is not None and comm.size > 1:
        num = numbering(rcb(p.x, comm.size), comm.size)
        own = np.sort(num.old_of_new[num.ranges[comm.rank]:num.ranges[comm.rank + 1]])
    r = nodal_integration(rk, cells, boundary_rule(p.x, p.boundary_edges), rule, points=own)
    return NodalDiscretization(p, rk, r, own, num)


def owned(d, nodes: np.ndarray) -> np.ndarray:
    """The nodes of ``nodes`` the rank owns (all of them when serial): where it collocates."""
    return nodes if d.own is None else np.intersect1d(nodes, d.own)


def whole_unknowns(model) -> int:
    """A model's unknowns over all ranks (a distributed model counts its owned ones)."""
    share = getattr(model, "share", None)
    return model.layout.size if share is None else int(round(share.total(share.num_owned)))


def rank_unknowns(d, constraints: sp.spmatrix, comm) -> LocalUnknowns:
    """On MPI ranks, a rank's local u-p unknowns (``u`` interleaved, then ``p``) of a
    discretization split by ``nodal_discretization(..., comm=)``: its own nodes, then the ghosts
    its rule's rows and the ``constraints`` rows (over the whole vector) touch. Collective."""
    n = d.particles.num_nodes
    cols = sp.csr_matrix(constraints).indices
    touched = np.unique(np.r_[d.own, np.where(cols < 2 * n, cols // 2, cols - 2 * n), d.rule.columns()])
    return local_unknowns(d.numbering, touched, (2, 1), comm)


def split_over_ranks(d, comm, constraints: list[sp.spmatrix], probe: sp.spmatrix,
                     touching: sp.spmatrix | None = None):
    """A model's pieces over a rank's local unknowns: ``(local, constraints, sample)``, with
    ``local`` of ``rank_unknowns`` for the ghosts that ``touching`` (default: the
    ``constraints``) touches, the ``constraints`` rows over the local unknowns, and ``sample``
    the ``probe`` rows (over the whole vector) as a function of the local one (collective).
    Serially: ``(None, constraints, probe @)``."""
    if d.own is None:
        return None, constraints, probe.__matmul__
    local = rank_unknowns(d, sp.vstack(constraints) if touching is None else touching, comm)
    return local, [sp.csr_matrix(c)[:, local.index].tocsr() for c in constraints], local.observer(probe)


def edge_load(rk: MovingRK, edges: np.ndarray, traction) -> np.ndarray:
    """f_I = int N_I t ds over boundary ``edges`` (node pairs, the domain on their left) by two
    Gauss points per edge, interleaved, shape ``(2 num_nodes,)``; ``traction(x, n)`` [Pa] takes
    the points and their outward unit normals, shape ``(m, 2)`` each."""
    b = boundary_rule(rk.x, edges)
    w = np.linalg.norm(b.normal_length, axis=1)
    t = np.asarray(traction(b.points, b.normal_length / w[:, None]), float).reshape(-1, 2)
    f = evaluate_moving(rk, b.points, b.owner).matrix().T @ (w[:, None] * t)
    return f.ravel()
