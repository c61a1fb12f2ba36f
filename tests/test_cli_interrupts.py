"""Issue 17, item 4: an interrupted or failed run of `jourdain simulate` and `jourdain run` keeps
what it computed, says so on screen and in every file it wrote, and exits 130 (Ctrl-C) or 1
(the integration failed)."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import EXIT_INTERRUPTED, main
from jourdain.io import capabilities

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: a point mass in polar coordinates pulled to the centre by an overdamped spring: M = diag(m x²,
#: m) loses positive definiteness as x = exp(−5 t) → 0, at t ≈ 2.99 (tests/test_simulate.py)
POLAR_BEAD = """
[model]
name = "polar bead"
[coordinates]
a = "rad"
x = "m"
[parameters]
m = 1.0
[bodies.arm]
parent = "world"
mass = 0
inertia = "point"
joint = { type = "revolute", coordinate = "a", axis = "z" }
[bodies.bead]
parent = "arm"
mass = "m"
inertia = "point"
joint = { type = "prismatic", coordinate = "x", axis = "x" }
[forces.pull]
type = "rotational_spring_damper"
coordinate = "x"
stiffness = 100
damping = 25
[simulation]
t_end = 10
y0 = { x = 1 }
yd0 = { x = -5 }
rtol = 1e-10
atol = 1e-12
"""


def _command() -> list[str]:
    exe = Path(sys.executable).parent / "jourdain"
    return [str(exe)] if exe.is_file() else [sys.executable, "-m", "jourdain.cli"]


def _data_rows(path: Path) -> int:
    try:
        return sum(1 for line in path.read_text().splitlines()[1:] if line[:1].isdigit()
                   or line[:1] == "-")
    except (OSError, UnicodeDecodeError):
        return 0


def _interrupt_when(proc: subprocess.Popen, started, timeout: float = 60.0) -> tuple[str, str]:
    """Send SIGINT once ``started()`` holds (the run is under way and writing), then wait for
    the end."""
    t0 = time.monotonic()
    try:
        while not started():
            assert proc.poll() is None, proc.communicate()
            assert time.monotonic() - t0 < timeout, "the run wrote nothing while it went"
            time.sleep(0.1)
        proc.send_signal(signal.SIGINT)
        return proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()


def test_sigint_during_simulate_keeps_the_motion_and_exits_130(tmp_path):
    """A long run (10⁶ s of a double pendulum) that writes as it goes: SIGINT once rows are in
    the file. Before: exit 0 and a report of success; now 130, the message on screen, the
    header of the file says where the motion ends."""
    out = tmp_path / "long.csv"
    proc = subprocess.Popen([*_command(), "simulate", str(EXAMPLES / "double_pendulum.toml"),
                             "--t-end", "1e6", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stdout, stderr = _interrupt_when(proc, lambda: _data_rows(out) >= 3)
    assert proc.returncode == EXIT_INTERRUPTED, stderr
    assert "Traceback" not in stderr
    assert "interrupted (Ctrl-C) at t = " in stderr and f"is in {out}" in stderr
    assert f"wrote {out}" in stdout and "; interrupted)" in stdout
    res = jd.Results.load(out)
    assert res.status == "interrupted" and "Ctrl-C" in res.message
    assert len(res.t) >= 3 and 0 < res.t[-1] < 1e6
    assert np.all(np.isfinite(res.ydd))  # the complete file replaced the partial one


def test_sigint_during_run_writes_the_report_of_what_was_computed(tmp_path):
    """`jourdain run` interrupted in its simulation: report.html, run.json and simulation.csv
    are written and each says the run was interrupted; exit 130."""
    out = tmp_path / "report"
    csv = out / "simulation.csv"
    proc = subprocess.Popen([*_command(), "run", str(EXAMPLES / "double_pendulum.toml"),
                             "--t-end", "1e6", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    stdout, stderr = _interrupt_when(proc, lambda: _data_rows(csv) >= 3)
    assert proc.returncode == EXIT_INTERRUPTED, stderr
    assert "Traceback" not in stderr and "interrupted" in stderr
    assert f"report: {out / 'report.html'}" in stdout
    manifest = json.loads((out / "run.json").read_text())
    assert manifest["format"] == "jourdain-run/1" and manifest["status"] == "interrupted"
    assert "Ctrl-C" in manifest["message"] and "simulation.csv" in manifest["files"]
    html = (out / "report.html").read_text()
    assert "<p class='bad'>Interrupted: the simulation was interrupted" in html
    assert "The plots and simulation.csv hold the motion up to t = " in html
    assert jd.Results.load(csv).status == "interrupted"


def _interrupting_inputs(monkeypatch, at: float) -> None:
    """Let capabilities.simulate run the model with an input function that raises
    KeyboardInterrupt (as Ctrl-C does) once t passes ``at``."""
    original = capabilities.simulate

    def law(t: float) -> float:
        if t > at:
            raise KeyboardInterrupt
        return 0.0

    def simulate(model, *args, **kw):
        kw["inputs"] = {name: law for name in model.system.input_names}
        return original(model, *args, **kw)

    monkeypatch.setattr(capabilities, "simulate", simulate)


def test_interrupted_simulate_in_process(tmp_path, capsys, monkeypatch):
    _interrupting_inputs(monkeypatch, 0.5)
    out = tmp_path / "car.csv"
    code = main(["simulate", str(EXAMPLES / "quarter_car.toml"), "--t-end", "2", "--out",
                 str(out)])
    cap = capsys.readouterr()
    assert code == EXIT_INTERRUPTED
    res = jd.Results.load(out)
    assert res.status == "interrupted" and 0 < res.t[-1] <= 0.5 and len(res.t) > 10
    assert f"interrupted (Ctrl-C) at t = {res.t[-1]:g};" in cap.err
    assert f"state at t = {res.t[-1]:g}:" in cap.out


def test_interrupted_report_in_process(tmp_path, capsys, monkeypatch):
    _interrupting_inputs(monkeypatch, 0.5)
    code = main(["run", str(EXAMPLES / "quarter_car.toml"), "--t-end", "2", "--out",
                 str(tmp_path / "r")])
    cap = capsys.readouterr()
    assert code == EXIT_INTERRUPTED, cap.err
    assert json.loads((tmp_path / "r" / "run.json").read_text())["status"] == "interrupted"
    assert "Interrupted:" in (tmp_path / "r" / "report.html").read_text()


def test_ctrl_c_before_the_simulation_leaves_a_report_of_the_sections_done(tmp_path,
                                                                          monkeypatch):
    """Ctrl-C while the report linearizes: the sections before it, the banner and run.json."""
    from jourdain.io import report

    def stop(*args, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(capabilities, "linear_analysis", stop)
    model = jd.load_model(EXAMPLES / "double_pendulum.toml")
    try:
        info = report.write_report(model, tmp_path / "r")
    except KeyboardInterrupt:
        pytest.fail("Ctrl-C went through write_report without a report of what was done")
    assert info.status == "interrupted" and "after section 3 of 5" in info.message
    html = (tmp_path / "r" / "report.html").read_text()
    assert "3. Numbers at the initial state" in html and "5. Simulation" not in html
    assert "Interrupted:" in html
    assert json.loads((tmp_path / "r" / "run.json").read_text())["status"] == "interrupted"


def test_failed_integration_writes_the_motion_up_to_the_failure(tmp_path, capsys):
    """Before: nothing written (the API keeps the motion on the exception). Now the motion up
    to the failure is in --out, the file and the message say where it ends; exit 1."""
    model = tmp_path / "polar.toml"
    model.write_text(POLAR_BEAD)
    out = tmp_path / "polar.csv"
    code = main(["simulate", str(model), "--out", str(out)])
    cap = capsys.readouterr()
    assert code == 1
    assert "not positive definite at t = 2.99" in cap.err and "Traceback" not in cap.err
    res = jd.Results.load(out)
    assert res.status == "failed" and "not positive definite" in res.message
    assert 2.5 < res.t[-1] < 3.0 and len(res.t) > 100
    assert f"the motion up to t = {res.t[-1]:g} ({len(res.t)} samples) is in {out}" in cap.err
    assert "; failed)" in cap.out
    # the report: the plots of the motion up to the failure, status "failed", exit 1
    code = main(["run", str(model), "--out", str(tmp_path / "r")])
    cap = capsys.readouterr()
    assert code == 1 and "the simulation failed" in cap.err
    manifest = json.loads((tmp_path / "r" / "run.json").read_text())
    assert manifest["status"] == "failed" and "simulation.csv" in manifest["files"]
    assert jd.Results.load(tmp_path / "r" / "simulation.csv").status == "failed"
    assert "Failed: the simulation failed" in (tmp_path / "r" / "report.html").read_text()


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to a child process")
def test_partial_file_is_readable_while_the_run_goes(tmp_path):
    """The rows written as the run goes can be read at any time (a killed run leaves them)."""
    out = tmp_path / "live.csv"
    proc = subprocess.Popen([*_command(), "simulate", str(EXAMPLES / "double_pendulum.toml"),
                             "--t-end", "1e6", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        while _data_rows(out) < 3:
            assert proc.poll() is None and time.monotonic() - t0 < 120
            time.sleep(0.1)
        partial = jd.Results.load(out)
        assert partial.status == "running" and len(partial.t) >= 3
        assert np.isnan(partial.ydd).all() and partial.y.shape[1] == 2
    finally:
        proc.kill()
        proc.communicate()
