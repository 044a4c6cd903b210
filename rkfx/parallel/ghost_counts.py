"""The halo of an explicit step over ranks: ghost nodes, ghost points and bytes per step.

With nodal integration a particle L couples to the nodes I whose supports cover one of its
evaluation points (the node itself and the smoothing points of its cell and subcells). On a
partition, an entry (L, I) with ``part[L] != part[I]`` makes I a *ghost node* of ``part[L]``
(the rank of L reads I's coefficients and receives the internal force at I from I's owner) and L a *ghost point*
of ``part[I]`` (the owner of I needs the stress loads of L's subcell rows). The entries do not
depend on the partition, so ``coupling`` finds them once and ``count_halo`` counts any number of
partitions of the same particles from them, serially and without building one rank's share.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.approximation.neighbours import support_neighbours
from rkfx.approximation.shape_functions import RKApproximation
from rkfx.geometry.nodal_domains import NodalDomains

FORCE_DOUBLES = 2  # internal force per ghost node: (f_x, f_y)
STRESS_DOUBLES = 3  # stress load per subcell row of a ghost point: (s_xx, s_yy, s_xy)
CHUNK = 50_000  # particles per neighbour search: bounds the memory of the raw entries


@dataclass(frozen=True)
class Coupling:
    """The distinct entries (particle L, node I), L != I, of nodal integration.

    Attributes:
        particle: L of each entry, shape ``(nnz,)`` int32.
        node: I of each entry, shape ``(nnz,)`` int32.
        subcells: Subcell rows of each particle (MSCNI), shape ``(num_nodes,)`` int64.
    """

    particle: np.ndarray
    node: np.ndarray
    subcells: np.ndarray


@dataclass(frozen=True)
class HaloCounts:
    """Per-rank counts of one partition, each of shape ``(num_parts,)``.

    Attributes:
        owned: Particles owned.
        ghost_nodes: Nodes owned elsewhere in the supports of its evaluation points.
        ghost_points: Particles owned elsewhere whose evaluation points its nodes cover.
        ghost_subcells: Subcell rows of its ghost points.
        neighbours: Distinct ranks it exchanges with (messages per step = 2 x neighbours).
    """

    owned: np.ndarray
    ghost_nodes: np.ndarray
    ghost_points: np.ndarray
    ghost_subcells: np.ndarray
    neighbours: np.ndarray

    @property
    def bytes(self) -> np.ndarray:
        """Bytes per step of each rank: forces at its ghost nodes and stress loads of its ghost
        points' subcell rows, 8-byte doubles."""
        return 8 * (FORCE_DOUBLES * self.ghost_nodes + STRESS_DOUBLES * self.ghost_subcells)


def _owned_points(domains: NodalDomains, x: np.ndarray, lo: int, hi: int, by_node: np.ndarray,
                  sub_ptr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Evaluation points of particles ``lo:hi`` and the particle of each, as in
    ``rkfx.parallel.ownership.nodal_integration_points`` (duplicates kept): the particles and
    their subcells' smoothing points (which include their cells')."""
    d = domains
    subs = by_node[sub_ptr[lo]:sub_ptr[hi]]
    points = np.concatenate([x[lo:hi], d.smoothing_points[d.subcell_point[subs].ravel()]])
    owner = np.concatenate([np.arange(lo, hi), np.repeat(d.subcell_node[subs], d.subcell_point.shape[1])])
    return points, owner


def coupling(rk: RKApproximation, domains: NodalDomains, chunk: int = CHUNK) -> Coupling:
    """The entries (L, I) of nodal integration over the nodal domains ``domains`` of ``rk``'s nodes.

    Args:
        rk: The approximation (its supports decide the entries).
        domains: Nodal domains of the same nodes (cells, subcells, smoothing points).
        chunk: Particles per neighbour search.
    """
    n = rk.num_nodes
    by_node = np.argsort(domains.subcell_node, kind="stable")
    sub_ptr = np.searchsorted(domains.subcell_node[by_node], np.arange(n + 1))
    particles, nodes = [], []
    for lo in range(0, n, chunk):
        hi = min(n, lo + chunk)
        points, owner = _owned_points(domains, rk.x, lo, hi, by_node, sub_ptr)
        ptr, idx = support_neighbours(rk.x, rk.support, points)
        key = np.unique(np.repeat(owner, np.diff(ptr)) * n + idx)  # distinct (L, I) of this chunk
        ll, ii = np.divmod(key, n)
        keep = ll != ii
        particles.append(ll[keep].astype(np.int32))
        nodes.append(ii[keep].astype(np.int32))
    subcells = np.bincount(domains.subcell_node, minlength=n).astype(np.int64)
    return Coupling(np.concatenate(particles), np.concatenate(nodes), subcells)


def _distinct(rank: np.ndarray, other: np.ndarray, size: int) -> tuple[np.ndarray, np.ndarray]:
    """The distinct pairs (rank, other), ``other`` in 0..size-1, as two arrays."""
    return np.divmod(np.unique(rank.astype(np.int64) * size + other), size)


def count_halo(c: Coupling, part: np.ndarray, num_parts: int) -> HaloCounts:
    """The per-rank halo of the partition ``part`` (part of each node, shape ``(num_nodes,)``)."""
    n = len(part)
    pl, pi = part[c.particle], part[c.node]
    cross = pl != pi
    ll, ii, pl, pi = c.particle[cross], c.node[cross], pl[cross], pi[cross]
    r_nodes, _ = _distinct(pl, ii, n)
    r_points, points = _distinct(pi, ll, n)
    r_nb, _ = _distinct(np.concatenate([pl, pi]), np.concatenate([pi, pl]), num_parts)

    def per_rank(r, weights=None):
        return np.bincount(r, weights, minlength=num_parts)

    return HaloCounts(per_rank(part), per_rank(r_nodes), per_rank(r_points),
                per_rank(r_points, c.subcells[points]).astype(np.int64), per_rank(r_nb))


def ghost_nodes(c: Coupling, part: np.ndarray, rank: int) -> np.ndarray:
    """Sorted ghost nodes of ``rank`` (as ``rkfx.parallel.ownership.ownership`` gives them)."""
    mine = part[c.particle] == rank
    return np.unique(c.node[mine & (part[c.node] != rank)]).astype(np.int64)


def ghost_points(c: Coupling, part: np.ndarray, rank: int) -> np.ndarray:
    """Sorted ghost points of ``rank``: particles owned elsewhere coupled to one of its nodes."""
    mine = part[c.node] == rank
    return np.unique(c.particle[mine & (part[c.particle] != rank)]).astype(np.int64)
