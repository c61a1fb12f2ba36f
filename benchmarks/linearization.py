"""Linearization: jourdain against sympy.physics.mechanics' ``KanesMethod.linearize``, in one run.

Model: ``n_link_pendulum_on_cart(n)`` (sympy's own model for sympy, jourdain's equal model for
jourdain), n = 1, 2, 4, 6. Reported per case, each sympy stage in a subprocess with a time limit
(``--timeout``, "timeout" when reached):

* *general form*: jourdain's ``linearization_general`` (M̃, P, Q, h, B as functions of the state,
  from the equations of motion) against sympy's ``Linearizer.linearize()`` (M, A, B as functions
  of the state; ``KanesMethod.to_linearizer`` included);
* *operating point*: the upright equilibrium, symbolic in the parameters: jourdain's
  ``linearization`` (M̃, P, Q, B: M is never inverted) against
  ``KanesMethod.linearize(A_and_B=True, op_point=...)`` (A, B: sympy inverts M symbolically);
  operation counts of both results after CSE, counted by the same function
  (``jourdain.symbolic.count_ops`` on SymEngine versions), and as trees (without CSE:
  ``jourdain.graph.tree_ops``);
* the numeric A, B at the default parameters from both, and their largest relative difference.

Derivation of the equations of motion is timed separately (it is the same work in both tools'
pipelines: sympy's model function forms Kane's equations). A last section times the numeric
eigen-analysis of ``spatial_chain(16)`` about an equilibrium, derivation included.

    python benchmarks/linearization.py             # n = 1, 2, 4, 6 (a few minutes)
    python benchmarks/linearization.py --quick     # n = 1, 2
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

import jourdain as jd  # noqa: E402
from jourdain.graph import tree_ops  # noqa: E402
from jourdain.models import n_link_pendulum_on_cart, spatial_chain  # noqa: E402
from jourdain.stages.linearization import linearization_general  # noqa: E402
from jourdain.symbolic import count_ops  # noqa: E402


def _best(fn, repeat: int) -> tuple[float, object]:
    best, out = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _jourdain_case(n: int, repeat: int) -> dict:
    t_eom, eom = _best(lambda: n_link_pendulum_on_cart(n).equations_of_motion(), repeat)
    system = eom.system
    upright = {c: 0 for c in system.coordinate_names}
    t_gen, gen = _best(lambda: linearization_general(eom), repeat)
    t_op, lin = _best(lambda: jd.linearization(eom, upright), repeat)
    t_ab, ss = _best(lambda: jd.state_space(lin), repeat)

    def ops(obj) -> int:
        return count_ops([*obj.M_tilde.entries(), *obj.P.entries(), *obj.Q.entries(),
                          *obj.B.entries()])

    tree = sum(tree_ops(e) for m in (lin.M_tilde, lin.P, lin.Q, lin.B) for e in m.entries())
    return {"eom_s": t_eom, "general_s": t_gen, "op_s": t_op, "AB_s": t_ab,
            "ops_general": ops(gen), "ops_op": ops(lin), "ops_op_tree": tree,
            "A": ss.A, "B": ss.B,
            "f": system.f, "parameters": system.parameter_values}


def _sympy_worker(stage: str, n: int, params: dict, out: mp.Queue) -> None:
    import sympy as sp
    from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

    t0 = time.perf_counter()
    kane = sympy_model(n, cart_force=True)
    res: dict = {"eom_s": time.perf_counter() - t0}
    if stage == "general":
        t0 = time.perf_counter()
        linearizer = kane.to_linearizer()
        M, A, B = linearizer.linearize()
        res["time"] = time.perf_counter() - t0
        res["ops"] = _sympy_ops([*M, *A, *B])
    else:
        op = {**{q: 0 for q in kane.q}, **{u: 0 for u in kane.u}}
        t0 = time.perf_counter()
        A, B, _ = kane.linearize(A_and_B=True, op_point=op, new_method=True)
        res["time"] = time.perf_counter() - t0
        res["ops"] = _sympy_ops([*A, *B])
        res["ops_tree"] = _sympy_ops([*A, *B], tree=True)
        syms = sorted(A.free_symbols | B.free_symbols, key=str)
        names = [str(s) for s in syms]
        f_AB = sp.lambdify(syms, [A, B], cse=True)
        A_val, B_val = f_AB(*(params[k] for k in names))
        res["A"], res["B"] = np.array(A_val, float), np.array(B_val, float)
    out.put(res)


def _sympy_ops(entries: list, tree: bool = False) -> int:
    import sympy as sp

    # count on plain symbols, as for jourdain: q0(t) -> q0
    funcs = set().union(*(e.atoms(sp.Function) for e in entries)) if entries else set()
    plain = {x: sp.Symbol(x.func.__name__) for x in funcs
             if isinstance(x, sp.core.function.AppliedUndef)}
    exprs = [se.sympify(e.xreplace(plain)) for e in entries]
    return sum(tree_ops(e) for e in exprs) if tree else count_ops(exprs)


def _sympy_case(stage: str, n: int, params: dict, timeout: float) -> dict | None:
    ctx = mp.get_context("fork")
    queue: mp.Queue = ctx.Queue()
    proc = ctx.Process(target=_sympy_worker, args=(stage, n, params, queue))
    proc.start()
    try:
        res = queue.get(timeout=timeout)
    except Exception:  # noqa: BLE001 - queue.Empty: the time limit was reached
        res = None
    proc.join(1.0 if res else 0.1)
    if proc.is_alive():
        proc.terminate()
        proc.join()
    return res


def _fmt(x: float | None, timeout: float) -> str:
    return f"{x:9.4f}" if x is not None else f"{'timeout':>9}"


def run(ns: list[int], timeout: float, repeat: int) -> list[dict]:
    rows = []
    print("  n   f | eom[s] jourdain  sympy | general form [s]: jourdain   sympy   ratio | "
          "operating point [s]: jourdain   sympy   ratio | ops general j/s | ops op-point j/s "
          "| A,B rel diff")
    for n in ns:
        ours = _jourdain_case(n, repeat)
        gen = _sympy_case("general", n, ours["parameters"], timeout)
        op = _sympy_case("op", n, ours["parameters"], timeout)
        diff = None
        if op is not None:
            dA = np.abs(ours["A"] - op["A"]).max() / np.abs(op["A"]).max()
            dB = np.abs(ours["B"] - op["B"]).max() / np.abs(op["B"]).max()
            diff = float(max(dA, dB))
        sym_eom = (gen or op or {}).get("eom_s")
        row = {"n": n, "f": ours["f"], "jourdain_eom_s": ours["eom_s"],
               "sympy_eom_s": sym_eom,
               "jourdain_general_s": ours["general_s"],
               "sympy_general_s": gen["time"] if gen else None,
               "jourdain_op_s": ours["op_s"], "jourdain_AB_numeric_s": ours["AB_s"],
               "sympy_op_s": op["time"] if op else None,
               "jourdain_ops_general": ours["ops_general"],
               "sympy_ops_general": gen["ops"] if gen else None,
               "jourdain_ops_op": ours["ops_op"], "sympy_ops_op": op["ops"] if op else None,
               "jourdain_ops_op_tree": ours["ops_op_tree"],
               "sympy_ops_op_tree": op["ops_tree"] if op else None,
               "AB_max_rel_diff": diff}
        rows.append(row)
        dtext = f"{diff:.1e}" if diff is not None else "-"
        rg = (f"{row['sympy_general_s'] / row['jourdain_general_s']:7.0f}x"
              if gen else f"{'-':>8}")
        ro = f"{row['sympy_op_s'] / row['jourdain_op_s']:7.0f}x" if op else f"{'-':>8}"
        print(f"{n:3d} {ours['f']:3d} | {ours['eom_s']:8.4f} {_fmt(sym_eom, timeout)} | "
              f"{ours['general_s']:26.4f} {_fmt(row['sympy_general_s'], timeout)} {rg} | "
              f"{ours['op_s']:29.4f} {_fmt(row['sympy_op_s'], timeout)} {ro} | "
              f"{ours['ops_general']:>7}/{row['sympy_ops_general'] or '-':<8} | "
              f"{ours['ops_op']:>7}/{row['sympy_ops_op'] or '-':<8} | {dtext}", flush=True)
    print("operation counts at the operating point without CSE (as trees), jourdain M̃,P,Q,B / "
          "sympy A,B: " + ", ".join(
              f"n={r['n']}: {r['jourdain_ops_op_tree']}/{r['sympy_ops_op_tree'] or '-'}"
              for r in rows))
    return rows


def chain_eigen(n: int = 16, repeat: int = 3) -> dict:
    """Eigen-analysis of spatial_chain(n) about an equilibrium, derivation included."""
    system = spatial_chain(n)
    t0 = time.perf_counter()
    # body 1 and the rest turned to hang down; "stable": downhill into the hanging equilibrium
    eq = jd.find_equilibrium(system, {"q1": np.pi}, method="stable")
    t_eq = time.perf_counter() - t0

    def numeric() -> tuple:
        s = spatial_chain(n)
        lin = jd.linearize_numeric(s, eq)
        ss = jd.state_space(lin)
        return ss, jd.modes(ss), jd.stability(ss)

    def symbolic() -> tuple:
        s = spatial_chain(n)
        lin = s.linearize(eq)
        ss = jd.state_space(lin)
        return ss, jd.modes(ss), jd.stability(ss)

    t_num, (ss_num, m_num, st) = _best(numeric, repeat)
    t_sym, (ss_sym, _, _) = _best(symbolic, 1)
    diff = max(float(np.abs(getattr(ss_num, k) - getattr(ss_sym, k)).max()
                     / max(1.0, np.abs(getattr(ss_sym, k)).max())) for k in ("M_tilde", "P", "Q"))
    # M̃ against the separately compiled equations of motion at the equilibrium
    M_ref = system.evaluate(eq.y, np.zeros(system.f))["M"]
    diff = max(diff, float(np.abs(ss_num.M_tilde - M_ref).max() / np.abs(M_ref).max()))
    return {"n": n, "f": system.f, "equilibrium_s": t_eq, "numeric_path_s": t_num,
            "symbolic_path_s": t_sym, "matrix_rel_diff": diff, "verdict": st.verdict,
            "reason": st.reason,
            "lowest_nonzero_hz": float(np.min(m_num.frequencies_hz[m_num.frequencies_hz > 1e-3]))}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="n = 1, 2 only, no chain")
    ap.add_argument("--timeout", type=float, default=60.0, help="limit per sympy stage [s]")
    ap.add_argument("--repeat", type=int, default=3, help="jourdain runs per case (best taken)")
    ap.add_argument("--json", type=Path, help="also write the results to this JSON file")
    args = ap.parse_args(argv)
    ns = [1, 2] if args.quick else [1, 2, 4, 6]
    rows = run(ns, args.timeout, args.repeat)
    result: dict = {"pendulum_on_cart": rows}
    if not args.quick:
        c = chain_eigen(16, args.repeat)
        result["spatial_chain"] = c
        print(f"\nspatial_chain({c['n']}) (f = {c['f']}) about an equilibrium (found in "
              f"{c['equilibrium_s']:.1f} s, not counted):\n"
              f"  derivation + numeric linearization + eigen-analysis + verdict: "
              f"{c['numeric_path_s']:.3f} s (best of {args.repeat})\n"
              f"  the same through the symbolic M_tilde, P, Q: {c['symbolic_path_s']:.3f} s; "
              f"M_tilde, P, Q of both paths (and M of System.evaluate) agree to "
              f"{c['matrix_rel_diff']:.1e}\n"
              f"  lowest non-zero natural frequency {c['lowest_nonzero_hz']:.4f} Hz\n"
              f"  verdict: {c['verdict']}: {c['reason']}")
    if args.json:
        args.json.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
