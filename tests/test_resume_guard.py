"""Runs never lose or mix work: a resume refuses runs computed with other parameters (or, with
--recompute, computes them again), and a run killed anywhere — between steps, half-way through
a checkpoint or a finished-run file — resumes to the results of an uninterrupted run, bit for
bit; a garbled newest checkpoint falls back to the previous one."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rkfx.cases import kalthoff
from rkfx.errors import InputError
from rkfx.solvers.checkpoint import CHECKPOINT, PREVIOUS, has_checkpoint, load_arrays, save_arrays

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "faults"))
from killed_run import ARGS  # noqa: E402


def runs(out: Path) -> dict:
    """Every run's method, series, errors and info (not its wall time) from results.json."""
    data = json.loads((out / "results.json").read_text())
    return {r["method"]: (r["series"], r["errors"], r["info"]) for r in data["runs"]}


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    out = tmp_path_factory.mktemp("whole")
    assert kalthoff.main([*ARGS, "--out", str(out)]) == 0
    return out


def killed(out: Path, point: str, n: int) -> None:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "faults" / "killed_run.py"), str(out), point, str(n)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == -9, (point, n, proc.returncode, proc.stderr[-2000:])


@pytest.mark.parametrize("point, n", [("after-checkpoint", 2), ("mid-checkpoint", 3), ("mid-previous", 6),
                                      ("mid-result", 2)])
def test_killed_anywhere_resumes_bit_identical(whole, tmp_path, point, n, capsys):
    out = tmp_path / "run"
    killed(out, point, n)
    assert not (out / "results.json").exists()
    assert kalthoff.main([*ARGS, "--resume", str(out)]) == 0
    assert runs(out) == runs(whole)
    assert "resume:" in capsys.readouterr().err


def test_a_garbled_newest_checkpoint_falls_back_to_the_previous(whole, tmp_path, capsys):
    out = tmp_path / "run"
    killed(out, "after-checkpoint", 3)  # inside the first model: its checkpoints 2 and 3 are kept
    folder = next(d for d in (out / "checkpoints").iterdir() if has_checkpoint(d))
    assert (folder / PREVIOUS).is_file()
    newest = folder / CHECKPOINT
    newest.write_bytes(newest.read_bytes()[:200])
    capsys.readouterr()
    assert kalthoff.main([*ARGS, "--resume", str(out)]) == 0
    err = capsys.readouterr().err
    assert "falling back to checkpoint.previous.npz" in err and CHECKPOINT in err, err
    assert runs(out) == runs(whole)


def test_a_checkpoint_keeps_its_predecessor(tmp_path):
    for step in (1, 2, 3):
        save_arrays(tmp_path, {"state__step": np.int64(step)})
    assert int(load_arrays(tmp_path)["state__step"]) == 3
    (tmp_path / CHECKPOINT).write_bytes(b"garbage")
    assert int(load_arrays(tmp_path)["state__step"]) == 2
    (tmp_path / PREVIOUS).write_bytes(b"garbage")
    with pytest.raises(InputError, match=f"{CHECKPOINT} and {PREVIOUS} beside it are unreadable"):
        load_arrays(tmp_path)


def test_resume_with_other_parameters_is_refused_in_one_line(whole, tmp_path, capsys):
    """Resuming a v0 = 16.5 folder with v0 = 30 would label v0 = 16.5 models as v0 = 30."""
    out = tmp_path / "k"
    assert kalthoff.main([*ARGS, "--out", str(out)]) == 0
    capsys.readouterr()
    before = sorted(p.relative_to(out) for p in out.rglob("*"))
    with pytest.raises(SystemExit) as err:
        kalthoff.main([*ARGS, "--resume", str(out), "--set", "v0=30", "GF=3e4"])
    message = capsys.readouterr().err.strip().splitlines()
    assert err.value.code == 2 and len(message) == 1, message
    assert "v0 = 16.5 (now 30.0)" in message[0] and "GF = 20000.0 (now 30000.0)" in message[0], message
    assert "--recompute" in message[0]
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == before  # nothing moved or written


def test_recompute_computes_the_differing_runs_again(tmp_path, capsys):
    out, fresh = tmp_path / "k", tmp_path / "fresh"
    assert kalthoff.main([*ARGS, "--out", str(out)]) == 0
    assert kalthoff.main([*ARGS, "--set", "v0=30", "--out", str(fresh)]) == 0
    capsys.readouterr()
    assert kalthoff.main([*ARGS, "--set", "v0=30", "--resume", str(out), "--recompute"]) == 0
    assert "computing every run again" in capsys.readouterr().err
    assert runs(out) == runs(fresh)
    assert json.loads((out / "checkpoints" / "fingerprint.json").read_text())["params"]["v0"] == 30.0
    assert (out / "previous" / "checkpoints" / "fingerprint.json").is_file()  # the v0 = 16.5 runs, kept aside
    # the folder now resumes with v0 = 30 without recomputing
    assert kalthoff.main([*ARGS, "--set", "v0=30", "--resume", str(out)]) == 0
    assert "read back finished" in capsys.readouterr().err


def test_a_new_level_on_resume_keeps_the_stored_runs(whole, tmp_path, capsys):
    """Values that only choose which runs exist (fingerprint=False) may change on resume."""
    out = tmp_path / "k"
    assert kalthoff.main([*ARGS, "--out", str(out)]) == 0
    capsys.readouterr()
    more = [*ARGS[:-2], "angle_radius=0.05", *ARGS[-2:]]
    assert kalthoff.main([*more, "--resume", str(out)]) == 0
    assert capsys.readouterr().err.count("read back finished") == 3


def test_a_folder_without_fingerprint_is_not_trusted(whole, tmp_path, capsys):
    out = tmp_path / "k"
    assert kalthoff.main([*ARGS, "--out", str(out)]) == 0
    (out / "checkpoints" / "fingerprint.json").unlink()
    capsys.readouterr()
    with pytest.raises(SystemExit):
        kalthoff.main([*ARGS, "--resume", str(out)])
    assert "no fingerprint.json" in capsys.readouterr().err


def test_bad_input_leaves_no_fingerprint(tmp_path, capsys):
    out = tmp_path / "k"
    with pytest.raises(SystemExit):
        kalthoff.main([*ARGS, "--set", "h=0.01", "--out", str(out)])
    assert not out.exists()
    with pytest.raises(SystemExit):
        kalthoff.main([*ARGS, "--recompute", "--out", str(out)])
    assert "--recompute" in capsys.readouterr().err and not out.exists()


def test_a_checkpoint_of_another_shape_is_refused_in_one_line():
    """A history written by another version (e.g. fewer history columns) names the array and
    the way out instead of failing inside numpy."""
    from rkfx.solvers.checkpoint import copy_into

    target = {"history": np.zeros((4, 7))}
    with pytest.raises(InputError, match=r"'history' has shape \(4, 6\), this run's \(4, 7\).*delete it") as err:
        copy_into(target, {"history": np.ones((4, 6))}, "run history")
    assert "\n" not in str(err.value)
    copy_into(target, {"history": np.ones((4, 7))}, "run history")
    assert target["history"].sum() == 28
