"""Derivation of the equations of motion: jourdain against sympy.physics.mechanics, in one run.

Family 1: ``n_link_pendulum_on_cart(n)``, jourdain against sympy's ``KanesMethod`` on sympy's own
model (``sympy.physics.mechanics.models.n_link_pendulum_on_cart``).
Family 2: ``spatial_chain(n)``, jourdain against sympy's ``System``/joints API on the same data
(relative joint coordinates; see ``benchmarks/sympy_models.py``).

Reported per case: derivation times (best of ``--repeat`` for jourdain, one run for sympy, each
sympy case in a subprocess with a time limit), their ratio, and the operation counts of M and of the
forcing vector q - k after common-subexpression elimination, both counted by the same function
(``jourdain.symbolic.count_ops``: graph CSE, n-ary + and * count n-1) on SymEngine versions of
both results. Where sympy finishes, both results are also compared numerically at a random state.

    python benchmarks/derivation.py            # the full run (several minutes: sympy is slow)
    python benchmarks/derivation.py --quick    # n = 1, 2 only
"""

from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import sys
import time
from pathlib import Path

import numpy as np
import symengine as se

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from jourdain.models import n_link_pendulum_on_cart, spatial_chain  # noqa: E402
from jourdain.symbolic import count_ops  # noqa: E402


def _jourdain_case(family: str, n: int, repeat: int) -> dict:
    make = n_link_pendulum_on_cart if family == "pendulum" else spatial_chain
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        eom = make(n).equations_of_motion()
        best = min(best, time.perf_counter() - t0)
    return {"time": best, "ops_M": count_ops(eom.M.entries()),
            "ops_f": count_ops(eom.forcing.entries()),
            "eom": eom}


def _sympy_worker(family: str, n: int, check: bool, out: mp.Queue) -> None:
    import sympy as sp

    t0 = time.perf_counter()
    if family == "pendulum":
        from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

        kane = sympy_model(n, cart_force=True)
        M, F = kane.mass_matrix, kane.forcing
        q, u = list(kane.q), list(kane.u)
        syms = {str(s): s for s in M.free_symbols | F.free_symbols if isinstance(s, sp.Symbol)}
    else:
        from benchmarks.sympy_models import spatial_chain_sympy

        system, q, syms = spatial_chain_sympy(n)
        M, F = system.mass_matrix, system.forcing
        u = list(system.u)
    elapsed = time.perf_counter() - t0
    # count sympy's results on plain symbols, as jourdain's: q0(t) -> q0, F(t) -> F
    funcs = {x for x in M.atoms(sp.Function) | F.atoms(sp.Function)
             if isinstance(x, sp.core.function.AppliedUndef)} | set(q) | set(u)
    plain = {x: sp.Symbol(x.func.__name__) for x in funcs}
    M, F = M.xreplace(plain), F.xreplace(plain)
    q, u = [plain[x] for x in q], [plain[x] for x in u]
    res = {"time": elapsed,
           "ops_M": count_ops([se.sympify(e) for e in M]),
           "ops_f": count_ops([se.sympify(e) for e in F])}
    if check:
        Fin = sp.Symbol("F")
        make = n_link_pendulum_on_cart if family == "pendulum" else spatial_chain
        pv = make(n).parameter_values
        names = sorted(k for k in syms if k in pv)  # t appears only inside q(t), u(t)
        args = [*q, *u, *(syms[k] for k in names), Fin]
        res["M_f"] = (sp.lambdify(args, M, cse=True), sp.lambdify(args, F, cse=True), names)
        rng = np.random.default_rng(7)
        yv, ydv = rng.uniform(-1, 1, len(q)), rng.uniform(-1, 1, len(q))
        res["state"] = (yv, ydv)
        vals = [*yv, *ydv, *(pv[k] for k in names), 0.0]
        res["M_val"] = np.array(res["M_f"][0](*vals), float)
        res["F_val"] = np.array(res["M_f"][1](*vals), float).ravel()
        del res["M_f"]
    out.put(res)


def _sympy_case(family: str, n: int, timeout: float, check: bool) -> dict | None:
    # spawn: a fresh interpreter per case (fork after threads were started can hang, and sympy
    # would start with the caches of earlier cases)
    ctx = mp.get_context("spawn")
    queue: mp.Queue = ctx.Queue()
    proc = ctx.Process(target=_sympy_worker, args=(family, n, check, queue))
    proc.start()
    t0 = time.perf_counter()
    try:
        res = queue.get(timeout=timeout)
    except Exception:  # noqa: BLE001 - queue.Empty: the time limit was reached
        res = None
    proc.join(max(0.0, timeout - (time.perf_counter() - t0)) if res else 0.1)
    if proc.is_alive():
        proc.terminate()
        proc.join()
    return res


def _agreement(family: str, n: int, ours: dict, theirs: dict) -> float | None:
    if "M_val" not in theirs:
        return None
    yv, ydv = theirs["state"]
    system = ours["eom"].system
    inputs = {name: 0.0 for name in system.input_names} or None
    out = system.evaluate(yv, ydv, inputs=inputs)
    eM = np.abs(out["M"] - theirs["M_val"]).max() / np.abs(theirs["M_val"]).max()
    eF = np.abs(out["q"] - out["k"] - theirs["F_val"]).max() / np.abs(theirs["F_val"]).max()
    return float(max(eM, eF))


def run(cases: dict[str, list[int]], timeout: float, repeat: int, check_upto: int) -> list[dict]:
    rows = []
    for family, ns in cases.items():
        for n in ns:
            ours = _jourdain_case(family, n, repeat)
            theirs = _sympy_case(family, n, timeout, check=n <= check_upto)
            row = {"family": family, "n": n, "f": ours["eom"].system.f,
                   "jourdain_s": ours["time"], "jourdain_ops_M": ours["ops_M"],
                   "jourdain_ops_f": ours["ops_f"],
                   "sympy_s": theirs["time"] if theirs else None,
                   "sympy_ops_M": theirs["ops_M"] if theirs else None,
                   "sympy_ops_f": theirs["ops_f"] if theirs else None,
                   "max_rel_diff": _agreement(family, n, ours, theirs) if theirs else None}
            rows.append(row)
            _print_row(row, timeout)
    return rows


def _print_row(r: dict, timeout: float) -> None:
    sym = f"{r['sympy_s']:9.3f}" if r["sympy_s"] is not None else f" >{timeout:6.0f}s"
    ratio = f"{r['sympy_s'] / r['jourdain_s']:8.0f}x" if r["sympy_s"] is not None else "        -"
    so = (f"{r['sympy_ops_M']:>9} {r['sympy_ops_f']:>9}" if r["sympy_ops_M"] is not None
          else f"{'-':>9} {'-':>9}")
    diff = f"{r['max_rel_diff']:.1e}" if r["max_rel_diff"] is not None else "-"
    print(f"{r['family']:9} {r['n']:3d} {r['f']:3d} {r['jourdain_s']:10.4f} {sym} {ratio} "
          f"{r['jourdain_ops_M']:>9} {r['jourdain_ops_f']:>9} {so} {diff:>8}", flush=True)


def _growth(rows: list[dict], family: str) -> float | None:
    pts = [(r["n"], r["jourdain_s"]) for r in rows if r["family"] == family and r["n"] >= 4]
    if len(pts) < 2:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="n = 1, 2 only (a smoke test)")
    ap.add_argument("--timeout", type=float, default=600.0, help="time limit per sympy case [s]")
    ap.add_argument("--repeat", type=int, default=3, help="jourdain runs per case (best taken)")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    if args.quick:
        cases = {"pendulum": [1, 2], "chain": [2]}
    else:
        cases = {"pendulum": [1, 2, 4, 8, 16, 32], "chain": [2, 4, 8, 16]}
    print("family      n   f  jourdain[s]  sympy[s]    ratio   ops M(j)  ops q-k(j)  "
          "ops M(s)  ops q-k(s)  max rel diff")
    rows = run(cases, args.timeout, args.repeat, check_upto=4)
    for fam in cases:
        g = _growth(rows, fam)
        if g is not None:
            print(f"jourdain derivation time grows like n^{g:.2f} on {fam} (n >= 4)")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
