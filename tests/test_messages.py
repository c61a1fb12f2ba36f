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
