"""Compiled threads and MPI ranks sharing one machine's cores.

Each rank starts numba with as many threads as the machine has cores, so n ranks on one node
run n x cores threads on cores cores, and they fight: a Kalthoff run that took 2.6 s serially
took 74 s on two ranks of a two-core machine, 3.2 s with one thread per rank. ``share_cores``
gives each rank its share of the cores of its node.
"""
import os

import numba


def usable_cores() -> int:
    """Cores this process may run on (its affinity mask, else the machine's count)."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def ranks_on_this_node(comm) -> int:
    """How many ranks of ``comm`` (mpi4py-style, or ``None``) share this process's node."""
    if comm is None or comm.size == 1:
        return 1
    from mpi4py import MPI  # noqa: PLC0415  (MPI only where a communicator is given)

    local = comm.Split_type(MPI.COMM_TYPE_SHARED)
    try:
        return local.size
    finally:
        local.Free()


def share_cores(comm, cores: int | None = None) -> int:
    """Set numba's thread count to this rank's share of its node's cores and return it.

    ``max(1, cores // ranks on the node)``; an explicit ``NUMBA_NUM_THREADS`` in the
    environment is the user's choice and is kept. Collective on ``comm`` (it counts the
    ranks of each node).
    """
    local = ranks_on_this_node(comm)
    if os.environ.get("NUMBA_NUM_THREADS"):
        return numba.get_num_threads()
    threads = max(1, (usable_cores() if cores is None else int(cores)) // local)
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    return numba.get_num_threads()
