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
# # A parameter study: where a rotor loses its stability
#
# A Jeffcott (Laval) rotor — a disc of mass m on a massless elastic shaft (stiffness k),
# spinning at Ω — with external (air) damping d_a and internal (material) damping d_i of the
# shaft. The internal damping acts in the turning shaft's frame and gives the skew-symmetric
# circulatory matrix N with entries ±d_i·Ω: above the speed
#
#     Ω_crit = √(k/m) · (1 + d_a/d_i)
#
# the rotor whirls unstably. This tutorial loads the model from its file
# (`examples/rotor_internal_damping.toml`), sweeps the speed, finds the threshold and checks
# it against the formula, then maps the stability over speed and internal damping with
# `jourdain.study` ([parameter studies](../studies.md)). It is executed at every build.

# %%
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import jourdain as jd
import jourdain.study as st

# the repository's examples/ folder, from wherever the notebook runs inside the repository
EXAMPLES = next((p / "examples" for p in (Path.cwd(), *Path.cwd().parents)
                 if (p / "examples" / "rotor_internal_damping.toml").is_file()), None)
if EXAMPLES is None:
    raise FileNotFoundError(f"examples/rotor_internal_damping.toml is not in {Path.cwd()} or "
                            "a folder above it: run this notebook inside the jourdain repository")
model = jd.load_model(EXAMPLES / "rotor_internal_damping.toml")
defaults = dict(model.system.parameters)
print(model.description)
print("parameters:", defaults)

# %% [markdown]
# ## Linearized once, evaluated for many speeds
#
# The stages of the method are functions too, named after it: kinematics, Newton–Euler
# equations, projection onto the equations of motion, linearization about the nominal motion
# `centred` (the disc on the bearing axis). The linearization is derived once, symbolically;
# a sweep only evaluates numbers. `jd.sweep` gives the eigenvalues over a parameter:

# %%
centred = model.nominal[0]
eom = jd.projection(jd.newton_euler(jd.kinematics(model.system)))
lin = jd.linearization(eom, dict(zip(("x", "y"), centred.y, strict=True)))
print("N =", lin.N.sympy())
speeds = np.linspace(0.0, 30.0, 61)
sweep = jd.sweep(lin, "Omega", speeds)
eigenvalues = np.array(sweep.eigenvalues)
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
ax1.plot(speeds, np.abs(eigenvalues.imag), ".", ms=3)
ax1.set_xlabel("Ω [rad/s]")
ax1.set_ylabel("|Im λ| [rad/s]")
ax1.set_title("Campbell diagram")
ax2.plot(speeds, eigenvalues.real.max(axis=1))
ax2.axhline(0, color="k", lw=0.6)
ax2.set_xlabel("Ω [rad/s]")
ax2.set_ylabel("max Re λ [1/s]")
ax2.set_title("largest real part")
fig.tight_layout()

# %% [markdown]
# ## The threshold, against the closed form
#
# `jd.stability_boundary` finds where the verdict changes between two speeds (bisection on
# the verdict, then the zero of the largest real part). The closed form above gives
# √(100/1)·(1 + 0.5/1) = 15 rad/s:

# %%
critical = jd.stability_boundary(lin, "Omega", 0.0, 30.0)
closed_form = np.sqrt(defaults["k"] / defaults["m"]) * (1 + defaults["d_a"] / defaults["d_i"])
print(f"jourdain: {critical:.12f} rad/s   closed form: {closed_form:.12f} rad/s")
# the boundary is found to rtol 1e-10 (the function's default) of the bracket's scale
assert abs(critical - closed_form) <= 1e-10 * 30.0 + 64 * np.finfo(float).eps * closed_form
print(jd.stability(lin, parameters={"Omega": 12.0}).verdict,
      jd.stability(lin, parameters={"Omega": 20.0}).verdict)

# %% [markdown]
# ## A stability map with `jourdain.study`
#
# A study file (TOML, read as data) varies the speed and the internal damping on a grid and
# linearizes every case; the model is compiled once and the cases are evaluated in batches.
# `workers=1` keeps it in this process (a study spreads over every core, or a Dask cluster,
# by default). The result is an `xarray.Dataset`.

# %%
spec = st.loads_study("""
[study]
name = "rotor stability map"
design = "grid"

[vary.Omega]
range = { start = 0, stop = 40, num = 41 }

[vary.d_i]
values = [0.25, 0.5, 1.0, 2.0]

[compute.linearize]
about = "centred"
""", model=EXAMPLES / "rotor_internal_damping.toml")
ds = st.run_study(spec, workers=1, quiet=True)
print(ds)

# %% [markdown]
# Each curve of the largest real part crosses zero at its own threshold
# √(k/m)·(1 + d_a/d_i): more internal damping lowers the speed at which the rotor goes
# unstable.

# %%
fig, ax = plt.subplots(figsize=(6, 3.5))
for d_i in ds.d_i.values:
    line = ds.max_real_part.sel(d_i=d_i)
    ax.plot(ds.Omega, line, label=f"d_i = {d_i:g}")
    threshold = np.sqrt(defaults["k"] / defaults["m"]) * (1 + defaults["d_a"] / d_i)
    ax.axvline(threshold, color=ax.lines[-1].get_color(), ls=":", lw=0.8)
ax.axhline(0, color="k", lw=0.6)
ax.set_xlabel("Ω [rad/s]")
ax.set_ylabel("max Re λ [1/s]")
ax.legend()
ax.set_title("dotted: the closed-form thresholds")
fig.tight_layout()

# %% [markdown]
# And on the grid, the verdicts agree with the formula at every point not within one grid
# step of its threshold (0 asymptotically stable, 2 unstable):

# %%
Om, Di = np.meshgrid(ds.Omega.values, ds.d_i.values, indexing="ij")
formula = np.sqrt(defaults["k"] / defaults["m"]) * (1 + defaults["d_a"] / Di)
verdict = ds.verdict.transpose("Omega", "d_i").values
clear = np.abs(Om - formula) > 1.0                 # 1 rad/s: the grid step
assert np.all(verdict[clear & (Om < formula)] == 0)
assert np.all(verdict[clear & (Om > formula)] == 2)
print(f"{clear.sum()} of {clear.size} grid points checked against the formula")
