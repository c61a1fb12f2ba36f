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
# # A double pendulum from Python
#
# Two uniform rods hang from each other on revolute joints about z, with gravity along −y.
# This tutorial builds the model in Python, derives the Newton–Euler equations and the
# equations of motion ([the method](../method.md), §1–4), checks the mass matrix against the
# textbook, simulates a swing and plots it. It is executed at every build of this site.
#
# The minimal coordinates are the absolute angle `phi1` of the first rod and the relative
# angle `phi2` of the second.

# %%
import numpy as np
import sympy as sp

import jourdain as jd

phi1, phi2 = jd.symbols("phi1 phi2")
m1, m2, l1, l2, g = jd.symbols("m1 m2 l1 l2 g")

system = jd.System(
    coordinates=[phi1, phi2],
    bodies=[
        jd.Body("rod1", "world", jd.Revolute("hinge1", phi1, "z"),
                mass=m1, com=(0, -l1 / 2, 0), inertia=jd.rod(m1, l1, "y")),
        jd.Body("rod2", "rod1", jd.Revolute("hinge2", phi2, "z", position=(0, -l1, 0)),
                mass=m2, com=(0, -l2 / 2, 0), inertia=jd.rod(m2, l2, "y")),
    ],
    forces=[jd.Gravity((0, -g, 0))],
    parameters={"m1": 1.0, "m2": 0.5, "l1": 1.0, "l2": 0.7, "g": 9.81},
)

# %% [markdown]
# ## The equations
#
# `newton_euler()` gives the Newton–Euler equations of all bodies, `M̄·J̄·ÿ + q̄^c = q̄^e`,
# with the 6p×6p block-diagonal mass matrix `M_bar` and the 6p×f global Jacobian `J_bar`
# (p = 2 bodies, f = 2 coordinates). The projection with `J̄ᵀ` gives the equations of motion
# `M·ÿ + k = q`.

# %%
ne = system.newton_euler()
eom = system.equations_of_motion()
M = sp.simplify(eom.M.sympy())
print("M_bar:", ne.M_bar.shape, " J_bar:", ne.J_bar.shape, " M:", M.shape)
sp.pprint(M, use_unicode=True)

# %% [markdown]
# The mass matrix of the double pendulum is known in closed form: with the rods' moments of
# inertia m·l²/12 about their centres,
# M₁₁ = m₁l₁²/3 + m₂(l₁² + l₂²/3 + l₁l₂ cos φ₂), M₁₂ = m₂(l₂²/3 + l₁l₂ cos(φ₂)/2),
# M₂₂ = m₂l₂²/3. The derived one must equal it symbolically:

# %%
m1_, m2_, l1_, l2_, phi2_ = (sp.Symbol(n) for n in ("m1", "m2", "l1", "l2", "phi2"))
M_textbook = sp.Matrix([
    [m1_ * l1_**2 / 3 + m2_ * (l1_**2 + l2_**2 / 3 + l1_ * l2_ * sp.cos(phi2_)),
     m2_ * (l2_**2 / 3 + l1_ * l2_ * sp.cos(phi2_) / 2)],
    [m2_ * (l2_**2 / 3 + l1_ * l2_ * sp.cos(phi2_) / 2), m2_ * l2_**2 / 3],
])
difference = sp.simplify(M - M_textbook)
print(difference)
assert difference == sp.zeros(2, 2)

# %% [markdown]
# ## Numbers at a state
#
# `evaluate` gives every matrix and vector of the method as NumPy arrays, by the names of
# the method, at a state (y, ẏ) and the parameters' defaults.

# %%
out = system.evaluate([0.3, -0.2], [1.0, 0.5])
print("M =\n", out["M"])
print("k =", out["k"], " q =", out["q"])
print("ÿ =", np.linalg.solve(out["M"], out["q"] - out["k"]))

# %% [markdown]
# ## A simulation
#
# Released at rest from φ₁ = 1 rad. Without friction the energy is conserved; the result
# reports how well the integration kept it (`energy_balance_error`, relative to the energy
# exchanged).

# %%
res = system.simulate((0, 5), y0=[1.0, 0.0], yd0=[0.0, 0.0], rtol=1e-9, atol=1e-9)
print(res.summary())
# the integration's tolerance is 1e-9: an energy error a thousand times larger is a bug
assert res.energy_balance_error < 1e3 * 1e-9

# %%
ax = res.plot("y")

# %%
ax = res.plot("energy")

# %% [markdown]
# ## Reaction forces
#
# The joints' reactions come from `N̂·g = k̂ − q̂` at any state, without ÿ
# ([the method](../method.md), §4); at rest in the hanging position the first hinge carries
# the weight of both rods, (m₁ + m₂)·g.

# %%
rest = system.evaluate([0.0, 0.0], [0.0, 0.0])
reactions = dict(zip(rest["g_names"], rest["g"], strict=True))
print({name: round(float(value), 6) for name, value in reactions.items()})
weight = (1.0 + 0.5) * 9.81
# a Cholesky solve of a well-conditioned N̂: a few dozen roundings of the weight
assert abs(reactions["hinge1.F_y"] - weight) <= 64 * np.finfo(float).eps * weight
