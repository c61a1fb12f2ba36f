"""The compiled derivatives of the dynamics (jourdain.numeric.derivatives, issue 37) against
the symbolic linearization in its general form (an independent path: the symbolic stages and
the forward mode over their expression graph, :func:`jourdain.linearization_general`), whose
``M̃, P, Q, B, h`` at a state ``(y, ẏ, ÿ, u)`` are exactly ``∂τ/∂ÿ, ∂τ/∂ẏ, ∂τ/∂y, −∂τ/∂u``
and ``−τ`` of ``τ = M·ÿ + k − q``; the forward dynamics against ``M⁻¹`` of the same numbers;
a batch against the states one by one (bit for bit); the errors.

Tolerances: both sides evaluate sums of products of the same magnitudes (no solve), so
:func:`tests.tolerance.eval_tol` with the number of bodies' terms and the largest entry; the
forward derivatives come out of a solve with M: :func:`tests.tolerance.solve_tol`. Pinocchio
and central differences are the other references (tests/reference/test_derivatives_pinocchio.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.errors import ClosedSystemError, EvaluationError
from jourdain.io.modelfile.loader import load_model
from jourdain.models import four_bar, heavy_top, n_link_pendulum_on_cart, spatial_chain
from tests.tolerance import eval_tol, solve_tol

ROOT = Path(__file__).resolve().parents[1]


def _models():
    return {
        "cart3": n_link_pendulum_on_cart(3),               # absolute angles, an input
        "top": heavy_top(),                                 # spatial, gyroscopic
        "chain4": spatial_chain(4),                         # universal and spherical joints
        "quarter_car": load_model(ROOT / "examples" / "quarter_car.toml").system,
        "bushings": load_model(ROOT / "examples" / "vehicle_on_bushings.toml").system,
    }


MODELS = _models()


def _state(system, rng):
    f, nu = system.f, len(system.inputs)
    return (rng.uniform(-0.5, 0.5, f), rng.uniform(-1, 1, f), rng.uniform(-2, 2, f),
            rng.uniform(-1, 1, nu) if nu else None)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_inverse_derivatives_equal_the_symbolic_linearization(name):
    system = MODELS[name]
    glin = jd.linearization_general(system.equations_of_motion())
    d = jd.derivatives(system)
    rng = np.random.default_rng(3)
    n_terms = 6 * len(system.bodies) + 6
    for _ in range(3):
        y, yd, ydd, u = _state(system, rng)
        inputs = None if u is None else dict(zip(system.input_names, u, strict=True))
        ref = glin.evaluate(y, yd, ydd, inputs=inputs)
        inv = d.inverse(y, yd, ydd, u)
        pairs = (("tau", inv.tau, -ref["h"].reshape(-1)), ("tau_y", inv.tau_y, ref["Q"]),
                 ("tau_yd", inv.tau_yd, ref["P"]), ("tau_ydd", inv.tau_ydd, ref["M_tilde"]))
        for what, ours, theirs in pairs:
            scale = max(np.abs(theirs).max(), np.abs(ref["M_tilde"] @ ydd).max(), 1.0)
            tol = eval_tol(n_terms, scale)
            assert np.abs(ours - theirs).max() <= tol, (name, what)
        if u is not None:
            B = ref["B"]
            assert np.abs(inv.tau_u + B).max() <= eval_tol(n_terms, max(np.abs(B).max(), 1.0))


@pytest.mark.parametrize("name", ["cart3", "top", "quarter_car"])
def test_forward_derivatives_are_minus_m_inverse_times_the_inverse_ones(name):
    system = MODELS[name]
    d = jd.derivatives(system)
    rng = np.random.default_rng(5)
    y, yd, _, u = _state(system, rng)
    fw = d.forward(y, yd, u)
    out = system.evaluate(y, yd, inputs=None if u is None else list(u))
    M = out["M"]
    ydd = np.linalg.solve(M, out["q"] - out["k"])
    assert np.abs(fw.ydd - ydd).max() <= solve_tol(M, max(np.abs(ydd).max(), 1.0))
    inv = d.inverse(y, yd, fw.ydd, u)
    for ours, tau_x in ((fw.ydd_y, inv.tau_y), (fw.ydd_yd, inv.tau_yd), (fw.ydd_u, inv.tau_u)):
        if tau_x.size == 0:
            continue
        ref = -np.linalg.solve(M, tau_x)
        assert np.abs(ours - ref).max() <= solve_tol(M, max(np.abs(ref).max(), 1e-300))


def test_a_batch_equals_the_states_one_by_one():
    system = MODELS["cart3"]
    d = system.derivatives()
    rng = np.random.default_rng(9)
    n = 5
    Y = rng.uniform(-1, 1, (n, system.f))
    YD = rng.uniform(-1, 1, (n, system.f))
    YDD = rng.uniform(-1, 1, (n, system.f))
    U = rng.uniform(-1, 1, (n, 1))
    inv = d.inverse(Y, YD, YDD, U)
    fw = d.forward(Y, YD, U)
    assert inv.tau_y.shape == (n, system.f, system.f) and fw.ydd_u.shape == (n, system.f, 1)
    for i in range(n):
        one = d.inverse(Y[i], YD[i], YDD[i], U[i])
        assert np.array_equal(one.tau_y, inv.tau_y[i]) and np.array_equal(one.tau, inv.tau[i])
        f1 = d.forward(Y[i], YD[i], U[i])
        assert np.array_equal(f1.ydd_y, fw.ydd_y[i]) and np.array_equal(f1.ydd, fw.ydd[i])
    shared = d.forward(Y, YD, U[0])  # one input vector for all states
    assert np.array_equal(shared.ydd[0], fw.ydd[0])


def test_parameters_change_the_numbers_without_a_new_library():
    system = MODELS["cart3"]
    d = jd.derivatives(system)
    y, yd, ydd, u = _state(system, np.random.default_rng(1))
    base = d.inverse(y, yd, ydd, u)
    heavier = d.inverse(y, yd, ydd, u, parameters={"m0": 2 * system.parameter_values["m0"]})
    assert jd.derivatives(system) is d
    assert not np.array_equal(base.tau_ydd, heavier.tau_ydd)
    glin = jd.linearization_general(system.equations_of_motion())
    ref = glin.evaluate(y, yd, ydd, parameters={"m0": 2 * system.parameter_values["m0"]},
                        inputs=dict(zip(system.input_names, u, strict=True)))
    assert np.abs(heavier.tau_y - ref["Q"]).max() <= eval_tol(30, max(np.abs(ref["Q"]).max(), 1))


def test_bad_input_is_named():
    system = MODELS["cart3"]
    d = jd.derivatives(system)
    f = system.f
    with pytest.raises(EvaluationError, match="y contains NaN"):
        d.forward(np.full(f, np.nan), np.zeros(f), [0.0])
    with pytest.raises(EvaluationError, match="shape"):
        d.inverse(np.zeros(f + 1), np.zeros(f), np.zeros(f), [0.0])
    with pytest.raises(EvaluationError, match="inputs"):
        d.forward(np.zeros(f), np.zeros(f))
    with pytest.raises(EvaluationError, match="unknown parameter"):
        d.forward(np.zeros(f), np.zeros(f), [0.0], parameters={"nope": 1.0})
    # the compiled derivatives are a tree's (jd.derivatives takes a closed system to its own:
    # tests/test_derivatives_closed.py)
    from jourdain.numeric.derivatives import derivatives as compiled

    with pytest.raises(ClosedSystemError, match="derivatives"):
        compiled(four_bar())


@pytest.mark.parametrize("name", ["cart3", "chain4"])  # the forward mode; screw joints
def test_exported_c_sources_compile_alone_and_give_the_same_numbers(tmp_path, name):
    import shutil
    import subprocess

    from jourdain.numeric.toolchain import CompilerError, compiler

    try:
        cc = compiler()
    except CompilerError:
        pytest.skip("no C compiler")
    system = MODELS[name]
    d = jd.derivatives(system)
    paths = d.export_c(tmp_path / "src")
    header = (tmp_path / "src" / "jourdain_derivatives.h").read_text()
    assert "jd_forward_derivatives" in header and system.coordinate_names[0] in header
    y, yd, _, u = _state(system, np.random.default_rng(11))
    p = np.array(list(system.parameter_values.values()))
    def fmt(values) -> str:
        return ", ".join(repr(float(v)) for v in values)

    main = f"""#include <stdio.h>
#include "jourdain_derivatives.h"
int main(void) {{
    double y[] = {{{fmt(y)}}}, yd[] = {{{fmt(yd)}}};
    double p[] = {{{fmt(p)}}}, u[] = {{{fmt(u) if u is not None else "0.0"}}};
    double out[JOURDAIN_F + 2 * JOURDAIN_F * JOURDAIN_F + JOURDAIN_F * JOURDAIN_NU];
    if (jd_forward_derivatives(y, yd, 0.0, p, u, out)) return 1;
    for (int i = 0; i < (int)(sizeof out / sizeof *out); ++i) printf("%.17g\\n", out[i]);
    return 0;
}}
"""
    (tmp_path / "src" / "main.c").write_text(main)
    exe = tmp_path / "run"
    sources = [str(x) for x in paths[1:]] + [str(tmp_path / "src" / "main.c")]
    subprocess.run([cc, "-O2", "-std=c99", "-o", str(exe), *sources, "-lm"], check=True,
                   capture_output=True)
    printed = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    numbers = np.array([float(x) for x in printed.split()])
    fw = d.forward(y, yd, u)
    ours = np.concatenate([fw.ydd, fw.ydd_y.ravel(), fw.ydd_yd.ravel(), fw.ydd_u.ravel()])
    # another compilation of the same source (flags may differ: -march): rounding only
    M = system.evaluate(y, yd, inputs=None if u is None else list(u))["M"]
    assert np.abs(numbers - ours).max() <= solve_tol(M, max(np.abs(ours).max(), 1.0))
    shutil.rmtree(tmp_path / "src")


def _screw_against_forward_mode(system, seed: int) -> None:
    """Two implementations of the same derivatives at random states: the recursions on the
    columns of screw joints (derivative_screw.h, what jd.derivatives takes for the model) and
    the forward mode of every intermediate quantity (derivative_engine.h)."""
    from jourdain.numeric.derivative_screw import screw_columns
    from jourdain.numeric.derivatives import compiled_derivatives

    assert screw_columns(system) is not None
    screw, fwd = compiled_derivatives(system), compiled_derivatives(system, forward_mode=True)
    rng = np.random.default_rng(seed)
    n_terms = 6 * len(system.bodies) + 6
    for _ in range(3):
        y, yd, ydd, u = _state(system, rng)
        a, b = screw.inverse(y, yd, ydd, u), fwd.inverse(y, yd, ydd, u)
        for x, z in ((a.tau, b.tau), (a.tau_y, b.tau_y), (a.tau_yd, b.tau_yd),
                     (a.tau_ydd, b.tau_ydd), (a.tau_u, b.tau_u)):
            scale = max(np.abs(z).max(initial=0.0), np.abs(b.tau_ydd @ ydd).max(), 1.0)
            assert np.abs(x - z).max(initial=0.0) <= eval_tol(n_terms, scale)
        fa, fb = screw.forward(y, yd, u), fwd.forward(y, yd, u)
        for x, z in ((fa.ydd, fb.ydd), (fa.ydd_y, fb.ydd_y), (fa.ydd_yd, fb.ydd_yd),
                     (fa.ydd_u, fb.ydd_u)):
            bound = solve_tol(b.tau_ydd, max(np.abs(z).max(initial=0.0), 1.0))
            assert np.abs(x - z).max(initial=0.0) <= bound


@pytest.mark.parametrize("name", ["top", "chain4"])
def test_the_recursions_of_screw_joints_equal_the_forward_mode(name):
    _screw_against_forward_mode(MODELS[name], 17)

def test_joint_friction_is_refused_by_name():
    """Joint friction is set-valued at rest: no derivatives (never silently without it)."""
    from tests.test_friction import incline

    system = incline(0.5, 0.3)
    assert system.frictions
    with pytest.raises(jd.ModelError, match="joint friction"):
        jd.derivatives(system)


def _mixed_joints():
    """Every kind of screw joint on one tree, a fixed joint between, axes and offsets of
    parameters, a torque input and two gravity elements."""
    x, a, b1, b2, c1, c2, c3, p1, p2, p3, s1, s2 = jd.symbols(
        "x a b1 b2 c1 c2 c3 p1 p2 p3 s1 s2")
    L, m, tau = jd.symbols("L m tau")
    box = jd.box(m, 0.3, 0.2, 0.1)
    bodies = [
        jd.Body("cart", "world", jd.Prismatic("slide", x, (1, L, 0)), mass=m, com=(0.1, 0, 0),
                inertia=box),
        jd.Body("arm", "cart", jd.Revolute("hinge", a, "z", position=(0, 0.2, 0)), mass=m,
                com=(L / 2, 0, 0.05), inertia=box),
        jd.Body("plate", "arm", jd.Fixed("weld", position=(L, 0, 0)), mass=m / 2,
                com=(0, 0.1, 0), inertia=box),
        jd.Body("fork", "plate", jd.Universal("cardan", [b1, b2], ("x", "y"),
                                              position=(0.1, 0, 0)), mass=m, com=(0, 0, -L),
                inertia=box),
        jd.Body("ball", "fork", jd.Spherical("socket", [c1, c2, c3], "zyx",
                                             position=(0, 0, -L)), mass=m, com=(0.1, 0.1, -0.2),
                inertia=box),
        jd.Body("puck", "arm", jd.Planar("plane", [p1, p2, p3], "z", position=(0, 0.3, 0)),
                mass=m, com=(0.05, 0, 0), inertia=box),
        jd.Body("sleeve", "puck", jd.Cylindrical("tube", [s1, s2], (0, 1, 1)), mass=m,
                com=(0, 0.1, 0.1), inertia=box),
    ]
    return jd.System([x, a, b1, b2, c1, c2, c3, p1, p2, p3, s1, s2], bodies,
                     [jd.Gravity((0, -9.81, 0)), jd.Gravity((0.5, 0, -1.0), name="tilt"),
                      jd.GeneralizedForce("drive", a, 2 * tau)],
                     parameters={"L": 0.7, "m": 1.3}, inputs=[tau], name="mixed joints")


def test_every_screw_joint_kind_against_the_forward_mode():
    _screw_against_forward_mode(_mixed_joints(), 23)
