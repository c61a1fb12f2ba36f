"""Kinematic loops: derivation and simulation of the four-bar, against sympy + SciPy and IDA.

Derivation: jourdain's symbolic stages of a loop model (the tree's M, k, q and the
constraints Φ, Φ_z, Φ_t, c) against sympy.physics.mechanics' ``KanesMethod`` with dependent
speeds (configuration and velocity constraints) on the same four-bar (the model of
``tests/test_loops.py``), and for the slider-crank.

Simulation of the four-bar over ``T`` seconds from the same consistent state, each route's
error measured against a reference (jourdain at rtol 1e-13) at the end, each the best of
``--repeat`` runs (IDA one):

* jourdain: coordinate partitioning (``System.simulate``, the default formulation, DOP853), the
  compiled right-hand side in jourdain's C integrator, and the same
  method stepped by SciPy from Python (``method="scipy:DOP853"``, "jd+scipy");
* sympy + SciPy: Kane's ``mass_matrix_full`` and ``forcing_full`` lambdified (NumPy) and
  integrated by ``solve_ivp`` (DOP853) in q, u with the dependent speeds from the velocity
  constraints (the standard sympy route; Φ drifts with the integration error);
* IDA (scikit-sundae, if installed): the index-1 redundant form in z, ż, λ with jourdain's
  compiled tree and constraints in the residual.

Units of length (``--units``): the same four-bar with its lengths and g multiplied by
s = 1, 1e-3, 1e-5 (the angle equations unchanged), each route at rtol 1e-10 over ``T``: the
right-hand sides it takes and how far its angles end from its own run at s = 1 (jourdain's
also the closure residual relative to the lengths). A stop or an error norm that mixes metres
and radians shows as more right-hand sides and angles apart at small s.

    python benchmarks/loops.py [--T 5] [--repeat 5] [--no-ida] [--units]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from jourdain.loops import LoopEvaluator, constraints  # noqa: E402
from jourdain.models.loops import four_bar, slider_crank  # noqa: E402


def derive_jourdain(make) -> float:  # noqa: ANN001
    t0 = time.perf_counter()
    loop = make()
    loop.tree.equations_of_motion()
    constraints(loop)
    return time.perf_counter() - t0


def derive_sympy() -> tuple[float, object]:
    from tests.test_loops import _kane_four_bar

    t0 = time.perf_counter()
    fns = _kane_four_bar()
    return time.perf_counter() - t0, fns


def kane_full_four_bar():  # noqa: ANN201
    """Kane's full (q, u) mass matrix and forcing of the four-bar, lambdified (the model of
    tests/test_loops.py)."""
    from tests.test_loops import _kane_four_bar

    return _kane_four_bar(full=True)


PARS = [0.4, 1.0, 0.8, 1.1, 1.0, 2.0, 1.5, 9.81]


def simulate_sympy(fns, z0, zd0, T, rtol, pars=PARS):  # noqa: ANN001, ANN201
    from scipy.integrate import solve_ivp

    MMf, Ff = fns

    def rhs(_t: float, x: np.ndarray) -> np.ndarray:
        MM = np.asarray(MMf(*x, *pars), dtype=float)
        F = np.asarray(Ff(*x, *pars), dtype=float).reshape(-1)
        return np.linalg.solve(MM, F)

    t0 = time.perf_counter()
    r = solve_ivp(rhs, (0, T), np.concatenate([z0, zd0]), method="DOP853", rtol=rtol,
                  atol=rtol * 1e-2)
    return time.perf_counter() - t0, r.y[:3, -1], r.nfev


def simulate_ida(loop, z0, zd0, T, rtol):  # noqa: ANN001, ANN201
    from sksundae.ida import IDA

    ev = LoopEvaluator(loop, z0)
    n = loop.f
    m = len(ev.labels)
    zdd, lam = ev.redundant_accelerations(z0, zd0, 0.0)

    def res(t: float, y: np.ndarray, yp: np.ndarray, r: np.ndarray) -> None:
        z, v, lm = y[:n], y[n:2 * n], y[2 * n:]
        tr = ev.tree_mkq.split(ev.tree_mkq.raw(np.ascontiguousarray(z),
                                               np.ascontiguousarray(v), t, ev.p, ev.u))
        cd = ev._con(z, v, t)
        r[:n] = yp[:n] - v
        r[n:2 * n] = tr["M"] @ yp[n:2 * n] + tr["k"][:, 0] - tr["q"][:, 0] - cd["Phi_z"].T @ lm
        r[2 * n:] = cd["Phi_z"] @ yp[n:2 * n] + cd["c"][:, 0]

    y0 = np.concatenate([z0, zd0, lam])
    yp0 = np.concatenate([zd0, zdd, np.zeros(m)])
    solver = IDA(res, rtol=rtol, atol=rtol * 1e-2, algebraic_idx=list(range(2 * n, 2 * n + m)))
    t0 = time.perf_counter()
    sol = solver.solve(np.array([0.0, T]), y0, yp0)
    wall = time.perf_counter() - t0
    zT = sol.y[-1, :n]
    cd = ev._con(zT, sol.y[-1, n:2 * n], T)
    return wall, zT, float(np.max(np.abs(cd["Phi"])))


SCALES = (1.0, 1e-3, 1e-5)


def length_units(T: float, rtol: float = 1e-10) -> list[dict]:
    """The four-bar at the lengths and g of :data:`PARS` times each of :data:`SCALES`, by
    jourdain (System.simulate) and by sympy + SciPy in one run: per route and scale the
    right-hand sides, the angles' largest distance from the route's s = 1 run at T, and for
    jourdain max|Φ| / s (the closure residual relative to the lengths)."""
    loop = four_bar()
    names = ("a", "b", "c", "d", "m1", "m2", "m3", "g")
    lengths = {"a", "b", "c", "d", "g"}
    fns = kane_full_four_bar()
    start = loop.evaluate([0.5, 0.8, 1.9], [1.0, 0, 0])  # assembled: a consistent state
    z0, zd0 = start["y"], start["yd"]
    loop.simulate((0, 0.1), z0, zd0, samples=2, rtol=rtol)  # compiled and loaded before timing
    rows, base = [], {}
    for s in SCALES:
        pars = [v * s if n in lengths else v for n, v in zip(names, PARS, strict=True)]
        t0 = time.perf_counter()
        r = loop.simulate((0, T), z0, zd0, samples=2, rtol=rtol, atol=rtol * 1e-2,
                          parameters=dict(zip(names, pars, strict=True)))
        wall = time.perf_counter() - t0
        base.setdefault("jourdain", r.y[-1])
        rows.append({"route": "jourdain", "s": s, "nfev": r.nfev, "wall_s": wall,
                     "angles_apart": float(np.max(np.abs(r.y[-1] - base["jourdain"]))),
                     "max_angle": float(np.max(np.abs(r.y))),
                     "max_Phi_per_length": r.closure_residual[0] / s})
        wall, zs, nfev = simulate_sympy(fns, z0, zd0, T, rtol, pars)
        base.setdefault("sympy+scipy", zs)
        rows.append({"route": "sympy+scipy", "s": s, "nfev": nfev, "wall_s": wall,
                     "angles_apart": float(np.max(np.abs(zs - base["sympy+scipy"])))})
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--T", type=float, default=5.0)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="best of N (IDA: one run)")
    ap.add_argument("--no-ida", action="store_true", help="skip IDA (slow)")
    ap.add_argument("--units", action="store_true",
                    help="only the four-bar in other units of length, jourdain and sympy+SciPy")
    args = ap.parse_args(argv)
    T = args.T
    if args.units:
        rows = length_units(T)
        if args.json:
            print(json.dumps(rows, indent=2))
            return
        print(f"four-bar, lengths and g times s, rtol 1e-10 over {T} s:")
        for r in rows:
            extra = (f", max|Φ|/s {r['max_Phi_per_length']:.1e}"
                     if "max_Phi_per_length" in r else "")
            print(f"  {r['route']:<12} s = {r['s']:<6g} {r['nfev']:>7} right-hand sides, "
                  f"angles {r['angles_apart']:.1e} from s = 1, {r['wall_s']:.4f} s{extra}")
        return
    out: dict = {}
    out["derivation_s"] = {"jourdain_four_bar": derive_jourdain(four_bar),
                           "jourdain_slider_crank": derive_jourdain(slider_crank)}
    t_sym, _ = derive_sympy()
    out["derivation_s"]["sympy_kane_four_bar"] = t_sym
    loop = four_bar()
    ref = loop.simulate((0, T), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=2, rtol=1e-13,
                        atol=1e-14)
    z0, zd0, zT = ref.y[0], ref.yd[0], ref.y[-1]
    rows = []
    fns = kane_full_four_bar()
    loop.simulate((0, 0.1), z0, zd0, samples=2, rtol=1e-10, atol=1e-12)  # compiled and loaded before timing
    for rtol in (1e-8, 1e-10):
        for method, route in (("DOP853", "jourdain"), ("scipy:DOP853", "jd+scipy")):
            best = np.inf
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                r = loop.simulate((0, T), z0, zd0, samples=2, rtol=rtol, atol=rtol * 1e-2,
                                  method=method)
                best = min(best, time.perf_counter() - t0)
            rows.append({"route": route, "rtol": rtol, "wall_s": best, "nfev": r.nfev,
                         "error": float(np.max(np.abs(r.y[-1] - zT))),
                         "max_Phi": r.closure_residual[0],
                         "max_Phi_dot": r.closure_residual[1]})
        wall, zs, nfev = min(simulate_sympy(fns, z0, zd0, T, rtol) for _ in range(args.repeat))
        rows.append({"route": "sympy+scipy", "rtol": rtol, "wall_s": wall, "nfev": nfev,
                     "error": float(np.max(np.abs(zs - zT)))})
        try:
            if args.no_ida:
                raise ImportError
            wall, zi, phi = simulate_ida(loop, z0, zd0, T, rtol)
            rows.append({"route": "IDA index-1", "rtol": rtol, "wall_s": wall,
                         "error": float(np.max(np.abs(zi - zT))), "max_Phi_end": phi})
        except ImportError:
            rows.append({"route": "IDA index-1", "rtol": rtol,
                         "skipped": "--no-ida" if args.no_ida else "no scikit-sundae"})
    out["simulation"] = rows
    if args.json:
        print(json.dumps(out, indent=2))
        return
    d = out["derivation_s"]
    print(f"derivation: jourdain four-bar {d['jourdain_four_bar']:.3f} s, slider-crank "
          f"{d['jourdain_slider_crank']:.3f} s; sympy KanesMethod four-bar "
          f"{d['sympy_kane_four_bar']:.3f} s (ratio "
          f"{d['sympy_kane_four_bar'] / d['jourdain_four_bar']:.0f}x)")
    print(f"simulation of the four-bar over {T} s (error: max |z(T) − z_ref(T)|):")
    for r in rows:
        if "skipped" in r:
            print(f"  {r['route']:<12} rtol {r['rtol']:.0e}: {r['skipped']}")
            continue
        extra = (f", max |Φ| {r['max_Phi']:.1e}" if "max_Phi" in r else
                 f", |Φ(T)| {r['max_Phi_end']:.1e}" if "max_Phi_end" in r else "")
        print(f"  {r['route']:<12} rtol {r['rtol']:.0e}: {r['wall_s']:.4f} s, error "
              f"{r['error']:.2e}{extra}")
    for rtol in (1e-8, 1e-10):
        by = {r["route"]: r for r in rows if r["rtol"] == rtol and "wall_s" in r}
        c = by["jourdain"]["wall_s"]
        print(f"  rtol {rtol:.0e}: sympy+scipy / jourdain = {by['sympy+scipy']['wall_s'] / c:.1f}x, "
              f"jourdain's SciPy engine / C engine = {by['jd+scipy']['wall_s'] / c:.1f}x "
              f"(errors {by['jourdain']['error']:.1e}, {by['sympy+scipy']['error']:.1e})")
    print(f"  (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)")


if __name__ == "__main__":
    main()
