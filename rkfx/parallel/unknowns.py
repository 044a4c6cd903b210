"""One rank's unknowns of a distributed implicit model: owned entries, ghost copies, global rows.

A rank integrates over the nodal domains of the nodes it owns (``rkfx.parallel.partition``).
Its *local nodes* are its own nodes, first and in the global order, then the nodes owned
elsewhere that its integration points and collocation rows touch (ghosts), by owning rank.
A model on the rank has the fields of the whole model on its local nodes (``FieldLayout`` on
``num_local`` nodes), and every vector or matrix it returns is the contribution of the rank's
own integration points only: the whole model's is the sum over the ranks.

``UnknownShare`` turns such contributions into values: ``assemble`` adds the ghost entries
to their owners (``rkfx.parallel.halo``) and copies the sums back to the ghosts, so that every
local entry holds the whole model's value. ``row_system`` turns a rank's contribution to a
Jacobian, and the rows it owns outright (its constraint rows), into the rank's block of rows
of the global system, which a row-distributed PETSc matrix takes
(``rkfx.linalg.linear_solver`` dispatches on ``RowSystem``).

The global numbering of a system puts each rank's unknowns in one contiguous block, in rank
order: its owned model unknowns (field by field, nodes in the global order, components
interleaved) and then its extra unknowns (the multipliers of its constraint rows).
This module does not import MPI: ``comm`` is any mpi4py communicator.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from rkfx.errors import InputError
from rkfx.parallel.halo import Halo, halo
from rkfx.parallel.ownership import Numbering
from rkfx.parallel.rows import owned_block, renumbered


@dataclass(frozen=True)
class UnknownShare:
    """Which local unknowns a rank owns and how the ghosts reach their owners.

    Attributes:
        owner: Owning rank of every local unknown, shape ``(num_local,)``.
        ordinal: Position of every local unknown among its owner's owned ones, ``(num_local,)``.
        owned: Local indices of the owned unknowns in the order of their ordinals, ``(num_owned,)``.
        halo: The exchange over the local unknowns.
        comm: The communicator.
    """

    owner: np.ndarray
    ordinal: np.ndarray
    owned: np.ndarray
    halo: Halo
    comm: object

    @property
    def rank(self) -> int:
        return self.comm.rank

    @property
    def size(self) -> int:
        return self.comm.size

    @property
    def num_local(self) -> int:
        return len(self.owner)

    @property
    def num_owned(self) -> int:
        return len(self.owned)

    def assemble(self, partial: np.ndarray) -> np.ndarray:
        """The whole model's values at every local entry from this rank's contributions
        (shape ``(num_local, ...)``); a new array. Collective."""
        values = np.array(partial, dtype=np.float64, order="C")
        self.halo.accumulate(values)
        return self.halo.exchange(values)

    def spread(self, values: np.ndarray) -> np.ndarray:
        """Overwrite the ghost entries of ``values`` with their owners' values, in place."""
        return self.halo.exchange(values)

    def max(self, value: float) -> float:
        """The largest ``value`` over the ranks (a NaN anywhere gives NaN everywhere)."""
        values = self.comm.allgather(float(value))
        return float("nan") if any(v != v for v in values) else float(max(values))

    def least(self, value: int) -> int:
        return int(min(self.comm.allgather(int(value))))

    def total(self, value: float) -> float:
        return float(sum(self.comm.allgather(float(value))))


def field_share(nodes: np.ndarray, num: Numbering, components: tuple[int, ...], comm) -> UnknownShare:
    """The share of a rank whose local nodes are ``nodes`` (global indices, its owned nodes first
    in the global order), for fields of ``components`` values per node laid out one block after
    another (``rkfx.solvers.fields``). Collective.

    Args:
        nodes: Global node of every local node, shape ``(num_local_nodes,)``.
        num: The partition's numbering (``rkfx.parallel.ownership.numbering``).
        components: Values per node of each field, e.g. ``(2, 1)`` for u-p.
        comm: The communicator.
    """
    nodes = np.asarray(nodes, np.int64)
    rank = comm.rank
    part = np.searchsorted(num.ranges, num.new_of_old[nodes], side="right") - 1
    own = int(num.ranges[rank + 1] - num.ranges[rank])
    if not (np.all(part[:own] == rank) and np.all(part[own:] != rank)
            and np.all(np.diff(num.new_of_old[nodes[:own]]) > 0)):
        raise InputError("field_share: the local nodes must start with all of the rank's own nodes, in order")
    pos = num.new_of_old[nodes] - num.ranges[part]  # place among the owner's nodes
    counts = np.diff(num.ranges)
    owner, ordinal, owned = [], [], []
    before = np.zeros(len(counts), np.int64)  # owned unknowns of the earlier fields, per rank
    first = 0
    for c in components:
        owner.append(np.repeat(part, c))
        ordinal.append((before[part][:, None] + c * pos[:, None] + np.arange(c)).ravel())
        owned.append(first + np.arange(c * own))
        before += c * counts
        first += c * len(nodes)
    owner, ordinal = np.concatenate(owner), np.concatenate(ordinal)
    starts = np.r_[0, np.cumsum(before)]
    return UnknownShare(owner, ordinal, np.concatenate(owned), halo(starts[owner] + ordinal, owner, comm), comm)


@dataclass(frozen=True)
class RowSystem:
    """A rank's block of rows of a distributed square system.

    Attributes:
        block: The owned rows over the global columns, shape ``(num_rows, size)``.
        rows: Local index of each owned row, in the global order, shape ``(num_rows,)``: the
            local vector of the system is the model's local unknowns followed by the rank's
            extra unknowns.
        share: The share of the model's local unknowns (the extras have no ghosts).
        num_local: Length of the local vector.
    """

    block: sp.csr_matrix
    rows: np.ndarray
    share: UnknownShare
    num_local: int

    @property
    def shape(self) -> tuple[int, int]:
        return self.block.shape

    def owned_values(self, local: np.ndarray) -> np.ndarray:
        """The owned entries of a local vector, in the global order."""
        return np.asarray(local, float)[self.rows]

    def local_values(self, owned: np.ndarray) -> np.ndarray:
        """The local vector of the owned entries, ghosts filled from their owners. Collective."""
        out = np.zeros(self.num_local)
        out[self.rows] = owned
        n = self.share.num_local
        head = np.ascontiguousarray(out[:n])
        self.share.spread(head)
        out[:n] = head
        return out


def row_system(contribution: sp.spmatrix, share: UnknownShare, extra: int, comm) -> RowSystem:
    """The ``RowSystem`` of a local square matrix over ``[model unknowns, extras]``.

    Args:
        contribution: Shape ``(n + extra, n + extra)``, n = ``share.num_local``: rows of the
            model unknowns are this rank's contributions (summed over the ranks), rows of
            the extras are this rank's own rows (its constraint rows).
        share: The model unknowns' share.
        extra: This rank's extra unknowns.
        comm: The communicator. Collective.
    """
    n = share.num_local
    if contribution.shape != (n + extra, n + extra):
        raise InputError(f"row_system: the matrix is {contribution.shape}, the local unknowns {n} + {extra}")
    sizes = np.array(comm.allgather(share.num_owned + int(extra)), np.int64)
    starts = np.r_[0, np.cumsum(sizes)]
    glob = np.r_[starts[share.owner] + share.ordinal, starts[comm.rank] + share.num_owned + np.arange(extra)]
    rows = np.r_[share.owned, n + np.arange(extra)]
    return RowSystem(owned_block(renumbered(contribution, glob, int(starts[-1])), starts, comm), rows, share,
                     n + int(extra))


@dataclass(frozen=True)
class LocalUnknowns:
    """A rank's local nodes and unknowns within a whole model's numbering.

    Attributes:
        nodes: Global node of every local node: the owned ones first (global order), then
            the ghosts by owning rank, shape ``(num_local_nodes,)``.
        num_owned_nodes: How many of ``nodes`` the rank owns.
        index: The whole model's unknown of every local unknown, shape ``(num_local,)``.
        share: The local unknowns' ``UnknownShare``.
    """

    nodes: np.ndarray
    num_owned_nodes: int
    index: np.ndarray
    share: UnknownShare

    def vector(self, whole: np.ndarray) -> np.ndarray:
        """The local entries of a whole model's vector."""
        return np.asarray(whole)[self.index]

    def matrix(self, whole: sp.spmatrix) -> sp.csr_matrix:
        """The local rows and columns of a whole model's matrix (a rank's contribution)."""
        return sp.csr_matrix(whole)[self.index][:, self.index]

    def observer(self, rows: sp.spmatrix):
        """``rows`` over a whole model's vector (samples, probes) as a function of the local
        vector: each rank's owned terms, summed over the ranks (collective; every rank gets
        the values)."""
        owned = np.zeros(len(self.index))
        owned[self.share.owned] = 1.0
        mine = (sp.csr_matrix(rows)[:, self.index] @ sp.diags(owned)).tocsr()
        return lambda x: self.share.comm.allreduce(mine @ x)


def touched_nodes(components: tuple[int, ...], num_nodes: int, *matrices: sp.spmatrix,
                  constraints: tuple[sp.spmatrix, ...] = ()) -> np.ndarray:
    """The nodes whose unknowns (fields of ``components`` values per node, one block after
    another) are a row or a column of an entry of any of the square ``matrices``, or a column
    of an entry of any of ``constraints`` (rows of conditions, not of unknowns), sorted."""
    starts = np.r_[0, np.cumsum(np.asarray(components) * num_nodes)]
    found = []
    for m, square in [(m, True) for m in matrices] + [(m, False) for m in constraints]:
        m = sp.csr_matrix(m)
        for unknowns in (m.indices, np.flatnonzero(np.diff(m.indptr))) if square else (m.indices,):
            unknowns = np.asarray(unknowns, np.int64)
            block = np.searchsorted(starts, unknowns, side="right") - 1
            found.append((unknowns - starts[block]) // np.asarray(components)[block])
    return np.unique(np.concatenate(found)) if found else np.zeros(0, np.int64)


def local_unknowns(num: Numbering, touched: np.ndarray, components: tuple[int, ...], comm) -> LocalUnknowns:
    """The ``LocalUnknowns`` of a rank owning its part of ``num`` whose contributions touch the
    nodes ``touched`` (``touched_nodes``). Collective."""
    rank = comm.rank
    owned = num.old_of_new[num.ranges[rank]:num.ranges[rank + 1]]
    owned = np.sort(owned)
    ghosts = np.setdiff1d(np.asarray(touched, np.int64), owned)
    part = np.searchsorted(num.ranges, num.new_of_old[ghosts], side="right") - 1
    ghosts = ghosts[np.lexsort((ghosts, part))]
    nodes = np.r_[owned, ghosts].astype(np.int64)
    n = len(num.new_of_old)
    index, first = [], 0
    for c in components:
        index.append((first + c * nodes[:, None] + np.arange(c)).ravel())
        first += c * n
    return LocalUnknowns(nodes, len(owned), np.concatenate(index), field_share(nodes, num, components, comm))
