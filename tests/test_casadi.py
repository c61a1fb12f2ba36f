"""jd.to_casadi (jourdain.io.casadi): the equations of motion as CasADi functions, against
jourdain's own compiled numbers (the recursion's M, k, q: code independent of the translation
to SX), the Jacobian of the forward dynamics against central differences of those numbers, a
small problem in ``casadi.Opti`` checked by jourdain's integrator, and the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain import models
from jourdain.errors import ClosedSystemError, EvaluationError
from jourdain.graph import evaluate_float
from jourdain.io.casadi import sx_of
from jourdain.models.rolling import chaplygin_sleigh
from jourdain.models.trees import random_tree
from jourdain.numeric import evaluate
from tests.tolerance import EPS, assert_close_eval, eom_terms, ydd_of, ydd_tol

cs = pytest.importorskip("casadi")

MODELS = {
    "double_pendulum": models.double_pendulum,
    "cart_pendulum_2": lambda: models.n_link_pendulum_on_cart(2),
    "heavy_top": models.heavy_top,
    "spatial_chain_3": lambda: models.spatial_chain(3),
    "random_tree_4": lambda: random_tree(4, seed=3),
}


@pytest.fixture(scope="module", params=list(MODELS))
def model(request):  # noqa: ANN001, ANN201
    system = MODELS[request.param]()
    return system, jd.to_casadi(system)


def random_point(system: jd.System, rng: np.random.Generator
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict[str, float]]:
    """A state, inputs and parameters within ±20 % of the model's (the entries of inertia
    tensors, named I…, by one factor: each tensor stays that of a rigid body)."""
    y = rng.uniform(-1.5, 1.5, system.f)
    yd = rng.uniform(-2.0, 2.0, system.f)
    u = rng.uniform(-3.0, 3.0, len(system.inputs))
    inertia = rng.uniform(0.8, 1.2)
    params = {k: v * (inertia if k.startswith("I") else rng.uniform(0.8, 1.2))
              for k, v in system.parameter_values.items()}
    return y, yd, u, params


def numbers(system: jd.System, y: np.ndarray, yd: np.ndarray, u: np.ndarray,
            params: dict[str, float]) -> dict[str, np.ndarray]:
    return evaluate(system, y, yd, parameters=params,
                    inputs=list(u) if system.inputs else None)


def p_vector(system: jd.System, params: dict[str, float]) -> np.ndarray:
    return np.array([params[str(s)] for s in system.parameter_symbols])


def test_forward_and_inverse_against_the_compiled_numbers(model, rng):  # noqa: ANN001
    system, dyn = model
    assert dyn.coordinates == tuple(system.coordinate_names)
    assert dyn.parameters == tuple(str(s) for s in system.parameter_symbols)
    n_terms = 6 * len(system.bodies)
    for _ in range(5):
        y, yd, u, params = random_point(system, rng)
        out = numbers(system, y, yd, u, params)
        p = p_vector(system, params)
        M, k, q = (np.array(v) for v in dyn.eom(y, yd, u, p, 0.0))
        kt, qt = eom_terms(out)
        assert_close_eval(M, out["M"], n_terms, err_msg="M")
        assert_close_eval(k.ravel(), out["k"], n_terms, float(kt.max()), err_msg="k")
        assert_close_eval(q.ravel(), out["q"], n_terms, float(qt.max()), err_msg="q")
        # ÿ: two solves of M (LDLᵀ in SX, LU here), each within ydd_tol
        ref = ydd_of(out)
        ydd = np.array(dyn.forward(y, yd, u, p, 0.0)).ravel()
        assert np.abs(ydd - ref).max() <= 2 * ydd_tol(out, ref)
        xdot = np.array(dyn.ode(np.r_[y, yd], u, p, 0.0)).ravel()
        np.testing.assert_array_equal(xdot, np.r_[yd, ydd])
        # τ = M·ÿ + k − q at an arbitrary ÿ, a sum over the same terms and M·ÿ
        a = rng.uniform(-2.0, 2.0, system.f)
        tau = np.array(dyn.inverse(y, yd, a, u, p, 0.0)).ravel()
        scale = float((np.abs(out["M"]) @ np.abs(a)).max() + kt.max() + qt.max())
        assert_close_eval(tau, out["M"] @ a + out["k"] - out["q"], n_terms + system.f, scale,
                          err_msg="tau")


def test_forward_jacobian_against_central_differences(model, rng):  # noqa: ANN001
    """∂ÿ/∂(y, ẏ, u, p) from CasADi against central differences of the compiled ÿ; the bound
    is the truncation error estimated by Richardson (the steps h and 2h) plus the rounding of
    ÿ divided by the step."""
    system, dyn = model
    names = list(system.parameter_values)
    y, yd, u, params = random_point(system, rng)
    p = p_vector(system, params)
    x = np.r_[y, yd, u, p]
    f, m = system.f, len(u)
    xs = cs.SX.sym("x", x.size)
    ydd = dyn.forward(xs[:f], xs[f:2 * f], xs[2 * f:2 * f + m], xs[2 * f + m:], 0.0)
    jac = cs.Function("J", [xs], [cs.jacobian(ydd, xs)])
    J = np.array(jac(x))

    def ydd_at(v: np.ndarray) -> tuple[np.ndarray, float]:
        pv = dict(zip(names, v[2 * f + m:], strict=True))
        out = numbers(system, v[:f], v[f:2 * f], v[2 * f:2 * f + m], pv)
        a = ydd_of(out)
        return a, ydd_tol(out, a)

    _, rounding = ydd_at(x)
    for j in range(x.size):
        h = EPS ** (1 / 3) * max(1.0, abs(x[j]))
        e = np.zeros(x.size)
        e[j] = h
        d1 = (ydd_at(x + e)[0] - ydd_at(x - e)[0]) / (2 * h)
        d2 = (ydd_at(x + 2 * e)[0] - ydd_at(x - 2 * e)[0]) / (4 * h)
        bound = 10 * (np.abs(d2 - d1) + rounding / h)
        err = np.abs(J[:, j] - d1)
        assert np.all(err <= bound), (j, err.max(), bound.min())


def test_inside_opti_a_feasibility_problem():
    """Ten RK4 steps of the cart pendulum in ``casadi.Opti``: the constant force that moves the
    cart to a target in 0.02 s; jourdain's integrator with that force lands there (to the
    error of the RK4 steps, some 1e-12 here, and the integrator's tolerance)."""
    system = models.n_link_pendulum_on_cart(2)
    dyn = jd.to_casadi(system)
    x0 = np.array([0.1, 0.4, -0.3, 0.2, -0.5, 0.7])
    dt, target = 0.02, 0.1 + 0.02 * 0.2 + 0.001
    opti = cs.Opti()
    F = opti.variable()

    def ode(x):  # noqa: ANN001, ANN202
        return dyn.ode(x, F, dyn.p, 0.0)

    x1, h = cs.DM(x0), dt / 10
    for _ in range(10):
        k1 = ode(x1)
        k2 = ode(x1 + h / 2 * k1)
        k3 = ode(x1 + h / 2 * k2)
        k4 = ode(x1 + h * k3)
        x1 = x1 + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    opti.subject_to(x1[0] == target)
    opti.minimize(F ** 2)
    opti.solver("ipopt", {"print_time": False}, {"print_level": 0, "sb": "yes"})
    sol = opti.solve()
    force = float(sol.value(F))
    assert math.isfinite(force) and abs(force) > 1.0
    res = system.simulate((0.0, dt), x0[:3], x0[3:], inputs={"F": force}, rtol=1e-12,
                          atol=1e-14)
    # IPOPT meets the constraint to its own tolerance (1e-8 scaled); the state it predicts
    # is jourdain's motion under that force
    assert abs(sol.value(x1[0]) - target) <= 1e-6
    np.testing.assert_allclose(np.r_[res.y[-1], res.yd[-1]], sol.value(x1), rtol=0, atol=1e-10)


def test_parameters_and_refusals():
    system = models.n_link_pendulum_on_cart(2)
    dyn = jd.to_casadi(system, parameters={"m0": 3.0})
    assert dyn.p[dyn.parameters.index("m0")] == 3.0
    assert dyn.inputs == ("F",) and dyn.rates == ("q0_d", "q1_d", "q2_d")
    with pytest.raises(EvaluationError, match=r"unknown parameter\(s\) \['mass'\].*m0"):
        jd.to_casadi(system, parameters={"mass": 1.0})
    with pytest.raises(ClosedSystemError, match="closure") as info:
        jd.to_casadi(models.four_bar())
    assert "to_casadi" in info.value.capability
    with pytest.raises(ClosedSystemError, match="contact"):
        jd.to_casadi(chaplygin_sleigh())


def test_every_function_of_the_expression_language_is_translated():
    """Each function jourdain's code generator knows, and powers of every kind, translated to
    SX, against the graph's own floating-point evaluation; one it does not: a named error."""
    x, z = se.symbols("x z")
    exprs = [se.sin(x) + se.cos(z) * se.tan(x), se.asin(x / 3) * se.acos(z / 3) + se.atan(x),
             se.atan2(x, z), se.sinh(x) - se.cosh(z) + se.tanh(x * z), se.asinh(x),
             se.acosh(z + 2), se.atanh(x / 3), se.exp(x) * se.log(z + 2), se.Abs(x - z),
             se.sign(x), se.floor(3 * x), se.ceiling(3 * z), se.erf(x),
             se.Max(x, z, 0.1), se.Min(x, z), se.cot(x) + se.sec(z) + se.csc(x),
             x ** 3 / z ** 2, se.sqrt(z + 2), 1 / se.sqrt(z + 2), (z + 2) ** x,
             se.exp(x * z), se.Rational(1, 3) * x + se.pi, se.Integer(7), x]
    xs, zs = cs.SX.sym("x"), cs.SX.sym("z")
    fn = cs.Function("f", [xs, zs], sx_of(cs, exprs, {"x": xs, "z": zs}))
    for xv, zv in ((0.7, -0.4), (-0.45, 1.3)):
        ours = np.array([float(v) for v in fn(xv, zv)])
        ref = evaluate_float(exprs, {"x": xv, "z": zv})
        for e, a, b in zip(exprs, ours, ref, strict=True):
            # one or two operations each, evaluated by CasADi and by math
            assert abs(a - b) <= 100 * EPS * max(1.0, abs(b)), (str(e), a, b)
    with pytest.raises(EvaluationError, match="cannot translate the function gamma"):
        sx_of(cs, [se.gamma(x)], {"x": xs})
    with pytest.raises(EvaluationError, match='symbol "w"'):
        sx_of(cs, [x + se.Symbol("w")], {"x": xs})
