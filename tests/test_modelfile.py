"""Model files: what they describe equals the same model built with the Python API, and every
kind of mistake is reported with the file, the line and the key path."""

import math
import textwrap

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.cli import main
from jourdain.io import ModelFileError, load_model, loads_model
from jourdain.io.toml_positions import key_lines
from jourdain.numeric import evaluate

BASE = textwrap.dedent('''\
    [model]
    name = "test model"
    [coordinates]
    phi1 = { unit = "rad" }
    phi2 = "rad"
    [parameters]
    m1 = { value = 1.0, unit = "kg" }
    m2 = 0.5
    l1 = 1.0
    l2 = 0.7
    g = 9.81
    k = 10.0
    [inputs]
    F = "N"
    [bodies.link1]
    parent = "world"
    mass = "m1"
    com = [0, "-l1/2", 0]
    inertia = { rod = { length = "l1", axis = "y" } }
    joint = { type = "revolute", coordinate = "phi1", axis = "z" }
    [bodies.link2]
    parent = "link1"
    mass = "m2"
    com = [0, "-l2/2", 0]
    inertia = [0.1, 0.01, 0.1]
    [bodies.link2.joint]
    type = "revolute"
    coordinate = "phi2"
    axis = "z"
    position = [0, "-l1", 0]
    [forces.gravity]
    type = "gravity"
    vector = [0, "-g", 0]
    [forces.spring]
    type = "spring_damper"
    body_a = "world"
    point_a = [1, 0, 0]
    body_b = "link2"
    point_b = [0, "-l2", 0]
    stiffness = "k"
    damping = 0.5
    [forces.push]
    type = "force"
    body = "link2"
    vector = ["F", 0, 0]
    [nominal.down]
    y = { phi1 = 0, phi2 = 0 }
    [simulation]
    t_end = 2.0
    y0 = { phi1 = 0.1 }
    ''')


def python_model() -> jd.System:
    phi1, phi2, m1, m2, l1, l2, g, k, F = jd.symbols("phi1 phi2 m1 m2 l1 l2 g k F")
    bodies = [
        jd.Body("link1", "world", jd.Revolute("link1", phi1, "z"), mass=m1,
                com=(0, -l1 / 2, 0), inertia=jd.rod(m1, l1, "y")),
        jd.Body("link2", "link1", jd.Revolute("link2", phi2, "z", position=(0, -l1, 0)),
                mass=m2, com=(0, -l2 / 2, 0), inertia=(0.1, 0.01, 0.1)),
    ]
    forces = [jd.Gravity((0, -g, 0)),
              jd.SpringDamper("spring", "world", (1, 0, 0), "link2", (0, -l2, 0), stiffness=k,
                              damping=0.5),
              jd.Force("push", "link2", (F, 0, 0))]
    return jd.System([phi1, phi2], bodies, forces,
                     parameters={"m1": 1.0, "m2": 0.5, "l1": 1.0, "l2": 0.7, "g": 9.81,
                                 "k": 10.0}, inputs=[F])


def test_base_model_equals_the_python_api_model():
    mf = loads_model(BASE, "base.toml")
    ref = python_model()
    assert mf.system.coordinate_names == ["phi1", "phi2"]
    assert dict(mf.system.units)["m1"] == "kg"
    for y, yd in (([0.3, -0.7], [1.1, -0.4]), ([2.0, 1.0], [0.0, 3.0])):
        a = evaluate(mf.system, y, yd, t=0.2, inputs={"F": 1.5})
        b = evaluate(ref, y, yd, t=0.2, inputs={"F": 1.5})
        for key in ("M_bar", "J_bar", "q_c", "q_e", "M", "k", "q"):
            np.testing.assert_allclose(a[key], b[key], rtol=1e-13, atol=1e-13)
    assert mf.simulation.t_end == 2.0 and mf.simulation.y0 == (0.1, 0.0)
    assert mf.nominal_motion("down").is_equilibrium


def test_every_joint_and_force_type_matches_the_python_api():
    src = textwrap.dedent('''\
        coordinates = ["a", "b", "c", "d", "e", "f", "u", "v", "w", "x1", "x2", "x3", "x4", "x5", "x6"]
        [parameters]
        m = 1.5
        r = 0.2
        L = 0.4
        Om = 3.0
        kc = 20.0
        dc = 0.3
        [inputs]
        T = "N*m"
        [bodies.cyl]
        parent = "world"
        mass = "m"
        com = [0.1, 0, 0]
        inertia = { cylinder = { radius = "r", length = "L", axis = "z" } }
        joint = { type = "cylindrical", coordinates = ["a", "b"], axis = [0, 0, 1], position = [0, 0, 1] }
        [bodies.uni]
        parent = "cyl"
        mass = "m/2"
        inertia = { box = { a = 0.1, b = 0.2, c = 0.3 } }
        joint = { type = "universal", coordinates = ["c", "d"], axes = ["x", "y"], position = [0, 0, "L"] }
        [bodies.ball]
        parent = "uni"
        mass = 0.7
        com = [0, 0, 0.1]
        inertia = [[0.02, 0.001, 0], [0.001, 0.03, 0], [0, 0, 0.04]]
        joint = { type = "spherical", coordinates = ["e", "f", "u"], sequence = "zxz", orientation = [{ rot = "x", angle = "pi/2" }] }
        [bodies.slider]
        parent = "ball"
        mass = 0.3
        inertia = "point"
        joint = { type = "prismatic", coordinate = "v", axis = "-y" }
        [bodies.spin]
        parent = "slider"
        mass = 0.2
        inertia = { disc = { radius = "r", axis = "x" } }
        joint = { type = "general", steps = [{ rot = "x", angle = "Om*t" }, { rot = "z", angle = "w" }] }
        [bodies.free]
        parent = "world"
        mass = 1.0
        inertia = [0.1, 0.2, 0.3]
        joint = { type = "free", coordinates = ["x1", "x2", "x3", "x4", "x5", "x6"] }
        [bodies.fixed]
        parent = "free"
        mass = 0.1
        com = [0.2, 0, 0]
        inertia = { rod = { length = 0.4 } }
        joint = { type = "fixed", position = [0.1, 0, 0] }
        [forces.g]
        type = "gravity"
        vector = [0, 0, -9.81]
        [forces.torque]
        type = "torque"
        body = "uni"
        vector = [0, "T", 0]
        frame = "uni"
        [forces.pull]
        type = "force"
        body = "ball"
        vector = ["-dc*e_d", 0, 1]
        point = [0, 0.1, 0]
        frame = "ball"
        [forces.sd]
        type = "spring_damper"
        body_a = "cyl"
        point_a = [0, 0, 0]
        body_b = "free"
        point_b = [0, 0, 0]
        law = "kc*elongation + kc*elongation^3 + dc*elongation_d"
        rest_length = 0.5
        [forces.rsd]
        type = "rotational_spring_damper"
        coordinate = "c"
        stiffness = "kc"
        damping = "dc"
        rest_angle = 0.1
        [forces.gen]
        type = "generalized"
        coordinate = "w"
        value = "-kc*w - dc*w_d + sin(t)"
        ''')
    mf = loads_model(src, "all.toml")
    a, b, c, d, e, f, u, v, w, *x = jd.symbols("a b c d e f u v w x1 x2 x3 x4 x5 x6")
    m, r, L, Om, cc, dd, T = jd.symbols("m r L Om kc dc T")
    el, eld, t = jd.elongation, jd.elongation_d, jd.t
    bodies = [
        jd.Body("cyl", "world", jd.Cylindrical("cyl", (a, b), "z", position=(0, 0, 1)), mass=m,
                com=(0.1, 0, 0), inertia=jd.cylinder(m, r, L, "z")),
        jd.Body("uni", "cyl", jd.Universal("uni", (c, d), ("x", "y"), position=(0, 0, L)),
                mass=m / 2, inertia=jd.box(m / 2, 0.1, 0.2, 0.3)),
        jd.Body("ball", "uni", jd.Spherical("ball", (e, f, u), "zxz",
                                            orientation=[jd.Rot("x", se.pi / 2)]),
                mass=0.7, com=(0, 0, 0.1),
                inertia=[[0.02, 0.001, 0], [0.001, 0.03, 0], [0, 0, 0.04]]),
        jd.Body("slider", "ball", jd.Prismatic("slider", v, "-y"), mass=0.3,
                inertia=jd.point_mass()),
        jd.Body("spin", "slider", jd.General("spin", [jd.Rot("x", Om * t), jd.Rot("z", w)],
                                             coordinates=[w]),
                mass=0.2, inertia=jd.disc(0.2, r, "x")),
        jd.Body("free", "world", jd.Free("free", x), mass=1.0, inertia=(0.1, 0.2, 0.3)),
        jd.Body("fixed", "free", jd.Fixed("fixed", position=(0.1, 0, 0)), mass=0.1,
                com=(0.2, 0, 0), inertia=jd.rod(0.1, 0.4, "x")),
    ]
    forces = [
        jd.Gravity((0, 0, -9.81), name="g"),
        jd.Torque("torque", "uni", (0, T, 0), frame="uni"),
        jd.Force("pull", "ball", (-dd * jd.rate(e), 0, 1), point=(0, 0.1, 0), frame="ball"),
        jd.SpringDamper("sd", "cyl", (0, 0, 0), "free", (0, 0, 0), rest_length=0.5,
                        law=cc * el + cc * el**3 + dd * eld),
        jd.RotationalSpringDamper("rsd", c, stiffness=cc, damping=dd, rest_angle=0.1),
        jd.GeneralizedForce("gen", w, -cc * w - dd * jd.rate(w) + se.sin(t)),
    ]
    ref = jd.System([a, b, c, d, e, f, u, v, w, *x], bodies, forces,
                    parameters={"m": 1.5, "r": 0.2, "L": 0.4, "Om": 3.0, "kc": 20.0, "dc": 0.3},
                    inputs=[T])
    rng = np.random.default_rng(3)
    y, yd = rng.normal(size=15), rng.normal(size=15)
    # the equations of motion only: the model-file system must be the Python one
    A = evaluate(mf.system, y, yd, t=0.3, inputs={"T": 0.8})
    B = evaluate(ref, y, yd, t=0.3, inputs={"T": 0.8})
    for key in ("M", "k", "q", "q_e", "J_bar"):
        np.testing.assert_allclose(A[key], B[key], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("spec, python", [
    ('{ type = "revolute", coordinate = "phi2", axis = [1, 1, 0] }',
     lambda q, ax: jd.Revolute("link2", q, ax)),
    ('{ type = "prismatic", coordinate = "phi2", axis = [1, 1, 0] }',
     lambda q, ax: jd.Prismatic("link2", q, ax)),
    ('{ type = "universal", coordinates = ["phi2", "phi3"], axes = ["z", [1, 1, 0]] }',
     lambda q, ax: jd.Universal("link2", (q, jd.symbols("phi3")), ("z", ax))),
    ('{ type = "general", steps = [{ rot = [1, 1, 0], angle = "phi2" }, '
     '{ trans = [1, 1, 0], distance = "phi3" }] }',
     lambda q, ax: jd.General("link2", [jd.Rot(ax, q), jd.Trans(ax, jd.symbols("phi3"))],
                              coordinates=[q, jd.symbols("phi3")])),
], ids=["revolute", "prismatic", "universal", "general"])
def test_a_vector_axis_is_the_same_joint_in_a_file_and_in_python(spec, python):
    """One rule: [1, 1, 0] in a file, (1, 1, 0) and (√2/2, √2/2, 0) in Python give one joint."""
    coords = 'phi2 = "rad"\nphi3 = "rad"' if "phi3" in spec else 'phi2 = "rad"'
    text = BASE.replace('phi2 = "rad"', coords).replace(
        '[bodies.link2.joint]\ntype = "revolute"\ncoordinate = "phi2"\naxis = "z"\n'
        'position = [0, "-l1", 0]\n', "").replace(
        'inertia = [0.1, 0.01, 0.1]\n', f"inertia = [0.1, 0.01, 0.1]\njoint = {spec}\n")
    joint = loads_model(text).system.body("link2").joint
    q = jd.symbols("phi2")
    assert joint == python(q, (1, 1, 0)) == python(q, (se.sqrt(2) / 2, se.sqrt(2) / 2, 0))


def test_an_axis_with_parameters_is_the_same_joint_in_a_file_and_in_python():
    text = BASE.replace('axis = "z"\nposition', 'axis = ["l1", "l2", 0]\nposition')
    joint = loads_model(text).system.body("link2").joint
    phi2, l1, l2 = jd.symbols("phi2 l1 l2")
    assert joint == jd.Revolute("link2", phi2, (l1, l2, 0), position=(0, -l1, 0))
    n = se.sqrt(l1**2 + l2**2)
    assert joint.steps[0].axis == (l1 / n, l2 / n, 0)


def test_bodies_keep_the_file_order_and_a_child_before_its_parent_is_refused():
    head, rest = BASE.split("[bodies.link1]\n")
    link1, rest = rest.split("[bodies.link2]\n")
    link2, tail = rest.split("[forces.gravity]\n")
    assert loads_model(BASE).system.body_names == ["link1", "link2"]
    text = (f"{head}[bodies.link2]\n{link2}[bodies.link1]\n{link1}"
            f"[forces.gravity]\n{tail}")
    with pytest.raises(ModelFileError) as info:
        loads_model(text, "swapped.toml")
    err = info.value
    parent_line = _line(text, "[bodies.link1]")
    assert err.line == _line(text, 'parent = "link1"')
    assert str(err) == (
        f'swapped.toml:{err.line}: body "link2" → parent: body "link2" (position 1) comes '
        f'before its parent "link1" (position 2, line {parent_line}): list parents before '
        "their children")


def test_nominal_motion_rates_are_time_derivatives():
    text = BASE.replace("[nominal.down]\ny = { phi1 = 0, phi2 = 0 }",
                        '[nominal.spin]\ny = { phi1 = "k*t", phi2 = "sin(2*t)" }')
    n = loads_model(text).nominal_motion("spin")
    t, k = se.symbols("t k")
    assert n.y[0] == k * t and n.yd[0] == k and n.ydd[0] == 0
    assert n.yd[1] == 2 * se.cos(2 * t) and n.ydd[1] == -4 * se.sin(2 * t)
    assert not n.is_equilibrium


def test_key_lines_of_tables_inline_tables_and_arrays():
    lines = key_lines(BASE)
    row = {ln: i + 1 for i, ln in enumerate(BASE.splitlines())}
    assert lines[("bodies", "link2", "joint", "axis")] == row['axis = "z"']
    assert lines[("bodies", "link1", "joint", "coordinate")] == row[
        'joint = { type = "revolute", coordinate = "phi1", axis = "z" }']
    assert lines[("bodies", "link2", "com", 1)] == row['com = [0, "-l2/2", 0]']


def _line(text: str, snippet: str) -> int:
    hits = [i + 1 for i, ln in enumerate(text.splitlines()) if snippet in ln]
    assert hits, snippet
    return hits[0]


# (what, old text, new text, expected message fragment, line snippet or None for "no line")
MISTAKES = [
    ("toml syntax", "m2 = 0.5", "m2 = 0.5 0.6", "TOML syntax error", "m2 = 0.5 0.6"),
    ("unclosed string", 'mass = "m1"', 'mass = "m1', "TOML syntax error", 'mass = "m1'),
    ("bad axis", 'axis = "z"\nposition', 'axis = "w"\nposition',
     'body "link2" → joint → axis: expected one of x, y, z or a 3-vector, got "w"',
     'axis = "w"'),
    ("axis of wrong type", 'axis = "z"\nposition', 'axis = 3\nposition',
     "expected one of x, y, z or a 3-vector, got the number 3", "axis = 3"),
    ("zero axis", 'axis = "z"\nposition', 'axis = [0, 0, 0]\nposition',
     'body "link2" → joint → axis: the axis of joint "link2" must not be the zero vector',
     "axis = [0, 0, 0]"),
    ("axis zero at the default values", 'axis = "z"\nposition', 'axis = ["l1 - 1", 0, 0]\nposition',
     'joint "link2" (body "link2"): the axis is the zero vector at the default parameter values',
     "[bodies.link2.joint]"),
    ("unknown section", "[simulation]", "[simulations]",
     'unknown key "simulations" (did you mean "simulation"?)', "[simulations]"),
    ("unknown body key", 'mass = "m2"', 'mas = "m2"', 'unknown key "mas" (did you mean "mass"?)',
     'mas = "m2"'),
    ("missing mass", 'mass = "m2"\n', "", 'body "link2": missing key "mass"', "[bodies.link2]"),
    ("unknown parent", 'parent = "link1"', 'parent = "link3"', 'unknown parent "link3"',
     'parent = "link3"'),
    ("cycle of parents", 'parent = "world"', 'parent = "link2"', "the parents form a cycle",
     'parent = "link2"'),
    ("unknown joint type", 'type = "revolute", coordinate = "phi1"',
     'type = "hinge", coordinate = "phi1"', 'unknown joint type "hinge"', 'type = "hinge"'),
    ("undeclared coordinate", 'coordinate = "phi2"', 'coordinate = "phi3"',
     '"phi3" is not a declared coordinate', 'coordinate = "phi3"'),
    ("coordinate driven twice", 'coordinate = "phi2"', 'coordinate = "phi1"',
     'coordinate "phi1" is already driven by the joint of body "link1"', "@"),
    ("undeclared name", 'com = [0, "-l2/2", 0]', 'com = [0, "-l3/2", 0]',
     "body \"link2\" → com[1]: in expression \"-l3/2\" at column 2: unknown name 'l3'",
     'com = [0, "-l3/2", 0]'),
    ("coordinate in mass data", 'mass = "m2"', 'mass = "m2*phi1"',
     "coordinates are not allowed in mass data", 'mass = "m2*phi1"'),
    ("rate in mass data", 'mass = "m1"', 'mass = "m1*phi1_d"', "rates are not allowed",
     'mass = "m1*phi1_d"'),
    ("time in mass data", 'mass = "m1"', 'mass = "m1*t"', "time t is not allowed",
     'mass = "m1*t"'),
    ("input in a joint", 'position = [0, "-l1", 0]', 'position = [0, "-F", 0]',
     "inputs are not allowed", 'position = [0, "-F", 0]'),
    ("boolean instead of number", 'stiffness = "k"', "stiffness = true",
     "got a boolean", "stiffness = true"),
    ("string instead of vector", 'com = [0, "-l2/2", 0]', 'com = "0"',
     "expected a 3-vector (an array of 3 numbers or expressions), got the string", 'com = "0"'),
    ("vector of wrong dimension", 'com = [0, "-l2/2", 0]', 'com = [0, "-l2/2"]',
     "expected a 3-vector, got 2 components", 'com = [0, "-l2/2"]'),
    ("inertia of wrong dimension", "inertia = [0.1, 0.01, 0.1]", "inertia = [0.1, 0.01]",
     "expected the 3 principal moments", "inertia = [0.1, 0.01]"),
    ("inertia row of wrong dimension", "inertia = [0.1, 0.01, 0.1]",
     "inertia = [[1, 0, 0], [0, 1], [0, 0, 1]]", "expected a row of 3 entries",
     "inertia = [[1, 0, 0]"),
    ("inertia not symmetric", "inertia = [0.1, 0.01, 0.1]",
     "inertia = [[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]", "not symmetric", "inertia = [[1, 0.5"),
    ("inertia not positive", "inertia = [0.1, 0.01, 0.1]", "inertia = [0.1, -0.01, 0.1]",
     "not positive semi-definite", "inertia = [0.1, -0.01, 0.1]"),
    # the parameter's value is what is wrong: its line, not the body's (issue 17, item 6)
    ("negative mass", "m2 = 0.5", "m2 = -0.5", "mass must be a non-negative number",
     "m2 = -0.5"),
    ("parameter given as string", "m2 = 0.5", 'm2 = "0.5"',
     "a parameter value must be a number", 'm2 = "0.5"'),
    ("parameter table without value", 'm1 = { value = 1.0, unit = "kg" }', 'm1 = { unit = "kg" }',
     'parameter "m1": missing key "value"', 'm1 = { unit = "kg" }'),
    ("name declared twice", "k = 10.0", "phi1 = 10.0", '"phi1" is already declared in '
     "[coordinates]", "phi1 = 10.0"),
    ("reserved name", "k = 10.0", "sin = 10.0", '"sin" is a reserved name', "sin = 10.0"),
    ("bad identifier", "k = 10.0", '"k 2" = 10.0', 'parameter name "k 2" must start with',
     '"k 2" = 10.0'),
    ("python import", 'stiffness = "k"', 'stiffness = "__import__(k)"',
     "double-underscore names are reserved", 'stiffness = "__import__'),
    ("python call with string", 'stiffness = "k"',
     "stiffness = \"__import__('os').system('rm -rf /')\"", "strings are not allowed",
     "stiffness = \"__import__"),
    ("attribute access", 'stiffness = "k"', 'stiffness = "k.__class__"',
     "attribute access is not allowed", 'stiffness = "k.__class__"'),
    ("lambda", 'stiffness = "k"', 'stiffness = "(lambda: k)()"', "lambdas",
     'stiffness = "(lambda'),
    ("eval call", 'stiffness = "k"', 'stiffness = "eval(k)"', "'eval' is not a function",
     'stiffness = "eval(k)"'),
    ("indexing", 'stiffness = "k"', 'stiffness = "k[0]"', "indexing", 'stiffness = "k[0]"'),
    ("unbalanced parenthesis", 'stiffness = "k"', 'stiffness = "(k"', "expected ')'",
     'stiffness = "(k"'),
    ("huge power", 'stiffness = "k"', 'stiffness = "k*10^10^10"', "too large",
     'stiffness = "k*10^10^10"'),
    ("unknown force type", 'type = "spring_damper"', 'type = "spring"',
     'unknown force type "spring" (did you mean "spring_damper"?)', 'type = "spring"'),
    ("force on unknown body", 'body = "link2"', 'body = "link9"', 'unknown body "link9"',
     'body = "link9"'),
    ("undeclared input", 'vector = ["F", 0, 0]', 'vector = ["G", 0, 0]', "unknown name 'G'",
     'vector = ["G", 0, 0]'),
    ("unknown coordinate in nominal motion", "y = { phi1 = 0, phi2 = 0 }",
     "y = { phi1 = 0, phi9 = 0 }", 'nominal motion "down" → y → phi9: "phi9" is not a declared',
     "y = { phi1 = 0, phi9 = 0 }"),
    ("negative end time", "t_end = 2.0", "t_end = -2.0", "expected a positive number",
     "t_end = -2.0"),
    ("unknown coordinate in y0", "y0 = { phi1 = 0.1 }", "y0 = { phi = 0.1 }",
     '"phi" is not a declared coordinate', "y0 = { phi = 0.1 }"),
    ("unused coordinate", 'phi2 = "rad"', 'phi2 = "rad"\nphi3 = "rad"',
     "are not used by any joint", "[coordinates]"),
    ("missing bodies", "[bodies.link1]", "[links.link1]", 'unknown key "links"', "[links.link1]"),
    ("body named world", "[bodies.link1]", "[bodies.world]", '"world" is the inertial frame',
     "[bodies.world]"),
]


@pytest.mark.parametrize("what, old, new, message, line", MISTAKES, ids=[m[0] for m in MISTAKES])
def test_mistakes_name_file_line_and_key(what, old, new, message, line, tmp_path, capsys):
    assert old in BASE, what
    text = BASE.replace(old, new, 1)
    path = tmp_path / "model.toml"
    path.write_text(text)
    with pytest.raises(ModelFileError) as info:
        load_model(path)
    err = info.value
    assert message in str(err), str(err)
    expected = BASE[:BASE.index(old)].count("\n") + 1 if line == "@" else _line(text, line)
    assert err.line == expected, str(err)
    assert str(err).startswith(f"{path}:{err.line}: ")
    # the command says the same, with exit status 1 and no traceback
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr()
    assert message in out.err and "Traceback" not in out.err
    assert f"{path}:{err.line}:" in out.err


def test_at_least_thirty_kinds_of_mistakes():
    assert len(MISTAKES) >= 30
    assert sum("python" in m[0] or m[0] in ("attribute access", "lambda", "eval call", "indexing")
               for m in MISTAKES) >= 5


def test_file_level_errors(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ModelFileError, match="cannot read the model file"):
        load_model(missing)
    binary = tmp_path / "bin.toml"
    binary.write_bytes(b'[model]\nname = "\xff\xfe"\n')
    with pytest.raises(ModelFileError, match=r"bin.toml:2: the file is not valid UTF-8"):
        load_model(binary)
    with pytest.raises(ModelFileError, match="missing table \\[coordinates\\]"):
        loads_model("[model]\nname='x'\n", "empty.toml")


def test_expression_values_keep_exact_numbers():
    mf = loads_model(BASE.replace('com = [0, "-l2/2", 0]', 'com = [0, "-0.35", 0]'))
    body = mf.system.body("link2")
    assert body.com[1] == se.Rational(-7, 20)
    assert math.isclose(float(body.com[1]), -0.35)


def test_the_documented_complete_example_loads_and_runs(tmp_path):
    """docs/model-format.md's complete example is a valid model file with every section."""
    import re
    from pathlib import Path

    doc = (Path(__file__).resolve().parents[1] / "docs" / "model-format.md").read_text()
    block = re.search(r"```toml\n(.*?)```", doc, re.S).group(1)
    mf = loads_model(block, "model-format.md")
    s = mf.system
    assert s.coordinate_names == ["x", "phi"] and s.input_names == ["F"]
    assert [n.name for n in mf.nominal] == ["down", "towed"]
    assert mf.simulation.y0 == (0.0, pytest.approx(math.pi / 6)) and mf.simulation.yd0[0] == 0.2
    assert str(dict(mf.simulation.inputs)["F"]) == "2*sin(3*t)"
    # at x = 0 the end stop is at its rest length; towed at x_d = 0.5 it pulls back with its
    # damping 0.1*0.5 and the rail damping adds -d*0.5: q_x = -0.05 - 0.75
    v = evaluate(s, [0.0, 0.0], [0.5, 0.0], inputs={"F": 0.0})
    assert np.ravel(v["q"])[0] == pytest.approx(-0.8, rel=1e-12)


def test_mutated_examples_fail_only_with_located_model_file_errors():
    """300 random mutations of the examples (lines deleted, duplicated, values replaced by
    values of other types): every failure is a ModelFileError with a line, never another
    exception."""
    import random
    from pathlib import Path

    rng = random.Random(2024)
    files = sorted((Path(__file__).resolve().parents[1] / "examples").glob("*.toml"))
    texts = [f.read_text() for f in files]
    values = ['1', '-1', '0', '"x"', '"w"', 'true', '[1, 2]', '[1, 2, 3]', '{}', '{ a = 1 }',
              '"phi1"', '"sin("', '1e400', '"1/0"', '[]', '"world"', '"t"', 'nan', 'inf',
              '"__x__"', '"a.b"', '[[1, 2, 3], [1, 2, 3], [1, 2, 3]]',
              '[{ rot = "z", angle = "t" }]']
    failures = 0
    for _ in range(300):
        lines = rng.choice(texts).splitlines()
        for _ in range(rng.randint(1, 3)):
            i = rng.randrange(len(lines))
            op = rng.random()
            if op < 0.3:
                del lines[i]
            elif op < 0.8 and "=" in lines[i] and not lines[i].startswith("#"):
                lines[i] = lines[i].split("=")[0] + "= " + rng.choice(values)
            else:
                lines.insert(i, lines[rng.randrange(len(lines))])
        try:
            loads_model("\n".join(lines), "mutant.toml")
        except ModelFileError as exc:
            failures += 1
            assert exc.line is not None and str(exc).startswith(f"mutant.toml:{exc.line}: ")
    assert failures > 100  # the mutations do break most files
