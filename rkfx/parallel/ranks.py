"""Serial work under MPI: run it on rank 0 and hand the result to every rank.

``comm`` is any mpi4py-style communicator (``rank``, ``size``, ``bcast``) or ``None``; this
module does not import MPI. The result must pickle. An error on rank 0 is raised on every
rank, so no rank waits for a broadcast that never comes.
"""
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")


def on_root(comm, work: Callable[[], T]) -> T:
    """``work()`` on rank 0 of ``comm`` (directly without ``comm`` or with one rank); its
    result, or its exception, on every rank."""
    if comm is None or comm.size == 1:
        return work()
    result, error = None, None
    if comm.rank == 0:
        try:
            result = work()
        except Exception as exc:  # re-raised on every rank
            error = exc
    result, error = comm.bcast((result, error), root=0)
    if error is not None:
        raise error
    return result
