"""The benchmark bicycle (Meijaard, Papadopoulos, Ruina, Schwab 2007, Proc. R. Soc. A 463,
1955–1982), built from its geometry and mass data (Table 1) as four rigid bodies with two
wheels rolling without slip (:func:`jourdain.models.rolling.benchmark_bicycle`), against the
paper's linear matrices (eq. A 20–A 24 / §5: M, C1, K0, K2, printed to 14 digits), its
eigenvalues (Table 2) and its weave and capsize speeds.

Tolerances: the paper prints its numbers to 14 decimals, so 1e-12 relative (as the issue
asks) is two digits above their rounding; the complex-step linearization carries no
truncation error, so only rounding separates ours from theirs.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
import symengine as se

import jourdain as jd
from jourdain.models.rolling import benchmark_bicycle

M = np.array([[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]])
C1 = np.array([[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]])
K0 = np.array([[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]])
K2 = np.array([[0.0, 76.59734589573222], [0.0, 2.65431523794604]])
#: Table 2: eigenvalues at v = 0, 4, 5, 10 m/s
TABLE2 = {
    0.0: [-5.53094371765393, -3.13164324790656, 3.13164324790656, 5.53094371765393],
    4.0: [-12.15861426576447, -1.42944427361326, 0.41325331521125 - 3.07910818603206j,
          0.41325331521125 + 3.07910818603206j],
    5.0: [-14.07838969279822, -0.77534188219585 - 4.46486771378823j,
          -0.77534188219585 + 4.46486771378823j, -0.32286642900409],
    10.0: [-24.62459635017404, -3.72016840437287 - 10.90681139476287j,
           -3.72016840437287 + 10.90681139476287j, 0.16105338653172],
}
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837
V, RR = se.Symbol("v"), se.Symbol("rR")
NOMINAL = {"zc": -RR, "thetaR_d": -V / RR}


@pytest.fixture(scope="module")
def bicycle() -> jd.System:
    return benchmark_bicycle()


@pytest.fixture(scope="module")
def lin0(bicycle: jd.System):
    return bicycle.linearize(NOMINAL).at({"v": 0.0})


def _close(ours: np.ndarray, ref: np.ndarray, rtol: float = 1e-12) -> None:
    scale = float(np.max(np.abs(ref)))
    assert np.max(np.abs(ours - ref)) <= rtol * scale, (ours, ref)


def test_linear_matrices_equal_the_papers(bicycle: jd.System, lin0) -> None:
    lin1 = lin0.at({"v": 1.0})
    assert lin0.names == ("phi", "delta")
    assert set(lin0.cyclic) == {"x", "y", "psi", "thetaR", "thetaF"}
    g = bicycle.parameter_values["g"]
    _close(lin0.M_tilde, M)
    _close(lin1.P, C1)        # P = v·C1
    _close(lin0.Q / g, K0)    # Q = g·K0 + v²·K2
    _close(lin1.Q - lin0.Q, K2, 1e-11)  # a difference of two Q of size g·K0: rounding ×10
    assert np.all(lin0.P == 0.0) or np.max(np.abs(lin0.P)) <= 1e-12 * np.max(np.abs(C1))
    # the split: velocity constraints alone give damping-like and circulatory terms
    assert np.max(np.abs(lin1.N)) > 0.1 and np.max(np.abs(lin1.D)) > 0.1


@pytest.mark.parametrize("v", sorted(TABLE2))
def test_eigenvalues_equal_table_2(lin0, v: float) -> None:
    lam = lin0.at({"v": v}).eigenvalues
    ref = np.array(TABLE2[v])
    for r in ref:
        assert np.min(np.abs(lam - r)) <= 1e-12 * max(1.0, abs(r)), (lam, r)


def test_weave_and_capsize_speeds(lin0) -> None:
    weave = jd.stability_boundary(lin0, "v", 3.0, 5.0)
    capsize = jd.stability_boundary(lin0, "v", 5.0, 7.0)
    assert abs(weave - WEAVE) <= 1e-10 * WEAVE
    assert abs(capsize - CAPSIZE) <= 1e-10 * CAPSIZE
    assert jd.stability(lin0.at({"v": 5.0})).verdict == "asymptotically stable"
    assert jd.stability(lin0.at({"v": 3.0})).verdict == "unstable"


def test_contact_forces_and_jourdains_principle(bicycle: jd.System) -> None:
    """Upright at rest: the normal loads are the statics' (moments about the rear contact),
    no tangential force; the contact directions are orthogonal to L̄ = J̄·L at any state."""
    p = bicycle.parameter_values
    names = bicycle.coordinate_names
    y = np.zeros(9)
    y[names.index("zc")] = -p["rR"]
    out = bicycle.evaluate(y, np.zeros(9))
    g = p["g"]
    weight = g * (p["mR"] + p["mB"] + p["mH"] + p["mF"])
    front = g * (p["mB"] * p["xB"] + p["mH"] * p["xH"] + p["mF"] * p["w"]) / p["w"]
    f = out["contact_forces"]
    assert abs(f["front.N"] - front) <= 1e-12 * weight
    assert abs(f["rear.N"] + f["front.N"] - weight) <= 1e-12 * weight
    for k in ("rear.T1", "rear.T2", "front.T1", "front.T2"):
        assert abs(f[k]) <= 1e-12 * weight
    rng = np.random.default_rng(3)
    y = rng.uniform(-0.3, 0.3, 9)
    y[names.index("zc")] = -p["rR"]
    yd = rng.uniform(-2.0, 2.0, 9)
    out = bicycle.evaluate(y, yd)
    scale = float(np.max(np.abs(out["J_bar_tree"]))) * float(np.max(np.abs(out["Q_c"])))
    assert out["orthogonality"] <= 100 * np.finfo(float).eps * scale * 9
    assert np.max(np.abs(out["Phi"])) <= 1e-13
    assert np.max(np.abs(out["Phi_dot"])) <= 100 * np.finfo(float).eps * (
        1 + float(np.max(np.abs(out["yd"]))))


def test_nonlinear_motion_follows_the_linearization(bicycle: jd.System, lin0) -> None:
    """A small lean at 5 m/s: the nonlinear run (constraints at rounding all along) and the
    linear motion exp(A·t)·x0 differ by second-order terms only."""
    p = bicycle.parameter_values
    names = bicycle.coordinate_names
    phi0 = 1e-4
    y0 = np.zeros(9)
    y0[names.index("zc")] = -p["rR"]
    y0[names.index("phi")] = phi0
    yd0 = np.zeros(9)
    yd0[names.index("thetaR")] = -5.0 / p["rR"]
    res = bicycle.simulate((0.0, 1.0), y0, yd0, rtol=1e-11, atol=1e-13, t_eval=[0.5, 1.0])
    assert res.status == "finished"
    lin = lin0.at({"v": 5.0})
    x = sla.expm(lin.A * 1.0) @ np.array([phi0, 0.0, 0.0, 0.0])
    assert abs(res.y[-1, names.index("phi")] - x[0]) <= 1e-3 * phi0
    assert abs(res.y[-1, names.index("delta")] - x[1]) <= 1e-3 * phi0
    cons = res.constraints
    assert np.max(np.abs(cons.Phi)) <= 1e-13
    assert np.max(np.abs(cons.Phi_dot)) <= 1e-12
