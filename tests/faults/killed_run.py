"""Run a small Kalthoff model (or a quick Mandel run) through the CLI and SIGKILL the process
at a chosen point.

    python tests/faults/killed_run.py OUT POINT N [CASE]

POINT is where the process dies:
    after-checkpoint  right after the N-th checkpoint is in place;
    mid-checkpoint    half-way through writing the N-th checkpoint's temporary file;
    mid-previous      after the N-th checkpoint's predecessor became checkpoint.previous.npz,
                      before the new one replaces checkpoint.npz;
    mid-result        half-way through writing a finished run's result.npz (N-th run);
    never             run to the end.
CASE is ``kalthoff`` (default), ``mandel``, ``liakopoulos`` or ``wave_column``; under mpiexec every rank dies at its own N-th
checkpoint (one file per rank).
"""
import importlib
import io
import os
import signal
import sys

import numpy as np

from rkfx.solvers import checkpoint

ARGS = ["--method", "rkpm", "--set", "h=2.564e-3", "unregularized_h=2.564e-3", "no_tracking_h=2.564e-3", "nonlocal_h=none",
        "t_end=2e-5", "--checkpoint-every", "20"]
MANDEL_ARGS = ["--quick", "--method", "rkpm", "--checkpoint-every", "4"]
LIAKOPOULOS_ARGS = ["--quick", "--method", "rkpm", "--checkpoint-every", "30"]
WAVE_COLUMN_ARGS = ["--quick", "--method", "rkpm", "--checkpoint-every", "200"]
CASE_ARGS = {"kalthoff": ARGS, "mandel": MANDEL_ARGS, "liakopoulos": LIAKOPOULOS_ARGS, "wave_column": WAVE_COLUMN_ARGS}


def die():
    sys.stdout.flush()
    os.kill(os.getpid(), signal.SIGKILL)


def main(out: str, point: str, n: int, case: str = "kalthoff") -> None:
    calls = {"checkpoint": 0, "result": 0}
    savez, replace, keep = np.savez, os.replace, checkpoint._keep_as_previous

    def counted(fh) -> tuple[str, int]:
        kind = "result" if "result" in getattr(fh, "name", "") else "checkpoint"
        calls[kind] += 1
        return kind, calls[kind]

    def half_written(fh, **arrays):
        kind, k = counted(fh)
        if (point, k) in (("mid-checkpoint", n), ("mid-result", n)) and kind in point:
            buf = io.BytesIO()
            savez(buf, **arrays)
            fh.write(buf.getvalue()[: len(buf.getvalue()) // 2])
            fh.flush()
            os.fsync(fh.fileno())
            die()
        savez(fh, **arrays)

    def replaced(src, dst):
        replace(src, dst)
        if point == "after-checkpoint" and str(dst).endswith(checkpoint.CHECKPOINT) and calls["checkpoint"] == n:
            die()

    def kept(target, previous):
        keep(target, previous)
        if point == "mid-previous" and calls["checkpoint"] == n:
            die()

    checkpoint.np.savez = half_written
    checkpoint.os.replace = replaced
    checkpoint._keep_as_previous = kept
    importlib.import_module(f"rkfx.cases.{case}").main([*CASE_ARGS[case], "--out", out])


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]), *sys.argv[4:5])
