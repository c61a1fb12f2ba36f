"""An HDF5 file whose lock another holds for a moment (a compiler forked by a build thread
inherits the descriptors of files open at that moment): opened once the lock is free; held
longer than the wait, the error is raised."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

h5py = pytest.importorskip("h5py")

from jourdain.simulation.results import files  # noqa: E402

HOLD = ("import sys, time, h5py\nf = h5py.File(sys.argv[1], 'r+')\nprint('held', flush=True)\n"
        "time.sleep(float(sys.argv[2]))\nf.close()\n")


def _holder(path, seconds: float) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", HOLD, str(path), str(seconds)],
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None and proc.stdout.readline().strip() == "held"
    return proc


def test_a_lock_held_for_a_moment_is_waited_for(tmp_path):
    path = tmp_path / "r.h5"
    with h5py.File(path, "w") as h:
        h["x"] = np.arange(3.0)
    proc = _holder(path, 1.0)
    with pytest.raises(BlockingIOError):  # what h5py alone does meanwhile
        h5py.File(path, "r")
    with files.h5_file(path, "r") as h:
        assert h["x"][()].tolist() == [0.0, 1.0, 2.0]
    proc.wait(timeout=30)


def test_a_lock_held_longer_is_an_error(tmp_path, monkeypatch):
    path = tmp_path / "r.h5"
    with h5py.File(path, "w") as h:
        h["x"] = np.arange(3.0)
    monkeypatch.setattr(files, "LOCK_WAIT_S", 0.05)
    proc = _holder(path, 3.0)
    try:
        with pytest.raises(BlockingIOError):
            files.h5_file(path, "r")
    finally:
        proc.kill()
        proc.wait(timeout=30)
