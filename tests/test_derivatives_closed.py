"""The derivatives of closed systems' dynamics (jourdain.loops.derivatives, issue 37), in their
state x = (y_i, z):

* the four-bar linkage (closing joint): ∂ẋ/∂x and ∂τ/∂x against the loop linearization of
  :mod:`jourdain.loops.linearization` (another evaluator, :class:`LoopEvaluator`, with central
  differences: tolerance from their truncation and rounding, ~eps^(2/3) relative);
* the benchmark bicycle (rolling contacts, speeds): ∂(φ̈, δ̈)/∂(φ, δ) = −M⁻¹(g·K0 + v²·K2)
  and ∂(φ̈, δ̈)/∂(φ̇, δ̇) = −M⁻¹·v·C1 with the paper's matrices (Meijaard et al. 2007,
  printed to 14 digits);
* the complex step's arithmetic: integer powers and quotients of negative numbers exact
  (SymEngine's complex evaluation gave derivatives of 1e44 there).
"""

from __future__ import annotations

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.graph.complex_step import ComplexTape
from jourdain.loops.derivatives import ClosedDerivatives
from jourdain.loops.linearization import linearize_loop
from jourdain.models import four_bar
from jourdain.models.rolling import benchmark_bicycle
from tests.reference.test_benchmark_bicycle import C1, K0, K2, M

EPS = float(np.finfo(float).eps)


def test_complex_step_arithmetic_is_exact_for_negative_bases():
    x, y = se.symbols("x y")
    exprs = [x ** 2, x ** 3 * y, 1 / x, x ** -2, se.Abs(x) * y, se.atan2(y, x)]
    tape = ComplexTape([x, y], exprs)
    h = 1e-60
    for xv in (-0.7, 0.7):
        yv = 1.3
        v = tape(np.array([xv + 1j * h, yv]))
        ref = [2 * xv, 3 * xv ** 2 * yv, -1 / xv ** 2, -2 / xv ** 3, np.sign(xv) * yv,
               -yv / (xv ** 2 + yv ** 2)]
        assert np.allclose(np.imag(v) / h, ref, rtol=4 * EPS, atol=0)
        vals = np.real(tape(np.array([xv + 0j, yv])))
        assert np.allclose(vals, [xv ** 2, xv ** 3 * yv, 1 / xv, xv ** -2, abs(xv) * yv,
                                  np.arctan2(yv, xv)], rtol=4 * EPS, atol=0)


def test_four_bar_against_the_loop_linearization():
    system = four_bar()
    d = jd.derivatives(system)
    assert isinstance(d, ClosedDerivatives) and isinstance(system.derivatives(), ClosedDerivatives)
    y0, yd0 = [0.5, 0.8, 1.9], [1.3, 0.0, 0.0]
    fw = d.forward(y0, yd0)
    assert fw.x_names == ("theta1", "theta1_d")
    lin = linearize_loop(system, fw.y, fw.yd, ydd_s=[fw.xd[1]])
    # central differences with step eps^(1/3): truncation and rounding both ~eps^(2/3)
    scale = max(np.abs(lin.A).max(), 1.0)
    tol = 100 * EPS ** (2 / 3) * scale
    assert np.abs(fw.xd_x - lin.A).max() <= tol
    inv = d.inverse(y0, yd0, [0.3])
    lin3 = linearize_loop(system, fw.y, fw.yd, ydd_s=[0.3])
    tau_x = np.hstack([lin3.Q, lin3.P])
    assert np.abs(inv.tau_x - tau_x).max() <= 100 * EPS ** (2 / 3) * max(np.abs(tau_x).max(), 1)
    assert np.allclose(inv.tau_zd, lin3.M_tilde, rtol=10 * EPS, atol=0)
    assert np.allclose(inv.tau, -lin3.h, rtol=1e3 * EPS, atol=1e3 * EPS * np.abs(lin3.h).max())
    # the acceleration agrees with the closed system's own evaluation (jourdain.loops.evaluation)
    out = system.evaluate(fw.y, fw.yd)
    Mz = np.atleast_2d(out["M"])
    zdd = np.linalg.solve(Mz, np.atleast_1d(out["q"] - out["k"]))
    assert np.allclose(fw.xd[1:], zdd, rtol=1e3 * EPS * np.linalg.cond(Mz), atol=0)


@pytest.mark.parametrize("v", [0.0, 5.0])
def test_bicycle_against_the_papers_matrices(v):
    system = benchmark_bicycle()
    names = system.coordinate_names
    y0 = np.zeros(system.f)
    y0[names.index("zc")] = -0.3
    yd0 = np.zeros(system.f)
    yd0[names.index("thetaR")] = -v / 0.3
    fw = jd.derivatives(system).forward(y0, yd0)
    ix = [fw.x_names.index(n) for n in ("phi", "delta")]
    iz = [fw.x_names.index(n) for n in ("phi_d", "delta_d")]
    K = -np.linalg.solve(M, 9.81 * K0 + v ** 2 * K2)
    C = -np.linalg.solve(M, v * C1)
    rows = np.ix_(iz, ix)
    rtol = 1e-12  # the paper's 14 digits through a solve with cond(M) ≈ 8e2
    assert np.abs(fw.xd_x[rows] - K).max() <= rtol * np.abs(K).max()
    assert np.abs(fw.xd_x[np.ix_(iz, iz)] - C).max() <= rtol * max(np.abs(C).max(), 1.0)
    # the kinematic rows: ∂(φ̇, δ̇)/∂(φ̇, δ̇) = E
    assert np.array_equal(fw.xd_x[np.ix_(ix, iz)], np.eye(2))


def test_closed_derivatives_name_bad_input():
    d = jd.derivatives(four_bar())
    with pytest.raises(jd.EvaluationError, match="zd must be 1"):
        d.inverse([0.5, 0.8, 1.9], [1.0, 0, 0], [0.1, 0.2])
    with pytest.raises(jd.EvaluationError, match="NaN"):
        d.forward([np.nan, 0.8, 1.9], [1.0, 0, 0])
