"""Which particles a rank owns, which it keeps as ghosts, and the global numbering.

A rank owns the nodes of its part (``rkfx.parallel.partition``): the rows of their unknowns
and the nodal domains (the integration points of nodal integration) around them. Its ghosts
are the nodes owned elsewhere whose supports cover one of its evaluation points: they are
the columns its integration points couple to besides its own nodes.

The global numbering puts the owned nodes of rank 0 first, then those of rank 1, and so on,
each block in the original order, so a rank's nodes are the contiguous range
``[start, end)``: PETSc's ownership range of a row-distributed matrix.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError
from rkfx.geometry.nodal_domains import NodalDomains
from rkfx.approximation.neighbours import support_neighbours
from rkfx.approximation.shape_functions import RKApproximation


@dataclass(frozen=True)
class Numbering:
    """Nodes renumbered so that every part's nodes are contiguous.

    Attributes:
        ranges: Part r holds the new indices ``ranges[r]:ranges[r + 1]``, shape ``(num_parts + 1,)``.
        new_of_old: New index of each node, shape ``(num_nodes,)`` int64.
        old_of_new: Node of each new index, shape ``(num_nodes,)`` int64 (the inverse).
    """

    ranges: np.ndarray
    new_of_old: np.ndarray
    old_of_new: np.ndarray


def numbering(part: np.ndarray, num_parts: int) -> Numbering:
    """The numbering of ``part`` (the part of each node, shape ``(num_nodes,)``): parts in
    order, each part's nodes in their original order."""
    part = np.asarray(part)
    if part.size and (part.min() < 0 or part.max() >= num_parts):
        raise InputError(f"node parts must lie in 0..{num_parts - 1}; got {part.min()}..{part.max()}")
    old_of_new = np.argsort(part, kind="stable").astype(np.int64)
    new_of_old = np.empty_like(old_of_new)
    new_of_old[old_of_new] = np.arange(len(part))
    ranges = np.zeros(num_parts + 1, np.int64)
    np.cumsum(np.bincount(part, minlength=num_parts), out=ranges[1:])
    return Numbering(ranges, new_of_old, old_of_new)


@dataclass(frozen=True)
class Ownership:
    """One rank's share of the particles.

    Attributes:
        rank: The rank (part) it describes.
        numbering: The global numbering of all parts.
        owned: Owned nodes (original indices) in the new order, shape ``(num_owned,)``.
        ghosts: Nodes owned elsewhere whose supports cover an owned evaluation point
            (original indices, sorted), shape ``(num_ghosts,)``.
    """

    rank: int
    numbering: Numbering
    owned: np.ndarray
    ghosts: np.ndarray

    @property
    def start(self) -> int:
        return int(self.numbering.ranges[self.rank])

    @property
    def end(self) -> int:
        return int(self.numbering.ranges[self.rank + 1])

    @property
    def num_owned(self) -> int:
        return len(self.owned)

    @property
    def num_ghosts(self) -> int:
        return len(self.ghosts)


def nodal_integration_points(domains: NodalDomains, x: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The points where nodal integration (SCNI, MSCNI) of the cells of ``nodes`` evaluates N,
    shape ``(m, 2)``: the nodes and the smoothing points of their subcells (which include
    their cells' and their boundary half-segment midpoints)."""
    d = domains
    mine = np.zeros(len(d.area), bool)
    mine[nodes] = True
    used = np.unique(d.subcell_point[mine[d.subcell_node]].ravel())
    return np.concatenate([x[nodes], d.smoothing_points[used]])


def ownership(part: np.ndarray, num_parts: int, rank: int, rk: RKApproximation, points: np.ndarray) -> Ownership:
    """The share of ``rank`` given the part of every node and its owned evaluation points.

    Args:
        part: Part of each node, shape ``(num_nodes,)`` (e.g. ``rcb(x, num_parts)``).
        num_parts: Number of parts (ranks).
        rank: This rank, 0 <= rank < num_parts.
        rk: The approximation (its supports decide the ghosts).
        points: Where this rank evaluates shape functions, shape ``(m, 2)``
            (``nodal_integration_points`` for nodal integration).
    """
    if not 0 <= rank < num_parts:
        raise InputError(f"rank = {rank!r} must lie in 0..{num_parts - 1}")
    num = numbering(part, num_parts)
    owned = num.old_of_new[num.ranges[rank]:num.ranges[rank + 1]]
    _, covering = support_neighbours(rk.x, rk.support, points)
    ghosts = np.setdiff1d(np.unique(covering), owned)
    return Ownership(rank, num, owned, ghosts.astype(np.int64))
