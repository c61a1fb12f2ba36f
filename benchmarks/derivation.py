"""Derivation of the equations of motion: jourdain against sympy.physics.mechanics, in one run.

Family ``pendulum``: ``n_link_pendulum_on_cart(n)``, jourdain against sympy's ``KanesMethod`` on
sympy's own model (``sympy.physics.mechanics.models.n_link_pendulum_on_cart``).
Family ``chain``: ``spatial_chain(n)``, f = 3 … 127, jourdain against sympy's ``System``/joints
API on the same data (relative joint coordinates, ``form_eoms()`` with its default
``KanesMethod``; see ``benchmarks/sympy_models.py``), sympy up to ``--sympy-upto`` links.

Every case runs in fresh processes, jourdain's (``python -m benchmarks.derivation '{...}'``) and
sympy's (with the time limit ``--timeout``), so that each peak resident memory (``ru_maxrss``) is
its own. Reported per case: the time of the symbolic M, k, q (jourdain: the first
``equations_of_motion()`` of a fresh process, the smallest over ``--repeat`` processes; sympy:
one), the process's
peak RSS and what the derivation added to it (Δ: over the RSS after the imports and the model's
construction; for jourdain also the C heap it added, ``heap MB``, glibc's mallinfo2: exact, where
Δ RSS rounds to what the imports left free), the ratios sympy/jourdain of time and of peak RSS, and the operation counts of M
and of the forcing vector q - k after common-subexpression elimination, both counted by the same
function (``jourdain.symbolic.count_ops``: graph CSE, n-ary + and * count n-1) on SymEngine
versions of both results. Where sympy finishes (up to ``--check-upto`` links), both symbolic
results are evaluated at a random state and compared.

Below the table: the growth exponents with f of jourdain's time, memory (heap) and operation count
over the chains (least-squares log-log slope from f = 25 on, and over the top half: see
:func:`growth`), and the targets of issue 35, item 4 at the largest chain: f = 127 in ≤ 1.5 s
and ≤ 300 MB peak RSS, growth ≤ f².

    python benchmarks/derivation.py            # the full run (several minutes: sympy is slow)
    python benchmarks/derivation.py --quick    # n = 1, 2 and a chain of f = 7, sympy at n ≤ 2
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

#: issue 35, item 4: the spatial chain of f = 127 in at most this many seconds and MB of peak
#: RSS, growing at most like f^GROWTH_TARGET
TARGET_F, TARGET_S, TARGET_MB, GROWTH_TARGET = 127, 1.5, 300.0, 2.0
CASES = {"pendulum": [1, 2, 4, 8, 16, 32], "chain": [2, 3, 4, 5, 6, 8, 16, 32, 64]}
QUICK = {"pendulum": [1, 2], "chain": [2, 4]}


def _make(family: str, n: int):  # noqa: ANN202 - a jourdain System
    from jourdain.models import n_link_pendulum_on_cart, spatial_chain

    return (n_link_pendulum_on_cart if family == "pendulum" else spatial_chain)(n)


def _rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


def _heap_mb() -> float | None:
    """Bytes in use on the C heap (glibc's mallinfo2: SymEngine's expression graph, and Python's
    larger objects), in MB; None where there is no mallinfo2."""
    import ctypes

    class Info(ctypes.Structure):
        _fields_ = [(k, ctypes.c_size_t) for k in ("arena", "ordblks", "smblks", "hblks",
                                                    "hblkhd", "usmblks", "fsmblks", "uordblks",
                                                    "fordblks", "keepcost")]
    try:
        fn = ctypes.CDLL("libc.so.6").mallinfo2
    except (OSError, AttributeError):
        return None
    fn.restype = Info
    info = fn()
    return (info.uordblks + info.hblkhd) / 2**20


def jourdain_case(family: str, n: int) -> dict:
    """One model in this process (which should be fresh): time, peak RSS and operation counts
    of its first ``equations_of_motion()``, what a program that derives once pays."""
    from jourdain.symbolic import count_ops

    system = _make(family, n)
    rss0, heap0 = _rss_mb(), _heap_mb()
    t0 = time.perf_counter()
    eom = system.equations_of_motion()
    elapsed = time.perf_counter() - t0
    rss, heap = _rss_mb(), _heap_mb()
    return {"f": system.f, "time": elapsed, "rss_mb": rss, "delta_mb": rss - rss0,
            "heap_mb": None if heap is None or heap0 is None else heap - heap0,
            "ops_M": count_ops(eom.M.entries()), "ops_f": count_ops(eom.forcing.entries())}


def _sympy_worker(family: str, n: int, check: bool, out: mp.Queue) -> None:
    import symengine as se
    import sympy as sp

    from jourdain.symbolic import count_ops

    rss0 = _rss_mb()
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
    rss = _rss_mb()
    # count sympy's results on plain symbols, as jourdain's: q0(t) -> q0, F(t) -> F
    funcs = {x for x in M.atoms(sp.Function) | F.atoms(sp.Function)
             if isinstance(x, sp.core.function.AppliedUndef)} | set(q) | set(u)
    plain = {x: sp.Symbol(x.func.__name__) for x in funcs}
    M, F = M.xreplace(plain), F.xreplace(plain)
    q, u = [plain[x] for x in q], [plain[x] for x in u]
    res = {"time": elapsed, "rss_mb": rss, "delta_mb": rss - rss0,
           "ops_M": count_ops([se.sympify(e) for e in M]),
           "ops_f": count_ops([se.sympify(e) for e in F])}
    if check:
        Fin = sp.Symbol("F")
        pv = _make(family, n).parameter_values
        names = sorted(k for k in syms if k in pv)  # t appears only inside q(t), u(t)
        args = [*q, *u, *(syms[k] for k in names), Fin]
        rng = np.random.default_rng(7)
        yv, ydv = rng.uniform(-1, 1, len(q)), rng.uniform(-1, 1, len(q))
        res["state"] = (yv, ydv)
        vals = [*yv, *ydv, *(pv[k] for k in names), 0.0]
        res["M_val"] = np.array(sp.lambdify(args, M, cse=True)(*vals), float)
        res["F_val"] = np.array(sp.lambdify(args, F, cse=True)(*vals), float).ravel()
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


def _agreement(family: str, n: int, theirs: dict) -> float | None:
    """Largest relative difference of jourdain's symbolic M and q - k from sympy's at sympy's
    random state (inputs zero)."""
    if "M_val" not in theirs:
        return None
    from jourdain.graph import evaluate_float

    system = _make(family, n)
    eom = system.equations_of_motion()
    yv, ydv = theirs["state"]
    values = dict(system.parameter_values)
    values.update({str(s): float(v) for s, v in zip(system.y, yv, strict=True)})
    values.update({str(s): float(v) for s, v in zip(system.yd, ydv, strict=True)})
    values.update({str(s): 0.0 for s in system.inputs})
    values["t"] = 0.0
    M = np.array(evaluate_float(eom.M.entries(), values)).reshape(system.f, system.f)
    F = np.array(evaluate_float(eom.forcing.entries(), values))
    eM = np.abs(M - theirs["M_val"]).max() / np.abs(theirs["M_val"]).max()
    eF = np.abs(F - theirs["F_val"]).max() / np.abs(theirs["F_val"]).max()
    return float(max(eM, eF))


def _jourdain_fresh(family: str, n: int, repeat: int) -> dict:
    """:func:`jourdain_case` in ``repeat`` fresh processes: the smallest time and memory (a busy
    machine only ever adds), the operation counts (the same in each)."""
    from benchmarks.crosscheck import spawn

    runs = [spawn({"family": family, "n": n}, "0", module="benchmarks.derivation")
            for _ in range(max(repeat, 1))]
    out = dict(runs[0])
    out.update({k: min(r[k] for r in runs) for k in ("time", "rss_mb", "delta_mb")})
    out["heap_mb"] = runs[0]["heap_mb"]  # exact: the same in every process
    return out


def run(cases: dict[str, list[int]], timeout: float, repeat: int, check_upto: int,
        sympy_upto: dict[str, int] | None = None) -> list[dict]:
    """Measure every case (jourdain and, up to ``sympy_upto[family]`` links, sympy), printing
    one line each under :data:`HEADER`; the rows as dicts."""
    print(HEADER)
    rows = []
    for family, ns in cases.items():
        for n in ns:
            ours = _jourdain_fresh(family, n, repeat)
            upto = (sympy_upto or {}).get(family)
            theirs = (_sympy_case(family, n, timeout, check=n <= check_upto)
                      if upto is None or n <= upto else None)
            row = {"family": family, "n": n, "f": ours["f"],
                   "jourdain_s": ours["time"], "jourdain_rss_mb": ours["rss_mb"],
                   "jourdain_delta_mb": ours["delta_mb"], "jourdain_heap_mb": ours["heap_mb"],
                   "jourdain_ops_M": ours["ops_M"],
                   "jourdain_ops_f": ours["ops_f"],
                   "sympy_tried": upto is None or n <= upto,
                   **{f"sympy_{k}": (theirs or {}).get(k)
                      for k in ("time", "rss_mb", "delta_mb", "ops_M", "ops_f")},
                   "max_rel_diff": _agreement(family, n, theirs) if theirs else None}
            row["sympy_s"] = row.pop("sympy_time")
            rows.append(row)
            print(_row(row, timeout), flush=True)
    return rows


HEADER = (f"{'family':<9}{'n':>3}{'f':>5}{'jourdain s':>12}{'RSS MB':>8}{'Δ MB':>7}{'heap MB':>8}"
          f"{'sympy s':>10}{'RSS MB':>8}{'Δ MB':>7}{'time ×':>9}{'RSS ×':>7}"
          f"{'ops M(j)':>10}{'ops q-k(j)':>11}{'ops M(s)':>10}{'ops q-k(s)':>11}{'rel diff':>10}")


def _row(r: dict, timeout: float) -> str:
    if r["sympy_s"] is not None:
        sym = (f"{r['sympy_s']:10.3f}{r['sympy_rss_mb']:8.0f}{r['sympy_delta_mb']:7.0f}"
               f"{r['sympy_s'] / r['jourdain_s']:8.0f}×{r['sympy_rss_mb'] / r['jourdain_rss_mb']:6.1f}×")
        ops = f"{r['sympy_ops_M']:>10}{r['sympy_ops_f']:>11}"
    else:
        what = f">{timeout:.0f}s" if r["sympy_tried"] else "-"
        sym = f"{what:>10}{'-':>8}{'-':>7}{'-':>9}{'-':>7}"
        ops = f"{'-':>10}{'-':>11}"
    diff = f"{r['max_rel_diff']:.1e}" if r["max_rel_diff"] is not None else "-"
    heap = "-" if r.get("jourdain_heap_mb") is None else f"{r['jourdain_heap_mb']:.1f}"
    return (f"{r['family']:<9}{r['n']:>3}{r['f']:>5}{r['jourdain_s']:12.4f}"
            f"{r['jourdain_rss_mb']:8.0f}{r['jourdain_delta_mb']:7.0f}{heap:>8}{sym}"
            f"{r['jourdain_ops_M']:>10}{r['jourdain_ops_f']:>11}{ops}{diff:>10}")


#: the quantities whose growth with f is reported: time, the derivation's memory, the size of
#: the equations (operations of M and q - k after CSE)
GROWTH = {"jourdain_s": "time", "memory": "memory", "ops": "operations"}
#: the smallest f of the least-squares fit: jourdain's SHARED_FROM_F, from which on the
#: equations are formed from composite bodies (below, the body-by-body sums and fixed costs)
FIT_F_MIN = 25


def growth(rows: list[dict], family: str = "chain") -> dict[str, dict]:
    """Exponents a of x ∝ f^a of the :data:`GROWTH` quantities of jourdain over ``family``:
    ``"fit"``, the least-squares slope of log x against log f over the rows with
    f ≥ FIT_F_MIN (at least two), and ``"top"``, the slope from the row nearest half the
    largest f to the largest."""
    rs = sorted((dict(r, ops=r["jourdain_ops_M"] + r["jourdain_ops_f"], memory=_memory(r))
                 for r in rows if r["family"] == family), key=lambda r: r["f"])
    out: dict[str, dict] = {}
    fit = [r for r in rs if r["f"] >= FIT_F_MIN]
    if len(fit) >= 2:
        x = np.log([r["f"] for r in fit])
        out["fit"] = {"f_min": fit[0]["f"], "f_max": fit[-1]["f"],
                      **{k: float(np.polyfit(x, np.log([max(r[k], 1e-3) for r in fit]), 1)[0])
                         for k in GROWTH}}
    if len(rs) >= 2:
        hi = rs[-1]
        lo = min(rs[:-1], key=lambda r: abs(r["f"] - hi["f"] / 2))
        span = math.log(hi["f"] / lo["f"])
        out["top"] = {"f_min": lo["f"], "f_max": hi["f"],
                      **{k: math.log(max(hi[k], 1e-3) / max(lo[k], 1e-3)) / span
                         for k in GROWTH}}
    return out


def _memory(r: dict) -> float:
    """The derivation's memory: the C heap it added where measured (exact), else the RSS it
    added (rounded to what the imports left free: only its top-half growth is meaningful)."""
    heap = r.get("jourdain_heap_mb")
    return r["jourdain_delta_mb"] if heap is None else heap


def summary(rows: list[dict]) -> list[str]:
    """The growth exponents and the targets, as lines of text."""
    lines = []
    g = growth(rows)
    for label, s in g.items():
        how = "least squares" if label == "fit" else "between the two"
        lines.append(f"jourdain on spatial chains, f = {s['f_min']}…{s['f_max']} ({how}): "
                     + ", ".join(f"{name} f^{s[k]:.2f}" for k, name in GROWTH.items()))
    top = [r for r in rows if r["family"] == "chain" and r["f"] == TARGET_F]
    if top and g:
        r = top[0]
        # over the fitted range (the top half's, where there is no fit); the RSS's over the
        # top half only (_memory)
        fit = g.get("fit", g["top"])
        exact = all(x.get("jourdain_heap_mb") is not None for x in rows)
        a = {"time": fit["jourdain_s"], "operations": fit["ops"],
             "memory": (fit if exact else g.get("top", fit))["memory"]}
        ok = ["met" if c else "NOT met" for c in (
            r["jourdain_s"] <= TARGET_S, r["jourdain_rss_mb"] <= TARGET_MB,
            all(round(v, 2) <= GROWTH_TARGET for v in a.values()))]
        lines.append(f"targets at f = {TARGET_F}: {r['jourdain_s']:.2f} s (≤ {TARGET_S} s: "
                     f"{ok[0]}), peak RSS {r['jourdain_rss_mb']:.0f} MB (≤ {TARGET_MB:.0f} MB: "
                     f"{ok[1]}), growth " + ", ".join(f"{k} f^{v:.2f}" for k, v in a.items())
                     + f" (≤ f^{GROWTH_TARGET:.0f}: {ok[2]})")
    for r in rows:
        if r["sympy_s"] is not None:
            lines.append(f"{r['family']} n = {r['n']} (f = {r['f']}): sympy takes "
                         f"{r['sympy_s'] / r['jourdain_s']:.0f}× jourdain's time and "
                         f"{r['sympy_rss_mb'] / r['jourdain_rss_mb']:.1f}× its peak RSS")
    return lines


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("child", nargs="?", help=argparse.SUPPRESS)
    ap.add_argument("--quick", action="store_true",
                    help="n = 1, 2 and chains of f = 3, 7 (a smoke test)")
    ap.add_argument("--timeout", type=float, default=600.0, help="time limit per sympy case [s]")
    ap.add_argument("--repeat", type=int, default=3,
                    help="fresh jourdain processes per case (the smallest time and RSS taken)")
    ap.add_argument("--sympy-upto", type=int, default=6,
                    help="largest chain given to sympy (default 6: n = 8 takes it hours)")
    ap.add_argument("--check-upto", type=int, default=4,
                    help="largest n whose results are compared numerically (4)")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    if args.child is not None:
        s = json.loads(args.child)
        print(json.dumps(jourdain_case(s["family"], int(s["n"]))))
        return 0
    cases = QUICK if args.quick else CASES
    upto = {"chain": 2 if args.quick else args.sympy_upto}
    rows = run(cases, args.timeout, args.repeat, args.check_upto, upto)
    print()
    print("\n".join(summary(rows)))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
