"""Setup time and per-call overhead of a simulation (issue 35, item 3: "setup in milliseconds").

Each measurement of a start runs in a fresh Python process (:func:`benchmarks.crosscheck.spawn`),
``--trials`` times (default 5), and every column is the smallest over the trials: on a shared
machine other work only ever adds to a time. Models: ``n_link_pendulum_on_cart(n)`` (f = n + 1)
and ``spatial_chain(n)`` (revolute, universal and spherical joints in turn) for f = 2 … 32.
Columns:

* ``import s``: ``import jourdain, jourdain.models`` in the child (the interpreter's own
  start-up not included; ``python -c pass`` is printed above the table);
* ``cold s``: import → the model built → the first simulated step returned
  (``system.simulate((0, 1e-3), y0, ẏ0)``) with an empty ``JOURDAIN_CACHE``: derivation, code
  generation, C compilation and loading included; the integrator library is the one compiled
  at install time (``prebuilt/``), as on a user's machine;
* ``warm s``: the same with the cache filled by an earlier process (nothing compiled);
* ``mujoco s``: with ``--mujoco`` (``pip install jourdain[bench]``), MuJoCo's ``import
  mujoco`` → ``MjModel.from_xml_string`` of an MJCF of the same chain (generated here) → the
  first ``mj_step``, in a fresh process, as the reference of the issue.

Below the table, in this process (the model compiled and memoized, as in a user's loop):

* ``simulate() overhead``: the median time of ``system.simulate((0, 1e-9), y0, ẏ0)`` (one
  step, a dozen right-hand sides) of the 4-link pendulum on a cart, of the same call with
  ``t_eval=[1e-9]``, and of calls with a new parameter value each (a sweep, which the memo of
  run templates never serves), in µs per call, next to the figures before the memo
  (:data:`BEFORE_US`): what a call costs outside the C step loop (the target: 20 µs);
* ``step loop``: a 10 s run of the same model (DOP853, the default tolerances; best of 20
  runs, 3 before 2026-11-27's second pass: a 1 ms run on a shared machine needs more than 3
  to reach its time): its time per right-hand side evaluation against one ``jd_accel`` call
  timed alone in C (the model's ÿ = M⁻¹(q − k) with its LDLᵀ solve, :data:`ACCEL_LOOP`
  calling it on 10 000 states, best of 5): the loop's share of a right-hand side (its step
  arithmetic, error control and output; the target: 30 %), against the calls on
  independent states (as before) and chained (each call's state waiting on the last call's
  results, as each stage of a step waits on the one before: the time a stage must wait;
  since 2026-11-27), and, as before, against the compiled M, k, q per state (``fn.batch``).

Measured 2026-11-27 (issue 35's memo of run templates; the same 2-core machine, medians of
3000 calls, the old and the new tree run one after the other in quiet minutes: other work
doubled some runs): the plain call 71-72 → 18.6-19.0 µs, with t_eval 80-81 → 19.2-19.9 µs, a
new parameter value each call 75 → 55 µs; the step loop 0.174 µs per right-hand side (8 894
in a 10 s run of 1.55 ms, best of 20) against jd_accel's 0.095 µs alone: the loop 80 % of a
right-hand side (target 30 %: not met; M, k, q alone 0.055-0.069 µs). Then the step loop's
vector tiles (``numeric/integrator_kernels.h``; ``--quick`` twice, old and new trees in turn):
0.137-0.145 → 0.117 µs per right-hand side, jd_accel 0.077-0.083 µs: 75-78 → 46-51 % (not met).
Then a second pass (2026-11-27; the old and the new library alternated in one process by a C
driver, best of 100 runs, 3-10 rounds each, a loaded 2-core AMD EPYC): the error norm and the
PI factor before the right-hand side at x_new, the stage sums' tiles in registers
(``integrator_kernels.h``, ``integrator_explicit.h``; the same numbers to the bit): 0.1132-0.1134
→ 0.1120-0.1127 µs per right-hand side; jd_accel alone on independent states 0.077-0.083 µs
(the loop 44-47 → 43-46 %, not met), chained 0.100-0.111 µs (the loop 2-13 → 1-12 %, met).
What the profile showed: the loop with a right-hand side of no cost takes 0.029 µs per
right-hand side (490 → 405 instructions), but beside the model's it adds 0.01 µs, hidden
under jd_accel's latency; the rest of the 46 % is jd_accel's own latency (0.100 µs) against
its throughput (0.077 µs: the processor overlaps consecutive independent calls, which the
stages of a Runge–Kutta step, each waiting on the one before, never are). The chained figure
measures what a stage waits for; the independent one stays printed beside it.

The first run interpreted while the model compiles (``numeric/interpreter.py``; symbolic-path
models), 2026-11-27, ``--trials 3 --mujoco``, one run each, the same machine (before: the tree
without it, minutes earlier, ``--trials 2``; every motion the same to the bit, cold and warm):

| model | f | path | cold s before → after | warm s after | MuJoCo s |
| --- | ---: | --- | ---: | ---: | ---: |
| cart(1) | 2 | symbolic | 0.345 → 0.202 | 0.193 | 0.220 |
| cart(4) | 5 | symbolic | 0.410 → 0.171 | 0.165 | 0.241 |
| cart(8) | 9 | symbolic | 0.441 → 0.193 | 0.206 | 0.229 |
| cart(16) | 17 | symbolic | 0.790 → 0.220 | 0.216 | 0.246 |
| cart(31) | 32 | planar | 0.561 → 0.509 | 0.186 | 0.185 |
| chain(2) | 3 | symbolic | 0.376 → 0.142 | 0.152 | 0.124 |
| chain(4) | 7 | symbolic | 1.061 → 0.212 | 0.216 | 0.171 |
| chain(8) | 15 | spatial | 0.936 → 0.898 | 0.212 | 0.141 |
| chain(16) | 31 | spatial | 0.864 → 0.773 | 0.187 | 0.147 |

(build + first step after the import, cold: 0.017-0.079 s on the symbolic path, against
0.12-0.92 s before; the recursions' engines still wait for the compiler: 0.37-0.73 s.) Then
the recursions' first runs on their units compiled at -O0 while the -O2 library compiles
(``numeric/first_run.py``; the old and the new tree in turn, ``--trials 3``, a loaded
machine: import 0.23-0.26 s; motions the same to the bit): cold, build + first step after
the import, cart(31) 0.311 → 0.224 s, chain(8) 0.625 → 0.241 s, chain(16) 0.709 → 0.238 s;
import → first step 0.564 → 0.455, 0.936 → 0.472 and 0.952 → 0.509 s. Then without a
compiler before the first number: the recursions' engines sized at run time in the prebuilt
integrator library, their per-joint code interpreted (``numeric/runtime_engine.py``;
2026-11-27, the old and the new tree in turn, 3 trials each, best; motions the same to the
bit): cold, build + first step after the import, cart(31) 0.286 → 0.088 s, chain(8)
0.324 → 0.077 s, chain(16) 0.245 → 0.054 s.

Warm starts without the derivation (``numeric/recipes.py``: the library named by a recipe kept
under an exact fingerprint of the model; ``numeric/native.py``: the native target asked of the
compiler once per processor, not in every process, 7-8 ms), 2026-11-27, ``--trials 3``, the
tree before (9473c84) and after in turn, twice, a machine loaded by other work (import
0.19-0.27 s): warm, build + first step after the import, in s (rounds 1 and 2):

| model | before | after |
| --- | ---: | ---: |
| cart(1) | 0.010, 0.010 | 0.009, 0.008 |
| cart(4) | 0.015, 0.022 | 0.011, 0.010 |
| cart(8) | 0.040, 0.046 | 0.013, 0.009 |
| cart(16) | 0.064, 0.103 | 0.017, 0.016 |
| cart(31) | 0.065, 0.094 | 0.017, 0.015 |
| chain(2) | 0.020, 0.021 | 0.019, 0.018 |
| chain(4) | 0.071, 0.085 | 0.018, 0.015 |
| chain(8) | 0.129, 0.082 | 0.016, 0.018 |
| chain(16) | 0.043, 0.040 | 0.024, 0.033 |

All of issue 35's setup work together (the interpreter, the engines sized at run time, the
recipes), ``--trials 3 --mujoco``, the tree before (9473c84, which had the interpreter and the
-O0 first builds) and after in turn, a quieter machine (import 0.14-0.19 s), in s:

| model | cold before → after | cold after the import | warm before → after | warm after the import | MuJoCo |
| --- | ---: | ---: | ---: | ---: | ---: |
| cart(1) | 0.191 → 0.227 | 0.014 → 0.020 | 0.181 → 0.192 | 0.011 → 0.008 | 0.268 |
| cart(4) | 0.165 → 0.239 | 0.021 → 0.030 | 0.176 → 0.170 | 0.018 → 0.010 | 0.277 |
| cart(8) | 0.187 → 0.213 | 0.031 → 0.043 | 0.170 → 0.165 | 0.026 → 0.010 | 0.223 |
| cart(16) | 0.284 → 0.255 | 0.096 → 0.116 | 0.222 → 0.209 | 0.062 → 0.014 | 0.198 |
| cart(31) | 0.520 → 0.227 | 0.313 → 0.072 | 0.242 → 0.201 | 0.075 → 0.021 | 0.197 |
| chain(2) | 0.215 → 0.179 | 0.036 → 0.028 | 0.217 → 0.194 | 0.026 → 0.016 | 0.138 |
| chain(4) | 0.310 → 0.259 | 0.111 → 0.091 | 0.288 → 0.151 | 0.091 → 0.016 | 0.126 |
| chain(8) | 0.562 → 0.253 | 0.367 → 0.086 | 0.304 → 0.163 | 0.115 → 0.017 | 0.183 |
| chain(16) | 0.490 → 0.256 | 0.301 → 0.070 | 0.207 → 0.161 | 0.043 → 0.022 | 0.186 |

(the symbolic path's cold columns did not change in code: their spread is the machine's; the
step loop in the same run: 0.115 µs per right-hand side, jd_accel alone 0.097 µs (19 %),
chained 0.104 µs (11 %); jd_accel alone varies between processes from 0.077 to 0.097 µs.)

What is left of a warm start after the import is the model's own construction (its
validation; ``spatial_chain``'s random inertias import ``numpy.random``), the fingerprint (1 µs
per piece: 0.2-2 ms here, 15-25 ms for models of f = 127) and the run's setup.

    .venv/bin/python benchmarks/setup.py                   # f = 2 … 32, 5 trials (minutes)
    .venv/bin/python benchmarks/setup.py --quick           # f = 2 and 5, 2 trials
    .venv/bin/python benchmarks/setup.py --mujoco --json setup.json

A child runs ``python -m benchmarks.setup '{"kind": "cart", "n": 4}'`` and prints one JSON
line (:func:`case`).

Measured 2026-11-26 on a 2-core AMD EPYC shared with other sessions' test runs (load average
3.8-4.5 during both runs, so every figure carries that noise), best of 3, byte code cached,
without (before, commit 2608593) and with issue 35's lazy imports (``import s`` here is
``import jourdain, jourdain.models``; ``import jourdain`` alone went 0.24 → 0.10 s at load 1-2):

| model | f | import s | cold s | warm s | build+step cold | build+step warm | MuJoCo s |
| --- | ---: | --- | --- | --- | --- | --- | ---: |
| cart(1) | 2 | 0.239 → 0.167 | 0.371 → 0.314 | 0.248 → 0.175 | 0.109 → 0.093 | 0.008 | 0.178 |
| cart(4) | 5 | 0.251 → 0.170 | 0.440 → 0.337 | 0.277 → 0.184 | 0.170 → 0.130 | 0.014 | 0.166 |
| cart(8) | 9 | 0.233 → 0.227 | 0.501 → 0.612 | 0.254 → 0.264 | 0.221 → 0.300 | 0.021 → 0.032 | 0.326 |
| cart(16) | 17 | 0.240 → 0.262 | 0.682 → 0.944 | 0.312 → 0.393 | 0.442 → 0.646 | 0.054 → 0.051 | 0.286 |
| cart(31) | 32 | 0.232 → 0.246 | 1.049 → 1.548 | 0.272 → 0.303 | 0.747 → 1.195 | 0.039 → 0.056 | 0.315 |
| chain(2) | 3 | 0.339 → 0.238 | 0.621 → 0.448 | 0.367 → 0.286 | 0.267 → 0.198 | 0.022 → 0.025 | 0.122 |
| chain(4) | 7 | 0.273 → 0.233 | 0.894 → 1.064 | 0.388 → 0.272 | 0.617 → 0.812 | 0.045 → 0.039 | 0.125 |
| chain(8) | 15 | 0.320 → 0.245 | 1.253 → 1.195 | 0.414 → 0.340 | 0.864 → 0.929 | 0.094 → 0.092 | 0.097 |
| chain(16) | 31 | 0.326 → 0.229 | 1.548 → 1.323 | 0.404 → 0.290 | 1.176 → 1.090 | 0.051 → 0.027 | 0.098 |

(the columns after the import did not change in code: their spread is the load's). simulate()
per call 76 → 74 µs; the step loop at n = 4: 0.14 µs per right-hand side against 0.054 µs of
M, k, q (155-165 %). The targets stand unmet, and why: the interpreter's start-up and the
imports of NumPy and SymEngine alone take 0.09-0.13 s here (``import numpy`` 0.09 s), over the
cold target before any model code runs; cold starts wait for gcc (0.09 s for the smallest
model's one unit, 0.4 s at -O2 for the recursion's engine of chains: -O0 halves it, but a
first library at -O0 with the -O2 one built meanwhile needs both in one process and an exit
that does not cut the build off); warm starts derive the symbolic projection before they can
name the library to load (chain(8): 45 ms, of which the projection and its node count take
30 ms; a derivation cache keyed by the model's content needs an exact serialization of its
expressions: SymEngine's ``str`` prints 15 digits, so two models can print alike); and the
per-call cost is Python around the C call (argument checks, the packing of the problem, the
copies into Results, ~15-25 µs each).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CASES = (("cart", 1), ("cart", 4), ("cart", 8), ("cart", 16), ("cart", 31),
         ("chain", 2), ("chain", 4), ("chain", 8), ("chain", 16))
QUICK_CASES = (("cart", 1), ("cart", 4))
#: the issue's targets (seconds; the overhead in µs, the loop's share in %)
TARGET_COLD, TARGET_WARM, TARGET_OVERHEAD_US, TARGET_LOOP_SHARE = 0.100, 0.030, 20.0, 30.0
HEADER = ("| model | f | import s | cold s | warm s | build+step cold s | build+step warm s "
          "| mujoco s |")


def _name(kind: str, n: int) -> str:
    return f"n_link_pendulum_on_cart({n})" if kind == "cart" else f"spatial_chain({n})"


def case(kind: str, n: int) -> dict:
    """One start, measured in this process (which should be fresh): import, build, first
    simulated step."""
    t0 = time.perf_counter()
    import numpy as np

    import jourdain  # noqa: F401 - the import is what is timed
    import jourdain.models as models

    t1 = time.perf_counter()
    system = models.n_link_pendulum_on_cart(n) if kind == "cart" else models.spatial_chain(n)
    f = system.f
    inputs = {u: 0.0 for u in system.input_names}
    res = system.simulate((0.0, 1e-3), np.full(f, 0.1), np.zeros(f), inputs=inputs)
    t2 = time.perf_counter()
    return {"kind": kind, "n": n, "f": f, "import_s": t1 - t0, "first_s": t2 - t0,
            "after_import_s": t2 - t1, "y_end": res.y[-1].tolist()}


def mujoco_xml(kind: str, n: int) -> str:
    """An MJCF of the same chain: the cart (a slide along x) with n links turning about z
    (point masses at their ends, gravity along -y), or the spatial chain's bodies, inertias
    and joints (a universal joint as two hinges, a spherical one as a ball)."""
    if kind == "cart":
        inner = ""
        for i in range(n, 0, -1):
            inner = (f'<body name="l{i}" pos="{0 if i == 1 else 1} 0 0"><joint type="hinge" '
                     f'axis="0 0 1"/><inertial pos="1 0 0" mass="0.01" '
                     f'diaginertia="1e-6 1e-6 1e-6"/>{inner}</body>')
        body = ('<body name="cart"><joint type="slide" axis="1 0 0"/><inertial pos="0 0 0" '
                f'mass="0.01" diaginertia="1e-6 1e-6 1e-6"/>{inner}</body>')
        gravity = "0 -9.81 0"
    else:
        from jourdain.models import spatial_chain_data

        body = ""
        data = spatial_chain_data(n)
        for i, d in reversed(list(enumerate(data))):
            prev = data[i - 1]["offset"] if i else (0.0, 0.0, 0.0)
            if d["joint"] == "spherical":
                joints = '<joint type="ball"/>'
            else:
                joints = "".join(f'<joint type="hinge" axis="{_axis(a)}"/>' for a in d["axes"])
            inertia = d["inertia"]
            full = " ".join(str(float(v)) for v in (inertia[0][0], inertia[1][1], inertia[2][2],
                                                    inertia[0][1], inertia[0][2], inertia[1][2]))
            com = " ".join(str(float(c)) for c in d["com"])
            pos = " ".join(str(float(c)) for c in prev)
            body = (f'<body name="b{i}" pos="{pos}">{joints}<inertial pos="{com}" '
                    f'mass="{float(d["mass"])}" fullinertia="{full}"/>{body}</body>')
        gravity = "0 0 -9.81"
    return (f'<mujoco><option gravity="{gravity}" timestep="1e-3"/><worldbody>{body}'
            "</worldbody></mujoco>")


def _axis(name: str) -> str:
    return " ".join("1" if name == c else "0" for c in "xyz")


def mujoco_case(kind: str, n: int) -> dict:
    """MuJoCo's start in this (fresh) process: import, model from the MJCF, first mj_step."""
    xml = mujoco_xml(kind, n)  # the text is ready before the clock runs
    t0 = time.perf_counter()
    import mujoco

    t1 = time.perf_counter()
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_step(model, data)
    t2 = time.perf_counter()
    return {"import_s": t1 - t0, "first_s": t2 - t0, "nv": int(model.nv)}


def _spawn(spec: dict, cache: str | None) -> dict:
    from benchmarks.crosscheck import spawn

    return spawn(spec, 0, cache=cache, module="benchmarks.setup")


def starts(kind: str, n: int, trials: int, mujoco: bool) -> dict:
    """Best of ``trials`` fresh processes: cold (a new empty cache each), warm (one cache
    filled by the first cold run), and MuJoCo's."""
    spec = {"kind": kind, "n": n}
    cold = [_spawn(spec, None) for _ in range(trials)]
    with tempfile.TemporaryDirectory(prefix="jourdain-setup-") as cache:
        fill = _spawn(spec, cache)
        warm = [_spawn(spec, cache) for _ in range(trials)]
    # the same motion from a filled cache as from an empty one, to the bit
    same = all(r["y_end"] == fill["y_end"] for r in (*cold, *warm))
    row = {"kind": kind, "n": n, "f": cold[0]["f"], "bit_identical": same,
           "import_s": min(r["import_s"] for r in (*cold, *warm)),
           "cold_s": min(r["first_s"] for r in cold),
           "warm_s": min(r["first_s"] for r in warm),
           "cold_after_import_s": min(r["after_import_s"] for r in cold),
           "warm_after_import_s": min(r["after_import_s"] for r in warm)}
    if mujoco:
        mj = [_spawn({**spec, "mujoco": True}, None) for _ in range(trials)]
        row["mujoco_s"] = min(r["first_s"] for r in mj)
        row["mujoco_import_s"] = min(r["import_s"] for r in mj)
    return row


#: simulate()'s cost per call before issue 35's memo of run templates (commit d91a913, this
#: function, 2-core AMD EPYC): the plain call and the one with t_eval (µs)
BEFORE_US = {"plain": 72.0, "t_eval": 81.0}

#: C loops that call the model's ``jd_accel`` (ÿ = M⁻¹(q − k) and the power ẏᵀq: the model's
#: part of a right-hand side) on ``m`` states through a function pointer, as the integrator
#: does, ``reps`` times: ``jd_accel_loop`` on states independent of each other (the processor
#: runs one call's start beside the last one's end: its throughput), ``jd_accel_chain`` with
#: each call's ẏ waiting on the last call's ÿ and its y on the last call's ẏ, as the state of
#: a Runge–Kutta stage waits on the stage before (its latency; the wait is one multiply and
#: one add per component, the least that a stage's sum does)
ACCEL_LOOP = r"""
typedef int (*jd_accel_fn)(const double *y, const double *yd, double t, const double *p,
                           const double *u, double *ydd, double *power);
double jd_accel_loop(void *fn, const double *Y, const double *YD, long m, long f,
                     const double *p, const double *u, long reps, double *ydd) {
    jd_accel_fn accel = (jd_accel_fn)fn;
    double power = 0.0, sum = 0.0;
    for (long r = 0; r < reps; ++r)
        for (long i = 0; i < m; ++i) {
            accel(Y + i * f, YD + i * f, 0.0, p, u, ydd, &power);
            sum += ydd[0] + power;
        }
    return sum;
}
double jd_accel_chain(void *fn, const double *Y, const double *YD, long m, long f,
                      const double *p, const double *u, long reps, double *ydd) {
    jd_accel_fn accel = (jd_accel_fn)fn;
    double power = 0.0, sum = 0.0, y[64], yd[64];
    if (f > 64) return 0.0;
    for (long j = 0; j < f; ++j) { yd[j] = 0.0; ydd[j] = 0.0; }
    for (long r = 0; r < reps; ++r)
        for (long i = 0; i < m; ++i) {
            for (long j = 0; j < f; ++j) {  /* + 0·(the last call's results) */
                y[j] = Y[i * f + j] + 0.0 * yd[j];
                yd[j] = YD[i * f + j] + 0.0 * ydd[j];
            }
            accel(y, yd, 0.0, p, u, ydd, &power);
            sum += ydd[0] + power;
        }
    return sum;
}
"""


def accel_seconds(fn, f: int, p, u, m: int = 10000, reps: int = 5,
                  chained: bool = False) -> float:
    """One ``jd_accel`` call of the compiled ``fn`` (:func:`jourdain.numeric.mkq_function`)
    timed alone in C (:data:`ACCEL_LOOP`: one ctypes call per ``m`` states, best of
    ``reps``), at random states; ``chained``: each call's state waiting on the last call's
    results, as in the stages of a step."""
    import ctypes

    import numpy as np

    from jourdain.numeric import toolchain

    lib = toolchain.build(toolchain.content_key("bench-accel-loop", ACCEL_LOOP), ACCEL_LOOP)
    loop = lib.jd_accel_chain if chained else lib.jd_accel_loop
    vp, lg = ctypes.c_void_p, ctypes.c_long
    loop.restype = ctypes.c_double
    loop.argtypes = [vp, vp, vp, lg, lg, vp, vp, lg, vp]
    rng = np.random.default_rng(0)
    Y, YD = rng.uniform(-1, 1, (m, f)), rng.uniform(-1, 1, (m, f))
    pv, uv = np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(u, dtype=float)
    ydd = np.empty(f)
    best = np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        loop(fn.accel_address, Y.ctypes.data, YD.ctypes.data, m, f, pv.ctypes.data,
             uv.ctypes.data, 1, ydd.ctypes.data)
        best = min(best, time.perf_counter() - t0)
    return best / m


def per_call_us(call, calls: int, rounds: int = 10) -> float:
    """The median time of ``call()`` over ``calls`` calls made in ``rounds`` rounds (µs)."""
    times = []
    for _ in range(rounds):
        for _ in range(max(calls // rounds, 1)):
            t0 = time.perf_counter()
            call()
            times.append(time.perf_counter() - t0)
    return 1e6 * statistics.median(times)


def overhead(repeat: int = 300) -> dict:
    """simulate()'s cost outside the C loop, and the step loop's share beyond a right-hand
    side, for the 4-link pendulum on a cart (this process; compiled once, memoized): the
    median per call of ``simulate((0, 1e-9), y0, ẏ0)``, with ``t_eval=[1e-9]``, and with a new
    parameter value each call (a sweep: the memo of run templates never serves it); a 10 s
    run's time per right-hand side against M, k, q per state (``fn.batch``) and against one
    ``jd_accel`` call timed alone in C (:func:`accel_seconds`)."""
    import numpy as np

    from jourdain.models import n_link_pendulum_on_cart
    from jourdain.numeric import mkq_function, parameter_vector

    system = n_link_pendulum_on_cart(4)
    f = system.f
    y0, yd0 = np.full(f, 0.1), np.zeros(f)
    u = {"F": 0.0}
    # compiled first: with an empty cache the first runs are interpreted while the library
    # compiles in a thread (numeric/interpreter.py); this measures the compiled runs
    fn = mkq_function(system)
    short = system.simulate((0.0, 1e-9), y0, yd0, inputs=u)
    g = iter(9.81 + 1e-6 * np.arange(1, 10 * repeat + 2))
    plain = per_call_us(lambda: system.simulate((0.0, 1e-9), y0, yd0, inputs=u), repeat)
    t_eval = per_call_us(lambda: system.simulate((0.0, 1e-9), y0, yd0, inputs=u,
                                                 t_eval=[1e-9]), repeat)
    sweep = per_call_us(lambda: system.simulate((0.0, 1e-9), y0, yd0, inputs=u,
                                                parameters={"g": next(g)}), repeat)
    long = min((system.simulate((0.0, 10.0), y0, yd0, inputs=u) for _ in range(20)),
               key=lambda r: r.wall_time)
    rng = np.random.default_rng(0)
    m = 10000
    Y, YD = rng.uniform(-1, 1, (m, f)), rng.uniform(-1, 1, (m, f))
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        fn.batch(Y, YD, 0.0, None, np.zeros((m, 1)))
        best = min(best, time.perf_counter() - t0)
    mkq_s = best / m
    pv = parameter_vector(system, None)
    accel_s = accel_seconds(fn, f, pv, [0.0])
    chain_s = accel_seconds(fn, f, pv, [0.0], chained=True)
    per_eval = long.wall_time / long.nfev
    return {"simulate_us": plain, "simulate_t_eval_us": t_eval, "simulate_sweep_us": sweep,
            "short_nfev": short.nfev, "run_s": long.wall_time, "run_nfev": long.nfev,
            "per_eval_us": 1e6 * per_eval, "mkq_us": 1e6 * mkq_s,
            "loop_share_pct": 100.0 * (per_eval - mkq_s) / mkq_s, "accel_us": 1e6 * accel_s,
            "accel_share_pct": 100.0 * (per_eval - accel_s) / accel_s,
            "accel_chain_us": 1e6 * chain_s,
            "chain_share_pct": 100.0 * (per_eval - chain_s) / chain_s}


def _mark(value: float, target: float) -> str:
    return "met" if value <= target else "not met"


def table(rows: list[dict], over: dict | None) -> str:
    out = [HEADER, "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for r in rows:
        mj = f"{r['mujoco_s']:.3f}" if "mujoco_s" in r else "—"
        out.append(f"| {_name(r['kind'], r['n'])} | {r['f']} | {r['import_s']:.3f} | "
                   f"{r['cold_s']:.3f} | {r['warm_s']:.3f} | {r['cold_after_import_s']:.3f} | "
                   f"{r['warm_after_import_s']:.3f} | {mj} |")
    worst_cold = max(r["cold_s"] for r in rows)
    worst_warm = max(r["warm_s"] for r in rows)
    out.append("")
    out.append(f"import → first step, empty cache: at most {worst_cold:.3f} s (target "
               f"{TARGET_COLD:.3f} s: {_mark(worst_cold, TARGET_COLD)}); warm cache: at most "
               f"{worst_warm:.3f} s (target {TARGET_WARM:.3f} s: "
               f"{_mark(worst_warm, TARGET_WARM)})")
    if not all(r["bit_identical"] for r in rows):
        out.append("WARNING: a warm start's motion differs from a cold start's")
    if over is not None:
        worst = max(over["simulate_us"], over["simulate_t_eval_us"])
        out.append(f"simulate() per call (one step, {over['short_nfev']} right-hand sides, "
                   f"median): {BEFORE_US['plain']:.0f} → {over['simulate_us']:.1f} µs, with "
                   f"t_eval {BEFORE_US['t_eval']:.0f} → {over['simulate_t_eval_us']:.1f} µs "
                   f"(before: commit d91a913; target {TARGET_OVERHEAD_US:.0f} µs: "
                   f"{_mark(worst, TARGET_OVERHEAD_US)}"
                   f"); a new parameter value each call {over['simulate_sweep_us']:.1f} µs")
        out.append(f"step loop, n = 4, 10 s: {over['run_nfev']} right-hand sides in "
                   f"{1e3 * over['run_s']:.2f} ms, {over['per_eval_us']:.3f} µs each against "
                   f"one jd_accel alone {over['accel_us']:.3f} µs: the loop "
                   f"{over['accel_share_pct']:.0f} % of a right-hand side (target "
                   f"{TARGET_LOOP_SHARE:.0f} %: "
                   f"{_mark(over['accel_share_pct'], TARGET_LOOP_SHARE)}); against one "
                   f"jd_accel waiting on the last, as a stage does, {over['accel_chain_us']:.3f}"
                   f" µs: {over['chain_share_pct']:.0f} % ("
                   f"{_mark(over['chain_share_pct'], TARGET_LOOP_SHARE)}); against M, k, q "
                   f"per state {over['mkq_us']:.3f} µs: {over['loop_share_pct']:.0f} %")
    return "\n".join(out)


def _startup() -> float:
    import subprocess

    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="f = 2 and 5, 2 trials")
    ap.add_argument("--trials", type=int, default=None, help="fresh processes per column")
    ap.add_argument("--mujoco", action="store_true", help="MuJoCo's start as a reference")
    ap.add_argument("--no-overhead", action="store_true", help="skip the in-process part")
    ap.add_argument("--json", help="write the rows to this file")
    args = ap.parse_args(argv)
    # the children's byte code cached as an installed package's is (not in the source tree)
    os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    os.environ.setdefault("PYTHONPYCACHEPREFIX",
                          str(Path(tempfile.gettempdir()) / "jourdain-setup-pycache"))
    cases = QUICK_CASES if args.quick else CASES
    trials = args.trials or (2 if args.quick else 5)
    import subprocess

    # one untimed import first, so that the children find their byte code cached
    subprocess.run([sys.executable, "-c", "import jourdain.models, jourdain.simulation.simulate"],
                   check=True, cwd=ROOT)
    print(f"python -c pass: {_startup():.3f} s (not in the columns)")
    rows = [starts(k, n, trials, args.mujoco) for k, n in cases]
    over = None if args.no_overhead else overhead(50 if args.quick else 300)
    print(table(rows, over))
    if args.json:
        Path(args.json).write_text(json.dumps({"rows": rows, "overhead": over}, indent=1))
    return rows


if __name__ == "__main__":
    if len(sys.argv) == 2 and sys.argv[1].startswith("{"):
        spec = json.loads(sys.argv[1])
        print(json.dumps(mujoco_case(spec["kind"], spec["n"]) if spec.get("mujoco")
                         else case(spec["kind"], spec["n"])))
    else:
        main()
