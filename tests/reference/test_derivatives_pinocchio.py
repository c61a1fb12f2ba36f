"""jourdain's compiled derivatives of the dynamics (``jourdain.derivatives``, issue 37) against
Pinocchio's ``computeRNEADerivatives`` and ``computeABADerivatives`` and against central
differences of jourdain's own compiled M, k, q.

* **Random tree, f = 66** (``random_tree(35, 0)``: branching, revolute, prismatic, universal,
  spherical and a free root about random axes; Pinocchio's twin of
  :func:`benchmarks.pinocchio_models.tree_model`, joints added depth-first, one Pinocchio
  coordinate per jourdain coordinate, so the map is the TreeIndex permutation): τ, ∂τ/∂y,
  ∂τ/∂ẏ, ∂τ/∂ÿ = M at random ``(y, ẏ, ÿ)``; ÿ, ∂ÿ/∂y, ∂ÿ/∂ẏ at random ``(y, ẏ)``, one batched
  call for all states, and single-state calls equal to the batch's rows.
* **URDF robots with a floating base** (example-robot-data: Solo-12, f = 18; Talos, f = 38):
  the free flyer's tangent space mapped explicitly (:mod:`tests.reference.pinocchio_derivatives`:
  ``q(y)``, ``ν = T(y)·ẏ``, ``c = Ṫẏ``, the chain rule through ``∂T/∂y``, ``∂c/∂y``,
  ``∂c/∂ẏ`` by the complex step), with the joints' torque inputs (``load_urdf(actuated=True)``)
  at random values: ``∂ÿ/∂u = M⁻¹·B`` checks Pinocchio's ``M⁻¹`` (``ddq_dtau``), ``∂τ/∂u = −B``.
  The map itself is checked on its own: T is the tangent map of ``q(y)`` in Pinocchio's tangent
  space (``pin.difference``), and Pinocchio's mapped derivatives agree with central differences
  of jourdain's τ and ÿ (no derivative code of jourdain involved).
* **Central differences** of jourdain's compiled M, k, q (``mkq_function(...).batch``, not the
  derivative code) for models with inputs and force elements: the 3-link pendulum on a cart
  (input F), the quarter car (spring-damper between two bodies, road input ``z_r``), the
  vehicle body on four bushings (spatial, free body, stiffness and damping).
* **Fresh processes** with two ``PYTHONHASHSEED`` values and private caches give the same
  derivatives bit for bit.

Tolerances (tests/tolerance.py, rules in tests/README.md), with ``p`` bodies, ``6p`` projected
rows, ``S_τ`` the largest entry of ``|J̄|ᵀ(|M̄||J̄||ÿ| + |q̄^c| + |q̄^e|)`` (the magnitude of the
terms τ is summed from):

* τ, ∂τ/∂u: evaluated directly, ``eval_tol(6p, S_τ)``; M: ``eval_tol(6p, max |J̄|ᵀ|M̄||J̄|)``.
* ∂τ/∂y, ∂τ/∂ẏ: evaluated directly (sums over the bodies of products, as τ), ``eval_tol(6p,
  scale)``, the scale the largest entry of Pinocchio's matrix plus, for ∂τ/∂y, ``S_τ`` (a
  rotation by an angle changes each term of τ by its own size, whatever their sum cancels to)
  and, for ∂τ/∂ẏ, ``2·max(|J̄|ᵀ|q̄^c|)/max|ẏ|`` (q̄^c is quadratic in ẏ).
* ÿ: two solves with M, ``2·ydd_tol``. ``∂ÿ/∂x = −M⁻¹·∂τ/∂x`` at that ÿ: Pinocchio's ∂ÿ/∂y is
  first moved from its ÿ to jourdain's (``− M⁻¹·(∂M/∂y)·(ÿ_j − ÿ_p)``, by its own RNEA
  derivatives), else the difference of the two ÿ, ``cond(M)·eps`` relative, would enter
  amplified by ``cond(M)`` again; then ``solve_tol(M, solve_scale(M, ∂ÿ/∂x, (∂τ/∂x,)))`` once
  per side; ``∂ÿ/∂u = M⁻¹B``: terms B.
* The same as residuals (backward errors, no condition number: tight where cond(M) is large):
  Pinocchio's τ at jourdain's ÿ is B·u, and ``M·∂ÿ/∂x = −∂τ/∂x`` with Pinocchio's M and ∂τ/∂x
  at jourdain's ÿ: ``residual_bound`` plus the evaluation errors of ∂τ/∂x and of M (times the
  column sums of ``|∂ÿ/∂x|``).
* Central differences ``(f(x + h) − f(x − h))/2h`` with ``h = eps^(1/3)·max(1, |x|)``: the
  truncation error ``h²|f'''|/6`` estimated by Richardson, ``(D(2h) − D(h))/3`` (twice that
  allowed), plus the rounding of f divided by h (f's own bound: ``eval_tol`` for τ,
  ``ydd_tol`` for ÿ).

Measured on this machine, the worst error / tolerance of each check is printed (``pytest -s``).
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pin = pytest.importorskip("pinocchio")

import jourdain  # noqa: E402
from benchmarks.crosscheck import build  # noqa: E402
from jourdain.numeric import evaluate, mkq_function, parameter_vector  # noqa: E402
from tests.reference.pinocchio_derivatives import (  # noqa: E402
    Chart,
    forward_dynamics,
    inverse_dynamics,
    tangent_map_error,
    tree_tangent,
    urdf_tangent,
)
from tests.tolerance import (  # noqa: E402
    EPS,
    eom_terms,
    eval_tol,
    residual_bound,
    solve_scale,
    solve_tol,
    ydd_tol,
)

ROOT = Path(__file__).resolve().parents[2]
#: random_tree(35, 0): f = 66
TREE = (35, 0, 66)
#: example-robot-data, floating base: path, f
URDF_ROBOTS = {"solo12": ("solo_description/robots/solo12.urdf", 18),
               "talos": ("talos_data/robots/talos_reduced.urdf", 38)}


# --- tolerances --------------------------------------------------------------------------------
def tau_terms(out: dict, ydd: np.ndarray, norm2: bool = False) -> float:
    """``S_τ``: the largest entry of ``|J̄|ᵀ(|M̄||J̄||ÿ| + |q̄^c| + |q̄^e|)`` (``norm2``: its
    2-norm)."""
    aJ, aM = np.abs(out["J_bar"]), np.abs(out["M_bar"])
    kc, qe = eom_terms(out)
    t = aJ.T @ (aM @ (aJ @ np.abs(ydd))) + kc + qe
    return float(np.linalg.norm(t) if norm2 else t.max())


def gyro_terms(out: dict, yd: np.ndarray) -> float:
    """``2·max(|J̄|ᵀ|q̄^c|)/max|ẏ|``: the terms of ∂k/∂ẏ (q̄^c is quadratic in ẏ: Euler's
    ``Σ ẏ_j·∂t/∂ẏ_j = 2t`` for each of its terms t), with the terms of ∂q/∂ẏ (dampers)
    bounded by the largest entry of the derivative itself."""
    kc, _ = eom_terms(out)
    return 2.0 * float(kc.max()) / max(float(np.abs(yd).max()), np.finfo(float).tiny)


def mass_terms(out: dict) -> float:
    """The largest entry of ``|J̄|ᵀ|M̄||J̄|``."""
    aJ = np.abs(out["J_bar"])
    return float((aJ.T @ np.abs(out["M_bar"]) @ aJ).max())


class Worst:
    """The largest error / tolerance per check; asserts each at most 1."""

    def __init__(self, what: str) -> None:
        self.what, self.ratio, self.error = what, {}, {}

    def check(self, name: str, ours: object, ref: object, tol: float) -> None:
        ours, ref = np.asarray(ours, dtype=float), np.asarray(ref, dtype=float)
        assert ours.shape == ref.shape, f"{self.what}: {name} shape {ours.shape} != {ref.shape}"
        err = float(np.abs(ours - ref).max(initial=0.0))
        assert err <= tol, f"{self.what}: {name} error {err:.3e} > tolerance {tol:.3e}"
        r = err / tol if tol > 0 else 0.0
        if r >= self.ratio.get(name, -1.0):
            self.ratio[name], self.error[name] = r, err

    def report(self) -> None:
        print(f"\n{self.what}: " + ", ".join(
            f"{k} {self.error[k]:.1e} ({self.ratio[k]:.1e} of tol)" for k in self.ratio))


def compare_with_pinocchio(system, model, chart_of, states, worst: Worst,
                           B: np.ndarray | None = None) -> None:
    """jourdain's derivatives at ``states`` (tuples ``(y, ẏ, ÿ, u)``, ``u`` None without
    inputs), batched and one state per call, against Pinocchio's mapped by ``chart_of(y, ẏ)``
    (a :class:`Chart`); ``B = ∂q/∂u`` (f × nu) where the system has inputs."""
    d = jourdain.derivatives(system)
    Y, YD, YDD = (np.array([s[i] for s in states]) for i in range(3))
    U = None if B is None else np.array([s[3] for s in states])
    fwd, inv = d.forward(Y, YD, u=U), d.inverse(Y, YD, YDD, u=U)
    n_rows = None
    data = model.createData()
    for i, (y, yd, ydd, u) in enumerate(states):
        out = evaluate(system, y, yd, inputs=u)
        n_rows = out["J_bar"].shape[0]  # 6p
        M = out["M"]
        ch = chart_of(y, yd)
        Bu = None if B is None else B @ u
        # --- inverse dynamics at (y, ẏ, ÿ) ---
        ref = inverse_dynamics(model, data, ch, ydd)
        if Bu is not None:
            ref["tau"] = ref["tau"] - Bu
        s_tau = tau_terms(out, ydd)
        worst.check("tau", inv.tau[i], ref["tau"], eval_tol(n_rows, s_tau))
        worst.check("M", inv.tau_ydd[i], ref["tau_ydd"], eval_tol(n_rows, mass_terms(out)))
        worst.check("tau_y", inv.tau_y[i], ref["tau_y"],
                    eval_tol(n_rows, np.abs(ref["tau_y"]).max() + s_tau))
        worst.check("tau_yd", inv.tau_yd[i], ref["tau_yd"],
                    eval_tol(n_rows, np.abs(ref["tau_yd"]).max() + gyro_terms(out, yd)))
        if B is not None:
            worst.check("tau_u", inv.tau_u[i], -B, eval_tol(n_rows, float(np.abs(B).max())))
        # --- forward dynamics at (y, ẏ, u) ---
        fref = forward_dynamics(model, data, ch, Bu)
        a, a_j = fref["ydd"], fwd.ydd[i]
        worst.check("ydd", a_j, a, 2.0 * ydd_tol(out, a))
        # ∂ÿ/∂x = −M⁻¹·∂τ/∂x at ÿ: Pinocchio's moved from its ÿ to jourdain's by the part of
        # ∂τ/∂y linear in ÿ, (∂M/∂y)·(ÿ_j − ÿ_p), so that both are solves at the same ÿ
        at_a = inverse_dynamics(model, data, ch, a_j)
        shift = at_a["tau_y"] - inverse_dynamics(model, data, ch, a)["tau_y"]
        ref_y = fref["ydd_y"] - fref["Minv"] @ shift
        worst.check("ydd_y", fwd.ydd_y[i], ref_y, 2.0 * solve_tol(
            M, solve_scale(M, ref_y, (at_a["tau_y"],))))
        worst.check("ydd_yd", fwd.ydd_yd[i], fref["ydd_yd"], 2.0 * solve_tol(
            M, solve_scale(M, fref["ydd_yd"], (at_a["tau_yd"],))))
        # and as residuals (backward errors, no condition number): jourdain's ÿ and its
        # derivatives solve Pinocchio's equations, M·ÿ + τ_p-terms = B·u, M·∂ÿ/∂x = −∂τ/∂x
        Mp, tol_M = at_a["tau_ydd"], eval_tol(n_rows, mass_terms(out))
        res = at_a["tau"] - (0.0 if Bu is None else Bu)
        worst.check("ydd residual", res, 0.0 * res, residual_bound(
            M, a_j, 0.0 * a_j, b_scale=tau_terms(out, a_j, norm2=True)) + eval_tol(n_rows, tau_terms(out, a_j)))
        for name, x, b, s_b in (
                ("ydd_y", fwd.ydd_y[i], -at_a["tau_y"],
                 np.abs(at_a["tau_y"]).max() + tau_terms(out, a_j)),
                ("ydd_yd", fwd.ydd_yd[i], -at_a["tau_yd"],
                 np.abs(at_a["tau_yd"]).max() + gyro_terms(out, yd)),
                *((("ydd_u", fwd.ydd_u[i], B, float(np.abs(B).max())),) if B is not None
                  else ())):
            worst.check(f"{name} residual", Mp @ x, b, residual_bound(M, x, b)
                        + eval_tol(n_rows, s_b) + tol_M * float(np.abs(x).sum(axis=0).max()))
        if B is not None:
            ref_u = fref["Minv"] @ B
            worst.check("ydd_u", fwd.ydd_u[i], ref_u,
                        2.0 * solve_tol(M, solve_scale(M, ref_u, (B,))))
        # one state per call: the batch's row
        f1 = d.forward(y, yd, u=u)
        i1 = d.inverse(y, yd, ydd, u=u)
        for name, one, row in (("ydd", f1.ydd, fwd.ydd[i]), ("ydd_y", f1.ydd_y, fwd.ydd_y[i]),
                               ("ydd_yd", f1.ydd_yd, fwd.ydd_yd[i]), ("tau", i1.tau, inv.tau[i]),
                               ("tau_y", i1.tau_y, inv.tau_y[i]),
                               ("tau_yd", i1.tau_yd, inv.tau_yd[i])):
            assert np.array_equal(one, row), f"{worst.what}: one-state {name} != batch row {i}"


# --- the random tree -----------------------------------------------------------------------------
def test_random_tree_f66_against_pinocchio():
    n, seed, f = TREE
    system, model, index = build("tree", n, seed)
    assert system.f == f and not np.array_equal(index.v, np.arange(f))  # not depth-first
    assert {b.joint.kind for b in system.bodies} >= {"revolute", "prismatic", "universal",
                                                     "spherical", "free"}
    tangent = tree_tangent(index)
    rng = np.random.default_rng(7)
    states = [(rng.uniform(-np.pi, np.pi, f), rng.uniform(-3, 3, f), rng.uniform(-3, 3, f), None)
              for _ in range(3)]
    worst = Worst(f"random_tree{TREE[:2]}, f = {f}")
    compare_with_pinocchio(system, model,
                           lambda y, yd: Chart.at(index.to_pinocchio(y), tangent, y, yd),
                           states, worst)
    worst.report()


# --- URDF robots with a floating base ----------------------------------------------------------
def _urdf(robot: str):
    """``(actuated system, Twin, B = ∂q/∂u)`` of an example-robot-data robot."""
    from jourdain.io.urdf import load_urdf
    from tests.reference.test_urdf_pinocchio import Twin, robots_dir

    path, f = URDF_ROBOTS[robot]
    twin = Twin(robots_dir() / path, floating_base=True)
    urdf = load_urdf(robots_dir() / path, floating_base=True)  # torque inputs tau_<joint>
    system = urdf.system
    assert system.f == f and system.coordinate_names == twin.system.coordinate_names
    names = system.coordinate_names
    coordinate_of = {j.name: names.index(j.coordinates[0]) for j in urdf.joints if j.coordinates}
    B = np.zeros((f, len(system.inputs)))
    for k, name in enumerate(system.input_names):
        B[coordinate_of[name.removeprefix("tau_")], k] = 1.0
    return system, twin, B


def _urdf_states(twin, n: int, seed: int, nu: int):
    from tests.reference.test_urdf_pinocchio import _states

    rng = np.random.default_rng(seed + 100)
    return [(y, yd, rng.uniform(-3, 3, len(y)), rng.uniform(-2, 2, nu))
            for y, yd in _states(twin, n, seed)]


def _chart_of(twin):
    tangent = urdf_tangent(twin)
    return lambda y, yd: Chart.at(twin.state(y, yd)[0], tangent, y, yd)


def test_free_flyer_tangent_map():
    """T(y) is the tangent map of y ↦ q(y) in Pinocchio's tangent space (central differences
    of ``pin.difference``: truncation ``h²·|q'''|``, the third derivatives of R and p in y of
    order 1 (angles) and 0 (p), plus rounding ``eps/h``); the complex-step T and c equal the
    Twin's closed forms."""
    from tests.reference.test_urdf_pinocchio import Twin, _states, robots_dir

    twin = Twin(robots_dir() / URDF_ROBOTS["solo12"][0], floating_base=True)
    tangent = urdf_tangent(twin)
    h = EPS ** (1 / 3)
    for y, yd in _states(twin, 3, 4):
        _, _, T, c = twin.state(y, yd)
        T2, c2 = tangent(y, yd)
        assert np.array_equal(T, T2) and np.abs(c - c2).max() <= 10 * EPS * np.abs(c).max()
        err = tangent_map_error(twin.pin, lambda x, yd=yd: twin.state(x, yd)[0], T, y, h)
        assert err <= 10 * (h * h + EPS / h), err


def central_differences(fn, x: np.ndarray, rounding: float) -> tuple[np.ndarray, np.ndarray]:
    """``∂fn/∂x`` at ``x`` by central differences and the tolerance of each entry.

    ``fn`` maps rows of points (m, n) to rows of values (m, k). Steps ``h_j = eps^(1/3)·
    max(1, |x_j|)``; ``D(h) = f' + h²f'''/6 + O(h⁴)``, so ``(D(2h) − D(h))/3`` estimates the
    truncation error of ``D(h)`` (per column, the largest; twice that allowed), and each value
    carries at most ``rounding`` (absolute), which ``D(h)`` divides by ``h``. Returns ``D(h)``
    (k, n) and the tolerance (k, n).
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    h = EPS ** (1 / 3) * np.maximum(1.0, np.abs(x))
    E = np.diag(h)
    F = fn(np.concatenate([x + E, x - E, x + 2 * E, x - 2 * E]))
    D1 = (F[:n] - F[n:2 * n]).T / (2 * h)
    D2 = (F[2 * n:3 * n] - F[3 * n:]).T / (4 * h)
    trunc = np.abs(D2 - D1).max(axis=0) / 3
    return D1, np.broadcast_to(2 * trunc + rounding / h, D1.shape)


def check_fd(worst: Worst, name: str, ours: np.ndarray, fd: tuple[np.ndarray, np.ndarray]
             ) -> None:
    D, tol = fd
    ours = np.asarray(ours, dtype=float).reshape(D.shape)
    err = np.abs(ours - D)
    k = np.unravel_index(int(np.argmax(err / tol)), err.shape)
    worst.check(name, ours[k], D[k], float(tol[k]))


class Numbers:
    """τ and ÿ of a system from its compiled M, k, q (``mkq_function(...).batch``, one call
    for all rows), the derivative code not involved."""

    def __init__(self, system) -> None:
        self.fn, self.f, self.nu = mkq_function(system), system.f, len(system.inputs)
        self.p = parameter_vector(system, None)

    def mkq(self, Y, YD, U):
        r = self.fn.batch(Y, YD, 0.0, self.p, U if self.nu else None)
        return r["M"], r["k"][..., 0], r["q"][..., 0]

    def tau(self, Y, YD, YDD, U):
        M, k, q = self.mkq(Y, YD, U)
        return np.einsum("nij,nj->ni", M, YDD) + k - q

    def ydd(self, Y, YD, U):
        M, k, q = self.mkq(Y, YD, U)
        return np.linalg.solve(M, (q - k)[..., None])[..., 0]


def fd_checks(system, states, worst: Worst, d) -> None:
    """Central differences of τ(y, ẏ, ÿ, u) and ÿ(y, ẏ, u) against ``d(y, ẏ, ÿ, u) ->
    (forward, inverse)``: jourdain's derivatives, or objects with the same attributes."""
    num = Numbers(system)
    for y, yd, ydd, u in states:
        fwd, inv = d(y, yd, ydd, u)
        _fd_state(system, num, worst, y, yd, ydd, u, fwd, inv)


def _fd_state(system, num: Numbers, worst: Worst, y, yd, ydd, u, fwd, inv) -> None:
    f, nu = system.f, num.nu
    uu = np.zeros(max(nu, 1)) if u is None else np.asarray(u, dtype=float)
    out = evaluate(system, y, yd, inputs=u)
    a = np.linalg.solve(out["M"], out["q"] - out["k"])
    r_tau, r_ydd = eval_tol(out["J_bar"].shape[0], tau_terms(out, ydd)), ydd_tol(out, a)

    def rows(x, X):
        return np.repeat(x[None, :], len(X), axis=0)

    check_fd(worst, "tau_y", inv.tau_y, central_differences(
        lambda X: num.tau(X, rows(yd, X), rows(ydd, X), rows(uu, X)), y, r_tau))
    check_fd(worst, "tau_yd", inv.tau_yd, central_differences(
        lambda X: num.tau(rows(y, X), X, rows(ydd, X), rows(uu, X)), yd, r_tau))
    check_fd(worst, "ydd_y", fwd.ydd_y, central_differences(
        lambda X: num.ydd(X, rows(yd, X), rows(uu, X)), y, r_ydd))
    check_fd(worst, "ydd_yd", fwd.ydd_yd, central_differences(
        lambda X: num.ydd(rows(y, X), X, rows(uu, X)), yd, r_ydd))
    if nu:
        check_fd(worst, "tau_u", inv.tau_u, central_differences(
            lambda X: num.tau(rows(y, X), rows(yd, X), rows(ydd, X), X), uu, r_tau))
        check_fd(worst, "ydd_u", fwd.ydd_u, central_differences(
            lambda X: num.ydd(rows(y, X), rows(yd, X), X), uu, r_ydd))
    assert np.shape(fwd.ydd_y) == (f, f) and np.shape(inv.tau_ydd) == (f, f)


def test_pinocchio_map_against_central_differences():
    """The map alone: Pinocchio's derivatives in jourdain's coordinates (free flyer included)
    agree with central differences of jourdain's τ and ÿ at Solo-12's states (jourdain's
    derivative code not involved)."""
    from types import SimpleNamespace

    system, twin, B = _urdf("solo12")
    chart_of = _chart_of(twin)
    model, data = twin.pin, twin.pin.createData()

    def pinocchio(y, yd, ydd, u):
        ch = chart_of(y, yd)
        inv = inverse_dynamics(model, data, ch, ydd)
        fwd = forward_dynamics(model, data, ch, B @ u)
        return (SimpleNamespace(**fwd, ydd_u=fwd["Minv"] @ B),
                SimpleNamespace(**inv, tau_u=-B))

    worst = Worst("Pinocchio mapped vs central differences, Solo-12")
    fd_checks(system, _urdf_states(twin, 2, 5, len(system.inputs)), worst, pinocchio)
    worst.report()


@pytest.mark.parametrize("robot", list(URDF_ROBOTS))
def test_floating_base_robot_against_pinocchio(robot):
    system, twin, B = _urdf(robot)
    worst = Worst(f"{robot}, f = {system.f}, {len(system.inputs)} inputs")
    compare_with_pinocchio(system, twin.pin, _chart_of(twin),
                           _urdf_states(twin, 3, 6, len(system.inputs)), worst, B)
    worst.report()


# --- central differences of jourdain's own numbers -------------------------------------------------
def _cart_states(system, rng):
    f = system.f
    y = rng.uniform(-np.pi, np.pi, f)
    y[0] = rng.uniform(-1, 1)
    return y, rng.uniform(-3, 3, f), rng.uniform(-3, 3, f), rng.uniform(-10, 10, 1)


def _quarter_car_states(system, rng):
    return (rng.uniform(-0.1, 0.1, 2), rng.uniform(-1, 1, 2), rng.uniform(-5, 5, 2),
            rng.uniform(-0.05, 0.05, 1))


def _vehicle_states(system, rng):
    y = np.concatenate([rng.uniform(-0.2, 0.2, 3), rng.uniform(-0.5, 0.5, 3)])
    return y, rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6), None


def _model(name: str):
    from jourdain.io.modelfile.loader import load_model
    from jourdain.models import n_link_pendulum_on_cart

    if name == "cart3":
        return n_link_pendulum_on_cart(3), _cart_states
    return load_model(ROOT / "examples" / f"{name}.toml").system, {
        "quarter_car": _quarter_car_states, "vehicle_on_bushings": _vehicle_states}[name]


@pytest.mark.parametrize("name", ["cart3", "quarter_car", "vehicle_on_bushings"])
def test_derivatives_against_central_differences(name):
    system, draw = _model(name)
    rng = np.random.default_rng(11)
    states = [draw(system, rng) for _ in range(3)]
    d = jourdain.derivatives(system)
    worst = Worst(f"{name} vs central differences")
    fd_checks(system, states, worst,
              lambda y, yd, ydd, u: (d.forward(y, yd, u=u), d.inverse(y, yd, ydd, u=u)))
    # the values themselves: ÿ and τ against jourdain's evaluate
    for y, yd, ydd, u in states:
        out = evaluate(system, y, yd, inputs=u)
        a = np.linalg.solve(out["M"], out["q"] - out["k"])
        worst.check("ydd", d.forward(y, yd, u=u).ydd, a, 2.0 * ydd_tol(out, a))
        inv = d.inverse(y, yd, ydd, u=u)
        worst.check("tau", inv.tau, out["M"] @ ydd + out["k"] - out["q"],
                    eval_tol(out["J_bar"].shape[0], tau_terms(out, ydd)))
        worst.check("M", inv.tau_ydd, out["M"], eval_tol(out["J_bar"].shape[0],
                                                         mass_terms(out)))
    worst.report()


# --- the same numbers in fresh processes ----------------------------------------------------------
CHILD = r"""
import hashlib, json
import numpy as np
import jourdain
from jourdain import models
out = {}
for name, system in (("cart", models.n_link_pendulum_on_cart(3)),
                     ("tree", models.random_tree(8, seed=4))):
    f, nu = system.f, len(system.inputs)
    rng = np.random.default_rng(3)
    Y, YD, YDD = (rng.uniform(-2, 2, (4, f)) for _ in range(3))
    U = rng.uniform(-1, 1, (4, nu)) if nu else None
    d = jourdain.derivatives(system)
    fw, inv = d.forward(Y, YD, u=U), d.inverse(Y, YD, YDD, u=U)
    h = hashlib.sha256()
    for a in (fw.ydd, fw.ydd_y, fw.ydd_yd, inv.tau, inv.tau_y, inv.tau_yd, inv.tau_ydd):
        h.update(np.ascontiguousarray(a).tobytes())
    out[name] = h.hexdigest()
print(json.dumps(out))
"""


@pytest.mark.own_hash_seeds
def test_derivatives_bit_identical_in_fresh_processes(tmp_path):
    results = []
    for seed in ("0", "12345"):
        env = {**os.environ, "PYTHONHASHSEED": seed, "JOURDAIN_CACHE": str(tmp_path / seed)}
        proc = subprocess.run([sys.executable, "-c", CHILD], env=env, cwd=ROOT,
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-3000:]
        results.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert results[0] == results[1], results
    assert hashlib.sha256(b"").hexdigest() not in results[0].values()
