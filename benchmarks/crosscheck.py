"""Cross-check of jourdain against Pinocchio at scale, every model in a fresh process.

For each model, a new Python process (with the given ``PYTHONHASHSEED`` and its own empty
``JOURDAIN_CACHE``, so nothing is inherited: no memory history, no compiled library) derives
and compiles the equations of motion and the reactions, and compares at one state
``y = 0.1·(1, …, 1)``, ``ẏ = 0`` (the table of issue 10) and at ``--states`` random states
(``y`` uniform in (-π, π), ``ẏ`` in (-3, 3)) with Pinocchio built from the same data
(``benchmarks/pinocchio_models.py``). Columns, each the largest over the states:

* ``M(0.1)``, ``λ_min(0.1)``: at ``y = 0.1·(1, …, 1)``, ``ẏ = 0`` only, the error of M (as
  the next column) and the smallest eigenvalue of M (issue 10: an indefinite M at f = 48);
* ``M``: ``max|M − M_crba| / max|M_crba|`` (CRBA symmetrized from its upper triangle);
* ``λ_min``: the smallest eigenvalue of M (the smallest over the states; must be > 0);
* ``cond``: the largest 2-norm condition number of M;
* ``nle``: ``max|k − q − nle| / max|nle|`` (Pinocchio's ``nonLinearEffects``);
* ``aba``: ``max|ÿ − ÿ_aba| / max|ÿ_aba|``, ÿ = M⁻¹(q − k) (LU of jourdain's M);
* ``rnea``: ``max|Σ g_k·w_k − f|`` over the joints, ``f`` = RNEA's ``data.f`` of the joint's
  last elementary Pinocchio joint with ÿ from jourdain, ``g`` jourdain's reactions and ``w_k``
  its constrained directions (the joint wrench in the child body frame at the joint), relative
  to the largest of ``|f|``, ``|q̄^e|`` and ``|q̄^c|`` (a free-floating tree at rest falls as one
  and its joint wrenches vanish);
* ``τ``: ``max|rnea(y, ẏ, ÿ)| / max|nle|`` (zero up to rounding: no actuators);
* ``first``: the model's first run against its compiled library, bit for bit (:func:`first_run`:
  a motion of 0.3 s, and M, k, q at the states): ``same``, else ``DIFFERS`` (and the exit
  status is 1). The fresh cache holds nothing, so the first run is what a user's first run is:
  the recursions' engines sized at run time, the interpreter, or an -O0 build. (It found GCC
  12's vectorizer fusing multiply-adds in ``random_tree(70, 3)``'s -O2 library:
  numeric/native.py, ``NO_FUSED``.)
* ``time``: the child's wall time (imports, derivation, code generation, C compilation, all
  states), and ``source``: the start of the SHA-256 of the generated C sources.

Models: ``spatial_chain(n)`` for ``--n`` and ``random_tree(n, seed)`` for ``--tree`` (branching,
revolute, prismatic, universal, spherical and a free root, all about random axes).

    .venv/bin/python benchmarks/crosscheck.py --n 8 16 24 32
    .venv/bin/python benchmarks/crosscheck.py --tree 10 20 35 --hashseed 12345
    .venv/bin/python benchmarks/crosscheck.py --n 4 --json      # one JSON object per model

A child runs ``crosscheck.py --child '{"kind": "tree", "n": 10, "seed": 0, "states": 5}'``
and prints one JSON line (see :func:`case`).
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
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def build(kind: str, n: int, seed: int = 0, **options: Any) -> tuple[Any, Any, Any]:
    """``(system, pinocchio model, TreeIndex)`` of ``spatial_chain(n, seed)`` (``kind`` "chain")
    or ``random_tree(n, seed, **options)`` (``kind`` "tree")."""
    from benchmarks.pinocchio_models import chain_index, chain_model, tree_model
    from jourdain.models import random_tree_data, spatial_chain_data, tree_from_data
    from jourdain.models import spatial_chain as make_chain

    if kind == "chain":
        data = spatial_chain_data(n, seed)
        return make_chain(n, seed), chain_model(data), chain_index(data)
    if kind == "tree":
        data = random_tree_data(n, seed, **options)
        model, index = tree_model(data)
        return tree_from_data(data, name=f"random tree of {n} bodies (seed {seed})"), model, index
    raise ValueError(f'kind must be "chain" or "tree", got {kind!r}')


def states(f: int, count: int, seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    """``y = 0.1·(1, …, 1), ẏ = 0`` (issue 10), then ``count`` random states."""
    rng = np.random.default_rng(seed)
    out = [(np.full(f, 0.1), np.zeros(f))]
    out += [(rng.uniform(-np.pi, np.pi, f), rng.uniform(-3.0, 3.0, f)) for _ in range(count)]
    return out


def compare(system: Any, model: Any, index: Any, y: np.ndarray, yd: np.ndarray) -> dict:
    """jourdain's and Pinocchio's numbers at one state, both in jourdain's coordinate order.

    Returns a dict: ``out`` (:meth:`System.evaluate`'s dict), ``ydd`` (M⁻¹(q − k)),
    ``M_pin`` (CRBA, symmetrized), ``nle_pin``, ``aba`` (ÿ by ABA), ``tau`` (RNEA at ÿ),
    ``wrench`` and ``wrench_pin`` (6-vectors per joint: ``Σ g_k·w_k`` and RNEA's ``data.f``,
    force then torque, child body frame at the joint point), ``W`` (per joint its constrained
    directions, rows), ``g`` (per joint its reactions) and ``points`` (2p×3: per body its
    frame's origin, the joint point, and its centre of mass in the inertial frame, by Pinocchio).
    """
    import pinocchio as pin

    from jourdain.stages.reactions import graph_values

    data = model.createData()
    out = system.evaluate(y, yd)
    if "reactions_error" in out:
        raise RuntimeError(out["reactions_error"])
    M, k, q = out["M"], out["k"], out["q"]
    ydd = np.linalg.solve(M, q - k)
    qp, vp = index.to_pinocchio(y), index.to_pinocchio(yd)
    Mp = pin.crba(model, data, qp)
    Mp = np.triu(Mp) + np.triu(Mp, 1).T  # CRBA fills the upper triangle
    res = {"out": out, "ydd": ydd, "M_pin": index.from_pinocchio(Mp),
           "nle_pin": index.from_pinocchio(pin.nonLinearEffects(model, data, qp, vp)),
           "aba": index.from_pinocchio(pin.aba(model, data, qp, vp, np.zeros(model.nv)))}
    res["tau"] = index.from_pinocchio(pin.rnea(model, data, qp, vp, index.to_pinocchio(ydd)))
    pin.forwardKinematics(model, data, qp)
    frames = [data.oMi[int(j)] for j in index.joint]
    res["points"] = np.array([x for o, j in zip(frames, index.joint, strict=True)
                              for x in (o.translation, o.act(model.inertias[int(j)].lever))])
    values = {**dict(zip(system.parameter_symbols, system.parameter_values.values(),
                         strict=True)), **dict(zip(system.y, y, strict=True))}
    res["W"], res["g"], res["wrench"], res["wrench_pin"] = [], [], [], []
    for jr, pid in zip(_joints(system), index.joint, strict=True):
        exprs = [x for w in jr.wrenches for x in w]
        W = np.array(graph_values(exprs, values), dtype=float).reshape(len(jr.names), 6)
        g = out["g"][list(jr.columns)]
        fp = data.f[int(pid)]
        res["W"].append(W)
        res["g"].append(g)
        res["wrench"].append(g @ W)
        res["wrench_pin"].append(np.concatenate([fp.linear, fp.angular]))
    return res


@lru_cache(maxsize=8)
def _joints(system: Any) -> tuple:
    """The joints' constrained directions (:meth:`System.reactions`), once per system."""
    return system.reactions().joints


def errors(c: dict) -> dict:
    """Relative errors of one :func:`compare` result (see the module docstring)."""
    out = c["out"]
    M, Mp, nle = out["M"], c["M_pin"], c["nle_pin"]
    # a free-floating tree at rest falls as one: its joint wrenches vanish, so they are
    # measured against the loads as well (the largest of q̄^e, q̄^c)
    fmax = max(max(np.abs(w).max() for w in c["wrench_pin"]), np.abs(out["q_e"]).max(),
               np.abs(out["q_c"]).max(), np.finfo(float).tiny)
    return {
        "M": float(np.abs(M - Mp).max() / np.abs(Mp).max()),
        "eig_min": float(np.linalg.eigvalsh(0.5 * (M + M.T)).min()),
        "cond": float(np.linalg.cond(M)),
        "nle": float(np.abs(out["k"] - out["q"] - nle).max() / max(np.abs(nle).max(), 1e-300)),
        "aba": float(np.abs(c["ydd"] - c["aba"]).max() / max(np.abs(c["aba"]).max(), 1e-300)),
        "rnea": float(max(np.abs(a - b).max() for a, b in zip(c["wrench"], c["wrench_pin"],
                                                               strict=True)) / fmax),
        "tau": float(np.abs(c["tau"]).max() / max(np.abs(nle).max(), 1e-300)),
    }


def source_digest(system: Any) -> str:
    """SHA-256 over the generated C sources of the equations of motion and the reactions of
    ``system`` (as cached in :func:`jourdain.numeric.cache_dir`, named by their content key)."""
    from jourdain.analysis.reactions import _reactions_function
    from jourdain.numeric import _eom_function, cache_dir

    keys = dict.fromkeys([_eom_function(system).key, _reactions_function(system)[1].key])
    h = hashlib.sha256()
    for key in keys:  # the reactions may reuse the compiled equations of motion
        h.update((cache_dir() / f"{key}.c").read_bytes())
    return h.hexdigest()


def first_run(system: Any, at: list[tuple[np.ndarray, np.ndarray]]) -> dict:
    """The first run of ``system`` (:func:`jourdain.numeric.first_run.run_function`, its
    library's build held back) and then its compiled library: whether a motion of 0.3 s from
    the second state of ``at`` and M, k, q at all of them are the same to the bit, and the
    kinds of the two functions."""
    from jourdain.numeric import first_run as runs

    jobs: list = []
    soon = runs.build_soon
    runs.build_soon = lambda fn, *args, **kw: jobs.append((fn, args))  # built below instead
    start = at[min(1, len(at) - 1)]
    try:
        first = runs.run_function(system)
        motions = [system.simulate((0.0, 0.3), *start)]
    finally:
        runs.build_soon = soon
    for fn, args in jobs:
        fn(*args)
    final = runs.run_function(system)
    motions.append(system.simulate((0.0, 0.3), *start))
    Y, YD = np.array([y for y, _ in at]), np.array([yd for _, yd in at])
    one, other = first.batch(Y, YD), final.batch(Y, YD)
    same = (all(one[k].tobytes() == other[k].tobytes() for k in ("M", "k", "q"))
            and all(getattr(motions[0], k).tobytes() == getattr(motions[1], k).tobytes()
                    for k in ("t", "y", "ydd")))
    return {"first_same": same, "first_kind": type(first).__name__,
            "final_kind": type(final).__name__}


def case(kind: str, n: int, seed: int = 0, n_states: int = 5, state_seed: int = 1) -> dict:
    """One model in this process: f, the largest relative errors over the states of
    :func:`states`, the smallest eigenvalue of M, the source digest, SHA-256 of M and g at all
    states (for bit-for-bit comparison between processes) and timings."""
    t0 = time.perf_counter()
    system, model, index = build(kind, n, seed)
    worst: dict[str, float] = {}
    hm, hg = hashlib.sha256(), hashlib.sha256()
    t_first = None
    for y, yd in states(system.f, n_states, state_seed):
        c = compare(system, model, index, y, yd)
        if t_first is None:
            t_first = time.perf_counter() - t0
        hm.update(np.ascontiguousarray(c["out"]["M"]).tobytes())
        hg.update(np.ascontiguousarray(c["out"]["g"]).tobytes())
        errs = errors(c)
        if not worst:  # y = 0.1·(1, …, 1), ẏ = 0: where issue 10 found an indefinite M
            worst.update({"M_0": errs["M"], "eig_min_0": errs["eig_min"]})
        for key, e in errs.items():
            better = min if key == "eig_min" else max
            worst[key] = better(worst.get(key, e), e)
    t_total = time.perf_counter() - t0
    # after the timed part, still a first run: the reactions above use their own library
    first = first_run(system, states(system.f, n_states, state_seed))
    return {"kind": kind, "n": n, "seed": seed, "f": system.f, "states": n_states + 1,
            **worst, **first, "source_sha256": source_digest(system), "M_sha256": hm.hexdigest(),
            "g_sha256": hg.hexdigest(), "t_first_s": t_first,
            "t_total_s": t_total,
            "hashseed": os.environ.get("PYTHONHASHSEED")}


def spawn(spec: dict, hashseed: int | str, cache: str | os.PathLike | None = None,
          timeout: float | None = None, module: str | None = None) -> dict:
    """Run ``spec`` in a fresh process with ``PYTHONHASHSEED=hashseed`` and ``JOURDAIN_CACHE``
    = ``cache`` (default: a new empty temporary directory, deleted afterwards); returns the JSON
    it prints, with ``wall_s`` (the child's wall time, start-up included) added.

    ``module``: run ``python -m module spec`` instead of this script's ``--child`` mode (the
    reference tests' child, which adds tolerances), from the repository root.
    """
    env = {**os.environ, "PYTHONHASHSEED": str(hashseed)}
    tmp = None
    if cache is None:
        tmp = tempfile.TemporaryDirectory(prefix="jourdain-crosscheck-")
        cache = tmp.name
    env["JOURDAIN_CACHE"] = str(cache)
    cmd = ([sys.executable, "-m", module, json.dumps(spec)] if module else
           [sys.executable, str(Path(__file__).resolve()), "--child", json.dumps(spec)])
    try:
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True,
                              timeout=timeout)
        wall = time.perf_counter() - t0
    finally:
        if tmp is not None:
            tmp.cleanup()
    if proc.returncode != 0:
        raise RuntimeError(f"child {spec} (PYTHONHASHSEED={hashseed}) failed with exit code "
                           f"{proc.returncode}:\n{proc.stderr[-4000:]}")
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    result["wall_s"] = wall
    return result


HEADER = (f"{'model':<22}{'f':>4}{'M(0.1)':>9}{'λ_min(0.1)':>11}{'M':>9}{'λ_min':>10}"
          f"{'cond':>9}{'nle':>9}{'aba':>9}{'rnea':>9}{'τ':>9}{'first':>8}{'time/s':>8}  source")


def row(r: dict) -> str:
    """One line of the table under :data:`HEADER`."""
    name = (f"spatial_chain({r['n']})" if r["kind"] == "chain"
            else f"random_tree({r['n']}, {r['seed']})")
    return (f"{name:<22}{r['f']:>4}{r['M_0']:>9.1e}{r['eig_min_0']:>11.2e}{r['M']:>9.1e}"
            f"{r['eig_min']:>10.2e}{r['cond']:>9.1e}{r['nle']:>9.1e}{r['aba']:>9.1e}"
            f"{r['rnea']:>9.1e}{r['tau']:>9.1e}{'same' if r['first_same'] else 'DIFFERS':>8}"
            f"{r['wall_s']:>8.1f}  {r['source_sha256'][:12]}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--n", type=int, nargs="*", default=[], help="spatial_chain lengths")
    p.add_argument("--tree", type=int, nargs="*", default=[], help="random_tree sizes")
    p.add_argument("--seed", type=int, default=0, help="model seed (default 0)")
    p.add_argument("--states", type=int, default=5, help="random states besides y = 0.1·1")
    p.add_argument("--hashseed", default="0", help="PYTHONHASHSEED of the children")
    p.add_argument("--cache", default=None,
                   help="JOURDAIN_CACHE of the children (default: a fresh empty one each)")
    p.add_argument("--timeout", type=float, default=None, help="seconds per model")
    p.add_argument("--json", action="store_true", help="one JSON object per model")
    p.add_argument("--child", default=None, help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.child is not None:
        s = json.loads(a.child)
        print(json.dumps(case(s["kind"], int(s["n"]), int(s.get("seed", 0)),
                              int(s.get("states", 5)), int(s.get("state_seed", 1)))))
        return 0
    specs = ([{"kind": "chain", "n": n, "seed": a.seed, "states": a.states} for n in a.n]
             + [{"kind": "tree", "n": n, "seed": a.seed, "states": a.states} for n in a.tree])
    if not specs:
        specs = [{"kind": "chain", "n": n, "seed": a.seed, "states": a.states}
                 for n in (8, 16, 24, 32)]
    if not a.json:
        print(f"PYTHONHASHSEED={a.hashseed}; errors relative to the largest entry, the largest "
              f"over y = 0.1·1, ẏ = 0 and {a.states} random states")
        print(HEADER)
    differ = 0
    for spec in specs:
        r = spawn(spec, a.hashseed, a.cache, a.timeout)
        print(json.dumps(r) if a.json else row(r), flush=True)
        differ += not r["first_same"]
    return 1 if differ else 0


if __name__ == "__main__":
    raise SystemExit(main())
