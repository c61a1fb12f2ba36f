"""Own C step loop or a maintained integrator? The decision written in
``jourdain.numeric.integrator_c``'s docstring, measured: the same compiled right-hand side
(``jd_rhs``: ÿ = M⁻¹(q − k) and the work W) of the n-link pendulum on a cart (10 s from the
hanging position, as in ``benchmarks/simulation.py``) under jourdain's DOP853 loop in C, SciPy's
``solve_ivp`` (DOP853, LSODA: one ctypes call from Python per evaluation) and SUNDIALS CVODE
(Adams, through scikit-sundae when it is installed: ``pip install scikit-sundae``), each at the
loosest tolerance whose final state is as close to the reference (jourdain at 1e-12) as the C
loop's at rtol = atol = 1e-8.

Usage::

    python benchmarks/integrators.py            # n = 4 and 12
    python benchmarks/integrators.py --n 4 --rounds 5
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.simulation import T_END, TOL, best_of, initial_state  # noqa: E402
from jourdain import numeric  # noqa: E402
from jourdain.models import n_link_pendulum_on_cart  # noqa: E402
from jourdain.simulation.problem import _Setup  # noqa: E402
from jourdain.simulation.simulate import integrator_library  # noqa: E402

#: tolerances tried for each integrator of the decision (rtol = atol), loosest first
DECISION_TOLS = tuple(float(f"{m}e{e}") for e in range(-5, -13, -1) for m in (7, 5, 3, 2, 1.5, 1))


def bench_integrators(n: int, rounds: int) -> list[dict]:
    """jourdain's C loop, SciPy and CVODE on the same compiled right-hand side of the n-link
    pendulum on a cart, each at the loosest tolerance as accurate as the C loop at 1e-8."""
    import ctypes

    from scipy.integrate import solve_ivp

    s = n_link_pendulum_on_cart(n)
    y0, yd0 = initial_state(n)
    f = s.f
    x0 = np.concatenate([y0, yd0, [0.0]])
    ref = s.simulate((0, T_END), y0, yd0, inputs={"F": 0.0}, rtol=1e-12, atol=1e-12)
    x_ref = np.concatenate([ref.y[-1], ref.yd[-1]])
    lib = integrator_library()
    setup = _Setup(s, numeric.mkq_function(s), numeric.parameter_vector(s, None), {"F": 0.0}, (),
                   1, TOL, np.full(2 * f + 1, TOL), math.inf, 0.0)
    problem = ctypes.byref(setup.problem)
    fail = np.zeros(2 * f + 2)
    nfev = [0]

    def rhs_into(t: float, x: np.ndarray, dx: np.ndarray) -> None:
        nfev[0] += 1
        if lib.jd_rhs(problem, float(t), x.ctypes.data, dx.ctypes.data, fail.ctypes.data):
            raise RuntimeError(f"right-hand side failed at t = {t}")

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        dx = np.empty(2 * f + 1)
        rhs_into(t, np.ascontiguousarray(x), dx)
        return dx

    def c_loop(tol: float) -> np.ndarray:
        r = s.simulate((0, T_END), y0, yd0, inputs={"F": 0.0}, rtol=tol, atol=tol)
        nfev[0] = r.nfev
        return np.concatenate([r.y[-1], r.yd[-1]])

    def scipy_run(method: str):
        def run(tol: float) -> np.ndarray:
            nfev[0] = 0
            sol = solve_ivp(rhs, (0, T_END), x0, method=method, rtol=tol, atol=tol)
            return sol.y[:2 * f, -1]
        return run

    tools = [("jourdain DOP853 (C loop)", c_loop), ("SciPy solve_ivp DOP853", scipy_run("DOP853")),
             ("SciPy solve_ivp LSODA", scipy_run("LSODA"))]
    try:
        from sksundae.cvode import CVODE
    except ImportError:
        print("   scikit-sundae not installed: CVODE skipped (pip install scikit-sundae)")
    else:
        def cvode(tol: float) -> np.ndarray:
            nfev[0] = 0
            solver = CVODE(lambda t, x, dx: rhs_into(t, x, dx), method="Adams", rtol=tol,
                           atol=tol, max_num_steps=10**6)
            return solver.solve(np.array([0.0, T_END]), x0).y[-1, :2 * f]
        tools.append(("SUNDIALS CVODE Adams (sksundae)", cvode))
    target = float(np.abs(c_loop(TOL) - x_ref).max())
    rows = []
    for label, run in tools:
        for tol in DECISION_TOLS:
            err = float(np.abs(run(tol) - x_ref).max())
            if err <= target:
                evals = nfev[0]
                t = math.inf
                for _ in range(rounds):
                    t = min(t, best_of(lambda run=run, tol=tol: run(tol), repeat=1, min_time=0.05))
                rows.append({"tool": label, "rtol": tol, "error": err, "nfev": evals, "time": t})
                break
        else:
            rows.append({"tool": label, "rtol": None, "error": None, "nfev": None, "time": None})
    return rows


def print_integrators(ns: list[int], rounds: int) -> list[dict]:
    print("Own C step loop against maintained integrators, the same compiled right-hand side, "
          "equal final-state accuracy (the C loop's at rtol = atol = 1e-8)")
    print(f"{'n':>2} {'integrator':<34} {'rtol':>8} {'|x-x_ref|':>10} {'rhs evals':>10} "
          f"{'time ms':>9} {'vs C loop':>9}")
    out = []
    for n in ns:
        rows = bench_integrators(n, rounds)
        base = rows[0]["time"]
        for r in rows:
            if r["time"] is None:
                print(f"{n:>2} {r['tool']:<34} no tolerance of the grid reaches the accuracy")
                continue
            print(f"{n:>2} {r['tool']:<34} {r['rtol']:>8.2g} {r['error']:>10.2e} {r['nfev']:>10d} "
                  f"{1e3 * r['time']:>9.3f} {r['time'] / base:>8.1f}x")
        out.append({"n": n, "integrators": rows})
    print()
    return out


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="*", default=[4, 12])
    ap.add_argument("--rounds", type=int, default=5, help="timing rounds, best taken")
    args = ap.parse_args(argv)
    return print_integrators(args.n, args.rounds)


if __name__ == "__main__":
    main()
