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
# # Linearization and stability of a spinning rotor
#
# A disc (mass m, radius r) spins at the prescribed rate Ω about its axis and can tilt about
# x (α) and y (β) in a massless gimbal held by rotational springs (stiffness c) and dampers
# (d). Linearized about the upright position, the spin couples the two tilts through the
# skew-symmetric gyroscopic matrix G: the natural frequency splits into a forward and a
# backward whirl. This tutorial builds the model, linearizes it
# ([the method](../method.md), §5–6), checks the whirl frequencies against their closed form
# and takes the stability verdict. (The same model as a file: `examples/gyroscopic_rotor.toml`.)

# %%
import matplotlib.pyplot as plt
import numpy as np

import jourdain as jd

alpha, beta = jd.symbols("alpha beta")
m, r, h, c, d, Omega = jd.symbols("m r h c d Omega")

system = jd.System(
    coordinates=[alpha, beta],
    bodies=[
        jd.Body("gimbal", "world", jd.Universal("gimbal", [alpha, beta], ["x", "y"]),
                mass=0, inertia=jd.point_mass()),
        # the spin is prescribed: a general joint with the rotation Ω·t and no coordinate
        jd.Body("disc", "gimbal",
                jd.General("spin", [jd.Rot("z", Omega * jd.t)], position=(0, 0, h)),
                mass=m, inertia=jd.disc(m, r, "z")),
    ],
    forces=[jd.RotationalSpringDamper("tilt_x", alpha, c, d),
            jd.RotationalSpringDamper("tilt_y", beta, c, d)],
    parameters={"m": 2.0, "r": 0.15, "h": 0.1, "c": 40.0, "d": 0.02, "Omega": 100.0},
)

# %% [markdown]
# ## The linearization
#
# About the nominal motion α = β = 0 the linearized equations are
# `M̃·η̈ + P·η̇ + Q·η = h`; P splits into the damping matrix D (symmetric) and the gyroscopic
# matrix G (skew-symmetric), Q into the stiffness K and the circulatory matrix N. The time t
# enters the rotor's equations through the prescribed spin, and cancels.

# %%
lin = system.linearize({"alpha": 0, "beta": 0})
for name in ("M_tilde", "D", "G", "K", "N"):
    print(f"{name} =", getattr(lin, name).sympy())

# %% [markdown]
# The gyroscopic entries are ±C·Ω with C = m·r²/2, the disc's moment of inertia about its
# spin axis:

# %%
num = lin.evaluate()
C, O = 2.0 * 0.15**2 / 2, 100.0
print("G =\n", num["G"])
tol = 64 * np.finfo(float).eps * C * O           # a few roundings of C·Ω
assert np.allclose(num["G"], [[0, C * O], [-C * O, 0]], rtol=0, atol=tol)

# %% [markdown]
# ## Whirl frequencies
#
# Without damping, the tilt frequencies ω solve A₀ω² ∓ CΩω − c = 0, with A₀ = A + m·h² the
# disc's moment of inertia about the gimbal's axes (A = m·r²/4 about a diameter): the forward
# whirl rises with the spin, the backward whirl falls.

# %%
undamped = {"d": 0.0}
modes = jd.modes(lin, parameters=undamped)
print(modes)
A0 = 2.0 * 0.15**2 / 4 + 2.0 * 0.1**2
forward = (C * O + np.sqrt((C * O) ** 2 + 4 * A0 * 40.0)) / (2 * A0)
backward = (-C * O + np.sqrt((C * O) ** 2 + 4 * A0 * 40.0)) / (2 * A0)
omega = np.sort(np.abs(modes.eigenvalues.imag))[::2]
print("jourdain:", omega, " closed form:", np.array([backward, forward]))
# an eigenvalue problem of condition ~1 in a 4×4 companion form: a few hundred ulps
assert np.allclose(omega, [backward, forward], rtol=1e3 * np.finfo(float).eps, atol=0)

# %% [markdown]
# ## The verdict
#
# With the dampers the rotor is asymptotically stable: every eigenvalue has a negative real
# part. `jd.stability` says so and why.

# %%
verdict = jd.stability(lin)
print(verdict)

# %%
ev = jd.modes(lin).eigenvalues
fig, ax = plt.subplots(figsize=(5, 3.5))
ax.plot(ev.real, ev.imag, "x", ms=9)
ax.axvline(0, color="k", lw=0.6)
ax.set_xlabel("Re λ  [1/s]")
ax.set_ylabel("Im λ  [rad/s]")
ax.set_title("eigenvalues of the spinning rotor (Ω = 100 rad/s)")
fig.tight_layout()
