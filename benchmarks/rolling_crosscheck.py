"""Cross-check of jourdain's general systems (velocity constraints) at scale: the wheeled snake
(:func:`jourdain.models.wheeled.snake`, n links on knife edges, f = n + 2, n velocity rows).

At ``--states`` random states, jourdain's ``System.evaluate`` (the velocity map
``ẏ = L·z + l`` from ``W = [Y; A]``, ``M = LᵀM_tree·L``, the multipliers by least norm)
against the augmented (index-1) system formed here from the open tree's numbers
(:func:`jourdain.numeric.evaluate` of ``system.tree``) and the rows' ``A``, ``c`` of the
constraint stage substituted by SymEngine::

    [M_tree  −Aᵀ] [ÿ]   [q − k]
    [A        0 ] [λ] = [ −c  ]

which shares no step of :mod:`jourdain.loops.general`. Columns: ``ydd`` and ``lambda``, the
largest difference relative to the largest entry of the reference, the largest condition
number of the augmented matrix (the errors stay within cond·eps of the scale), and the
wall time of the derivation, code generation and compilation (the first evaluation).

    .venv/bin/python benchmarks/rolling_crosscheck.py --n 62       # f = 64 (minutes: compiling)
    .venv/bin/python benchmarks/rolling_crosscheck.py --n 4        # the test's tiny case
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
import symengine as se

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import jourdain as jd  # noqa: E402
from jourdain.models.wheeled import snake  # noqa: E402
from jourdain.numeric import evaluate as tree_evaluate  # noqa: E402


def reference(system: jd.System, y: np.ndarray, yd: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, float]:
    """ÿ, λ of the augmented system at (y, ẏ), and its condition number."""
    tr = tree_evaluate(system.tree, y, yd)
    con = system.constraints()
    subs = {se.Symbol(k): v for k, v in system.parameters}
    subs.update({c: float(v) for c, v in zip(system.tree.coordinates, y, strict=True)})
    subs.update({jd.rate(c): float(v) for c, v in zip(system.tree.coordinates, yd, strict=True)})
    A = np.array([[float(e.subs(subs)) for e in row] for row in con.A.rows])
    c = np.array([float(r[0].subs(subs)) for r in con.c.rows])
    f, r = system.f, A.shape[0]
    K = np.block([[tr["M"], -A.T], [A, np.zeros((r, r))]])
    x = np.linalg.solve(K, np.concatenate([np.ravel(tr["q"] - tr["k"]), -c]))
    return x[:f], x[f:], float(np.linalg.cond(K))


def case(n: int, states: int, seed: int = 1) -> dict:
    system = snake(n)
    rng = np.random.default_rng(seed)
    start = time.perf_counter()
    out: dict = {"n": n, "f": system.f, "ydd": 0.0, "lambda": 0.0, "cond": 0.0}
    for k in range(states):
        y = rng.uniform(-0.3, 0.3, system.f)
        yd = rng.uniform(-1.0, 1.0, system.f)
        ev = system.evaluate(y, yd)
        if k == 0:
            out["first_evaluation_s"] = time.perf_counter() - start
        ydd, lam, cond = reference(system, ev["y"], ev["yd"])
        out["ydd"] = max(out["ydd"], float(np.max(np.abs(ev["ydd"] - ydd)) / np.max(np.abs(ydd))))
        out["lambda"] = max(out["lambda"],
                            float(np.max(np.abs(ev["lambda"] - lam)) / np.max(np.abs(lam))))
        out["cond"] = max(out["cond"], cond)
    return out


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[62])
    ap.add_argument("--states", type=int, default=3)
    ap.add_argument("--json", action="store_true", help="one JSON object per model")
    args = ap.parse_args(argv)
    rows = [case(n, args.states) for n in args.n]
    for r in rows:
        if args.json:
            print(json.dumps(r))
        else:
            print(f"snake n = {r['n']:3d} (f = {r['f']:3d}): ydd {r['ydd']:.1e}, lambda "
                  f"{r['lambda']:.1e}, cond {r['cond']:.1e}, cond·eps {r['cond'] * 2.2e-16:.1e}"
                  f"; first evaluation {r['first_evaluation_s']:.1f} s")
    return rows


if __name__ == "__main__":
    main()
