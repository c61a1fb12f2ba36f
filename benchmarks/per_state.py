"""Cost per state of jourdain's compiled recursion beside Pinocchio's, in one run (issue 13).

For each model (default ``spatial_chain(3)``, f = 6; ``spatial_chain(24)``, f = 48;
``random_tree(23)``, f = 47) and the same ``--states`` random states (y uniform in (-π, π),
ẏ in (-3, 3)), Pinocchio built from the same data (``benchmarks/pinocchio_models.py``):

(a) **M and the bias forces**: jourdain's ``fn.batch`` (M, k, q; one C call for all states;
    ``fn`` = :func:`jourdain.numeric.mkq_function`, the integrator's function) against
    ``pin.crba`` + ``pin.nonLinearEffects`` called from a Python loop over the states;
(b) **ÿ**: ``fn.dynamics`` against ``pin.aba`` (τ = 0). ``fn.dynamics`` computes every joint
    wrench as well: jourdain's ÿ alone (the integrator's ``jd_accel``) has no batched entry
    point, so this charges jourdain for more work than Pinocchio's;
(c) **every joint wrench**: ``fn.dynamics`` against ``pin.rnea`` at a = ÿ, reading ``data.f``
    of each joint into an array (given ÿ), and against ``pin.aba`` + ``pin.rnea`` + reading
    (from the state, which is what ``fn.dynamics`` does).

Pinocchio is driven from Python, one call per state, so its times include the interpreter's
loop and Boost.Python's argument conversion; jourdain's batch loop runs in C. To show how much
that is, the run also times a bare loop over the same rows, and the same Pinocchio calls on a
one-joint model (the per-call floor: conversion, dispatch, a trivial algorithm), and prints
Pinocchio's times net of that floor — an estimate of its C++ cost, the fair number for a user
calling it from C++. jourdain one state per Python call (``fn.raw``) is shown for the same
reason. Ratios are jourdain / Pinocchio: below 1, jourdain is faster.

Timing: rounds interleave all contenders (A B C … A B C …), best of ``--rounds`` per
contender, each measurement one pass over all states. The numbers are checked in the same
run (relative to the largest entry): M against CRBA, k − q against the nonlinear effects, ÿ
against ABA (accurate to about cond(M)·eps, so the largest cond(M) is printed too), and the
wrenches against RNEA's ``data.f`` at jourdain's ÿ.

    .venv/bin/python benchmarks/per_state.py                       # the three default models
    .venv/bin/python benchmarks/per_state.py --chain 3 --tree      # one chain, no tree
    .venv/bin/python benchmarks/per_state.py --quick               # spatial_chain(3), 100 states
    .venv/bin/python benchmarks/per_state.py --json out.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CHAINS, TREES = (3, 24), (23,)


def interleaved(fns: dict[str, Callable[[], object]], rounds: int) -> dict[str, float]:
    """Best wall time of each callable over ``rounds`` rounds that run them all in turn."""
    best = dict.fromkeys(fns, math.inf)
    for _ in range(rounds):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            best[name] = min(best[name], time.perf_counter() - t0)
    return best


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    """max|a − b| / max|b| (per state along the first axis, the largest)."""
    a, b = a.reshape(len(a), -1), b.reshape(len(b), -1)
    return float((np.abs(a - b).max(axis=1) / np.abs(b).max(axis=1)).max())


def pinocchio_floor(n_states: int, rounds: int) -> dict[str, float]:
    """Seconds per state of a bare Python loop over ``n_states`` rows, and of each Pinocchio
    call of the benchmark on a one-joint model (the per-call floor of calling from Python)."""
    import pinocchio as pin

    from benchmarks.pinocchio_models import chain_model
    from jourdain.models import spatial_chain_data

    model = chain_model(spatial_chain_data(1))
    data = model.createData()
    Q = np.random.default_rng(0).uniform(-1, 1, (n_states, 1))
    Z = np.zeros(1)

    def bare() -> None:
        for i in range(n_states):
            Q[i], Q[i]

    def crba_nle() -> None:
        for i in range(n_states):
            pin.crba(model, data, Q[i])
            pin.nonLinearEffects(model, data, Q[i], Q[i])

    def aba() -> None:
        for i in range(n_states):
            pin.aba(model, data, Q[i], Q[i], Z)

    def rnea() -> None:
        for i in range(n_states):
            pin.rnea(model, data, Q[i], Q[i], Q[i])

    best = interleaved({"bare": bare, "crba_nle": crba_nle, "aba": aba, "rnea": rnea}, rounds)
    return {k: v / n_states for k, v in best.items()}


def case(kind: str, n: int, seed: int = 0, n_states: int = 1000, rounds: int = 7,
         floor: dict[str, float] | None = None) -> dict:
    """Timings (seconds per state) and agreement for one model; see the module docstring."""
    import pinocchio as pin

    from benchmarks.crosscheck import build
    from jourdain.numeric import dynamics_function, mkq_function

    system, model, index = build(kind, n, seed)
    f = system.f
    fn = mkq_function(system)
    # small models: mkq_function is the symbolic projection's code, without joint wrenches
    fd = fn if fn.n_bodies else dynamics_function(system)
    data = model.createData()
    rng = np.random.default_rng(1)
    Y = rng.uniform(-np.pi, np.pi, (n_states, f))
    YD = rng.uniform(-3.0, 3.0, (n_states, f))
    p = np.array(list(system.parameter_values.values()))
    u = np.zeros(max(len(system.inputs), 1))
    # Pinocchio's order, one contiguous row per state (the loops only index rows)
    Qp = np.ascontiguousarray(np.array([index.to_pinocchio(y) for y in Y]))
    Vp = np.ascontiguousarray(np.array([index.to_pinocchio(v) for v in YD]))
    tau0 = np.zeros(model.nv)
    joints = [int(j) for j in index.joint]
    buf = np.zeros((n_states, fn.size))  # touched: no first-touch page faults in the timing
    flat = np.zeros(fn.size)
    res = {k: v.copy() for k, v in fn.batch(Y, YD, 0.0, p, None, out=buf).items()}
    ydd, W = fd.dynamics(Y, YD, 0.0, p, None)
    Ap = np.ascontiguousarray(np.array([index.to_pinocchio(a) for a in ydd]))

    # --- agreement, every state ---
    M_pin = np.empty((n_states, f, f))
    nle = np.empty((n_states, f))
    aba = np.empty((n_states, f))
    W_pin = np.empty_like(W)
    for i in range(n_states):
        Mp = pin.crba(model, data, Qp[i])
        M_pin[i] = index.from_pinocchio(np.triu(Mp) + np.triu(Mp, 1).T)
        nle[i] = index.from_pinocchio(pin.nonLinearEffects(model, data, Qp[i], Vp[i]))
        aba[i] = index.from_pinocchio(pin.aba(model, data, Qp[i], Vp[i], tau0))
        pin.rnea(model, data, Qp[i], Vp[i], Ap[i])
        W_pin[i] = [data.f[j].vector for j in joints]
    check = {"M": _rel(res["M"], M_pin), "bias": _rel(res["k"][..., 0] - res["q"][..., 0], nle),
             "ydd": _rel(ydd, aba), "wrenches": _rel(W, W_pin),
             "cond_M_max": float(np.linalg.cond(M_pin).max())}

    # --- timing ---
    def pin_crba_nle() -> None:
        for i in range(n_states):
            pin.crba(model, data, Qp[i])
            pin.nonLinearEffects(model, data, Qp[i], Vp[i])

    def pin_aba() -> None:
        for i in range(n_states):
            pin.aba(model, data, Qp[i], Vp[i], tau0)

    def pin_rnea() -> None:
        for i in range(n_states):
            pin.rnea(model, data, Qp[i], Vp[i], Ap[i])

    def pin_rnea_read() -> None:
        for i in range(n_states):
            pin.rnea(model, data, Qp[i], Vp[i], Ap[i])
            np.array([data.f[j].vector for j in joints])

    def pin_aba_rnea_read() -> None:
        for i in range(n_states):
            a = pin.aba(model, data, Qp[i], Vp[i], tau0)
            pin.rnea(model, data, Qp[i], Vp[i], a)
            np.array([data.f[j].vector for j in joints])

    def jd_raw() -> None:
        for i in range(n_states):
            fn.raw(Y[i], YD[i], 0.0, p, u, flat)

    fns: dict[str, Callable[[], object]] = {
        "jd_batch": lambda: fn.batch(Y, YD, 0.0, p, None, out=buf),
        "pin_crba_nle": pin_crba_nle,
        "jd_dynamics": lambda: fd.dynamics(Y, YD, 0.0, p, None),
        "pin_aba": pin_aba,
        "pin_rnea": pin_rnea,
        "pin_rnea_read": pin_rnea_read,
        "pin_aba_rnea_read": pin_aba_rnea_read,
        "jd_raw": jd_raw,
    }
    if fd is not fn:  # the recursion's M, k, q too, where the integrator's is the symbolic code
        rbuf = np.zeros((n_states, fd.size))
        fns["jd_batch_recursion"] = lambda: fd.batch(Y, YD, 0.0, p, None, out=rbuf)
    best = {k: v / n_states for k, v in interleaved(fns, rounds).items()}
    return {"kind": kind, "n": n, "seed": seed, "f": f, "bodies": len(system.bodies),
            "mkq_path": "recursion" if fn.n_bodies else "symbolic", "states": n_states,
            "rounds": rounds, "times": best, "check": check, "floor": floor or {}}


def name_of(r: dict) -> str:
    return (f"spatial_chain({r['n']})" if r["kind"] == "chain"
            else f"random_tree({r['n']}, {r['seed']})")


def report(r: dict) -> dict[str, float]:
    """Print one model's table; return its ratios jourdain / Pinocchio."""
    t, fl, c = r["times"], r["floor"], r["check"]
    us = 1e6
    # Pinocchio's C++ cost, estimated: its time less the per-call floor and the reading of data.f
    read = t["pin_rnea_read"] - t["pin_rnea"]
    f_cn, f_aba, f_rnea = (fl.get(k, math.nan) for k in ("crba_nle", "aba", "rnea"))
    jd = "fn.dynamics (ÿ + W)"
    # (quantity, jourdain, its key, Pinocchio, its key, Pinocchio net of the floor)
    rows = [
        ("(a) M + bias", "fn.batch (M, k, q)", "jd_batch", "crba + nonLinearEffects",
         "pin_crba_nle", t["pin_crba_nle"] - f_cn),
        ("(b) ÿ", jd, "jd_dynamics", "aba", "pin_aba", t["pin_aba"] - f_aba),
        ("(c) wrenches given ÿ", jd, "jd_dynamics", "rnea + read data.f", "pin_rnea_read",
         t["pin_rnea"] - f_rnea),
        ("(c) wrenches given ÿ", jd, "jd_dynamics", "rnea alone", "pin_rnea",
         t["pin_rnea"] - f_rnea),
        ("(c) ÿ + wrenches", jd, "jd_dynamics", "aba + rnea + read data.f", "pin_aba_rnea_read",
         t["pin_aba_rnea_read"] - read - f_aba - f_rnea),
    ]
    print(f"\n### {name_of(r)}: f = {r['f']}, {r['bodies']} bodies; integrator's M, k, q: "
          f"{r['mkq_path']}; {r['states']} states, best of {r['rounds']} interleaved rounds\n")
    head = (f"| {'quantity':<21} | {'jourdain':<20} | {'µs/state':>8} "
            f"| {'Pinocchio (Python loop)':<25} | {'µs/state':>8} | {'ratio':>5} "
            f"| {'net of floor µs':>15} | {'ratio':>5} |")
    print(head)
    print("|" + "|".join("-" * (len(x)) if i in (0, 1, 3) else "-" * (len(x) - 1) + ":"
                         for i, x in enumerate(head.strip().strip("|").split("|"))) + "|")
    ratios: dict[str, float] = {}
    for label, jname, jkey, pname, pkey, net in rows:
        j, pn = t[jkey], t[pkey]
        ratios[pkey], ratios[pkey + "_net"] = j / pn, j / net
        print(f"| {label:<21} | {jname:<20} | {us * j:>8.2f} | {pname:<25} | {us * pn:>8.2f} "
              f"| {j / pn:>5.2f} | {us * net:>15.2f} | {j / net:>5.2f} |")
    print(f"\nreading data.f into an array from Python: {us * read:.2f} µs/state; jourdain one "
          f"state per Python call (fn.raw, M, k, q): {us * t['jd_raw']:.2f} µs"
          + (f"; the recursion's fn.batch (M, k, q): {us * t['jd_batch_recursion']:.2f} µs/state"
             if "jd_batch_recursion" in t else ""))
    print(f"agreement (max relative difference over all states): M {c['M']:.1e}, "
          f"k − q vs nle {c['bias']:.1e}, ÿ vs aba {c['ydd']:.1e} (largest cond(M) "
          f"{c['cond_M_max']:.1e}), wrenches vs rnea data.f {c['wrenches']:.1e}")
    return ratios


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--chain", type=int, nargs="*", default=None,
                    help=f"spatial_chain lengths (default {' '.join(map(str, CHAINS))})")
    ap.add_argument("--tree", type=int, nargs="*", default=None,
                    help=f"random_tree sizes (default {' '.join(map(str, TREES))})")
    ap.add_argument("--seed", type=int, default=0, help="model seed (default 0)")
    ap.add_argument("--states", type=int, default=1000, help="states (default 1000)")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds, best taken (7)")
    ap.add_argument("--quick", action="store_true",
                    help="spatial_chain(3) only, 100 states, 2 rounds (a smoke test)")
    ap.add_argument("--json", type=Path, help="also write the results to this JSON file")
    a = ap.parse_args(argv)
    chains = CHAINS if a.chain is None else a.chain
    trees = TREES if a.tree is None else a.tree
    if a.quick:
        chains = (3,) if a.chain is None else a.chain
        trees = () if a.tree is None else a.tree
        a.states, a.rounds = min(a.states, 100), min(a.rounds, 2)
    floor = pinocchio_floor(a.states, a.rounds)
    print("Pinocchio from Python, per state: bare loop over the rows "
          f"{1e6 * floor['bare']:.3f} µs; on a one-joint model (the per-call floor) "
          f"crba + nonLinearEffects {1e6 * floor['crba_nle']:.2f} µs, aba "
          f"{1e6 * floor['aba']:.2f} µs, rnea {1e6 * floor['rnea']:.2f} µs. 'net of floor' "
          "subtracts these (and the reading of data.f) from Pinocchio's times; jourdain's "
          "batch runs its loop in C and pays no such cost per state.")
    results = []
    for kind, ns in (("chain", chains), ("tree", trees)):
        for n in ns:
            r = case(kind, n, a.seed, a.states, a.rounds, floor)
            r["ratios"] = report(r)
            results.append(r)
    if a.json:
        a.json.write_text(json.dumps(results, indent=2))
    return results


if __name__ == "__main__":
    main()
