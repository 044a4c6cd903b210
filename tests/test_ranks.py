"""Serial work under MPI (rkfx.parallel.ranks): rank 0 runs it, every rank gets the result or the error."""
import pytest

from rkfx.parallel.ranks import on_root


class _TwoRanks:
    """A stand-in communicator: this process plays ``rank`` of two; bcast returns what rank 0 sent."""

    size = 2

    def __init__(self, rank, sent=None):
        self.rank, self.sent = rank, sent

    def bcast(self, obj, root=0):
        if self.rank == root:
            self.sent = obj
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
