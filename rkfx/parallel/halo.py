"""Ghost copies of values owned by other ranks, refreshed by a neighbour-only exchange.

A rank holds *local* entries: its own and copies (ghosts) of entries owned by other ranks.
``halo`` pairs them up once; ``Halo.exchange(values)`` then overwrites every ghost entry
with its owner's current value, and ``Halo.accumulate(values)`` goes the other way: it adds
every ghost entry (a rank's contribution to an entry owned elsewhere, e.g. the force of its
integration points on a ghost node) to the owner's entry. Each rank talks only to the ranks it shares entries with
(nonblocking point-to-point messages of contiguous buffers), so the cost of an exchange
grows with the ghost layer, not with the number of ranks.

``comm`` is any mpi4py communicator (``rank``, ``size``, ``alltoall``, ``Isend``, ``Irecv``);
this module does not import MPI.
"""
from dataclasses import dataclass

import numpy as np

from rkfx.errors import InputError

_TAG = 7302


@dataclass(frozen=True)
class Halo:
    """Which local entries a rank sends to, and receives from, each neighbour rank.

    Attributes:
        neighbours: Ranks this rank exchanges with, ascending, shape ``(k,)``.
        send: For each neighbour, the local indices of owned entries it needs (in its order).
        recv: For each neighbour, the local indices of the ghost entries it owns.
        comm: The communicator.
    """

    neighbours: np.ndarray
    send: list[np.ndarray]
    recv: list[np.ndarray]
    comm: object

    @property
    def num_ghosts(self) -> int:
        return int(sum(len(r) for r in self.recv))

    def exchange(self, values: np.ndarray) -> np.ndarray:
        """Overwrite the ghost rows of ``values`` (shape ``(num_local, ...)``, C-contiguous)
        with their owners' rows, in place; returns ``values``. Collective over the neighbours."""
        if not len(self.neighbours):
            return values
        tail = values.shape[1:]
        # A neighbour's ghosts numbered as one block are received in place, others through a buffer.
        inbox = [values[r[0]:r[-1] + 1] if _block(r) else np.empty((len(r), *tail), values.dtype)
                 for r in self.recv]
        requests = [self.comm.Irecv(buf, source=int(p), tag=_TAG) for p, buf in zip(self.neighbours, inbox)]
        outbox = [np.ascontiguousarray(values[s]) for s in self.send]
        requests += [self.comm.Isend(buf, dest=int(p), tag=_TAG) for p, buf in zip(self.neighbours, outbox)]
        for r in requests:
            r.Wait()
        for rows, buf in zip(self.recv, inbox):
            if not _block(rows):
                values[rows] = buf
        return values


    def accumulate(self, values: np.ndarray) -> np.ndarray:
        """Add the ghost rows of ``values`` (shape ``(num_local, ...)``) to their owners' rows,
        in place, neighbours in ascending rank order; the ghost rows keep their own values.
        Returns ``values``. Collective over the neighbours."""
        if not len(self.neighbours):
            return values
        tail = values.shape[1:]
        inbox = [np.empty((len(s), *tail), values.dtype) for s in self.send]
        requests = [self.comm.Irecv(buf, source=int(p), tag=_TAG + 1) for p, buf in zip(self.neighbours, inbox)]
        outbox = [np.ascontiguousarray(values[r]) for r in self.recv]
        requests += [self.comm.Isend(buf, dest=int(p), tag=_TAG + 1) for p, buf in zip(self.neighbours, outbox)]
        for r in requests:
            r.Wait()
        for rows, buf in zip(self.send, inbox):
            values[rows] += buf  # rows are distinct within one neighbour
        return values


def _block(rows: np.ndarray) -> bool:
    """Whether ``rows`` is a non-empty run of consecutive indices."""
    return len(rows) > 0 and rows[-1] - rows[0] == len(rows) - 1


def halo(local: np.ndarray, owner: np.ndarray, comm) -> Halo:
    """The halo of a rank holding the global entries ``local`` (owned and ghost), collective.

    Args:
        local: Global index of each local entry, shape ``(num_local,)``, distinct.
        owner: Owning rank of each local entry, shape ``(num_local,)``; entries owned by this
            rank are its own, the others are ghosts.
        comm: The communicator.
    """
    local, owner = np.asarray(local, np.int64), np.asarray(owner, np.int64)
    if local.shape != owner.shape:
        raise InputError(f"halo: {len(local)} local entries but {len(owner)} owners")
    rank, size = comm.rank, comm.size
    wanted = [local[owner == r] if r != rank else local[:0] for r in range(size)]
    asked = comm.alltoall(wanted)  # what every rank wants of this one, in its local order
    order = np.argsort(local, kind="stable")
    neighbours = sorted(r for r in range(size) if len(wanted[r]) or len(asked[r]))
    send, recv = [], []
    for r in neighbours:
        mine = np.asarray(asked[r], np.int64)
        at = order[np.minimum(np.searchsorted(local[order], mine), len(local) - 1)] if len(local) else mine
        if len(mine) and (np.any(local[at] != mine) or np.any(owner[at] != rank)):
            raise InputError(f"halo: rank {r} asks rank {rank} for entries it does not own")
        send.append(at.astype(np.int64))
        recv.append(np.flatnonzero(owner == r).astype(np.int64))
    return Halo(np.array(neighbours, np.int64), send, recv, comm)
