"""Issue 17, items 4 and 5: the output target of `simulate --out` and `run --out` is checked
before any work (a usage error, exit 2, naming the option and the path: never a traceback
after the simulation); existing files are overwritten only with --force."""

import os
from pathlib import Path

import pytest

import jourdain as jd
from jourdain.cli import EXIT_USAGE, main
from jourdain.io import capabilities, report

ROOT = Path(__file__).resolve().parents[1]
MODEL = ROOT / "examples" / "simple_pendulum.toml"


@pytest.fixture
def no_work(monkeypatch):
    """Fail the test if a command gets as far as simulating or writing a report."""
    def refuse(*args, **kw):
        raise AssertionError("the work started before the output was checked")

    monkeypatch.setattr(capabilities, "simulate", refuse)
    monkeypatch.setattr(report.document, "compute_sections", refuse)


def _run(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err
    return code, cap.out, cap.err


def test_unknown_extension_is_a_usage_error(tmp_path, capsys, no_work):
    code, _, err = _run(capsys, "simulate", MODEL, "--out", tmp_path / "sim.txt")
    assert code == EXIT_USAGE and "--out" in err and "unknown file type '.txt'" in err
    code, _, err = _run(capsys, "simulate", MODEL, "--out", tmp_path / "sim")
    assert code == EXIT_USAGE and "(no extension)" in err


def test_path_under_a_file(tmp_path, capsys, no_work):
    (tmp_path / "plain").write_text("x")
    code, _, err = _run(capsys, "simulate", MODEL, "--out", tmp_path / "plain" / "sim.csv")
    assert code == EXIT_USAGE and "is a file, not a folder" in err
    code, _, err = _run(capsys, "run", MODEL, "--out", tmp_path / "plain" / "report")
    assert code == EXIT_USAGE and "is a file, not a folder" in err
    code, _, err = _run(capsys, "run", MODEL, "--out", tmp_path / "plain")
    assert code == EXIT_USAGE and "is a file; expected a folder" in err


def test_folder_that_cannot_be_written(tmp_path, capsys, no_work):
    # /proc refuses new entries even to root
    code, _, err = _run(capsys, "simulate", MODEL, "--out", "/proc/jourdain-test/sim.csv")
    assert code == EXIT_USAGE and "cannot write in the folder /proc/jourdain-test" in err


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="root writes into read-only folders")
def test_read_only_folder(tmp_path, capsys, no_work):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        code, _, err = _run(capsys, "simulate", MODEL, "--out", ro / "sim.csv")
        assert code == EXIT_USAGE and "cannot write in the folder" in err
        code, _, err = _run(capsys, "run", MODEL, "--out", ro / "report")
        assert code == EXIT_USAGE and "cannot write in the folder" in err
    finally:
        ro.chmod(0o700)


def test_the_models_own_folder_is_refused_for_a_report(tmp_path, capsys, no_work):
    """The report copies the model to model.toml: in the model's own folder that overwrote
    the model itself or failed with a traceback after all the work."""
    model = tmp_path / "model.toml"
    model.write_text(MODEL.read_text())
    code, _, err = _run(capsys, "run", model, "--out", tmp_path)
    assert code == EXIT_USAGE and "is the folder of the model file" in err
    assert model.read_text() == MODEL.read_text()
    code, _, err = _run(capsys, "run", model, "--out", tmp_path, "--force")
    assert code == EXIT_USAGE


def test_existing_results_file_needs_force(tmp_path, capsys):
    out = tmp_path / "sim.csv"
    out.write_text("precious\n")
    code, _, err = _run(capsys, "simulate", MODEL, "--t-end", "0.5", "--out", out)
    assert code == EXIT_USAGE and "the file exists; --force overwrites it" in err
    assert out.read_text() == "precious\n"
    code, text, err = _run(capsys, "simulate", MODEL, "--t-end", "0.5", "--out", out, "--force")
    assert code == 0, err
    assert out.read_text().startswith("# format: jourdain-results")
    code, _, err = _run(capsys, "simulate", MODEL, "--out", tmp_path)
    assert code == EXIT_USAGE and "is a folder" in err


def test_existing_report_needs_force(tmp_path, capsys):
    out = tmp_path / "r"
    code, _, err = _run(capsys, "run", MODEL, "--t-end", "0.5", "--out", out)
    assert code == 0, err
    assert set(report.report_files(jd.load_model(MODEL))) <= {p.name for p in out.iterdir()}
    (out / "report.html").write_text("precious")
    code, _, err = _run(capsys, "run", MODEL, "--t-end", "0.5", "--out", out)
    assert code == EXIT_USAGE and "would overwrite report.html" in err and "--force" in err
    assert (out / "report.html").read_text() == "precious"
    code, _, err = _run(capsys, "run", MODEL, "--t-end", "0.5", "--out", out, "--force")
    assert code == 0, err
    assert "<svg" in (out / "report.html").read_text()
    # a folder holding other files only is fine
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    code, _, err = _run(capsys, "run", MODEL, "--t-end", "0.5", "--out", other)
    assert code == 0, err
    assert (other / "notes.txt").read_text() == "mine"


def test_missing_model_file_is_a_usage_error(tmp_path, capsys):
    for cmd in (["check"], ["simulate"], ["run", "--out", str(tmp_path / "r")]):
        code, _, err = _run(capsys, cmd[0], tmp_path / "nowhere.toml", *cmd[1:])
        assert code == EXIT_USAGE and "nowhere.toml: no such model file" in err
    code, _, err = _run(capsys, "check", tmp_path)
    assert code == EXIT_USAGE and "is a folder; expected a model file" in err
    assert not (tmp_path / "r").exists()
