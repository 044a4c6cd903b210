"""Particle tracking of crack growth, eq. (4.22): which particles may start to damage next.

A damaged particle L carries a crack segment through x_L with unit normal n_L (fixed at
initiation along the maximum principal stress direction). Its neighbours I — particles whose
nodal domains share a side with L's, i.e. the triangulation edges at L — become candidates
when they lie close to the segment's line:

    | n_L . (x_I - x_L) / |x_I - x_L| | < tol                                      (4.22)

Only candidates (and seed particles, e.g. at the tips of pre-existing cracks) may initiate
damage in the next step; the other neighbours form the crack prevention zone. With tracking
switched off every particle is a candidate, which lets spurious damage spread (Fig 4.16).
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .errors import InputError
from .particles import Particles


@dataclass(frozen=True)
class NeighbourGraph:
    """Symmetric particle adjacency (nodal domains sharing a side) as CSR.

    Attributes:
        indptr: Shape ``(num_nodes + 1,)``.
        indices: Neighbours of each particle, shape ``(2 num_edges,)``.
    """

    indptr: np.ndarray
    indices: np.ndarray


def neighbour_graph(p: Particles) -> NeighbourGraph:
    """Neighbours of each particle: the ends of its triangulation edges (median-dual cells
    of two particles share a side exactly when the particles share an edge)."""
    e = p.edges
    n = p.num_nodes
    adj = sp.csr_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])), shape=(n, n))
    adj.sort_indices()
    return NeighbourGraph(adj.indptr, adj.indices)


def principal_direction(stress: np.ndarray) -> np.ndarray:
    """Unit direction of the maximum principal stress, shape ``(m, 2)``, from Voigt stress
    (sigma_xx, sigma_yy, sigma_xy) of shape ``(m, 3)``."""
    sxx, syy, sxy = stress[:, 0], stress[:, 1], stress[:, 2]
    theta = 0.5 * np.arctan2(2.0 * sxy, sxx - syy)
    return np.column_stack([np.cos(theta), np.sin(theta)])


def candidates(x: np.ndarray, graph: NeighbourGraph, damaged: np.ndarray, normal: np.ndarray, tol: float,
               seeds: np.ndarray | None = None, tracking: bool = True) -> np.ndarray:
    """Particles allowed to initiate damage in the next step.

    Args:
        x: Particle positions, shape ``(n, 2)``.
        graph: Neighbour graph.
        damaged: Damaged particles, shape ``(n,)`` bool.
        normal: Crack normal n_L of each damaged particle, shape ``(n, 2)`` (ignored elsewhere).
        tol: Tolerance of eq. (4.22), in (0, 1]; the seed uses 0.3-0.5.
        seeds: Particles that may always initiate (e.g. near pre-existing crack tips), bool.
        tracking: ``False`` allows every particle (no tracking).

    Returns:
        Bool mask, shape ``(n,)``: damaged particles, seeds and the candidates of (4.22).
    """
    if not (0.0 < tol <= 1.0):
        raise InputError(f"tracking tolerance tol = {tol!r} must lie in (0, 1]; the seed uses 0.3-0.5")
    n = len(x)
    if not tracking:
        return np.ones(n, bool)
    allowed = damaged.copy() if seeds is None else damaged | seeds
    src = np.flatnonzero(damaged)
    if src.size == 0:
        return allowed
    counts = np.diff(graph.indptr)[src]
    rows = np.repeat(src, counts)
    cols = np.concatenate([graph.indices[graph.indptr[i]:graph.indptr[i + 1]] for i in src])
    d = x[cols] - x[rows]
    cosine = np.abs(np.sum(normal[rows] * d, axis=1)) / np.linalg.norm(d, axis=1)
    allowed[cols[cosine < tol]] = True
    return allowed
