"""Child process of tests/reference/test_tree_pinocchio.py: one model against Pinocchio.

    python -m tests.reference.tree_crosscheck '{"kind": "tree", "n": 6, "seed": 2, "states": 4}'

from the repository root (``"options"``: keyword arguments of
:func:`jourdain.models.random_tree_data`); the parent sets ``PYTHONHASHSEED`` and a private
``JOURDAIN_CACHE``. Prints one JSON line: per check the largest error over the states and the
largest ratio of error to tolerance (``<check>_ratio``, at most 1 to pass; tolerances from
tests/tolerance.py), the smallest eigenvalue and the largest condition number of M, and SHA-256
digests of the generated C sources and of M and g at all states, which must not depend on the
process.

Checks at ``y = 0.1·(1, …, 1), ẏ = 0`` and at random states (benchmarks/crosscheck.py builds
both models and evaluates both tools):

* ``M``, ``M_sym``: M against CRBA, and M symmetric; a direct evaluation:
  ``eval_tol(6p, max(|J̄|ᵀ|M̄||J̄|))``;
* ``spd``: ``λ_min(M) > 10·f·eps·‖M‖`` (positive beyond rounding); the ratio is the bound
  over λ_min;
* ``nle``: ``k − q`` against ``nonLinearEffects``:
  ``eval_tol(6p, max(|J̄|ᵀ|q̄^c| + |J̄|ᵀ|q̄^e|))``;
* ``aba``: ÿ = M⁻¹(q − k) against ABA: two solves, ``2·ydd_tol``;
* ``tau``: RNEA at that ÿ is zero up to the residual of the solve and the differences above;
* ``rnea``, ``rnea_g``: each joint's wrench ``Σ g_k·w_k`` against RNEA's ``data.f``, and
  ``W·f`` against ``g``: ``subtree_tol`` (g from N̂·g = k̂ − q̂, the RNEA force from the
  sub-tree's Newton–Euler equations with jourdain's ÿ), the extent from Pinocchio's frames.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time

import numpy as np

from benchmarks.crosscheck import build, compare, source_digest, states
from tests.tolerance import (
    EPS,
    eom_terms,
    eval_tol,
    gram_solve_tol,
    norm,
    residual_bound,
    solve_scale,
    subtree_tol,
    ydd_tol,
)


def extent(points: np.ndarray) -> float:
    """The largest distance between any two of ``points`` and the inertial origin (the
    ``extent`` of :func:`tests.tolerance.subtree_tol`)."""
    pts = np.vstack([points, np.zeros((1, 3))])
    return float(np.max(np.linalg.norm(pts[:, None, :] - pts[None, :, :], axis=-1)))


def wrench_tol(out: dict, ydd: np.ndarray, ext: float) -> float:
    """:func:`tests.tolerance.subtree_tol`; for a model without constrained directions (free
    joints only: g and N̂ empty, which newton_euler_tol does not take) the same without the
    term of g."""
    if np.size(out["g"]):
        return subtree_tol(out, ydd, ext)
    Mb = np.asarray(out["M_bar"])
    MJ = Mb @ out["J_bar"]
    tol = gram_solve_tol(out["M"], norm(Mb), solve_scale(out["M"], ydd, eom_terms(out)))
    tol += eval_tol(MJ.shape[0], norm(MJ @ ydd) + norm(out["q_c"]) + norm(out["q_e"]))
    return float(np.sqrt(Mb.shape[0] // 6)) * (1.0 + ext) * tol


def judge(c: dict) -> dict[str, tuple[float, float]]:
    """``{check: (error, tolerance)}`` for one :func:`benchmarks.crosscheck.compare` result."""
    out = c["out"]
    M, k, q, ydd = out["M"], out["k"], out["q"], c["ydd"]
    Mb, Jb = np.abs(out["M_bar"]), np.abs(out["J_bar"])
    n_terms = Jb.shape[0]  # 6p rows projected
    tol_M = eval_tol(n_terms, float((Jb.T @ Mb @ Jb).max()))
    kc, qe = eom_terms(out)
    tol_nle = eval_tol(n_terms, float((kc + qe).max()))
    lam = float(np.linalg.eigvalsh(0.5 * (M + M.T)).min())
    tol_tau = (residual_bound(M, ydd, q - k, b_scale=norm(kc) + norm(qe))
               + tol_M * float(np.abs(ydd).sum()) + tol_nle)
    tol_w = wrench_tol(out, ydd, extent(c["points"]))
    d_wrench = max(np.abs(a - b).max() for a, b in zip(c["wrench"], c["wrench_pin"], strict=True))
    d_g = max((np.abs(W @ f - g).max() for W, g, f in zip(c["W"], c["g"], c["wrench_pin"],
                                                           strict=True) if g.size), default=0.0)
    return {
        "M": (float(np.abs(M - c["M_pin"]).max()), tol_M),
        "M_sym": (float(np.abs(M - M.T).max()), tol_M),
        "spd": (10.0 * M.shape[0] * EPS * norm(M), max(lam, 0.0)),
        "nle": (float(np.abs(k - q - c["nle_pin"]).max()), tol_nle),
        "aba": (float(np.abs(ydd - c["aba"]).max()), 2.0 * ydd_tol(out, ydd)),
        "tau": (float(np.abs(c["tau"]).max()), tol_tau),
        "rnea": (float(d_wrench), tol_w),
        "rnea_g": (float(d_g), tol_w),
    }


def run(spec: dict) -> dict:
    t0 = time.perf_counter()
    system, model, index = build(spec["kind"], int(spec["n"]), int(spec.get("seed", 0)),
                                 **spec.get("options", {}))
    result: dict = {"f": system.f, "hashseed": os.environ.get("PYTHONHASHSEED"),
                    "perm_identity": bool(np.array_equal(index.v, np.arange(system.f)))}
    hm, hg = hashlib.sha256(), hashlib.sha256()
    lam_min, cond_max = np.inf, 0.0
    for y, yd in states(system.f, int(spec.get("states", 4)), int(spec.get("state_seed", 1))):
        c = compare(system, model, index, y, yd)
        if "t_first_s" not in result:
            result["t_first_s"] = time.perf_counter() - t0
        M = c["out"]["M"]
        hm.update(np.ascontiguousarray(M).tobytes())
        hg.update(np.ascontiguousarray(c["out"]["g"]).tobytes())
        lam_min = min(lam_min, float(np.linalg.eigvalsh(0.5 * (M + M.T)).min()))
        cond_max = max(cond_max, float(np.linalg.cond(M)))
        for name, (err, tol) in judge(c).items():
            ratio = err / tol if tol > 0 else np.inf
            result[name] = max(result.get(name, 0.0), err)
            result[f"{name}_ratio"] = max(result.get(f"{name}_ratio", 0.0), ratio)
    result.update({"eig_min": lam_min, "cond_max": cond_max,
                   "source_sha256": source_digest(system), "M_sha256": hm.hexdigest(),
                   "g_sha256": hg.hexdigest(), "t_total_s": time.perf_counter() - t0})
    return result


if __name__ == "__main__":
    print(json.dumps(run(json.loads(sys.argv[1]))))
