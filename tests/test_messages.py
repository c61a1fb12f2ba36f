"""Error messages that say what and where (issue 17, item 6)."""

from pathlib import Path

import pytest

import jourdain as jd

EXAMPLE = (Path(__file__).parent.parent / "examples" / "double_pendulum.toml").read_text()


def _load_error(tmp_path: Path, text: str) -> jd.ModelFileError:
    path = tmp_path / "model.toml"
    path.write_text(text)
    with pytest.raises(jd.ModelFileError) as info:
        jd.load_model(path)
    return info.value


def _line_of(text: str, start: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), 1) if line.startswith(start))


def test_a_negative_mass_parameter_is_reported_at_the_parameter_once(tmp_path):
    text = "\n".join('m2 = { value = -0.5, unit = "kg" }' if line.startswith("m2 =") else line
                     for line in EXAMPLE.splitlines())
    err = _load_error(tmp_path, text)
    assert err.line == _line_of(text, "m2 =")
    assert 'parameter "m2"' in str(err) and 'body "rod2"' in str(err)
    assert str(err).count('body "rod2"') == 1 and "got -0.5" in str(err)


def test_a_name_in_the_wrong_case_gets_a_suggestion(tmp_path):
    err = _load_error(tmp_path, EXAMPLE.replace('"-g"', '"-G"'))
    assert "unknown name 'G'" in str(err) and '(did you mean "g"?)' in str(err)


def test_the_candidate_parents_of_a_body_are_the_other_bodies(tmp_path):
    text = EXAMPLE.replace('parent = "rod1"', 'parent = "rod3"')
    err = _load_error(tmp_path, text)
    assert 'unknown parent "rod3" (did you mean "rod1"?)' in str(err)
    assert str(err).endswith('expected "world" or one of the bodies rod1')


def test_python_messages_name_the_joint_and_the_element_using_a_symbol():
    q, g = jd.symbols("q g")
    with pytest.raises(jd.ModelError, match=r'joint "hinge" axis: expected one of x, y, z'):
        jd.Revolute("hinge", q, "w")
    body = jd.Body("b", "world", jd.Revolute("h", q, "z"), mass=1.0, com=(0, -1, 0),
                   inertia=jd.point_mass())
    with pytest.raises(jd.ModelError, match=r'force "gravity": undeclared symbol\(s\) \[\'g\'\]'):
        jd.System([q], [body], [jd.Gravity((0, -g, 0))])


def test_parameters_given_to_evaluate_are_checked_like_the_defaults():
    """A negative mass given at evaluation time is refused (it would give an indefinite M)."""
    from jourdain.models import double_pendulum

    s = double_pendulum()
    assert s.evaluate([0.1, 0.2], [0.0, 0.0], parameters={"m2": 0.8})["M"][0, 0] > 0
    with pytest.raises(jd.EvaluationError, match=r'with the parameters m2=-1: body "rod2": mass '
                                                 r"must be a non-negative number"):
        s.evaluate([0.1, 0.2], [0.0, 0.0], parameters={"m2": -1})


# ------------------------------------------------------------------------------------------
# issue 33, item 10
# ------------------------------------------------------------------------------------------

ROOT = Path(__file__).parent.parent


def test_a_loop_error_of_check_names_the_file(tmp_path, capsys, monkeypatch):
    """An error of the loops' summary (assembly, rank, partition at the initial state) is
    located in the file like every other error of jourdain check. Before: the bare
    message."""
    from jourdain.cli import main
    from jourdain.loops import report

    def fail(model):
        raise jd.AssemblyError("four-bar linkage: no configuration on the manifold")

    monkeypatch.setattr(report, "loop_summary", fail)
    path = tmp_path / "four_bar.toml"
    path.write_text((ROOT / "examples" / "four_bar.toml").read_text())
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"jourdain check: error: {path}:" in err
    assert "the loops at the initial state: four-bar linkage: no configuration" in err


def test_the_study_resume_error_names_the_option_of_each_interface(tmp_path, capsys):
    """The command line says --force, Python force=True; before, the command line said
    "pass force=True (--force)"."""
    from jourdain.cli import main
    from jourdain.study import StudyError, load_study, run_study

    spec = ROOT / "tests" / "data" / "study" / "montecarlo.toml"
    out = tmp_path / "mc.nc"
    out.write_text("")
    assert main(["study", "--spec", str(spec), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert f"{out} exists; pass --force to replace it" in err and "force=True" not in err
    with pytest.raises(StudyError, match=r"exists; pass force=True to replace it$"):
        run_study(load_study(spec), out, quiet=True)


def test_warnings_are_one_line_without_their_source(tmp_path, capsys, monkeypatch):
    """A warning during a command is one line naming the command; never the Python file,
    line and source of the warnings.warn, and NumPy's overflow warnings not at all (the
    overflowing result is an error that names the quantity)."""
    import warnings

    import numpy as np

    from jourdain.cli import main, model_commands

    def noisy(model):
        warnings.warn("the nominal motion is not a solution", jd.JourdainWarning, stacklevel=1)
        np.float64(1e308) * 10.0  # RuntimeWarning: overflow encountered
        np.array([1e308]) * 10.0

    monkeypatch.setattr(model_commands, "check_initial_state", noisy)
    assert main(["check", str(ROOT / "examples" / "simple_pendulum.toml")]) == 0
    err = capsys.readouterr().err
    assert err == "jourdain check: warning: the nominal motion is not a solution\n", err
    # the filters and the display are the caller's again afterwards
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        np.array([1e308]) * 10.0
    assert [w.category for w in seen] == [RuntimeWarning]


def test_a_value_of_5000_characters_is_not_echoed_whole(tmp_path, capsys):
    from jourdain.cli import main

    text = EXAMPLE.replace('type = "revolute"', 'type = "' + "revolute@" * 560 + '"', 1)
    path = tmp_path / "model.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 1
    err = capsys.readouterr().err
    assert f"{path}:" in err and "characters)" in err
    assert len(err) < 600, len(err)
    with pytest.raises(SystemExit) as exit_:  # argparse's own error, exit status 2
        main(["simulate", str(path), "--method", "x" * 5000])
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert "usage error" in err and max(len(ln) for ln in err.splitlines()) < 600
