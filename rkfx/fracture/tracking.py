"""Particle tracking of crack growth, eq. (4.22): which particles may start to damage next.

A damaged particle L carries a crack segment through x_L with unit normal n_L, fixed at
initiation along the major principal direction of the stress. Its neighbours I become
candidates when they lie close to the segment's line:

    | n_L . (x_I - x_L) / |x_I - x_L| | < tol                                      (4.22)

Only *allowed* particles may initiate: the seeds (e.g. the particles at a pre-existing crack
tip) and the candidates of the damaged ones; the other neighbours of L form its crack
prevention zone. Since n_L is fixed at initiation, the candidates of L are marked once, when
L initiates (``rkfx.models.damage_dynamics``). With tracking switched off every particle is allowed,
which lets spurious damage spread (Fig 4.16).

Growth direction. (4.22) is symmetric: it admits the neighbours on both sides of L along its
crack line, also those behind L, where the crack came from. There they start side cracks
off the main one ("feathers") that widen the damaged zone, flatten the path and add
dissipation: on Kalthoff's problem at 62,750 particles the path fitted to the failed
particles lies at 59 degrees with 3,296 particles damaged, and at 72 degrees with 2,109 when
candidates must lie ahead (``forward``, the default): a neighbour I of L becomes a
candidate only if also (x_I - x_L) . (x_L - x_P) >= 0, where P is the particle whose
initiation made L a candidate (its *parent*). Seeds have no parent and grow both ways.

The neighbour set N_L is the particles within ``radius`` h_L of x_L. On a grid, a radius of
1.5 h (side and diagonal neighbours) cannot follow a crack at 70 degrees with tol = 0.3: both
are 20-25 degrees off, and such a crack arrests after a few particles. 2.5 h adds the (1, 2)
neighbours, so every direction lies within 13.3 degrees of a neighbour; the default 3.5 h
adds (1, 3) and (2, 3), so the candidates along a crack are not all at one lattice angle (on
Kalthoff's problem with plain SCNI at 60-120 particles per side the final dissipation
spreads by 8.5% with 3.5 h and by 21% with 2.5 h). Keeping the neighbours that fail (4.22) from initiating even
when another particle allows them (a strict prevention zone) arrests Kalthoff's crack within
a few millimetres, so the zone only withholds candidacy.
"""
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from rkfx.errors import InputError
from rkfx.approximation.neighbours import covered, support_neighbours
from rkfx.approximation.sparse_rows import ranges


@dataclass(frozen=True)
class Tracking:
    """Particle tracking data (4.22).

    Attributes:
        x: Particle positions, shape ``(n, 2)`` [m].
        spacing: Nodal spacing h_L, shape ``(n,)`` [m].
        tol: Tolerance of (4.22), in (0, 1].
        seeds: Particles that may always initiate, shape ``(n,)`` bool.
        radius: Neighbourhood radius in spacings.
        enabled: ``False`` lets every particle damage.
        forward: Candidates only ahead of their particle (away from its parent).
        rows: The particles whose neighbour sets are kept, sorted (``None``: all). A rank of a
            distributed run keeps those of the particles near its own (``near``).
    """

    x: np.ndarray
    spacing: np.ndarray
    tol: float
    seeds: np.ndarray
    radius: float = 3.5
    enabled: bool = True
    forward: bool = True
    rows: np.ndarray | None = None

    @cached_property
    def neighbours(self) -> tuple[np.ndarray, np.ndarray]:
        """The neighbour sets N_L of ``rows`` (the others empty), built on first use: CSR
        ``(indptr, indices)`` over all particles, shapes ``(n + 1,)`` int64 and ``(nnz,)`` int32;
        N_L holds the particles I != L with |x_L - x_I| < radius h_I."""
        n = len(self.x)
        rows = np.arange(n) if self.rows is None else self.rows
        ptr, idx = support_neighbours(self.x, self.radius * np.asarray(self.spacing, float), self.x[rows])
        row = np.repeat(np.arange(len(rows)), np.diff(ptr))
        keep = idx != rows[row]
        counts = np.zeros(n, np.int64)
        counts[rows] = np.bincount(row[keep], minlength=len(rows))
        indptr = np.zeros(n + 1, np.int64)
        np.cumsum(counts, out=indptr[1:])
        return indptr, idx[keep]

    @property
    def indptr(self) -> np.ndarray:
        return self.neighbours[0]

    @property
    def indices(self) -> np.ndarray:
        return self.neighbours[1]

    def near(self, points: np.ndarray) -> "Tracking":
        """This tracking with the neighbour sets of only the particles that have one of
        ``points`` among their neighbours (and of ``points``): the initiations that can make
        one of ``points`` a candidate."""
        points = np.asarray(points, np.int64)
        a = self.radius * np.asarray(self.spacing, float)
        rows = np.flatnonzero(covered(self.x[points], a[points], self.x))
        return replace(self, rows=np.union1d(rows, points))

    def candidates(self, nodes: np.ndarray, normals: np.ndarray,
                   parents: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Neighbours of the particles ``nodes`` (crack normals ``normals``) that satisfy (4.22)
        and, with ``forward``, lie ahead of them: ``parents`` holds the parent of each of
        ``nodes`` (-1: none), shape ``(len(nodes),)``.

        Returns:
            (candidates, by): the distinct candidates and, for each, the first of ``nodes``
            that admits it (its parent).
        """
        nodes = np.asarray(nodes, np.int64)
        indptr, indices = self.neighbours
        counts = indptr[nodes + 1] - indptr[nodes]
        rows = np.repeat(np.arange(len(nodes)), counts)
        cols = indices[ranges(indptr[nodes], counts)]
        d = self.x[cols] - self.x[nodes[rows]]
        ok = np.abs(np.sum(normals[rows] * d, axis=1)) < self.tol * np.linalg.norm(d, axis=1)
        if self.forward and parents is not None:
            parent = np.asarray(parents, np.int64)
            if parent.shape != nodes.shape:
                raise InputError(f"parents has shape {parent.shape}; expected one per node, {nodes.shape}")
            has = parent >= 0
            back = np.zeros((len(nodes), 2))
            back[has] = self.x[nodes[has]] - self.x[parent[has]]
            ok &= np.sum(d * back[rows], axis=1) >= 0.0
        cand, first = np.unique(cols[ok], return_index=True)
        return cand, nodes[rows[ok][first]]


def check_tracking(tol: float, radius: float) -> None:
    """Raise InputError unless the tolerance of (4.22) lies in (0, 1] and the radius is >= 1 spacing."""
    if not (0.0 < tol <= 1.0):
        raise InputError(f"tracking tolerance tol = {tol!r} must lie in (0, 1]; the seed uses 0.3-0.5")
    if not radius >= 1.0:
        raise InputError(f"tracking radius = {radius!r} spacings must be >= 1 (2.5 reaches the (1, 2) neighbours)")


def admit(cand: np.ndarray, by: np.ndarray, allowed: np.ndarray, parent: np.ndarray) -> bool:
    """Allow the candidates ``cand`` (distinct, from ``Tracking.candidates``) in place; those not
    allowed before take their admitting particle ``by`` as parent. Whether any was new."""
    fresh = ~allowed[cand]
    parent[cand[fresh]] = by[fresh]
    allowed[cand] = True
    return bool(fresh.any())


def tracking(x: np.ndarray, spacing: np.ndarray, tol: float, seeds: np.ndarray | None = None,
             radius: float = 3.5, enabled: bool = True, forward: bool = True) -> Tracking:
    """Neighbour sets N_L = particles within ``radius`` h_L of x_L, and the tracking settings.

    Args:
        x: Particle positions, shape ``(n, 2)`` [m].
        spacing: Nodal spacing h_L, shape ``(n,)`` [m].
        tol: Tolerance of (4.22) (the seed uses 0.3 for Kalthoff, 0.5 for branching).
        seeds: Bool mask (or indices) of particles that may always initiate.
        radius: Neighbourhood radius in spacings (>= 1).
        enabled: ``False`` switches tracking off.
        forward: Candidates only ahead of their particle (``False``: (4.22) both ways).
    """
    check_tracking(tol, radius)
    x = np.ascontiguousarray(x, float)
    n = len(x)
    mask = np.zeros(n, bool)
    if seeds is not None:
        s = np.asarray(seeds)
        if s.dtype == bool:
            if s.shape != (n,):
                raise InputError(f"seeds mask has shape {s.shape}; expected ({n},)")
            mask |= s
        else:
            mask[s.astype(np.int64)] = True
    return Tracking(x, np.ascontiguousarray(spacing, float), float(tol), mask, float(radius), bool(enabled),
                    bool(forward))
