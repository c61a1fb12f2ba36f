"""Scaling of jourdain with the number of coordinates f (issue 13), every model in a fresh process.

Models: ``spatial_chain(n)`` for ``--n`` (default n = 4 … 64, f = 7 … 127) and
``random_tree(n, seed)`` for ``--tree`` (default: per chain, the tree whose f is closest). Each
row runs in a new Python process with its own empty ``JOURDAIN_CACHE`` (nothing compiled, no
memory history; :func:`benchmarks.crosscheck.spawn`) and measures, in this order:

* ``first s``: time to first number: the model is built, then the clock runs until the first
  ``system.evaluate(y, ẏ)`` returns (y = 0.1·(1, …, 1), ẏ = 0; M̄, J̄, q̄^c, q̄^e, M, k, q and
  the reactions: code generation and C compilation included);
* ``source kB``: bytes of the generated C (``<key>.c`` files in the cache) at that point;
* ``RSS1 MB``: the child's peak resident memory at that point (``ru_maxrss``);
* ``mkq s``: compiling :func:`jourdain.numeric.mkq_function` (the integrator's M, k, q, ÿ)
  afterwards; ``path``: ``rec`` where it is the recursion, ``sym`` where it is the symbolic
  projection's straight-line code (small models; the joint wrenches then come from
  :func:`jourdain.numeric.dynamics_function`, compiled in this column too); ``all kB``: the
  generated C in the cache after it;
* ``M,k,q µs`` and ``ÿ+W µs``: per state, ``fn.batch`` (M, k, q) and ``fn.dynamics`` (ÿ and
  every joint wrench) on ``--states`` random states in one C call, best of ``--repeat``
  (interleaved; the output array preallocated and touched once);
* ``derive s``: the symbolic ``system.equations_of_motion()`` (not needed for the numbers
  above, which come from the compiled recursion; measured last so that it cannot warm them);
* ``derive MB``: the memory the derivation added and holds, the C heap in use after it minus
  before it (glibc's mallinfo2; 0 without it): the expression graph of M, k, q and their
  stages. The peak RSS of a process that derives only, and sympy's, are in
  ``benchmarks/derivation.py``;
* ``RSS MB``: the child's peak resident memory over everything, derivation included;
* ``wall s``: the child's wall time, interpreter start-up and imports included.

Each model runs in ``--trials`` fresh processes (default 3; the trials of all models in turn),
and every time and memory column is the smallest over them: on a shared machine other work only
ever adds to a measurement.

Below the table: the growth exponents, log-log slopes between the smallest and the largest f
of each family, of the time to first number, the source size, the derivation and the per-state
costs (issue 13's target for the first two: at most 2, i.e. O(f²)).

    .venv/bin/python benchmarks/scaling.py                  # the full table (a few minutes)
    .venv/bin/python benchmarks/scaling.py --n 4 8 --tree   # two chains, no trees
    .venv/bin/python benchmarks/scaling.py --quick          # chains 2, 4 and trees 2, 3
    .venv/bin/python benchmarks/scaling.py --json out.json

A child runs ``python -m benchmarks.scaling '{"kind": "chain", "n": 8, ...}'`` and prints one
JSON line (:func:`case`).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

CHAINS = (4, 8, 12, 16, 24, 32, 48, 64)
QUICK_CHAINS, QUICK_TREES = (2, 4), (2, 3)


def _rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


def _source_bytes() -> int:
    from jourdain.numeric import cache_dir

    return sum(p.stat().st_size for p in cache_dir().glob("*.c"))


def case(kind: str, n: int, seed: int = 0, n_states: int = 1000, repeat: int = 3) -> dict:
    """One model, measured in this process (which should be fresh, with an empty cache)."""
    t0 = time.perf_counter()
    import numpy as np

    from jourdain.models import random_tree, spatial_chain
    from jourdain.numeric import dynamics_function, mkq_function

    t_import = time.perf_counter() - t0
    from benchmarks.per_state import interleaved  # the interleaved best-of timing (not timed)

    t0 = time.perf_counter()
    system = spatial_chain(n, seed) if kind == "chain" else random_tree(n, seed)
    t_build = time.perf_counter() - t0
    f = system.f
    # time to first number: everything System.evaluate needs, compiled from nothing
    t0 = time.perf_counter()
    out = system.evaluate(np.full(f, 0.1), np.zeros(f))
    t_first = time.perf_counter() - t0
    if "reactions_error" in out:
        raise RuntimeError(out["reactions_error"])
    src_first, rss_first = _source_bytes(), _rss_mb()
    # the integrator's compiled M, k, q (and ÿ, wrenches)
    t0 = time.perf_counter()
    fn = mkq_function(system)
    t_mkq = time.perf_counter() - t0
    # small models: mkq_function is the symbolic projection's straight-line code, without
    # the recursion's joint wrenches; those then come from dynamics_function (compiled here)
    fd = fn if fn.n_bodies else dynamics_function(system)
    src_all = _source_bytes()
    rng = np.random.default_rng(1)
    Y = rng.uniform(-np.pi, np.pi, (n_states, f))
    YD = rng.uniform(-3.0, 3.0, (n_states, f))
    p = np.array(list(system.parameter_values.values()))
    buf = np.zeros((n_states, fn.size))  # touched: no page faults inside the timing
    res = fn.batch(Y, YD, 0.0, p, None, out=buf)
    fd.dynamics(Y, YD, 0.0, p, None)
    # the batch agrees with System.evaluate (same state, different compiled function)
    one = fn.batch(np.full((1, f), 0.1), np.zeros((1, f)), 0.0, p, None)
    m_diff = float(np.abs(one["M"][0] - out["M"]).max() / np.abs(out["M"]).max())
    best = interleaved({"batch": lambda: fn.batch(Y, YD, 0.0, p, None, out=buf),
                        "dynamics": lambda: fd.dynamics(Y, YD, 0.0, p, None)}, repeat)
    del res
    from benchmarks.derivation import _heap_mb

    heap_before = _heap_mb()
    t0 = time.perf_counter()
    eom = system.equations_of_motion()
    t_derive = time.perf_counter() - t0
    heap_after = _heap_mb()
    derive_mb = (0.0 if heap_before is None or heap_after is None
                 else heap_after - heap_before)
    del eom
    return {"kind": kind, "n": n, "seed": seed, "f": f, "bodies": len(system.bodies),
            "import_s": t_import, "build_s": t_build, "first_s": t_first,
            "source_bytes": src_first, "rss_first_mb": rss_first, "mkq_s": t_mkq,
            "source_all_bytes": src_all, "mkq_path": "rec" if fn.n_bodies else "sym",
            "batch_us": 1e6 * best["batch"] / n_states,
            "dynamics_us": 1e6 * best["dynamics"] / n_states, "states": n_states,
            "M_vs_evaluate": m_diff, "derive_s": t_derive, "derive_mb": derive_mb,
            "rss_mb": _rss_mb()}


#: measured quantities of which :func:`combine` keeps the smallest over the trials
TIMES = ("import_s", "build_s", "first_s", "mkq_s", "batch_us", "dynamics_us", "derive_s",
         "derive_mb", "wall_s", "rss_first_mb", "rss_mb")


def combine(runs: list[dict]) -> dict:
    """One row from several fresh-process trials of the same model: the smallest of each of
    :data:`TIMES` (a busy machine only ever adds), the rest from the first trial; the generated
    source must be the same in every trial."""
    sizes = {(r["source_bytes"], r["source_all_bytes"]) for r in runs}
    if len(sizes) != 1:
        raise RuntimeError(f"generated source differs between trials: {sorted(sizes)}")
    out = dict(runs[0])
    out.update({k: min(r[k] for r in runs) for k in TIMES})
    out["M_vs_evaluate"] = max(r["M_vs_evaluate"] for r in runs)
    out["trials"] = len(runs)
    return out


def matching_tree(f: int, seed: int = 0, limit: int = 200) -> int:
    """The number of bodies of the ``random_tree(·, seed)`` whose f is closest to ``f``."""
    from jourdain.models import TREE_JOINTS, random_tree_data

    best, best_d = 1, math.inf
    for n in range(1, limit):
        d = abs(sum(TREE_JOINTS[x["joint"]] for x in random_tree_data(n, seed)) - f)
        if d < best_d:
            best, best_d = n, d
        if d == 0:
            break
    return best


HEADER = (f"| {'model':<22} | {'f':>3} | {'bodies':>6} | {'derive s':>8} | {'derive MB':>9} "
          f"| {'first s':>7} "
          f"| {'source kB':>9} | {'mkq s':>5} | {'path':>4} | {'all kB':>6} | {'M,k,q µs':>8} "
          f"| {'ÿ+W µs':>7} | {'RSS1 MB':>7} | {'RSS MB':>6} | {'wall s':>6} |")


def row(r: dict) -> str:
    """One line of the markdown table under :data:`HEADER`."""
    name = (f"spatial_chain({r['n']})" if r["kind"] == "chain"
            else f"random_tree({r['n']}, {r['seed']})")
    return (f"| {name:<22} | {r['f']:>3} | {r['bodies']:>6} | {r['derive_s']:>8.2f} "
            f"| {r['derive_mb']:>9.1f} "
            f"| {r['first_s']:>7.2f} | {r['source_bytes'] / 1e3:>9.1f} | {r['mkq_s']:>5.2f} "
            f"| {r['mkq_path']:>4} | {r['source_all_bytes'] / 1e3:>6.1f} | {r['batch_us']:>8.2f} "
            f"| {r['dynamics_us']:>7.2f} | {r['rss_first_mb']:>7.0f} | {r['rss_mb']:>6.0f} "
            f"| {r['wall_s']:>6.1f} |")


GROWTH = {"first_s": "time to first number", "source_bytes": "generated source",
          "derive_s": "symbolic derivation", "derive_mb": "memory of the derivation",
          "batch_us": "M, k, q per state",
          "dynamics_us": "ÿ + wrenches per state", "rss_first_mb": "peak RSS at first number"}


def growth(rows: list[dict]) -> dict[str, dict[str, float]]:
    """Per family, the log-log slope of each quantity of :data:`GROWTH` against f (exponent a
    of x ∝ f^a) between the smallest and the largest f (key ``"chain"``, ``"tree"``) and, with
    three rows or more, over the top of the range, from the row nearest f_max/2 to the largest
    (``"chain, top"``: the fixed costs that flatten the first slope matter less there)."""
    out: dict[str, dict[str, float]] = {}
    for kind in ("chain", "tree"):
        rs = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["f"])
        if len(rs) < 2 or rs[0]["f"] == rs[-1]["f"]:
            continue
        hi = rs[-1]
        spans = {kind: rs[0]}
        if len(rs) >= 3:
            spans[f"{kind}, top"] = min(rs[:-1], key=lambda r: abs(r["f"] - hi["f"] / 2))
        for label, lo in spans.items():
            span = math.log(hi["f"] / lo["f"])
            out[label] = {"f_min": lo["f"], "f_max": hi["f"],
                          **{k: math.log(max(hi[k], 1e-2) / max(lo[k], 1e-2)) / span
                             for k in GROWTH}}
    return out


#: issue 35, item 4: the symbolic derivation of spatial_chain(64), f = 127, in at most this many
#: seconds, growing at most like f² (its peak memory and sympy's: benchmarks/derivation.py)
DERIVE_F, DERIVE_S = 127, 1.5


def derivation_targets(rows: list[dict], slopes: dict[str, dict[str, float]]) -> list[str]:
    """Lines on issue 35's item 4 for the chain of f = DERIVE_F, where it was measured."""
    top = [r for r in rows if r["kind"] == "chain" and r["f"] == DERIVE_F]
    if not top:
        return []
    r = top[0]
    a = max((v[k] for key, v in slopes.items() if key.startswith("chain")
             for k in ("derive_s", "derive_mb")), default=float("nan"))
    ok = ["met" if c else "NOT met" for c in (r["derive_s"] <= DERIVE_S, round(a, 2) <= 2)]
    return [f"symbolic M, k, q of spatial_chain({r['n']}), f = {DERIVE_F}: {r['derive_s']:.2f} s "
            f"(target ≤ {DERIVE_S} s: {ok[0]}), {r['derive_mb']:.0f} MB held; growth of its "
            f"time and memory at most f^{a:.2f} (target ≤ f²: {ok[1]}); peak RSS of a "
            "derivation alone and sympy's KanesMethod on the same chains: "
            "benchmarks/derivation.py"]


def _rule(header: str) -> str:
    """The markdown rule under ``header`` (first column left-aligned, the others right)."""
    cells = header.strip().strip("|").split("|")
    return "|" + "|".join("-" * len(c) if i == 0 else "-" * (len(c) - 1) + ":"
                          for i, c in enumerate(cells)) + "|"


def main(argv: list[str] | None = None) -> list[dict]:
    from benchmarks.crosscheck import spawn

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("child", nargs="?", help=argparse.SUPPRESS)
    ap.add_argument("--n", type=int, nargs="*", default=None,
                    help=f"spatial_chain lengths (default {' '.join(map(str, CHAINS))})")
    ap.add_argument("--tree", type=int, nargs="*", default=None,
                    help="random_tree sizes (default: f matched to each chain; none if empty)")
    ap.add_argument("--seed", type=int, default=0, help="model seed (default 0)")
    ap.add_argument("--states", type=int, default=1000, help="states per batch (default 1000)")
    ap.add_argument("--repeat", type=int, default=3, help="timing rounds, best taken (3)")
    ap.add_argument("--trials", type=int, default=3,
                    help="fresh processes per model, smallest times taken (3)")
    ap.add_argument("--quick", action="store_true",
                    help="chains 2, 4 and trees 2, 3; 100 states, one round (a smoke test)")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per model")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    a = ap.parse_args(argv)
    if a.child is not None:
        s = json.loads(a.child)
        print(json.dumps(case(s["kind"], int(s["n"]), int(s.get("seed", 0)),
                              int(s.get("states", 1000)), int(s.get("repeat", 3)))))
        return []
    if a.quick:
        chains = QUICK_CHAINS if a.n is None else a.n
        trees = QUICK_TREES if a.tree is None else a.tree
        a.states, a.repeat, a.trials = min(a.states, 100), 1, 1
    else:
        chains = CHAINS if a.n is None else a.n
        if a.tree is None:
            from jourdain.models import spatial_chain_data

            nq = {"revolute": 1, "universal": 2, "spherical": 3}
            trees = [matching_tree(sum(nq[d["joint"]] for d in spatial_chain_data(n)), a.seed)
                     for n in chains]
        else:
            trees = a.tree
    specs = ([{"kind": "chain", "n": n} for n in chains]
             + [{"kind": "tree", "n": n} for n in trees])
    print(f"each row: the smallest of {a.trials} fresh processes, each with an empty "
          f"JOURDAIN_CACHE, the trials of all rows in turn; per-state costs: batch of "
          f"{a.states} states, best of {a.repeat}\n")
    t_all = time.perf_counter()
    # trial after trial over all models, so that a busy spell of the machine hits one trial of
    # several rows rather than every trial of one row
    runs: list[list[dict]] = [[] for _ in specs]
    for trial in range(a.trials):
        for spec, done in zip(specs, runs, strict=True):
            spec.update(seed=a.seed, states=a.states, repeat=a.repeat)
            done.append(spawn(spec, "0", timeout=a.timeout, module="benchmarks.scaling"))
            if trial == a.trials - 1:
                if spec is specs[0]:
                    print(HEADER)
                    print(_rule(HEADER))
                print(row(combine(done)), flush=True)
            else:
                print(f"trial {trial + 1}/{a.trials}: {spec['kind']} {spec['n']}, f = "
                      f"{done[-1]['f']}: {done[-1]['wall_s']:.1f} s", file=sys.stderr, flush=True)
    rows = [combine(done) for done in runs]
    print(f"\ntotal wall time {time.perf_counter() - t_all:.1f} s")
    worst = max((r["M_vs_evaluate"] for r in rows), default=0.0)
    print(f"M from fn.batch against System.evaluate at y = 0.1·1: max relative difference "
          f"{worst:.1e}")
    slopes = growth(rows)
    if slopes:
        print("\ngrowth exponents a (x ∝ f^a, log-log slope between the smallest and the "
              "largest f of each family, and over its top half; target for the first two: "
              "a ≤ 2)\n")
        cols = {k: f"{k} f = {v['f_min']:.0f}…{v['f_max']:.0f}" for k, v in slopes.items()}
        head = f"| {'quantity':<26} | " + " | ".join(cols.values()) + " |"
        print(head)
        print(_rule(head))
        for key, label in GROWTH.items():
            print(f"| {label:<26} | "
                  + " | ".join(f"{slopes[k][key]:>{len(c)}.2f}" for k, c in cols.items())
                  + " |")
        print()
        print("\n".join(derivation_targets(rows, slopes)))
    if a.json:
        a.json.write_text(json.dumps({"rows": rows, "growth": slopes}, indent=2))
    return rows


if __name__ == "__main__":
    main()
