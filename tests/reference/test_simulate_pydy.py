"""Trajectories of ``n_link_pendulum_on_cart(4)`` against PyDy's generated ODE function (from
sympy.physics.mechanics' KanesMethod of the same model) integrated with SciPy's ``odeint`` at
the same tolerances. Released near the hanging position, where the motion is regular (near the
upright position it is chaotic and no two integrators agree after a few seconds).

PyDy's ``lambdify`` generator keeps this test cheap; the benchmark uses its Cython backend."""

import math

import numpy as np
import pytest

from jourdain.models import n_link_pendulum_on_cart
from tests.tolerance import assert_close_solved, eom_terms, solve_scale

pydy_codegen = pytest.importorskip("pydy.codegen.ode_function_generators",
                                   reason="PyDy is not installed (pip install pydy)")


def pydy_rhs(n: int):
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

    kane = sympy_model(n, cart_force=True, joint_torques=False)
    M, F = kane.mass_matrix_full, kane.forcing_full
    t = dynamicsymbols._t
    consts = sorted((M.free_symbols | F.free_symbols) - {t}, key=str)
    specified = [sp.Function("F")(t)]
    rhs = pydy_codegen.generate_ode_function(
        F, kane.q, kane.u, consts, mass_matrix=M, specifieds=specified, generator="lambdify",
        linear_sys_solver="numpy")
    return rhs, [str(c) for c in consts]


def test_four_link_pendulum_on_cart_against_pydy():
    from scipy.integrate import odeint

    n = 4
    s = n_link_pendulum_on_cart(n)
    rhs, const_names = pydy_rhs(n)
    # parameters other than the defaults, to exercise the parameter vector
    params = {**s.parameter_values, "m0": 2.0, "m2": 0.7, "l1": 0.8, "l3": 1.2}
    p = np.array([params[c] for c in const_names])
    y0 = np.array([0.1, math.pi + 0.3, math.pi + 0.1, math.pi - 0.1, math.pi - 0.3])
    yd0 = np.array([0.0, 0.2, 0.0, -0.2, 0.0])
    t = np.linspace(0, 5, 51)
    tol = 1e-10
    ref = odeint(rhs, np.concatenate([y0, yd0]), t, args=(np.array([0.5]), p), rtol=tol,
                 atol=tol)
    res = s.simulate((0, 5), y0, yd0, parameters=params, inputs={"F": 0.5}, rtol=tol,
                     atol=tol, t_eval=t)
    np.testing.assert_allclose(res.y, ref[:, :n + 1], atol=1e-6)
    np.testing.assert_allclose(res.yd, ref[:, n + 1:], atol=1e-6)
    # the accelerations of the results equal PyDy's right-hand side at the same states: both
    # solve with M (jourdain's factorization, numpy's LU on PyDy's full mass matrix)
    for i in (10, 50):
        xd = rhs(np.concatenate([res.y[i], res.yd[i]]), t[i], np.array([0.5]), p)
        out = s.evaluate(res.y[i], res.yd[i], t[i], parameters=params, inputs={"F": 0.5})
        M = out["M"]
        assert_close_solved(res.ydd[i], xd[n + 1:], [M, M],
                            solve_scale(M, xd[n + 1:], eom_terms(out)))


def test_benchmark_script_runs_on_a_tiny_case():
    """benchmarks/simulation.py --quick: n = 2 against PyDy's lambdify backend."""
    from benchmarks.simulation import main

    report = main(["--quick", "--no-pinocchio", "--rounds", "1"])
    (entry,) = report["pendulum"]
    tools = entry["tools"]
    assert {"jourdain DOP853 (C loop)", "PyDy lambdify/numpy + odeint"} <= set(tools)
    # besides, jourdain at the loosest tolerance as accurate as PyDy (equal accuracy)
    assert all(k.startswith("jourdain DOP853, rtol=") for k in set(tools) - {
        "jourdain DOP853 (C loop)", "PyDy lambdify/numpy + odeint"})
    for t in tools.values():
        assert t["final_state_error"] < 1e-5 and t["integrate"] > 0 and t["nfev"] > 100
    assert entry["reference_check"] < 1e-8  # the reference agrees with odeint at 1e-12
