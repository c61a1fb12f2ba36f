"""The linearization's two floors (issue 16): the stage (:mod:`jourdain.stages.linearization`)
returns symbolic results only; their numbers — ``evaluate``, ``compile``, ``check_nominal`` and
the general form's ``evaluate`` — live on the numeric floor
(:mod:`jourdain.numeric.linearization`), as free functions for any result of the stage and as
methods of the subclasses that ``jd.linearization``, ``jd.linearization_general`` and
``System.linearize`` return. Checked against the closed forms of a pendulum (point mass m on a
massless rod of length l, φ from the downward vertical): M̃ = m·l², K = m·g·l·cos φ_s,
h = −m·g·l·sin φ_s, eigenvalues ±i·√(g/l)."""

import math

import numpy as np
import pytest

import jourdain as jd
from jourdain.analysis.state_space import state_space
from jourdain.errors import EvaluationError
from jourdain.numeric import linearization as numeric_lin
from jourdain.stages import linearization as stage

EPS = np.finfo(float).eps
# the matrices here are products of three parameters and a sine or cosine: a few roundings
RTOL = 16 * EPS
VALUES = {"m": 3.0, "l": 0.7, "g": 9.81, "d": 0.3}


def pendulum(damping: bool = False) -> jd.System:
    phi, m, l, g, d = jd.symbols("phi m l g d")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -l, 0),
                  inertia=jd.point_mass())
    forces: list = [jd.Gravity((0, -g, 0))]
    if damping:
        forces.append(jd.RotationalSpringDamper("damper", phi, damping=d))
    return jd.System([phi], [bob], forces, parameters={"m": 2.0, "l": 0.5, "g": 9.81, "d": 0.3})


def test_the_stage_is_symbolic_and_the_public_functions_add_the_numbers():
    s = pendulum()
    eom = s.equations_of_motion()
    bare = stage.linearization(eom, {"phi": 0})
    assert type(bare) is stage.Linearization
    for name in ("evaluate", "compile", "check_nominal"):
        assert not hasattr(bare, name), name
    assert not hasattr(stage.linearization_general(eom), "evaluate")
    for lin in (jd.linearization(eom, {"phi": 0}), s.linearize({"phi": 0})):
        assert type(lin) is numeric_lin.Linearization is jd.Linearization
        assert isinstance(lin, stage.Linearization)
        assert lin.M_tilde == bare.M_tilde and lin.Q == bare.Q and lin.h == bare.h
    lifted = numeric_lin.with_numbers(bare)
    assert type(lifted) is jd.Linearization and lifted.K == bare.K
    assert numeric_lin.with_numbers(lifted) is lifted
    assert type(jd.linearization_general(eom)) is jd.GeneralLinearization


@pytest.mark.parametrize("phi_s", [0.0, 0.4, math.pi / 2])
def test_numbers_of_a_bare_result_agree_with_the_closed_form(phi_s):
    s = pendulum()
    if phi_s == 0.0:
        bare = stage.linearization(s.equations_of_motion(), {"phi": phi_s})
    else:  # not an equilibrium: the stage says so at the default values, without numeric
        with pytest.warns(stage.NominalMotionWarning):
            bare = stage.linearization(s.equations_of_motion(), {"phi": phi_s})
    m, l, g = VALUES["m"], VALUES["l"], VALUES["g"]
    scale = m * g * l + m * l**2
    num = numeric_lin.evaluate_linearization(bare, parameters=VALUES)
    np.testing.assert_allclose(num["M_tilde"], [[m * l**2]], rtol=RTOL)
    np.testing.assert_allclose(num["K"], [[m * g * l * math.cos(phi_s)]], rtol=0,
                               atol=RTOL * scale)
    np.testing.assert_allclose(num["h"], [-m * g * l * math.sin(phi_s)], rtol=0,
                               atol=RTOL * scale)
    assert num["B"].shape == (1, 0) and set(num) >= {"D", "G", "K", "N"}
    # the method of the subclass and the compiled form give the same numbers
    lin = numeric_lin.with_numbers(bare)
    by_method = lin.evaluate(parameters=VALUES)
    compiled = numeric_lin.compile_linearization(bare)(0.0, VALUES)
    for key in ("M_tilde", "P", "Q", "h", "K"):
        np.testing.assert_array_equal(by_method[key], num[key])
        np.testing.assert_allclose(compiled[key], num[key], rtol=0, atol=RTOL * scale)
    check = numeric_lin.check_nominal(bare, 0.0, VALUES)
    assert check.is_solution == (phi_s == 0.0)
    np.testing.assert_allclose(check.h, num["h"], rtol=0, atol=RTOL * scale)
    assert lin.check_nominal(0.0, VALUES).is_solution == check.is_solution


def test_analyses_take_a_bare_result():
    """state_space and stability read a result of the stage through the numeric functions:
    eigenvalues ±i·√(g/l) about the hanging position."""
    bare = stage.linearization(pendulum().equations_of_motion(), {"phi": 0})
    ss = state_space(bare, parameters=VALUES)
    lam = np.sort_complex(np.linalg.eigvals(ss.A))
    omega = math.sqrt(VALUES["g"] / VALUES["l"])
    np.testing.assert_allclose(lam, [-1j * omega, 1j * omega], rtol=0,
                               atol=64 * EPS * max(1.0, omega**2))
    assert ss.nominal_check is not None and ss.nominal_check.is_solution


def test_is_conservative_stays_on_the_stage():
    eom = pendulum().equations_of_motion()
    assert stage.linearization(eom, {"phi": 0}).is_conservative
    assert not stage.linearization(pendulum(damping=True).equations_of_motion(),
                                   {"phi": 0}).is_conservative


def test_general_form_in_numbers():
    s = pendulum()
    eom = s.equations_of_motion()
    bare = stage.linearization_general(eom)
    y, yd, ydd = 0.3, -0.8, 1.7
    num = numeric_lin.evaluate_general_linearization(bare, [y], [yd], [ydd], 0.0, VALUES)
    m, l, g = VALUES["m"], VALUES["l"], VALUES["g"]
    scale = m * g * l + m * l**2 * abs(ydd)
    np.testing.assert_allclose(num["M_tilde"], [[m * l**2]], rtol=RTOL)
    np.testing.assert_allclose(num["Q"], [[m * g * l * math.cos(y)]], rtol=0, atol=RTOL * scale)
    np.testing.assert_allclose(num["P"], [[0.0]], rtol=0, atol=RTOL * scale)
    np.testing.assert_allclose(num["h"], [-(m * l**2 * ydd + m * g * l * math.sin(y))],
                               rtol=0, atol=RTOL * scale)
    by_method = jd.linearization_general(eom).evaluate([y], [yd], [ydd], 0.0, VALUES)
    for key in num:
        np.testing.assert_array_equal(by_method[key], num[key])


def test_bad_arguments_name_what_is_wrong():
    s = pendulum()
    lin = s.linearize({"phi": 0})
    with pytest.raises(EvaluationError, match="unknown parameter.*'mass'"):
        lin.evaluate(parameters={"mass": 1.0})
    with pytest.raises(EvaluationError, match="t = nan is not finite"):
        numeric_lin.evaluate_linearization(lin, t=float("nan"))
    with pytest.raises(EvaluationError, match='parameter "l"'):
        lin.check_nominal(0.0, {"l": "long"})
    gen = jd.linearization_general(s.equations_of_motion())
    with pytest.raises(EvaluationError, match="ydd must be 1 finite numbers"):
        gen.evaluate([0.0], [0.0], [0.0, 1.0])
