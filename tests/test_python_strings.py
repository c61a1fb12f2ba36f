"""Strings in the Python API (issue 38, item 8): ``Body(mass="m")``, ``com=(0, "-l/2", 0)``,
force vectors as text, read by the same restricted parser as model files
(:mod:`jourdain.io.expressions`), never by ``eval`` or ``sympify``: the same expressions as
built from symbols, the same refusals as in a model file (with the element and the column),
and undeclared names refused by the System like any other symbol.
"""

import builtins

import numpy as np
import pytest
import symengine as se
import sympy

import jourdain as jd
from tests.tolerance import assert_close_eval

P = {"m": 1.2, "l": 0.8, "g": 9.81, "c": 0.4}


def pendulum(text: bool) -> jd.System:
    phi = jd.symbols("phi")
    m, l, g, c = jd.symbols("m l g c")
    if text:
        body = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass="m",
                       com=(0, "-l/2", 0), inertia=(0, "m*l^2/12", "m*l^2/12"))
        forces = [jd.Gravity((0, "-g", 0)),
                  jd.Force("drag", "rod", ("-c*phi_d*cos(phi)", 0, 0), point=(0, "-l", 0))]
    else:
        body = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass=m,
                       com=(0, -l / 2, 0), inertia=(0, m * l**2 / 12, m * l**2 / 12))
        forces = [jd.Gravity((0, -g, 0)),
                  jd.Force("drag", "rod", (-c * jd.symbols("phi_d") * se.cos(phi), 0, 0),
                           point=(0, -l, 0))]
    return jd.System([phi], [body], forces, parameters=P)


def test_strings_give_the_expressions_built_from_symbols():
    a, b = pendulum(True), pendulum(False)
    assert a.bodies == b.bodies and a.forces == b.forces
    m, l = jd.symbols("m l")
    assert a.bodies[0].mass == m and a.bodies[0].com[1] == -l / 2
    for y, yd in ((0.3, 1.1), (-2.0, 0.2)):
        oa, ob = a.evaluate([y], [yd]), b.evaluate([y], [yd])
        for name in ("M", "k", "q"):
            assert_close_eval(oa[name], ob[name], 4, scale=20.0, err_msg=name)


def test_strings_are_never_evaluated_as_code(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError("a string of the Python API went to eval or sympify")

    monkeypatch.setattr(builtins, "eval", refuse)
    monkeypatch.setattr(se, "sympify", refuse)
    monkeypatch.setattr(sympy, "sympify", refuse)
    phi = jd.symbols("phi")
    body = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass="2*m + sqrt(l)",
                   inertia=(0, 0, 0))
    assert body.mass == 2 * jd.symbols("m") + se.sqrt(jd.symbols("l"))


@pytest.mark.parametrize("text, message", [
    ('__import__("os").system("true")', "strings are not allowed in an expression (column 12)"),
    ("open(1)", "'open' is not a function of the expression language"),
    ("m.real", "attribute access is not allowed (column 2)"),
    ("lambda: m", "lambda"),
    ("(((2^999)^999)^999)^999", "this power would build a number of about"),
    ("m +", "the expression ends where a number, a name or '(' is expected (column 4)"),
])
def test_strings_are_refused_as_in_model_files(text, message):
    phi = jd.symbols("phi")
    with pytest.raises(jd.ModelError) as info:
        jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass=text, inertia=(0, 0, 0))
    assert str(info.value).startswith(f'body "rod" mass: {text!r}: '), str(info.value)
    assert message in str(info.value)


def test_undeclared_names_in_strings_are_refused_by_the_system():
    phi = jd.symbols("phi")
    body = jd.Body("rod", "world", jd.Revolute("hinge", phi, "z"), mass="mass_of_rod",
                   inertia=(0, 0, 0), com=(0, -1, 0))
    with pytest.raises(jd.ModelError, match=r"undeclared symbol\(s\) \['mass_of_rod'\]"):
        jd.System([phi], [body], [jd.Gravity((0, -9.81, 0))], parameters={"m": 1.0})
    system = jd.System([phi], [body], [jd.Gravity((0, -9.81, 0))],
                       parameters={"mass_of_rod": 2.0})
    np.testing.assert_allclose(system.evaluate([0.0], [0.0])["M"], [[2.0]], rtol=1e-12)
