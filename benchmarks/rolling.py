"""Rolling contact: the benchmark bicycle (Meijaard, Papadopoulos, Ruina, Schwab 2007) by jourdain
and by ``sympy.physics.mechanics`` (+ SciPy), peers in one run (issue 34, item 5).

1. **Model to eigenvalues** at ``--speeds`` speeds over 0…10 m/s, everything from building the
   model counted, each route in a fresh process:

   * jourdain: ``benchmark_bicycle()`` → ``linearize({"zc": -rR, "thetaR_d": -v/rR})`` →
     ``.at({"v": v}).eigenvalues`` per speed; with its compile cache warm (what a user sees the
     second time) and empty (C code generated and compiled);
   * sympy: ``KanesMethod`` with dependent speeds and the holonomic constraint
     (:mod:`benchmarks.sympy_bicycle`) → ``linearize(A_and_B=True, linear_solver="CRAMER")`` as
     sympy's bicycle test → Table 1's numbers put in, ``A(v)`` lambdified → NumPy eigenvalues.

   Checked before the times are printed: jourdain's ``M̃, P, Q`` against the paper's ``M, C1,
   K0, K2``; both routes' lean and steer block of ``A`` against the paper's
   ``[[0, I], [−M⁻¹(g·K0 + v²·K2), −v·M⁻¹C1]]``; Table 2's eigenvalues; the two routes'
   eigenvalues against each other at every speed.

2. **A nonlinear run** of ``--T`` seconds at 5 m/s from a lean of 0.05 rad: jourdain's
   ``system.simulate`` (jourdain's C integrator, DOP853, on the compiled kernel of
   ``loops/general_c.h``) against sympy + SciPy
   (Kane's ``mass_matrix`` and ``forcing`` lambdified, the dependent speeds solved from the
   velocity constraints at each right-hand side, ``solve_ivp`` DOP853), the same integrator and
   tolerances (``atol = rtol·1e-2``); each route's error at the end against a reference
   (jourdain at rtol 1e-12), over the coordinates both have (rear centre x, y, yaw, lean, pitch,
   steer, wheel angles) and over lean and steer alone; the sympy reference run is checked
   against it first. Best of ``--repeat``. ``--profile``: cProfile's top entries of jourdain's
   run.

sympy's ``linearize`` of the bicycle takes minutes (3.5–7.5 on a shared 2-core machine, with
or without Table 1's numbers put in first); it runs in its own process under ``--timeout``. A
full run stores its ``A(v)`` (and its times) in jourdain's compile cache; ``--quick`` takes it
from there when present (its times then are that earlier run's, and say so) and otherwise
leaves sympy's linearization out, saying why. Timings from ``--quick`` are not the reported numbers.

    python benchmarks/rolling.py                 # 100 speeds, 10 s run (about 7 minutes)
    python benchmarks/rolling.py --quick         # 5 speeds, a 1 s run
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.reference.test_benchmark_bicycle import C1, K0, K2, TABLE2, M  # noqa: E402

G = 9.81
CHECK_SPEEDS = (0.0, 1.0, 4.0, 5.0, 10.0)


def paper_A(v: float) -> np.ndarray:
    """The paper's state matrix in (φ, δ, φ̇, δ̇) at speed ``v``."""
    Mi = np.linalg.inv(M)
    return np.block([[np.zeros((2, 2)), np.eye(2)],
                     [-Mi @ (G * K0 + v**2 * K2), -v * Mi @ C1]])


def speeds(n: int) -> np.ndarray:
    return np.linspace(0.0, 10.0, n)


def _pairs(z: np.ndarray) -> list:
    return [[float(c.real), float(c.imag)] for c in np.asarray(z).reshape(-1)]


def _complex(p: list) -> np.ndarray:
    return np.array([a + 1j * b for a, b in p])


# --- workers (fresh processes) ----------------------------------------------------------------

def worker_jourdain(n: int) -> dict:
    import symengine as se

    from jourdain.models.rolling import benchmark_bicycle

    t0 = time.perf_counter()
    bike = benchmark_bicycle()
    v, rR = se.Symbol("v"), se.Symbol("rR")
    lin = bike.linearize({"zc": -rR, "thetaR_d": -v / rR})
    t_lin = time.perf_counter() - t0
    eig = [lin.at({"v": float(s)}).eigenvalues for s in speeds(n)]
    total = time.perf_counter() - t0
    l0, l1 = lin.at({"v": 0.0}), lin.at({"v": 1.0})
    return {"linearize_s": t_lin, "total_s": total,
            "eig": [_pairs(e) for e in eig],
            "matrices": {"M": l0.M_tilde.tolist(), "C1": l1.P.tolist(),
                         "K0": (l0.Q / G).tolist(), "K2": (l1.Q - l0.Q).tolist()},
            "A": {str(s): lin.at({"v": s}).A.tolist() for s in CHECK_SPEEDS}}


def _sympy_cache() -> Path:
    import sympy

    from jourdain.numeric import cache_dir

    src = (ROOT / "benchmarks" / "sympy_bicycle.py").read_bytes()
    key = hashlib.sha256(src + sympy.__version__.encode()).hexdigest()[:16]
    return cache_dir() / f"bench-rolling-sympy-A-{key}.json"


def worker_sympy(n: int, mode: str) -> dict:
    """``mode``: "derive" (and store in the cache), "cache" (the stored result, or nothing)."""
    import sympy as sp

    from benchmarks.sympy_bicycle import linear_A, whipple_kane

    v = sp.Symbol("v")
    path = _sympy_cache()
    cached = mode == "cache"
    if cached:
        if not path.is_file():
            return {"missing": str(path)}
        rec = json.loads(path.read_text())
        A = sp.sympify(rec["A"])
        times = rec["times"]
    else:
        t0 = time.perf_counter()
        model = whipple_kane()
        t_kane = time.perf_counter() - t0
        A, v = linear_A(model)
        times = {"kane_s": t_kane, "linearize_s": time.perf_counter() - t0 - t_kane}
    t0 = time.perf_counter()
    fA = sp.lambdify(v, A, "numpy", cse=True)
    eig = [np.linalg.eigvals(np.asarray(fA(s), dtype=float)[1:5, 1:5]) for s in speeds(n)]
    t_num = time.perf_counter() - t0
    if not cached:
        times["lambdify_eig_s"] = t_num
        times["total_s"] = times["kane_s"] + times["linearize_s"] + t_num
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps({"A": str(A), "times": times}))
    return {**times, "cached": str(path) if cached else None,
            "eig": [_pairs(e) for e in eig],
            "A": {str(s): np.asarray(fA(s), dtype=float)[1:5, 1:5].tolist()
                  for s in CHECK_SPEEDS}}


def spawn(args: list[str], timeout: float, cache: str | None = None) -> dict | str:
    """``--worker ...`` in a fresh interpreter; its JSON, or why there is none."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(ROOT)])}
    if cache is not None:
        env["JOURDAIN_CACHE"] = cache
    try:
        p = subprocess.run([sys.executable, __file__, "--worker", *args], env=env,
                           capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"timeout ({timeout:.0f} s)"
    if p.returncode:
        return f"failed: {p.stderr.strip().splitlines()[-1] if p.stderr.strip() else p.returncode}"
    return json.loads(p.stdout.strip().splitlines()[-1])


# --- part 1: eigenvalues ------------------------------------------------------------------------

def _rel(a: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - ref)) / np.max(np.abs(ref)))


def _eig_apart(a: np.ndarray, b: np.ndarray) -> float:
    """Largest distance from an eigenvalue of ``a`` to the nearest of ``b`` (and back), relative
    to max(1, |λ|)."""
    d = [np.min(np.abs(b - x)) / max(1.0, abs(x)) for x in a]
    d += [np.min(np.abs(a - x)) / max(1.0, abs(x)) for x in b]
    return float(max(d))


def _table2(A: dict) -> float:
    out = 0.0
    for v, ref in TABLE2.items():
        lam = np.linalg.eigvals(np.asarray(A[str(v)]))
        out = max(out, _eig_apart(lam, np.array(ref)))
    return out


def eigenvalues(n: int, timeout: float, sympy_mode: str) -> dict:
    """Part 1; ``sympy_mode``: "derive", "cache" (a full run's result, if stored) or "off"."""
    warm = spawn(["jourdain", str(n)], timeout)  # compiles into the cache if it must
    warm = spawn(["jourdain", str(n)], timeout)
    with tempfile.TemporaryDirectory() as empty:
        cold = spawn(["jourdain", str(n)], timeout, cache=empty)
    if isinstance(warm, str):
        raise RuntimeError(f"jourdain's route: {warm}")
    out: dict = {"speeds": n, "jourdain_warm": warm, "jourdain_cold": cold}
    mats = {k: np.array(v) for k, v in warm["matrices"].items()}
    out["jourdain_vs_paper"] = {k: _rel(mats[k], ref) for k, ref in
                                (("M", M), ("C1", C1), ("K0", K0), ("K2", K2))}
    out["jourdain_vs_paper"]["A"] = max(_rel(np.array(warm["A"][str(s)]), paper_A(s))
                                        for s in CHECK_SPEEDS)
    out["jourdain_table2"] = _table2(warm["A"])
    if sympy_mode == "off":
        out["sympy"] = "left out (--no-sympy)"
        return out
    sym = spawn(["sympy", str(n), sympy_mode], timeout)
    if isinstance(sym, str):
        out["sympy"] = f"sympy's route: {sym}"
        return out
    if "missing" in sym:
        out["sympy"] = ("left out: sympy's linearize of the bicycle takes minutes, and no full "
                        f"run has stored its result ({sym['missing']}); run the benchmark "
                        "without --quick once")
        return out
    out["sympy"] = sym
    out["sympy_vs_paper_A"] = max(_rel(np.array(sym["A"][str(s)]), paper_A(s))
                                  for s in CHECK_SPEEDS)
    out["sympy_table2"] = _table2(sym["A"])
    out["eig_apart"] = max(_eig_apart(_complex(a), _complex(b))
                           for a, b in zip(warm["eig"], sym["eig"], strict=True))
    return out


# --- part 2: a nonlinear run --------------------------------------------------------------------

#: jourdain's coordinates that sympy's state has, and where: (psi, phi, delta, theta, u..., x,
#: y, thetaR, thetaF)
COMMON = {"psi": 0, "phi": 1, "delta": 2, "theta": 3, "x": 7, "y": 8, "thetaR": 9, "thetaF": 10}
LEAN, SPEED, REF_RTOL = 0.05, 5.0, 1e-12


def _best(fn, repeat: int):  # noqa: ANN001, ANN202
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def simulation(T: float, tols: list[float], repeat: int, profile: bool = False) -> dict:
    from scipy.integrate import solve_ivp

    from benchmarks.sympy_bicycle import make_rhs, rhs_functions, whipple_kane
    from jourdain.models.rolling import benchmark_bicycle

    bike = benchmark_bicycle()
    names, p = bike.coordinate_names, bike.parameter_values
    y0, yd0 = np.zeros(9), np.zeros(9)
    y0[names.index("zc")] = -p["rR"]
    y0[names.index("phi")] = LEAN
    yd0[names.index("thetaR")] = -SPEED / p["rR"]
    idx = [names.index(k) for k in COMMON]
    sidx = list(COMMON.values())
    ls = [list(COMMON).index(k) for k in ("phi", "delta")]

    def jd(rtol: float):  # noqa: ANN202
        # the end state, as SciPy's run without t_eval gives it (samples between would cost
        # DOP853's dense-output stages, which SciPy's side does not compute)
        return bike.simulate((0.0, T), y0, yd0, rtol=rtol, atol=rtol * 1e-2, t_eval=[0.0, T])

    t0 = time.perf_counter()
    jd(1e-6)  # compiled (or loaded) before timing
    out: dict = {"T": T, "jourdain_first_run_s": time.perf_counter() - t0}
    ref = jd(REF_RTOL).y[-1, idx]
    t0 = time.perf_counter()
    model = whipple_kane()
    out["sympy_kane_s"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    fns = rhs_functions(model)
    out["sympy_lambdify_s"] = time.perf_counter() - t0
    rhs = make_rhs(fns)
    x0 = np.zeros(11)
    x0[1], x0[6] = LEAN, -SPEED / p["rR"]

    def sy(rtol: float):  # noqa: ANN202
        return solve_ivp(rhs, (0.0, T), x0, method="DOP853", rtol=rtol, atol=rtol * 1e-2)

    sref = sy(REF_RTOL)
    out["references_apart"] = float(np.max(np.abs(sref.y[sidx, -1] - ref)))
    out["reference_scale"] = float(np.max(np.abs(ref)))
    rows = []
    for rtol in tols:
        wall, r = _best(lambda rtol=rtol: jd(rtol), repeat)
        e = np.abs(r.y[-1, idx] - ref)
        rows.append({"route": "jourdain", "rtol": rtol, "wall_s": wall, "nfev": int(r.nfev),
                     "error": float(e.max()), "error_lean_steer": float(e[ls].max()),
                     "max_Phi": float(np.max(np.abs(r.constraints.Phi)))})
        wall, s = _best(lambda rtol=rtol: sy(rtol), repeat)
        e = np.abs(s.y[sidx, -1] - ref)
        rows.append({"route": "sympy+scipy", "rtol": rtol, "wall_s": wall, "nfev": int(s.nfev),
                     "error": float(e.max()), "error_lean_steer": float(e[ls].max()),
                     "Phi_end": float(abs(np.asarray(fns["hol"](s.y[:4, -1])).item()))})
    out["rows"] = rows
    if profile:
        import cProfile
        import io
        import pstats

        prof = cProfile.Profile()
        prof.runcall(jd, tols[-1])
        buf = io.StringIO()
        pstats.Stats(prof, stream=buf).sort_stats("tottime").print_stats(12)
        out["profile"] = buf.getvalue()
    return out


# --- report -------------------------------------------------------------------------------------

def _t(r: dict | str, key: str = "total_s") -> str:
    return f"{r[key]:.2f} s" if isinstance(r, dict) else str(r)


def report(eig: dict, sim: dict) -> None:
    n = eig["speeds"]
    w, c = eig["jourdain_warm"], eig["jourdain_cold"]
    print(f"1. the benchmark bicycle, model to eigenvalues at {n} speeds 0..10 m/s")
    print(f"  jourdain (warm cache): {w['total_s']:.2f} s (build + linearize "
          f"{w['linearize_s']:.2f} s, then .at(v).eigenvalues {(w['total_s'] - w['linearize_s']) / n * 1e3:.0f} ms per speed); "
          f"empty cache: {_t(c)} (imports not counted)")
    jp = eig["jourdain_vs_paper"]
    print("  jourdain vs the paper (relative): " + ", ".join(f"{k} {v:.1e}" for k, v in jp.items())
          + f"; Table 2 eigenvalues {eig['jourdain_table2']:.1e}")
    s = eig["sympy"]
    if isinstance(s, str):
        print(f"  sympy: {s}")
    else:
        src = f" (an earlier full run's, from {s['cached']})" if s["cached"] else ""
        print(f"  sympy KanesMethod + linearize{src}: {s['total_s']:.2f} s (Kane {s['kane_s']:.2f} s, "
              f"linearize {s['linearize_s']:.2f} s, lambdify + eigenvalues {s['lambdify_eig_s']:.3f} s)")
        print(f"  sympy vs the paper: A {eig['sympy_vs_paper_A']:.1e}, Table 2 eigenvalues "
              f"{eig['sympy_table2']:.1e}; jourdain and sympy eigenvalues apart at most "
              f"{eig['eig_apart']:.1e} over the {n} speeds")
        ratio = s["total_s"] / w["total_s"]
        cold = f", {s['total_s'] / c['total_s']:.1f}x with an empty cache" if isinstance(c, dict) else ""
        if s["cached"]:
            print("  no ratio: sympy's times are an earlier run's (and its number of speeds)")
        else:
            print(f"  ratio sympy / jourdain: {ratio:.1f}x (warm cache){cold}; the issue's "
                  f"target is >= 100x: {'met' if ratio >= 100 else 'NOT met'}")
    T = sim["T"]
    print(f"2. a {T:g} s nonlinear run at {SPEED:g} m/s from a lean of {LEAN} rad "
          f"(error: max |y(T) - y_ref(T)| over {', '.join(COMMON)}; lean/steer alone)")
    print(f"  references (rtol {REF_RTOL:g}) apart {sim['references_apart']:.1e} "
          f"(largest coordinate {sim['reference_scale']:.0f}); sympy: Kane {sim['sympy_kane_s']:.1f} s, "
          f"lambdify {sim['sympy_lambdify_s']:.1f} s (not counted)")
    for r in sim["rows"]:
        extra = (f"max|Φ| {r['max_Phi']:.0e}" if "max_Phi" in r else f"|Φ(T)| {r['Phi_end']:.0e}")
        print(f"  {r['route']:<12} rtol {r['rtol']:.0e}: {r['wall_s']:.3f} s, {r['nfev']:5d} rhs "
              f"({r['wall_s'] / r['nfev'] * 1e3:.2f} ms each), error {r['error']:.1e}, lean/steer "
              f"{r['error_lean_steer']:.1e}, {extra}")
    for rtol in sorted({r["rtol"] for r in sim["rows"]}):
        by = {r["route"]: r for r in sim["rows"] if r["rtol"] == rtol}
        ratio = by["sympy+scipy"]["wall_s"] / by["jourdain"]["wall_s"]
        print(f"  equal rtol {rtol:.0e}: sympy+scipy / jourdain = {ratio:.2f}x")
    # equal accuracy: each sympy run against the fastest jourdain run at least as accurate
    ours = [r for r in sim["rows"] if r["route"] == "jourdain"]
    for r in (r for r in sim["rows"] if r["route"] == "sympy+scipy"):
        good = [o for o in ours if o["error"] <= r["error"]]
        if not good:
            continue
        o = min(good, key=lambda o: o["wall_s"])
        ratio = r["wall_s"] / o["wall_s"]
        print(f"  equal accuracy: sympy+scipy at rtol {r['rtol']:.0e} (error {r['error']:.1e}) / "
              f"jourdain at rtol {o['rtol']:.0e} (error {o['error']:.1e}) = {ratio:.1f}x; the "
              f"issue's target is >= 50x: {'met' if ratio >= 50 else 'NOT met'}")
    if "profile" in sim:
        print(sim["profile"])
    print(f"  (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


def main(argv: list[str] | None = None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="5 speeds, a 1 s run, sympy's "
                    "linearization from a full run's cache only")
    ap.add_argument("--speeds", type=int, default=None)
    ap.add_argument("--T", type=float, default=None)
    ap.add_argument("--repeat", type=int, default=None)
    ap.add_argument("--timeout", type=float, default=1800.0, help="limit per process [s]")
    ap.add_argument("--no-sympy-linearize", action="store_true")
    ap.add_argument("--profile", action="store_true", help="cProfile jourdain's run")
    ap.add_argument("--json", default=None, help="write the figures here")
    ap.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.worker:
        kind, n = a.worker[0], int(a.worker[1])
        r = worker_jourdain(n) if kind == "jourdain" else worker_sympy(n, a.worker[2])
        print(json.dumps(r))
        return r
    n = a.speeds or (5 if a.quick else 100)
    T = a.T or (1.0 if a.quick else 10.0)
    repeat = a.repeat or (1 if a.quick else 3)
    mode = "off" if a.no_sympy_linearize else "cache" if a.quick else "derive"
    eig = eigenvalues(n, a.timeout, mode)
    sim = simulation(T, [1e-6, 1e-8] if a.quick else [1e-6, 1e-8, 1e-10], repeat, a.profile)
    report(eig, sim)
    out = {"eigenvalues": eig, "simulation": sim}
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1, default=str))
    return out


if __name__ == "__main__":
    main()
