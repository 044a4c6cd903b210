"""Checkpoint files: named arrays written atomically, so an interrupted run never leaves a
half-written checkpoint (temporary file, fsync, then ``os.replace``).

A checkpoint folder keeps the last two checkpoints: ``checkpoint.npz`` and, before it,
``checkpoint.previous.npz``. A resume reads the newest; when that one is unreadable (a disk
that filled up, a file damaged after it was written) it says so and falls back to the
previous one, from which the deterministic run reaches the same result.
"""
import logging
import os
import shutil
import sys
import zipfile
import zlib
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from rkfx.errors import InputError

CHECKPOINT = "checkpoint.npz"
PREVIOUS = "checkpoint.previous.npz"  # the checkpoint before the newest
log = logging.getLogger("rkfx")


class _EachRank:
    """Passed as ``comm``: the calling rank writes its own file (one file per rank)."""

    rank = 0


EACH_RANK = _EachRank()


def rank_folder(directory: str | Path, rank: int, size: int) -> Path:
    """The folder of rank ``rank``'s files of a run on ``size`` ranks: ``DIR/rank<r>-of-<P>``."""
    return Path(directory) / f"rank{rank}-of-{size}"


class RankFiles:
    """Where one process of a run keeps its checkpoints.

    A model whose ``share`` (``rank``, ``size``, ``least``) splits it over several MPI ranks
    keeps one checkpoint per rank in ``rank<r>-of-<P>/`` and resumes from the newest step all
    ranks hold; any other run keeps one checkpoint in the folder itself, written by rank 0 of
    ``comm`` (``writes``).
    """

    def __init__(self, share=None, comm=None):
        self.share = share
        self.per_rank = share is not None and share.size > 1
        self.writer = EACH_RANK if self.per_rank else comm

    def folder(self, directory: str | Path | None) -> Path | None:
        """This process's checkpoint folder in ``directory`` (``None`` stays ``None``)."""
        if directory is None:
            return None
        return rank_folder(directory, self.share.rank, self.share.size) if self.per_rank else Path(directory)

    def load(self, directory: str | Path) -> dict[str, np.ndarray]:
        """``load_arrays`` of this process's folder in ``directory`` (collective on ranks)."""
        return load_arrays(self.folder(directory), common=self.share.least if self.per_rank else None)


def _ranks_of(folder: Path) -> int | None:
    """P of a ``rank<r>-of-<P>`` folder, else ``None``."""
    head, sep, size = folder.name.rpartition("-of-")
    return int(size) if sep and head.startswith("rank") and size.isdigit() else None


def _written_on(directory: Path) -> int | None:
    """On how many ranks the checkpoints in ``directory`` (a run's folder) were written, if any."""
    if any((directory / n).is_file() for n in (CHECKPOINT, PREVIOUS)):
        return 1
    sizes = {_ranks_of(d) for d in directory.glob("rank*-of-*") if d.is_dir() and has_checkpoint(d)} - {None} \
        if directory.is_dir() else set()
    return min(sizes) if sizes else None


def writes(comm) -> bool:
    """Whether this rank writes the files of a replicated state: rank 0 of ``comm``, or of
    MPI's world when no communicator is given and MPI is in use (this module never imports it)."""
    if comm is None:
        mpi = sys.modules.get("mpi4py.MPI")
        comm = mpi.COMM_WORLD if mpi is not None else None
    return comm is None or comm.rank == 0


def save_arrays(directory: str | Path, arrays: Mapping[str, np.ndarray], name: str = CHECKPOINT,
                comm=None) -> Path:
    """Write ``DIR/name`` atomically (on one rank of ``comm``, see ``writes``); returns its path.

    A new checkpoint (``name`` = ``CHECKPOINT``) first keeps the one it replaces as ``PREVIOUS``,
    so that at every instant the folder holds a complete newest checkpoint.
    """
    directory = Path(directory)
    if not writes(comm):
        return directory / name
    directory.mkdir(parents=True, exist_ok=True)
    target = directory / name
    tmp = directory / (name + ".tmp")
    with open(tmp, "wb") as fh:
        np.savez(fh, **{k: np.asarray(v) for k, v in arrays.items()})
        fh.flush()
        os.fsync(fh.fileno())
    if name == CHECKPOINT and target.is_file():
        _keep_as_previous(target, directory / PREVIOUS)
    os.replace(tmp, target)
    return target


def _keep_as_previous(target: Path, previous: Path) -> None:
    """``target`` also under the name ``previous``: a hard link renamed into place, so ``target``
    never goes missing (a copy where the file system has no links)."""
    tmp = previous.with_name(previous.name + ".tmp")
    tmp.unlink(missing_ok=True)
    try:
        os.link(target, tmp)
    except OSError:
        shutil.copyfile(target, tmp)
    os.replace(tmp, previous)


def run_folder(label: str) -> str:
    """The folder of a run's files (checkpoints, finished result) in a work directory: its label
    with spaces as '_', '/' as '-' and '=' dropped (``"rkpm-dpm n=150"`` -> ``rkpm-dpm_n150``)."""
    return label.replace(" ", "_").replace("=", "").replace("/", "-")


def has_checkpoint(directory: str | Path | None) -> bool:
    """Whether ``directory`` holds a checkpoint to resume from (the newest or the previous one,
    or one per rank in ``rank<r>-of-<P>/`` folders)."""
    if directory is None:
        return False
    directory = Path(directory)
    return any((directory / n).is_file() for n in (CHECKPOINT, PREVIOUS)) or \
        any(has_checkpoint(d) for d in directory.glob("rank*-of-*") if d.is_dir())


def read_arrays(path: str | Path) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` file at path; a truncated or garbled file gives a one-line
    error naming it and what to do."""
    path = Path(path)
    try:
        with np.load(path) as z:
            return {k: z[k] for k in z.files}
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, KeyError) as err:
        why = str(err).split(". ")[0][:80]
        raise InputError(f"{path} is unreadable ({type(err).__name__}: {why}); delete {path.parent} to compute "
                         "that run again, or resume without it") from None


def _step(arrays: Mapping[str, np.ndarray]) -> int | None:
    return next((int(v) for k, v in arrays.items() if k.split("__")[-1] == "step" and np.ndim(v) == 0), None)


def load_arrays(directory: str | Path, common: Callable[[int], int] | None = None) -> dict[str, np.ndarray]:
    """The arrays of the newest readable checkpoint in ``directory`` (logged as a resume, with its
    step, on logger ``rkfx``): ``CHECKPOINT``, else ``PREVIOUS`` with a warning naming why.

    ``common``: for one file per rank, the smallest of a step over the ranks (collective). The
    ranks agree on the newest step they all hold (a run killed while the ranks wrote a
    checkpoint leaves some of them one checkpoint ahead) and read that one.
    """
    directory = Path(directory)
    if common is None:
        return _load_newest(directory)
    try:
        arrays, error = _load_newest(directory), None
    except InputError as err:
        arrays, error = None, err
    mine = -1 if arrays is None else _step(arrays)
    agreed = common(mine)
    if agreed < 0:
        raise error or InputError(f"another rank cannot read its checkpoint beside {directory}; see its message")
    if mine != agreed:
        previous = directory / PREVIOUS
        arrays = read_arrays(previous) if previous.is_file() else {}
        if _step(arrays) != agreed:
            raise InputError(f"the ranks' checkpoints in {directory.parent} share no step ({directory.name} is at "
                             f"step {mine}, another rank at {agreed}); delete {directory.parent} to compute that "
                             "run again")
        log.info("resume: %s continues from step %s, the newest step of every rank", directory.name, agreed)
    return arrays


def _load_newest(directory: Path) -> dict[str, np.ndarray]:
    newest, previous = directory / CHECKPOINT, directory / PREVIOUS
    if not (newest.is_file() or previous.is_file()):
        now = _ranks_of(directory)
        run = directory if now is None else directory.parent
        now = now or 1
        ranks = _written_on(run)
        if ranks is not None and ranks != now:
            how = f"on {ranks} ranks" if ranks > 1 else "serially"
            again = f"mpiexec -n {ranks} ..." if ranks > 1 else "without mpiexec"
            raise InputError(f"the checkpoint in {run} was written {how}, this run has {now} rank(s); resume "
                             f"{again}, or delete {run} to compute that run again")
        raise InputError(f"no checkpoint at {str(newest)!r}; run with a checkpoint interval and folder first")
    try:
        arrays = read_arrays(newest) if newest.is_file() else None
    except InputError as err:
        if not previous.is_file():
            raise
        log.warning("resume: %s; falling back to %s", str(err).split(";")[0], previous.name)
        arrays = None
    if arrays is None:
        try:
            arrays = read_arrays(previous)
        except InputError:
            raise InputError(f"{newest} and {previous.name} beside it are unreadable; delete {directory} to "
                             "compute that run again") from None
    step = _step(arrays)
    log.info("resume: %s continues from step %s", directory.name, "?" if step is None else step)
    return arrays


def prefixed(arrays: Mapping[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    """``arrays`` with every name prefixed (to store several groups in one file)."""
    return {prefix + k: v for k, v in arrays.items()}


def unprefixed(arrays: Mapping[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    """The group of ``arrays`` stored under ``prefix``, without it."""
    return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}


def copy_into(targets: Mapping[str, np.ndarray], arrays: Mapping[str, np.ndarray], what: str = "array") -> None:
    """Set every array of ``targets`` in place from the one of the same name in ``arrays`` (the
    history of a resumed run, which its force or recorder holds on to)."""
    for k, arr in targets.items():
        if k not in arrays:
            raise InputError(f"checkpoint has no {what} {k!r}; it holds {sorted(arrays)}")
        if np.shape(arrays[k]) != arr.shape:
            raise InputError(f"checkpoint's {what} {k!r} has shape {np.shape(arrays[k])}, this run's {arr.shape}: "
                             "it was written by another version or set-up; delete it to start afresh")
        arr[...] = arrays[k]


MODEL, KEPT = "model__", "kept__"  # prefixes of the model's history and the recorder's arrays


def save_run(directory: str | Path, arrays: Mapping[str, np.ndarray], model, recorder=None,
             comm=None) -> Path:
    """A stepper's checkpoint: its own ``arrays``, the model's committed ``state()`` and the
    recorder's ``arrays()`` (when there is one), in one file written atomically."""
    out = dict(arrays) | prefixed(model.state(), MODEL)
    if recorder is not None:
        out |= prefixed(recorder.arrays(), KEPT)
    return save_arrays(directory, out, comm=comm)


def restore_run(arrays: Mapping[str, np.ndarray], model, recorder=None) -> None:
    """Restore the model's history and the recorder's arrays from the ``load_arrays`` of a
    ``save_run`` checkpoint (the stepper reads its own arrays)."""
    model.restore(unprefixed(arrays, MODEL))
    if recorder is not None:
        recorder.restore(unprefixed(arrays, KEPT))

