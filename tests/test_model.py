"""Model validation: every mistake gives a ModelError that names the body, joint, force or
parameter at fault; evaluation rejects bad states with an EvaluationError."""

import dataclasses
import math

import numpy as np
import pytest
import symengine as se

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
                           coords=(phi, psi)),
     'body "bob" is not connected to the inertial frame (a cycle of parents: bob → b2 → bob)'),
    ("child before its parent", lambda: make([pendulum(name="b2", parent="bob",
                                                       joint=jd.Revolute("p2", psi)), pendulum()],
                                             coords=(phi, psi)),
     'body "b2" (position 1) comes before its parent "bob" (position 2): list parents before '
     "their children"),
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
    ("zero axis", lambda: jd.Revolute("pivot", phi, (0, 0, 0)),
     'joint "pivot" axis must not be the zero vector'),
    ("zero float axis", lambda: jd.Prismatic("rail", phi, (0.0, 0.0, 0.0)),
     'joint "rail" axis must not be the zero vector'),
    ("zero second universal axis", lambda: jd.Universal("u", (phi, psi), ("x", (0, 0, 0))),
     'joint "u" axes[1] must not be the zero vector'),
    ("zero Rot axis", lambda: jd.Rot((0, 0, 0), phi), "Rot axis must not be the zero vector"),
    ("axis zero at the default values", lambda: make([pendulum(
        joint=jd.Revolute("pivot", phi, (l - 1, 0, 0)))]),
     'joint "pivot" (body "bob"): the axis is the zero vector at the default parameter values'),
    ("axis depending on a coordinate", lambda: make([pendulum(
        joint=jd.General("pivot", [jd.Rot((phi, 1, 0), phi)], coordinates=[phi]))]),
     'joint "pivot" (body "bob"): the axis uses [\'phi\']; axes may depend on parameters only'),
    ("axis wrong length", lambda: jd.Revolute("pivot", phi, (1, 0)), "expected a 3-vector, got 2 components"),
    ("expression as revolute coordinate", lambda: jd.Revolute("pivot", 2 * phi),
     'joint "pivot": coordinate must be a symbol'),
    ("parameter not a number", lambda: make(params={**P, "m": "heavy"}), 'parameter "m": value must be a number'),
    ("parameter NaN", lambda: make(params={**P, "m": float("nan")}), 'parameter "m": value nan is not finite'),
    ("name declared twice", lambda: make(params={**P, "phi": 1.0}), 'name "phi" is declared twice'),
    ("reserved name", lambda: make(params={**P, "t": 1.0}), 'parameter name "t" is reserved'),
    ("string as mass outside the language", lambda: pendulum(mass="m**2 if m else 0"),
     'body "bob" mass: \'m**2 if m else 0\': unexpected'),
    ("a list as mass", lambda: pendulum(mass=[1]), 'body "bob" mass: expected a number, a '
     "SymPy/SymEngine expression or a string of the expression language"),
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


def _four_bodies():
    """a ← world, b ← a, c ← b, d ← a: d, a child of a, is listed after c."""
    q1, q2, q3, q4 = jd.symbols("q1 q2 q3 q4")

    def body(name, parent, q, mass):
        pos = None if parent == "world" else (l, 0, 0)
        return jd.Body(name, parent, jd.Revolute(f"j{name}", q, "z", position=pos), mass=mass,
                       com=(l, 0, 0), inertia=(0.1 * mass, 0.2 * mass, 0.3 * mass))

    bodies = [body("a", "world", q1, 1), body("b", "a", q2, 2), body("c", "b", q3, 3),
              body("d", "a", q4, 4)]
    return (q1, q2, q3, q4), bodies


def test_bodies_keep_the_order_given():
    """A parent-before-child order is kept as written: in system.bodies, the kinematics, the
    rows of M̄ and J̄ and the joints of g (a breadth-first reordering would give a, b, d, c)."""
    y, bodies = _four_bodies()
    s = jd.System(y, bodies, [jd.Gravity((0, -g, 0))], parameters=P)
    assert s.body_names == ["a", "b", "c", "d"]
    ne = s.newton_euler()
    assert [bk.name for bk in ne.kinematics.bodies] == ["a", "b", "c", "d"]
    assert [child for _, child, _ in ne.joints] == ["a", "b", "c", "d"]
    v = s.evaluate([0.1, 0.2, 0.3, 0.4], [0.5, -0.2, 0.1, 0.3])
    # M̄ = diag(m_a E, m_b E, m_c E, m_d E, I_a, ..., I_d) with m = 1, 2, 3, 4
    masses = np.repeat([1.0, 2.0, 3.0, 4.0], 3)
    np.testing.assert_allclose(np.diag(v["M_bar"])[:12], masses)
    inertias = np.outer([1.0, 2.0, 3.0, 4.0], [0.1, 0.2, 0.3]).ravel()
    np.testing.assert_allclose(np.diag(v["M_bar"])[12:], inertias)
    # J̄'s translational rows of body k (3k..3k+2): d (rows 9..11) moves with q1 and q4 only,
    # c (rows 6..8) with q1, q2, q3
    J = v["J_bar"]
    assert np.abs(J[9:12, [1, 2]]).max() == 0 and np.abs(J[9:12, 3]).max() > 0
    assert np.abs(J[6:9, 3]).max() == 0 and np.abs(J[6:9, 2]).max() > 0
    joints = list(dict.fromkeys(n.split(".")[0] for n in v["g_names"]))
    assert joints == ["ja", "jb", "jc", "jd"]


def test_a_child_before_its_parent_is_refused():
    y, (a, b, c, d) = _four_bodies()
    with pytest.raises(jd.ModelError) as err:
        jd.System(y, [a, c, d, b], parameters=P)
    assert str(err.value) == ('body "c" (position 2) comes before its parent "b" (position 4): '
                              "list parents before their children")


AXIS = (1, 1, 0)
UNIT = (se.sqrt(2) / 2, se.sqrt(2) / 2, 0)
FLOAT_UNIT = (1 / math.sqrt(2), 1 / math.sqrt(2), 0.0)


@pytest.mark.parametrize("build", [
    lambda ax: jd.Revolute("j", phi, ax),
    lambda ax: jd.Prismatic("j", phi, ax),
    lambda ax: jd.Cylindrical("j", (phi, psi), ax),
    lambda ax: jd.Universal("j", (phi, psi), (ax, "z")),
    lambda ax: jd.Universal("j", (phi, psi), ("z", ax)),
    lambda ax: jd.General("j", [jd.Rot(ax, phi)]),
    lambda ax: jd.General("j", [jd.Trans(ax, phi)]),
], ids=["Revolute", "Prismatic", "Cylindrical", "Universal0", "Universal1", "Rot", "Trans"])
def test_a_vector_axis_is_normalized(build):
    """An axis is a direction: (1, 1, 0) is the unit axis (√2/2, √2/2, 0), exactly."""
    assert build(AXIS) == build(UNIT)
    steps = build(AXIS).steps
    for ref, step in zip(build(FLOAT_UNIT).steps, steps, strict=True):
        np.testing.assert_allclose([float(c) for c in step.axis], [float(c) for c in ref.axis],
                                   rtol=1e-15)
    assert all(step.axis is None or se.expand(sum(c * c for c in step.axis)) == 1
               for step in steps)


def test_unit_axes_are_kept_and_axes_with_parameters_divided_by_their_length():
    a, b, beta = jd.symbols("a b beta")
    assert jd.Rot((0.6, 0.8, 0), phi).axis == (se.Float(0.6), se.Float(0.8), 0)
    assert jd.Rot((3, 4, 0), phi).axis == (se.Rational(3, 5), se.Rational(4, 5), 0)
    assert jd.Rot((se.sin(beta), 0, se.cos(beta)), phi).axis == (se.sin(beta), 0, se.cos(beta))
    n = se.sqrt(a**2 + b**2)
    assert jd.Rot((a, b, 0), phi).axis == (a / n, b / n, 0)
    # normalizing twice gives the same axis
    assert jd.Rot(jd.Rot((a, b, 0), phi).axis, phi).axis == (a / n, b / n, 0)
