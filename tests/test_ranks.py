"""Serial work under MPI (rkfx.parallel.ranks): rank 0 runs it, every rank gets the result or the error."""
import pytest

from rkfx.parallel.ranks import on_root


class _TwoRanks:
    """A stand-in communicator: this process plays ``rank`` of two; rank 1 receives what rank 0
    sent, after a few empty probes."""

    size = 2

    def __init__(self, rank, sent=None):
        self.rank, self.sent, self.probes = rank, sent, 0

    def send(self, obj, dest, tag):
        self.sent = obj

    def iprobe(self, source, tag):
        self.probes += 1
        return self.probes > 3

    def recv(self, source, tag):
        return self.sent


def test_serial_work_runs_on_rank_zero_only_and_errors_reach_every_rank():
    calls = []
    root = _TwoRanks(0)
    assert on_root(root, lambda: calls.append(0) or "done") == "done"
    assert on_root(_TwoRanks(1, root.sent), lambda: calls.append(1)) == "done" and calls == [0]
    assert on_root(None, lambda: 7) == 7

    def fail():
        raise ValueError("bad")

    root = _TwoRanks(0)
    with pytest.raises(ValueError, match="bad"):
        on_root(root, fail)
    with pytest.raises(ValueError, match="bad"):
        on_root(_TwoRanks(1, root.sent), fail)


def test_share_cores_gives_each_rank_its_share(monkeypatch):
    import numba

    from rkfx.parallel import threads

    monkeypatch.delenv("NUMBA_NUM_THREADS", raising=False)
    before = numba.get_num_threads()
    try:
        monkeypatch.setattr(threads, "ranks_on_this_node", lambda comm: 2)
        assert threads.share_cores(object(), cores=2) == 1
        monkeypatch.setattr(threads, "ranks_on_this_node", lambda comm: 3)
        assert threads.share_cores(object(), cores=2) == 1  # never below one thread
        monkeypatch.setattr(threads, "ranks_on_this_node", lambda comm: 1)
        assert threads.share_cores(None, cores=1) == 1
        assert threads.ranks_on_this_node(None) == 1
        monkeypatch.setenv("NUMBA_NUM_THREADS", "1")
        numba.set_num_threads(before)
        assert threads.share_cores(object(), cores=1) == before  # the user's choice stands
    finally:
        numba.set_num_threads(before)
