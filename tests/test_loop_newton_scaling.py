"""Newton's stop on the closed-loop manifold is free of units (issue 32, item 5): the four-bar
with every length multiplied by s (and g by s, so that the angle equations are the same) is
solved and simulated as in metres, by the C kernel (loop_c.h) and by LoopEvaluator alike.

Before the change the stop was ``|Φ| ≤ 1e-13·(1 + max|z|)`` in the units of Φ: at s = 1e-5 the
simulation below took 208 470 right-hand sides instead of 4 014 and ended 1.7e-6 rad off the
run in metres (s = 1e-3: 1.5e-8 rad), and at s = 1e-10 the Python evaluator took a
configuration that closes no loop as solved."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jourdain.loops import LoopEvaluator, SingularConfiguration
from jourdain.loops.compiled import LoopKernel
from tests.tolerance import EPS, cond, solve_tol

try:
    from jourdain.models.loops import four_bar
except ImportError:  # before the models moved to jourdain.models
    from jourdain.loops.models import four_bar  # type: ignore[no-redef]

BASE = {"a": 0.4, "b": 1.0, "c": 0.8, "d": 1.1, "m1": 1.0, "m2": 2.0, "m3": 1.5, "g": 9.81}
Z0, ZD0 = [0.5, 0.8, 1.9], [1.0, 0.0, 0.0]
SPAN = (0.0, 5.0)


def _params(s: float, **change: float) -> dict[str, float]:
    """The four-bar with lengths and g multiplied by s: the angle equations do not change
    (the issue's case: a mechanism drawn in other units of length)."""
    p = {**BASE, **change}
    for k in ("a", "b", "c", "d", "g"):
        p[k] *= s
    return p


@pytest.fixture(scope="module")
def runs() -> dict[float, object]:
    loop = four_bar()
    return {s: loop.simulate(SPAN, Z0, ZD0, parameters=_params(s), samples=51, rtol=1e-10,
                             atol=1e-12)
            for s in (1.0, 1e-3, 1e-5)}


@pytest.mark.parametrize("s", [1e-3, 1e-5])
def test_simulation_does_not_depend_on_the_length_unit(runs: dict, s: float) -> None:
    """Same right-hand-side count (within 10 %) and the same angles as in metres. The equations
    are the same, so the two runs differ by rounding only: each right-hand side can move the
    state by about eps relative, so after nfev of them the angles are bounded by
    ``eps·nfev·max|θ|`` unless the integrator's decisions differ (measured: 3 954 right-hand
    sides at every s and 4e-13 rad apart, a tenth of that bound; the former stop: 4 014, 4 026
    and 33 378 right-hand sides, 6.6e-9 and 1.1e-6 rad apart)."""
    ref, res = runs[1.0], runs[s]
    assert ref.status == "finished" and res.status == "finished"
    assert abs(res.nfev - ref.nfev) <= 0.1 * ref.nfev
    assert res.t.shape == ref.t.shape and np.array_equal(res.t, ref.t)
    tol = EPS * ref.nfev * float(np.max(np.abs(ref.y)))
    assert float(np.max(np.abs(res.y - ref.y))) <= tol
    # the residual left is the same fraction of the lengths: the relative tolerance of the
    # stop on rows whose scale Σ|∂Φ/∂θ|·|θ| is at most (a + 2b + c)·max|θ|, or rounding
    p = _params(s)
    lever = (p["a"] + 2 * p["b"] + p["c"]) * float(np.max(np.abs(res.y)))
    ev = LoopEvaluator(four_bar(), Z0, 0.0, p)
    bound = ev.newton_tol * lever + 10 * EPS * (p["a"] + p["b"] + p["c"] + p["d"]) * 4
    assert float(np.max(np.abs(res.Phi))) <= bound


def _sweep(ev: LoopEvaluator, ys: np.ndarray) -> tuple[np.ndarray, list[int], list[float]]:
    """Dependent coordinates solved along the crank angles ys, each from the last solution."""
    ev.assemble(Z0)
    out, its, tols = [], [], []
    rows, dep = list(ev.part.rows), list(ev.part.dependent)
    for y in ys:
        z, cd, it = ev.solve_positions(np.array([y]), 0.0)
        ev.z_guess = z
        Pd = cd["Phi_z"][np.ix_(rows, dep)]
        # rounding of the solve, plus the relative tolerance of the stop mapped by Φ_d⁻¹
        tols.append(solve_tol(Pd, 1.0 + float(np.max(np.abs(z))))
                    + len(dep) * cond(Pd) * ev.newton_tol * float(np.max(np.abs(z))))
        out.append(z)
        its.append(it)
    return np.array(out), its, tols


def test_python_evaluator_does_not_depend_on_the_length_unit() -> None:
    """LoopEvaluator.solve_positions along a sweep of the crank, through θ1 = 0 and from the
    last solution: the same Newton steps (give or take one where a residual lands on the
    bound by rounding) and the same angles at s = 1e-5 as in metres."""
    loop = four_bar()
    ys = np.concatenate([np.linspace(0.5, -0.5, 11), [0.0], np.linspace(0.0, 2.5, 26)])
    z1, it1, tols = _sweep(LoopEvaluator(loop, Z0, 0.0, _params(1.0)), ys)
    z5, it5, _ = _sweep(LoopEvaluator(loop, Z0, 0.0, _params(1e-5)), ys)
    assert all(abs(a - b) <= 1 for a, b in zip(it1, it5, strict=True))
    for k in range(len(ys)):
        assert float(np.max(np.abs(z5[k] - z1[k]))) <= tols[k]


@pytest.mark.parametrize("s", [1.0, 1e-5, 1e-10])
def test_no_configuration_is_never_taken_as_solved(s: float) -> None:
    """With b = 0.5 the loop cannot close at θ1 = π (a + d = 1.5 > b + c = 1.3): Newton fails
    at every scale. The former absolute stagnation exit (|Φ| ≤ 1e-10·(1 + max|z|)) took the
    closest approach, 0.2·s off, as solved at s = 1e-10."""
    ev = LoopEvaluator(four_bar(), Z0, 0.0, _params(s, b=0.5))
    ev.assemble([0.5, 0.3, 1.5])
    with pytest.raises(SingularConfiguration):
        ev.solve_positions(np.array([math.pi]), 0.0)


def _zero_cases(s: float) -> list[tuple[dict[str, float], list[float], float]]:
    """(parameters, a guess on the branch, the crank angle): the crank at θ1 = 0 (independent
    coordinate 0), and with d = 0.3 the crank angle at which the rocker lies along x (θ3 = 0,
    dependent: its end at (c + d, 0) is b from the crank pin)."""
    p = _params(s, d=0.3)
    a, b, c, d = (p[k] for k in "abcd")
    th1 = math.acos((a * a + (c + d) ** 2 - b * b) / (2 * a * (c + d)))
    th2 = math.atan2(-a * math.sin(th1), c + d - a * math.cos(th1)) - th1
    return [(_params(s), [0.0, 1.2, 1.5], 0.0), (p, [th1, th2 + 0.05, 0.05], th1)]


@pytest.mark.parametrize("s", [1.0, 1e-5])
def test_zero_coordinates_converge(s: float) -> None:
    """A coordinate that is 0 keeps its row's scale through the others: both the Python
    evaluator and the C kernel converge where θ1 = 0 or θ3 = 0, within the solve's rounding of
    each other (and θ3 of the closed form)."""
    loop = four_bar()
    for p, guess, y in _zero_cases(s):
        ev = LoopEvaluator(loop, guess, 0.0, p)
        asm = ev.assemble(guess)
        rows, dep = list(ev.part.rows), list(ev.part.dependent)
        ev.z_guess = asm.z
        z, cd, it = ev.solve_positions(np.array([y]), 0.0)
        Pd = cd["Phi_z"][np.ix_(rows, dep)]
        tol = solve_tol(Pd, 1.0 + float(np.max(np.abs(z)))) \
            + len(dep) * cond(Pd) * ev.newton_tol * float(np.max(np.abs(z)))
        assert it < ev.max_newton
        if y != 0.0:
            assert abs(z[2]) <= tol
        kernel = LoopKernel(ev)
        kernel.restart(asm.z, asm.z[list(ev.part.independent)])
        got, bad = kernel.samples(np.zeros(1), np.array([[y, 0.0]]))
        assert bad == -1
        assert float(np.max(np.abs(got["z"][0] - z))) <= 2 * tol


@pytest.mark.parametrize("s", [1.0, 1e-5])
def test_plateau_exit_alone_solves_to_rounding(s: float) -> None:
    """With newton_tol = 0 the scaled residual test is out of reach (no residual is exactly
    0), so every solve ends at the rounding plateau: the Python evaluator and the C kernel
    still converge, to the configuration of the default tolerance within rounding, and a
    configuration that does not exist still fails."""
    loop = four_bar()
    p = _params(s)
    ref = LoopEvaluator(loop, Z0, 0.0, p)
    ev = LoopEvaluator(loop, Z0, 0.0, p)
    ev.newton_tol = 0.0
    asm = ev.assemble(Z0)
    rows, dep = list(ev.part.rows), list(ev.part.dependent)
    ys = [0.5, 0.7, 0.0, -0.3]
    zs = []
    for y in ys:
        z, cd, it = ev.solve_positions(np.array([y]), 0.0)
        ev.z_guess = z
        zr, _, _ = ref.solve_positions(np.array([y]), 0.0, z)
        Pd = cd["Phi_z"][np.ix_(rows, dep)]
        tol = solve_tol(Pd, 1.0 + float(np.max(np.abs(z)))) \
            + len(dep) * cond(Pd) * ref.newton_tol * float(np.max(np.abs(z)))
        assert it < ev.max_newton and float(np.max(np.abs(z - zr))) <= tol
        zs.append((z, tol))
    ev.z_guess = asm.z
    kernel = LoopKernel(ev)  # reads newton_tol = 0
    kernel.restart(asm.z, asm.z[list(ev.part.independent)])
    got, bad = kernel.samples(np.zeros(len(ys)), np.array([[y, 0.0] for y in ys]))
    assert bad == -1
    for k, (z, tol) in enumerate(zs):
        assert float(np.max(np.abs(got["z"][k] - z))) <= 2 * tol
    bad_ev = LoopEvaluator(loop, Z0, 0.0, _params(s, b=0.5))
    bad_ev.newton_tol = 0.0
    bad_ev.assemble([0.5, 0.3, 1.5])
    with pytest.raises(SingularConfiguration):
        bad_ev.solve_positions(np.array([math.pi]), 0.0)
