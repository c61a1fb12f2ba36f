# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # Swing-up of a double pendulum on a cart
#
# A cart on a rail carries two links in a chain; the only input is the horizontal force `F`
# on the cart. Starting at rest with both links hanging down, find the force history that
# brings them upright and to rest within 3 s, with the force bounded and the cart kept on a
# short rail, at the least control effort ∫F²dt. This tutorial
#
# 1. turns jourdain's equations of motion into CasADi functions (`jd.to_casadi`),
# 2. writes the optimal control problem by direct collocation in `casadi.Opti` and solves
#    it with IPOPT,
# 3. applies the optimal force to the model in jourdain's own integrator, open loop, and
#    checks that it arrives upright within 1e-3, and
# 4. solves the same problem with the equations of motion written by hand in CasADi, to
#    compare the solve times.
#
# It is executed at every build of this site ([the guide to optimal
# control](../control.md#optimal-control-with-casadi) describes `to_casadi`).

# %%
import time

import casadi as cs
import matplotlib.pyplot as plt
import numpy as np
import sympy as sp

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart

system = n_link_pendulum_on_cart(2)
print(system.coordinate_names, system.input_names, system.parameter_values)

# %% [markdown]
# The model (`jourdain.models.n_link_pendulum_on_cart`): the cart's position `q0` along x,
# the absolute angles `q1`, `q2` of the links from the upward y axis (positive
# counter-clockwise), point masses `m1`, `m2` at the ends of massless links of lengths `l0`,
# `l1`, all masses 1 kg and lengths 1 m. Upright is `q = 0`; hanging down is
# `q1 = q2 = π`.
#
# ## The equations as CasADi functions
#
# `jd.to_casadi` translates the expression graph of `M`, `k`, `q` node by node into
# CasADi's symbolic graph and forms `ÿ = M⁻¹(q − k)` there, so CasADi differentiates it
# exactly. Each function takes the parameters as an input `p`; `dyn.p` holds the model's
# values. `dyn.ode(x, u, p, t)` is the first-order form `ẋ = [ẏ; ÿ]` of the state
# `x = [y; ẏ]`.

# %%
dyn = jd.to_casadi(system)
print(dyn.forward)
print(dyn.ode)
print("parameters:", {n: float(v) for n, v in zip(dyn.parameters, dyn.p, strict=True)})


def solve_tol(M, ydd, q, k):
    """How far two solves of M·ÿ = q − k may differ by rounding: 2 · 10·f·cond(M)·eps,
    relative to ‖ÿ‖ + (‖q‖ + ‖k‖)/‖M‖ (tests/README.md)."""
    M = np.asarray(M)
    scale = np.linalg.norm(ydd) + (np.linalg.norm(q) + np.linalg.norm(k)) / np.linalg.norm(M, 2)
    return 2 * 10 * len(M) * np.linalg.cond(M) * np.finfo(float).eps * scale


# the CasADi function gives jourdain's own numbers: ÿ from M, k, q evaluated by jourdain
rng = np.random.default_rng(1)
for _ in range(3):
    y, yd, F = rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 3), rng.uniform(-20, 20)
    out = system.evaluate(y, yd, inputs={"F": F})
    ref = np.linalg.solve(out["M"], out["q"] - out["k"])
    ydd = np.array(dyn.forward(y, yd, F, dyn.p, 0.0)).ravel()
    assert np.abs(ydd - ref).max() <= solve_tol(out["M"], ref, out["q"], out["k"])

# %% [markdown]
# ## Direct collocation
#
# The horizon `T = 3 s` is cut into `N = 120` intervals of length `h`. On each, the force is
# constant, `U_k`, and the state is a polynomial of degree `d = 5` through the state `X_k`
# at the interval's start and `d` states at the Gauss–Legendre points `τ_j`; the
# polynomial's slope must equal the dynamics at those points, and its value at the
# interval's end is the next interval's start. Gauss–Legendre collocation is accurate to
# order `2d = 10` at the interval ends: the upright position is unstable, so an open-loop
# force is only as good as the motion it was optimized for, and this one has to carry over
# to another integrator with errors that stay small after their growth through the swing.
#
# The coefficients come from the Lagrange polynomials `ℓ_r` of the points `0, τ_1 … τ_d`:
# `C[r, j] = ℓ_r'(τ_j)` (the slope at the collocation points) and `D[r] = ℓ_r(1)` (the value
# at the end).

# %%
T, N, d = 3.0, 120, 5
F_MAX, X_MAX = 40.0, 1.0        # |F| ≤ 40 N, cart within ±1 m
h = T / N
tau = np.array(cs.collocation_points(d, "legendre"))
points = np.r_[0.0, tau]
C = np.zeros((d + 1, d + 1))
D = np.zeros(d + 1)
for r in range(d + 1):
    others = np.delete(points, r)
    ell = np.poly1d(others, r=True) / np.prod(points[r] - others)
    D[r] = ell(1.0)
    C[r] = ell.deriv()(points)

x_start = np.array([0.0, np.pi, np.pi, 0.0, 0.0, 0.0])   # hanging, at rest
x_end = np.zeros(6)                                      # upright, at rest, cart centred


def swing_up(ode: cs.Function, p: np.ndarray) -> dict:
    """Solve the swing-up with the dynamics ``ode(x, u, p, t)``; the NLP, its initial guess
    (a straight line from start to end) and IPOPT's options do not depend on ``ode``."""
    opti = cs.Opti()
    X = opti.variable(6, N + 1)        # states at the interval ends
    Xc = opti.variable(6, d * N)       # states at the collocation points
    U = opti.variable(1, N)            # force per interval
    # the dynamics at all collocation points in one call (U_k repeated d times)
    slopes = ode.map(d * N)(Xc, cs.kron(U, np.ones((1, d))), p, 0.0)
    for k in range(N):
        Z = cs.horzcat(X[:, k], Xc[:, d * k:d * (k + 1)])
        opti.subject_to(Z @ C[:, 1:] == h * slopes[:, d * k:d * (k + 1)])
        opti.subject_to(X[:, k + 1] == Z @ D)
    opti.subject_to(X[:, 0] == x_start)
    opti.subject_to(X[:, N] == x_end)
    opti.subject_to(opti.bounded(-F_MAX, U, F_MAX))
    opti.subject_to(opti.bounded(-X_MAX, X[0, :], X_MAX))
    opti.subject_to(opti.bounded(-X_MAX, Xc[0, :], X_MAX))
    opti.minimize(h * cs.sumsqr(U))
    s = np.linspace(0.0, 1.0, N + 1)
    sc = (np.arange(N)[:, None] + tau[None, :]).ravel() / N
    opti.set_initial(X, np.outer(x_start, 1 - s) + np.outer(x_end, s))
    opti.set_initial(Xc, np.outer(x_start, 1 - sc) + np.outer(x_end, sc))
    # tight tolerances: the open-loop check below needs the collocation equations met to
    # far below 1e-3 (errors grow by some 1e4 through the swing); "expand": the whole NLP
    # as one scalar graph (SX), three times faster here than CasADi's matrix graph
    opti.solver("ipopt", {"print_time": False, "expand": True},
                {"print_level": 0, "sb": "yes", "tol": 1e-10, "constr_viol_tol": 1e-10,
                 "max_iter": 1000})
    seconds = []
    for _ in range(3):  # the same start each time; the fastest of three solves
        start = time.perf_counter()
        sol = opti.solve()
        seconds.append(time.perf_counter() - start)
    return {"X": sol.value(X), "U": np.atleast_1d(sol.value(U)), "cost": sol.value(opti.f),
            "iterations": sol.stats()["iter_count"], "seconds": min(seconds)}


jd_solution = swing_up(dyn.ode, dyn.p)
X, U = jd_solution["X"], jd_solution["U"]
print(f"IPOPT: {jd_solution['iterations']} iterations, {jd_solution['seconds']:.2f} s, "
      f"∫F²dt = {jd_solution['cost']:.2f} N²s")
print(f"max |F| = {np.abs(U).max():.3f} N, max |q0| = {np.abs(X[0]).max():.4f} m")

# %% [markdown]
# ## The optimal force in jourdain's integrator
#
# Each interval is simulated with its constant force, exactly as the collocation assumed it,
# by `system.simulate` at tight tolerances. First from each collocated state `X_k` on its
# own: the difference at the interval's end is the collocation's error on that interval
# (the defect); then the whole motion open loop from the hanging state, where the errors
# grow through the swing.

# %%
t_mesh = np.linspace(0.0, T, N + 1)
tight = {"rtol": 1e-12, "atol": 1e-12}
defects = np.array([
    np.abs(np.r_[r.y[-1], r.yd[-1]] - X[:, k + 1]).max()
    for k in range(N)
    for r in [system.simulate((t_mesh[k], t_mesh[k + 1]), X[:3, k], X[3:, k],
                              inputs={"F": float(U[k])}, **tight)]
])
print(f"largest defect of an interval: {defects.max():.2e}")

y, yd = x_start[:3], x_start[3:]
pieces = []
for k in range(N):
    res = system.simulate((t_mesh[k], t_mesh[k + 1]), y, yd, inputs={"F": float(U[k])},
                          t_eval=np.linspace(t_mesh[k], t_mesh[k + 1], 5), **tight)
    pieces.append(res)
    y, yd = res.y[-1], res.yd[-1]
final_error = np.abs(np.r_[y, yd] - x_end).max()
print("final state (q0, q1, q2, rates):", np.r_[y, yd])
print(f"largest distance from upright at rest at t = {T} s: {final_error:.2e}")
assert final_error <= 1e-3

# %%
t_sim = np.concatenate([r.t for r in pieces])
y_sim = np.concatenate([r.y for r in pieces])
fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
axes[0].plot(t_sim, y_sim[:, 0], label="q0, simulated")
axes[0].plot(t_mesh, X[0], ".", ms=3, label="q0, collocation")
axes[0].axhline(X_MAX, color="0.6", ls="--")
axes[0].axhline(-X_MAX, color="0.6", ls="--")
axes[0].set_ylabel("cart position [m]")
axes[0].legend(loc="lower left")
for i in (1, 2):
    axes[1].plot(t_sim, y_sim[:, i], label=f"q{i}, simulated")
    axes[1].plot(t_mesh, X[i], ".", ms=3, label=f"q{i}, collocation")
axes[1].set_ylabel("link angles [rad]")
axes[1].legend(loc="upper right")
axes[2].step(t_mesh[:-1], U, where="post")
axes[2].axhline(F_MAX, color="0.6", ls="--")
axes[2].axhline(-F_MAX, color="0.6", ls="--")
axes[2].set_ylabel("force F [N]")
axes[2].set_xlabel("t [s]")
fig.tight_layout()

# %% [markdown]
# A strobe picture of the simulated swing, every 0.1 s (darker is later):

# %%
fig, ax = plt.subplots(figsize=(8, 4))
for j, t in enumerate(np.arange(0.0, T + 1e-9, 0.1)):
    q0, q1, q2 = y_sim[np.argmin(np.abs(t_sim - t))]
    cart = np.array([q0, 0.0])
    p1 = cart + np.array([-np.sin(q1), np.cos(q1)])
    p2 = p1 + np.array([-np.sin(q2), np.cos(q2)])
    shade = str(0.85 - 0.85 * j / (T / 0.1))
    ax.plot(*np.c_[cart, p1, p2], "-o", color=shade, ms=3, lw=1)
    ax.add_patch(plt.Rectangle((q0 - 0.15, -0.08), 0.3, 0.16, fill=False, ec=shade))
ax.axhline(0.0, color="0.5", lw=0.5)
ax.axvline(-X_MAX, color="0.6", ls="--")
ax.axvline(X_MAX, color="0.6", ls="--")
ax.set_aspect("equal")
ax.set_xlabel("x [m]")
ax.set_ylabel("y [m]")

# %% [markdown]
# ## The same problem with the equations written by hand
#
# For a model this small the equations fit in a few lines. With the positions of the two
# masses, `x₁ = q0 − l0 sin q1`, `y₁ = l0 cos q1`, `x₂ = x₁ − l1 sin q2`,
# `y₂ = y₁ + l1 cos q2`, Lagrange's equations give `M·ÿ + k = q` below. The function is
# written once for any `sin`/`cos`, so that the same lines give SymPy expressions, checked
# against Lagrange's equations formed by SymPy, and CasADi expressions for the solver.

# %%
def by_hand(q, qd, F, p, sin, cos):
    """M, k, q of the double pendulum on a cart; p = (m0, m1, m2, l0, l1, g)."""
    m0, m1, m2, l0, l1, g = p
    s1, c1, s2, c2 = sin(q[1]), cos(q[1]), sin(q[2]), cos(q[2])
    s12, c12 = sin(q[1] - q[2]), cos(q[1] - q[2])
    M = [[m0 + m1 + m2, -(m1 + m2) * l0 * c1, -m2 * l1 * c2],
         [-(m1 + m2) * l0 * c1, (m1 + m2) * l0**2, m2 * l0 * l1 * c12],
         [-m2 * l1 * c2, m2 * l0 * l1 * c12, m2 * l1**2]]
    k = [(m1 + m2) * l0 * s1 * qd[1]**2 + m2 * l1 * s2 * qd[2]**2,
         m2 * l0 * l1 * s12 * qd[2]**2,
         -m2 * l0 * l1 * s12 * qd[1]**2]
    Q = [F, (m1 + m2) * g * l0 * s1, m2 * g * l1 * s2]
    return M, k, Q


# Lagrange's equations by SymPy: M = ∂²T/∂ẏ², k = (∂/∂y ∂T/∂ẏ)·ẏ − ∂T/∂y, q = −∂V/∂y + (F, 0, 0)
qs, qds = sp.symbols("q0:3"), sp.symbols("q0:3_d")
Fs, ps = sp.Symbol("F"), sp.symbols("m0 m1 m2 l0 l1 g")
m0, m1, m2, l0, l1, g = ps
x1, y1 = qs[0] - l0 * sp.sin(qs[1]), l0 * sp.cos(qs[1])
x2, y2 = x1 - l1 * sp.sin(qs[2]), y1 + l1 * sp.cos(qs[2])


def rate(e):
    return sum(sp.diff(e, a) * b for a, b in zip(qs, qds, strict=True))


kinetic = (m0 * qds[0]**2 + m1 * (rate(x1)**2 + rate(y1)**2)
           + m2 * (rate(x2)**2 + rate(y2)**2)) / 2
potential = g * (m1 * y1 + m2 * y2)
dT = sp.Matrix([kinetic]).jacobian(qds)
M_ref = dT.jacobian(qds)
k_ref = dT.jacobian(qs) * sp.Matrix(qds) - sp.Matrix([kinetic]).jacobian(qs).T
q_ref = -sp.Matrix([potential]).jacobian(qs).T + sp.Matrix([Fs, 0, 0])
M_h, k_h, q_h = by_hand(qs, qds, Fs, ps, sp.sin, sp.cos)
for ours, ref in ((sp.Matrix(M_h), M_ref), (sp.Matrix(k_h), k_ref), (sp.Matrix(q_h), q_ref)):
    assert sp.simplify(ours - ref) == sp.zeros(*ref.shape)

# %% [markdown]
# The CasADi function from those lines, with `casadi.solve` for `ÿ`, takes the same inputs
# as `dyn.ode`; the same NLP, initial guess and options:

# %%
xs, us, pvec, ts = cs.SX.sym("x", 6), cs.SX.sym("u"), cs.SX.sym("p", 6), cs.SX.sym("t")
order = [dyn.parameters.index(n) for n in ("m0", "m1", "m2", "l0", "l1", "g")]
M_cs, k_cs, q_cs = by_hand(xs[:3], xs[3:], us, [pvec[i] for i in order], cs.sin, cs.cos)
ydd_hand = cs.solve(cs.blockcat(M_cs), cs.vertcat(*q_cs) - cs.vertcat(*k_cs))
ode_hand = cs.Function("ode_hand", [xs, us, pvec, ts], [cs.vertcat(xs[3:], ydd_hand)])

x_test = rng.uniform(-2, 2, 6)
a, b = np.array(ode_hand(x_test, 7.0, dyn.p, 0)), np.array(dyn.ode(x_test, 7.0, dyn.p, 0))
out = system.evaluate(x_test[:3], x_test[3:], inputs={"F": 7.0})
assert np.abs(a - b).max() <= solve_tol(out["M"], b[3:], out["q"], out["k"])

hand_solution = swing_up(ode_hand, dyn.p)
print(f"{'dynamics':<18}{'nodes of ẋ':>11}{'iterations':>12}{'solve [s]':>11}"
      f"{'per iteration [ms]':>20}{'∫F²dt':>10}")
for name, ode, sol in (("jd.to_casadi", dyn.ode, jd_solution),
                       ("written by hand", ode_hand, hand_solution)):
    per = 1e3 * sol["seconds"] / sol["iterations"]
    print(f"{name:<18}{ode.n_nodes():>11}{sol['iterations']:>12}{sol['seconds']:>11.2f}"
          f"{per:>20.1f}{sol['cost']:>10.3f}")
print("largest difference of the forces:", np.abs(hand_solution["U"] - U).max())

# %% [markdown]
# The two formulations are the same mathematics: IPOPT takes the same number of iterations
# to the same force (up to rounding), and the time per iteration is close, since the
# translated graph is no larger than the hand-written one (`dyn.forward` solves with an LDLᵀ
# factorization written out for the symmetric M, `casadi.solve` by a QR factorization).
# Most of the time goes to IPOPT's sparse linear algebra and to CasADi's derivatives of the
# collocation equations, which both share. For a larger model the translated function is
# the one that needs no derivation by hand, and stays in step with the model.
