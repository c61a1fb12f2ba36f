"""Model validation: every mistake gives a ModelError that names the body, joint, force or
parameter at fault; evaluation rejects bad states with an EvaluationError."""

import dataclasses

import numpy as np
import pytest

import jourdain as jd
from jourdain.models import double_pendulum

phi, psi, m, l, g = jd.symbols("phi psi m l g")
P = {"m": 1.0, "l": 1.0, "g": 9.81}


def pendulum(**over):
    kw = dict(name="bob", parent="world", joint=jd.Revolute("pivot", phi, "z"), mass=m,
              com=(0, -l, 0), inertia=jd.point_mass())
    kw.update(over)
    return jd.Body(kw.pop("name"), kw.pop("parent"), kw.pop("joint"), **kw)


def make(bodies=None, coords=(phi,), forces=(), params=P, inputs=()):
    return jd.System(list(coords), bodies if bodies is not None else [pendulum()], list(forces),
                     parameters=params, inputs=list(inputs))


CASES = [
    ("unknown parent", lambda: make([pendulum(parent="ghost")]), 'body "bob": unknown parent "ghost"'),
    ("duplicate body", lambda: make([pendulum(), pendulum(joint=jd.Revolute("p2", psi))],
                                    coords=(phi, psi)), 'duplicate body name "bob"'),
    ("duplicate joint", lambda: make([pendulum(), pendulum(name="b2", parent="bob",
                                                           joint=jd.Revolute("pivot", psi))],
                                     coords=(phi, psi)), 'duplicate joint name "pivot"'),
    ("coordinate driven twice", lambda: make([pendulum(), pendulum(name="b2", parent="bob",
                                                                   joint=jd.Revolute("p2", phi))]),
     'coordinate "phi" is driven by two joints: "pivot" and "p2"'),
    ("missing mass", lambda: make([pendulum(mass=None)]), 'body "bob": mass is missing'),
    ("missing inertia", lambda: make([pendulum(inertia=None)]), 'body "bob": inertia is missing'),
    ("unsymmetric inertia", lambda: make([pendulum(inertia=[[1, 0.2, 0], [0, 1, 0], [0, 0, 1]])]),
     'body "bob": inertia tensor is not symmetric'),
    ("indefinite inertia", lambda: make([pendulum(inertia=[[1, 0, 0], [0, -1, 0], [0, 0, 1]])]),
     'body "bob": inertia tensor is not positive semi-definite'),
    ("negative mass", lambda: make(params={**P, "m": -1.0}), 'body "bob": mass must be a non-negative'),
    ("massless with inertia", lambda: make([pendulum(mass=0, inertia=(1, 1, 1))]),
     'body "bob": a massless body cannot have rotational inertia'),
    ("cycle", lambda: make([pendulum(parent="b2"), pendulum(name="b2", parent="bob",
                                                            joint=jd.Revolute("p2", psi))],
                           coords=(phi, psi)), "not connected to the inertial frame"),
    ("undeclared symbol in joint", lambda: make([pendulum(
        joint=jd.Revolute("pivot", phi, position=(0, jd.symbols("h"), 0)))]),
     'joint "pivot" (body "bob"): undeclared symbol(s) [\'h\']'),
    ("rate in joint", lambda: make([pendulum(
        joint=jd.General("pivot", [jd.Rot("z", jd.rate(phi))], coordinates=[phi]))]),
     "joints may depend on coordinates, parameters and t only"),
    ("undeclared symbol in mass", lambda: make([pendulum(mass=jd.symbols("mm"))]),
     'body "bob": mass data use undeclared symbol(s) [\'mm\']'),
    ("unused coordinate", lambda: make(coords=(phi, psi)), "coordinate(s) ['psi'] are not used by any joint"),
    ("force on unknown body", lambda: make(forces=[jd.Force("push", "ghost", (1, 0, 0))]),
     'force "push": unknown body "ghost"'),
    ("force in unknown frame", lambda: make(forces=[jd.Force("push", "bob", (1, 0, 0), frame="sky")]),
     'force "push": unknown frame "sky"'),
    ("force with undeclared input", lambda: make(forces=[jd.Force("push", "bob", (jd.symbols("F"), 0, 0))]),
     "force \"push\": undeclared symbol(s) ['F']"),
    ("spring on one body", lambda: make(forces=[jd.SpringDamper("s", "bob", (0, 0, 0), "bob", (1, 0, 0))]),
     'spring-damper "s": both ends are on body "bob"'),
    ("bad axis name", lambda: jd.Revolute("pivot", phi, "w"), 'expected one of x, y, z or a 3-vector, got \'w\''),
    ("axis not unit", lambda: jd.Revolute("pivot", phi, (1, 1, 0)), "is not a unit vector"),
    ("axis wrong length", lambda: jd.Revolute("pivot", phi, (1, 0)), "expected a 3-vector, got 2 components"),
    ("expression as revolute coordinate", lambda: jd.Revolute("pivot", 2 * phi),
     'joint "pivot": coordinate must be a symbol'),
    ("parameter not a number", lambda: make(params={**P, "m": "heavy"}), 'parameter "m": value must be a number'),
    ("parameter NaN", lambda: make(params={**P, "m": float("nan")}), 'parameter "m": value nan is not finite'),
    ("name declared twice", lambda: make(params={**P, "phi": 1.0}), 'name "phi" is declared twice'),
    ("reserved name", lambda: make(params={**P, "t": 1.0}), 'parameter name "t" is reserved'),
    ("string as mass", lambda: pendulum(mass="m*2"), 'body "bob" mass: expected a number or a SymPy/SymEngine expression'),
    ("generalized force on non-step coordinate", lambda: make(
        [pendulum(joint=jd.General("pivot", [jd.Rot("z", 2 * phi)], coordinates=[phi]))],
        forces=[jd.GeneralizedForce("drive", phi, 1.0)]).equations_of_motion(),
     'generalized force "drive": coordinate "phi" is not the angle or distance of a single joint step'),
    ("universal with equal axes", lambda: jd.Universal("u", (phi, psi), ("x", "x")),
     'joint "u": the two axes of a universal joint must differ'),
    ("bad rotation sequence", lambda: jd.Spherical("s", (phi, psi, m), "xxy"),
     "rotation sequence 'xxy' is not one of"),
    ("no coordinates", lambda: make(coords=()), "at least one generalized coordinate"),
]


@pytest.mark.parametrize("what, build, message", CASES, ids=[c[0] for c in CASES])
def test_model_errors_name_the_culprit(what, build, message):
    with pytest.raises(jd.ModelError) as err:
        build()
    assert message in str(err.value), f"{what}: {err.value}"


def test_system_is_immutable_and_compares_by_content():
    a, b = double_pendulum(), double_pendulum()
    assert a == b and hash(a) == hash(b)
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.name = "other"  # type: ignore[misc]
    assert a.parameter_values is not a.parameter_values  # a fresh dict each time


def test_names_and_symbols():
    s = double_pendulum()
    assert s.coordinate_names == ["phi1", "phi2"]
    assert [str(x) for x in s.yd] == ["phi1_d", "phi2_d"]
    assert s.parameter_values["g"] == 9.81
    assert s.input_names == []


@pytest.mark.parametrize("call, message", [
    (lambda s: s.evaluate([0.1], [0, 0]), "y must have 2 entries (phi1, phi2), got 1"),
    (lambda s: s.evaluate([0.1, np.nan], [0, 0]), "y contains NaN or inf in ['phi2']"),
    (lambda s: s.evaluate([0.1, 0.2], [0, np.inf]), "yd contains NaN or inf in ['phi2_d']"),
    (lambda s: s.evaluate([0.1, 0.2], [0, 0], parameters={"mass": 1}), "unknown parameter(s) ['mass']"),
    (lambda s: s.evaluate([0.1, 0.2], [0, 0], parameters={"m1": float("nan")}), 'parameter "m1" = nan is not finite'),
    (lambda s: s.evaluate([0.1, 0.2], [0, 0], inputs={"F": 1.0}), "unknown input(s) ['F']"),
    (lambda s: s.evaluate("ab", [0, 0]), "y must be a sequence of 2 numbers"),
])
def test_evaluation_rejects_bad_states(call, message):
    with pytest.raises(jd.EvaluationError) as err:
        call(double_pendulum())
    assert message in str(err.value)


def test_parameters_override_without_changing_the_model():
    s = double_pendulum()
    a = s.evaluate([0.3, 0.1], [0, 0])["M"]
    b = s.evaluate([0.3, 0.1], [0, 0], parameters={"m2": 1.0})["M"]
    assert b[1, 1] == pytest.approx(a[1, 1] * 2.0)
    assert s.parameter_values["m2"] == 0.5
