"""Simulation benchmark, in one run, side by side with the peers:

1. ``n_link_pendulum_on_cart(n)``, n = 2, 4, 8, 12, 10 s of motion released from the hanging
   position (link angles π+0.3 … π−0.3, at rest), rtol = atol = 1e-8: jourdain
   (``System.simulate``, DOP853, step loop in C) against PyDy (``generate_ode_function``, Cython
   backend, ``linear_sys_solver="sympy"`` and ``"numpy"``, integrated with SciPy's ``odeint``).
   Reported: derivation, code generation and integration times, right-hand-side evaluations,
   accepted steps (jourdain also its rejected steps; ``odeint`` does not report them),
   evaluations per attempted step (for ``odeint``: per accepted step), and the distance of each
   final state from a reference computed by jourdain at 1e-12 (itself checked against
   ``odeint`` at 1e-12 on PyDy's function). Besides the run at rtol = 1e-8, jourdain at equal
   accuracy: the loosest tolerance (1e-6, 7e-7, 5e-7, … 1.5e-8) at which its final state, and
   that at every tighter tolerance of the grid, is as close to the reference as the most
   accurate PyDy run's (same tolerance is not same accuracy: DOP853
   and LSODA err differently at 1e-8). Below each n, where jourdain's time per right-hand side
   goes: M, k, q alone (one batched call at the run's states) and the set-up.
2. Batched ``M`` and ``k`` (and ``q``) evaluation per state against Pinocchio's ``crba`` +
   ``nonLinearEffects`` per call, for ``spatial_chain(6)`` and a 7-joint arm, with a check that
   the numbers agree (``M`` = crba, ``k − q`` = nonLinearEffects).

Usage::

    python benchmarks/simulation.py             # everything
    python benchmarks/simulation.py --n 2 4     # some sizes
    python benchmarks/simulation.py --quick     # n = 2, PyDy's lambdify backend (a smoke test)
    python benchmarks/simulation.py --json out.json

Where a run's time went (valgrind's instruction counts of the C loop alone, before sincos.h, n =
12, rtol = 5e-8, 4 118 right-hand sides, 343 steps, 12.0 per step, W not limiting the steps):
per right-hand side the LDLᵀ loop of the 13×13 M 5 400 instructions, M, k, q 2 000 plus 12
sincos 1 500, the step loop (stage sums, error norm, output) 1 400. The written-out LDLᵀ
(numeric/integrator_ldl.py) halves the solve's instructions but is slower at f = 13 (probably:
its code no longer fits beside M, k, q in the instruction caches), hence used up to f = 10; the
articulated-body recursion (numeric.dynamics_function) is 4× (n = 12) to 11× (n = 4) slower per
run here. -march=native on the step loop alone is slower (2.30 against 2.10 ms), on the model
code alone and on both faster (1.88 and 1.78 ms): hence both (numeric/toolchain.py). GCC unrolls the
LDLᵀ loop's inner loops (ldl_solve.h): 260 → 211-228 ns per solve alone, 7.1-7.3× → 7.6-7.7×
PyDy end to end at n = 12 (2026-11-23, the two alternated). The 12 sin/cos pairs in one
vectorized call (numeric/sincos.h) instead of 12 libm sincos: M, k, q 212 → 172 ns, jd_accel 429
→ 361 ns (C microbenchmark), 7.6-7.7× → 8.4-8.6× PyDy end to end at n = 12 and 21× → 23× at n =
4 (two alternated rounds each), 460-468 ns per right-hand side. Tried and not kept, each slower
in the same microbenchmark: the LDLᵀ right-looking with its updates vectorized (+35 ns), with L
stored by columns so that the dot products become vectorized column updates (+90 ns at -O2,
bit-identical), two rows per pass of the left-looking loop (±0), two partial sums per dot
product (+55 ns), each column's dot products written out with the loop over rows kept (+55 ns,
bit-identical), the solve written out at f = 13 (+90 ns); parameter-only products of M, k, q
hoisted out of the call (133 multiplications of about 1 300: −5 ns, within noise); the sin/cos
loop also compiled for AVX2 (−20 ns in M, k, q but not in jd_accel). 10× PyDy at n = 12 needs
about 400 ns per right-hand side. Fewer right-hand sides with Verner's "most efficient" 7(6)
pair (10 per step)? No: driven by SciPy's RungeKutta against its DOP853 on the same function, it
needed as many for the same final error (4 812 evaluations for 7.5e-7 against 4 742 for 6.5e-7).
Compiled for the machine (-march=native, AVX-512, -ffp-contract=off: bit-identical numbers; since
2026-11-27 without FMA and AVX-512, numeric/toolchain.py NO_FUSED, at the same speed) and
with the stage sums in registers: 8.4-8.7× → 9.2-9.4× PyDy at n = 12, 440-470 ns per
right-hand side (two alternated rounds on a loaded machine). Tried then and not kept: the LDLᵀ
written out at f = 13 under AVX-512 (32 registers): 343 → 277 ns in the C microbenchmark, but
1.72 → 1.81 ms end to end (one process, alternated, best of 45); the left-looking loop with the
forward substitution fused into it, and a vectorized column form (L by columns, -O3, AVX-512):
no gain and +210 ns; -O3 on the model code: +85 ns; the solve interleaved with the
computation of k and q: no gain. Each sum over the links below a joint formed from the next
smaller one (graph/sums.py: M, k, q 486 → 200 additions, 151 → 142 ns), the integrator's M, k,
q never split into parts, and the solve reading M's upper triangle from jd_fn_upper (no copies
into the lower one): 9.6-9.8× → 10.0-10.2× PyDy at n = 12 in two alternated runs, 405-415 ns
per right-hand side (a quiet machine); the written-out LDLᵀ at f = 13 still slower then (1.76 →
1.79 ms).

PyDy's symbolic linear solver can take long for large n; it is
skipped above ``--sympy-max-n`` (default 12: its code generation takes about 5 s at n = 12)
and the skip is printed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import jourdain as jd  # noqa: E402
from benchmarks.pinocchio_models import chain_model  # noqa: E402
from jourdain import numeric  # noqa: E402
from jourdain.models import (  # noqa: E402
    n_link_pendulum_on_cart,
    robot_arm,
    robot_arm_data,
    spatial_chain,
    spatial_chain_data,
)
from jourdain.numeric import toolchain  # noqa: E402
from jourdain.numeric.compiled import symbolic_mkq  # noqa: E402 - what mkq_function compiles
from jourdain.simulation.simulate import integrator_library  # noqa: E402

TOL = 1e-8
T_END = 10.0


def best_of(fn, repeat: int = 7, min_time: float = 0.2) -> float:
    """Best wall time of ``fn()`` over ``repeat`` rounds (each round loops to ``min_time``)."""
    best = math.inf
    for _ in range(repeat):
        k, t0 = 0, time.perf_counter()
        while True:
            fn()
            k += 1
            el = time.perf_counter() - t0
            if el >= min_time / repeat:
                break
        best = min(best, el / k)
    return best


def initial_state(n: int) -> tuple[np.ndarray, np.ndarray]:
    y0 = np.concatenate([[0.0], np.linspace(math.pi + 0.3, math.pi - 0.3, n)])
    return y0, np.zeros(n + 1)


# --- jourdain ------------------------------------------------------------------------------------
def bench_jourdain(n: int) -> dict:
    t0 = time.perf_counter()
    s = n_link_pendulum_on_cart(n)
    s.equations_of_motion()
    t_derive = time.perf_counter() - t0
    # code generation with an empty cache: CSE, C source, cc, load of what simulate() compiles
    # (M, k, q and the fused solve jd_accel, as numeric.mkq_function builds them from the
    # equations of motion derived above: compiled.symbolic_mkq); then the same from the warm
    # on-disk cache
    eom = s.equations_of_motion()
    old = os.environ.get("JOURDAIN_CACHE")
    with tempfile.TemporaryDirectory() as d:
        os.environ["JOURDAIN_CACHE"] = d
        toolchain._loaded.clear()
        t0 = time.perf_counter()
        symbolic_mkq(s, eom)
        t_codegen = time.perf_counter() - t0
        toolchain._loaded.clear()
        t0 = time.perf_counter()
        symbolic_mkq(s, eom)
        t_cached = time.perf_counter() - t0
        if old is None:
            del os.environ["JOURDAIN_CACHE"]
        else:
            os.environ["JOURDAIN_CACHE"] = old
        toolchain._loaded.clear()
    numeric.clear_cache()
    y0, yd0 = initial_state(n)
    kw: dict[str, Any] = {"inputs": {"F": 0.0}, "rtol": TOL, "atol": TOL}
    res = s.simulate((0, T_END), y0, yd0, **kw)
    ref = s.simulate((0, T_END), y0, yd0, inputs={"F": 0.0}, rtol=1e-12, atol=1e-12)
    # where the time of a run goes: M, k, q alone at the run's own states (one C call), and a
    # run over a vanishing interval (set-up and results, no steps)
    fn = numeric.mkq_function(s)
    p = numeric.parameter_vector(s, None)
    out = np.zeros((len(res.t), fn.size))
    t_mkq = best_of(lambda: fn.batch(res.y, res.yd, res.t, p, [0.0], out=out)) / len(res.t)
    t_setup = best_of(lambda: s.simulate((0, 1e-9), y0, yd0, **kw))
    return {"system": s, "derive": t_derive, "codegen": t_codegen, "codegen_cached": t_cached,
            "run": lambda: s.simulate((0, T_END), y0, yd0, **kw),
            "nfev": res.nfev, "steps": res.n_accepted, "rejected": res.n_rejected,
            "mkq_per_state": t_mkq, "setup": t_setup,
            "mkq_path": "recursion" if fn.n_bodies else "symbolic",
            "x_final": np.concatenate([res.y[-1], res.yd[-1]]),
            "x_ref": np.concatenate([ref.y[-1], ref.yd[-1]])}


#: tolerances tried for the run at PyDy's accuracy (rtol = atol), loosest first
EQUAL_ACCURACY_TOLS = (1e-6, 7e-7, 5e-7, 4e-7, 3e-7, 2e-7, 1.5e-7, 1e-7, 8e-8, 7e-8, 6e-8, 5e-8,
                       4e-8, 3e-8, 2e-8, 1.5e-8)


def equal_accuracy(J: dict, n: int, target: float) -> dict | None:
    """jourdain at the loosest tolerance of :data:`EQUAL_ACCURACY_TOLS` (looser than
    :data:`TOL`) whose final state is as close to the reference as ``target``, and so is it at
    every tighter tolerance of the grid: the error of one final state is not monotone in the
    tolerance (at n = 4, 8e-8 errs less than 7e-8), and a tolerance that happens to land below
    the target while tighter ones do not is not taken. None if none is."""
    s = J["system"]
    y0, yd0 = initial_state(n)
    best = None
    for tol in sorted(t for t in EQUAL_ACCURACY_TOLS if t > TOL):  # tightest first
        kw = {"inputs": {"F": 0.0}, "rtol": tol, "atol": tol}
        res = s.simulate((0, T_END), y0, yd0, **kw)
        x = np.concatenate([res.y[-1], res.yd[-1]])
        if np.abs(x - J["x_ref"]).max() > target:
            break
        best = {**J, "rtol": tol, "x_final": x, "nfev": res.nfev, "steps": res.n_accepted,
                "rejected": res.n_rejected,
                "run": lambda kw=kw: s.simulate((0, T_END), y0, yd0, **kw)}
    return best


# --- PyDy ----------------------------------------------------------------------------------------
def pydy_problem(n: int):
    import sympy as sp
    from sympy.physics.mechanics import dynamicsymbols
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

    t0 = time.perf_counter()
    kane = sympy_model(n, cart_force=True, joint_torques=False)
    M, F = kane.mass_matrix_full, kane.forcing_full
    t_derive = time.perf_counter() - t0
    t = dynamicsymbols._t
    consts = sorted((M.free_symbols | F.free_symbols) - {t}, key=str)
    return kane, M, F, consts, [sp.Function("F")(t)], t_derive


def bench_pydy(n: int, solver: str, generator: str, params: dict) -> dict:
    from pydy.codegen.ode_function_generators import generate_ode_function
    from scipy.integrate import odeint

    kane, M, F, consts, specified, t_derive = pydy_problem(n)
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        kw = {"tmp_dir": d} if generator == "cython" else {}
        rhs = generate_ode_function(F, kane.q, kane.u, consts, mass_matrix=M,
                                    specifieds=specified, generator=generator,
                                    linear_sys_solver=solver, **kw)
        t_codegen = time.perf_counter() - t0
        p = np.array([params[str(c)] for c in consts])
        y0, yd0 = initial_state(n)
        x0 = np.concatenate([y0, yd0])
        tt = np.array([0.0, T_END])
        args = (np.array([0.0]), p)
        # one output interval: mxstep must allow all the steps of 10 s
        kw_ode = {"rtol": TOL, "atol": TOL, "mxstep": 10**6}
        x, info = odeint(rhs, x0, tt, args=args, full_output=True, **kw_ode)
        x_ref = odeint(rhs, x0, tt, args=args, rtol=1e-12, atol=1e-12, mxstep=10**6)[-1]
    return {"derive": t_derive, "codegen": t_codegen,
            "run": lambda: odeint(rhs, x0, tt, args=args, **kw_ode),
            "nfev": int(info["nfe"][-1]), "steps": int(info["nst"][-1]), "rejected": None,
            "x_final": x[-1], "x_ref_odeint": x_ref}


# --- Pinocchio -----------------------------------------------------------------------------------
def bench_batched(name: str, system: jd.System, data: list[dict], n_states: int = 2000,
                  rounds: int = 15) -> dict:
    import pinocchio as pin

    eom = system.equations_of_motion()
    fn = numeric.lambdify(system, {"M": eom.M, "k": eom.k, "q": eom.q})
    model = chain_model(data)
    pdata = model.createData()
    rng = np.random.default_rng(1)
    Y = rng.uniform(-math.pi, math.pi, (n_states, system.f))
    YD = rng.uniform(-2, 2, (n_states, system.f))
    p = numeric.parameter_vector(system, None)
    out = np.empty((n_states, fn.size))
    y0, yd0, u0 = Y[0].copy(), YD[0].copy(), np.zeros(1)
    flat = np.empty(fn.size)

    def pin_loop() -> None:
        for i in range(n_states):
            pin.crba(model, pdata, Y[i])
            pin.nonLinearEffects(model, pdata, Y[i], YD[i])

    # interleaved rounds, best of each: a busy machine slows both alike
    t_batch = t_single = t_pin = math.inf
    for _ in range(rounds):
        t_batch = min(t_batch, best_of(lambda: fn.batch(Y, YD, 0.0, p, None, out=out),
                                       repeat=1, min_time=0.02) / n_states)
        t_single = min(t_single, best_of(lambda: fn.raw(y0, yd0, 0.0, p, u0, flat), repeat=1,
                                         min_time=0.01))
        t_pin = min(t_pin, best_of(pin_loop, repeat=1, min_time=0.02) / n_states)
    res = fn.batch(Y[:20], YD[:20], 0.0, p, None)
    err = 0.0
    for i in range(20):
        Mp = pin.crba(model, pdata, Y[i])
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        nle = pin.nonLinearEffects(model, pdata, Y[i], YD[i])
        err = max(err, np.abs(res["M"][i] - Mp).max(),
                  np.abs((res["k"][i] - res["q"][i])[:, 0] - nle).max())
    return {"name": name, "f": system.f, "batch_per_state": t_batch, "single_call": t_single,
            "pinocchio_per_call": t_pin, "max_difference": err}


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="*", default=[2, 4, 8, 12])
    ap.add_argument("--quick", action="store_true",
                    help="n = 2 and PyDy's lambdify backend only (smoke test)")
    ap.add_argument("--sympy-max-n", type=int, default=12)
    ap.add_argument("--no-pinocchio", action="store_true")
    ap.add_argument("--rounds", type=int, default=15, help="interleaved timing rounds")
    ap.add_argument("--json", type=str, default=None)
    args = ap.parse_args(argv)
    ns = [2] if args.quick else args.n
    t0 = time.perf_counter()
    integrator_library()
    print(f"integrator library (compiled once per machine, cached): "
          f"{time.perf_counter() - t0:.3f} s\n")
    report: dict = {"tolerance": TOL, "t_end": T_END, "pendulum": [], "batched": []}
    print(f"n-link pendulum on a cart, {T_END:g} s from the hanging position, rtol = atol = "
          f"{TOL:g}")
    hdr = (f"{'n':>2} {'tool':<32} {'derive s':>9} {'codegen s':>10} {'integrate ms':>13} "
           f"{'rhs evals':>10} {'steps':>6} {'rejected':>8} {'evals/step':>10} {'|x-x_ref|':>10} "
           f"{'speed-up':>9}")
    print(hdr)
    print("-" * len(hdr))
    for n in ns:
        J = bench_jourdain(n)
        params = J["system"].parameter_values
        x_ref = J["x_ref"]
        rows: list[tuple[str, dict[str, Any]]] = [("jourdain DOP853 (C loop)", J)]
        configs = [("lambdify", "numpy")] if args.quick else [("cython", "sympy"),
                                                               ("cython", "numpy")]
        skipped = []
        for gen, solver in configs:
            if solver == "sympy" and n > args.sympy_max_n:
                skipped.append(f"PyDy {gen}/{solver} (n > --sympy-max-n={args.sympy_max_n})")
                continue
            try:
                P = bench_pydy(n, solver, gen, params)
            except Exception as exc:  # noqa: BLE001 - a peer failing is reported, not fatal
                skipped.append(f"PyDy {gen}/{solver}: {type(exc).__name__}: {exc}")
                continue
            rows.append((f"PyDy {gen}/{solver} + odeint", P))
        pydy_rows = [r for _, r in rows[1:]]
        if pydy_rows:  # jourdain at the accuracy of the most accurate PyDy run
            target = min(float(np.abs(r["x_final"] - x_ref).max()) for r in pydy_rows)
            E = equal_accuracy(J, n, target)
            if E is not None:
                rows.insert(1, (f"jourdain DOP853, rtol={E['rtol']:g}", E))
        # interleaved rounds, best of each: a busy machine slows all tools alike
        for _, tool in rows:
            tool["integrate"] = math.inf
        for _ in range(args.rounds):
            for _, tool in rows:
                tool["integrate"] = min(tool["integrate"],
                                        best_of(tool["run"], repeat=1, min_time=0.05))
        pydy_times = [r["integrate"] for r in pydy_rows]
        fastest = min(pydy_times) if pydy_times else math.nan
        entry: dict[str, Any] = {"n": n, "tools": {}}
        for label, r in rows:
            d = float(np.abs(r["x_final"] - x_ref).max())
            speed = fastest / r["integrate"]
            rej = "-" if r["rejected"] is None else str(r["rejected"])
            per_step = r["nfev"] / (r["steps"] + (r["rejected"] or 0))
            print(f"{n:>2} {label:<32} {r['derive']:>9.3f} {r['codegen']:>10.3f} "
                  f"{1e3 * r['integrate']:>13.3f} {r['nfev']:>10d} {r['steps']:>6d} {rej:>8} "
                  f"{per_step:>10.2f} {d:>10.2e} {speed:>8.1f}x")
            entry["tools"][label] = {k: (float(v) if isinstance(v, (int, float, np.number))
                                         else None)
                                     for k, v in r.items() if k in ("derive", "codegen",
                                                                    "integrate", "nfev",
                                                                    "steps", "rejected", "rtol")}
            entry["tools"][label]["final_state_error"] = d
        odeint_refs = [r["x_ref_odeint"] for r in pydy_rows]
        if odeint_refs:
            dref = float(np.abs(odeint_refs[0] - x_ref).max())
            print(f"   reference (jourdain 1e-12) vs odeint 1e-12 on PyDy's function: {dref:.2e}")
            entry["reference_check"] = dref
        print(f"   jourdain code generation from a warm cache: {J['codegen_cached']:.4f} s")
        per_eval = (J["integrate"] - J["setup"]) / J["nfev"]
        print(f"   jourdain per right-hand side: {1e9 * per_eval:.0f} ns, of which M, k, q "
              f"({J['mkq_path']} code) {1e9 * J['mkq_per_state']:.0f} ns; the rest is the LDLᵀ "
              f"solve, the Runge–Kutta stages and the dense output; set-up and results "
              f"{1e3 * J['setup']:.3f} ms per run")
        entry["jourdain_per_rhs_s"] = per_eval
        entry["jourdain_mkq_per_state_s"] = J["mkq_per_state"]
        entry["jourdain_setup_s"] = J["setup"]
        for sk in skipped:
            print(f"   skipped: {sk}")
        report["pendulum"].append(entry)
    if not args.no_pinocchio:
        try:
            import pinocchio  # noqa: F401
        except ImportError:
            print("\nPinocchio not installed: batched comparison skipped")
        else:
            print("\nBatched M, k, q evaluation per state vs Pinocchio crba + nonLinearEffects "
                  "per call")
            print(f"{'model':<22} {'f':>3} {'batch us/state':>15} {'single call us':>15} "
                  f"{'pinocchio us':>13} {'ratio':>7} {'max diff':>9}")
            cases = [("spatial_chain(6)", spatial_chain(6), spatial_chain_data(6))]
            cases.append(("7-joint arm", robot_arm(), robot_arm_data()))
            for name, system, data in cases:
                b = bench_batched(name, system, data, rounds=args.rounds)
                ratio = b["pinocchio_per_call"] / b["batch_per_state"]
                print(f"{name:<22} {b['f']:>3} {1e6 * b['batch_per_state']:>15.3f} "
                      f"{1e6 * b['single_call']:>15.3f} {1e6 * b['pinocchio_per_call']:>13.3f} "
                      f"{ratio:>6.1f}x {b['max_difference']:>9.1e}")
                report["batched"].append({**b, "ratio": ratio})
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))
    return report


if __name__ == "__main__":
    main()
