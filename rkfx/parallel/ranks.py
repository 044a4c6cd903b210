"""Serial work under MPI: run it on rank 0 and hand the result to every rank.

``comm`` is any mpi4py-style communicator (``rank``, ``size``, ``send``, ``iprobe``, ``recv``) or
``None``; this module does not import MPI. The result must pickle. An error on rank 0 is
raised on every rank, so no rank waits for a message that never comes. The waiting ranks
sleep between polls of their receive (1 ms at first, backing off to 50 ms) instead of
spinning in a blocking broadcast, so the cores stay with the rank that works.
"""
import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

_FIRST_POLL, _LONGEST_POLL = 1e-3, 5e-2  # [s]
_TAG = 7301


def wait_idle(comm, source: int, tag: int, first: float = _FIRST_POLL, longest: float = _LONGEST_POLL):
    """Receive one message from ``source``, sleeping between probes (backing off) until it is there."""
    pause = first
    while not comm.iprobe(source=source, tag=tag):
        time.sleep(pause)
        pause = min(2.0 * pause, longest)
    return comm.recv(source=source, tag=tag)


def on_root(comm, work: Callable[[], T]) -> T:
    """``work()`` on rank 0 of ``comm`` (directly without ``comm`` or with one rank); its
    result, or its exception, on every rank."""
    if comm is None or comm.size == 1:
        return work()
    if comm.rank == 0:
        result, error = None, None
        try:
            result = work()
        except Exception as exc:  # re-raised on every rank
            error = exc
        for r in range(1, comm.size):
            comm.send((result, error), dest=r, tag=_TAG)
    else:
        result, error = wait_idle(comm, 0, _TAG)
    if error is not None:
        raise error
    return result
