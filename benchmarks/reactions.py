"""Reaction forces along a motion: jourdain against Pinocchio, in one run.

Model: ``spatial_chain(n)`` (revolute, universal and spherical joints, full inertia tensors) and
the same chain in Pinocchio (``benchmarks/pinocchio_models.py``). Per state, all joint
reaction forces:

* jourdain ``evaluate_reactions``: compiled Q̄, N̂, k̂, q̂ and a Cholesky solve of N̂·g = k̂ − q̂
  (no ÿ needed), including the input checks of the public function;
* jourdain ``joint_reactions`` for the first joint only (equations of motion, then the sub-tree
  residual);
* Pinocchio: ``aba`` for ÿ, then ``rnea``, reading ``data.f`` of the last elementary joint of
  every jourdain joint.

Reported: symbolic derivation time of the reactions stage, first-call time (code generation and
C compilation, or loading from the on-disk cache), time per state (best of ``--repeat`` loops
over the same random states) and the ratio to Pinocchio, and the largest difference between
the two tools' joint forces in the same run.

    python benchmarks/reactions.py            # n = 6, 16
    python benchmarks/reactions.py --n 3      # one small case
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from jourdain.analysis.reactions import evaluate_reactions, joint_reactions  # noqa: E402
from jourdain.models import spatial_chain, spatial_chain_data  # noqa: E402
from jourdain.stages.reactions import graph_values, reactions  # noqa: E402


def run(ns: list[int], states: int = 200, repeat: int = 3, seed: int = 0) -> list[dict]:
    """One row per chain length in ``ns`` (see the module docstring for the columns)."""
    rng = np.random.default_rng(seed)
    return [_case(n, states, repeat, rng) for n in ns]


def _case(n: int, states: int, repeat: int, rng: np.random.Generator) -> dict:
    import pinocchio as pin

    from benchmarks.pinocchio_models import chain_model

    system = spatial_chain(n)
    model = chain_model(spatial_chain_data(n))
    data = model.createData()
    t0 = time.perf_counter()
    r = reactions(system.newton_euler())
    t_derive = time.perf_counter() - t0
    Y = rng.uniform(-np.pi, np.pi, (states, system.f))
    V = rng.uniform(-3, 3, (states, system.f))
    t0 = time.perf_counter()
    evaluate_reactions(system, Y[0], V[0])
    t_first = time.perf_counter() - t0
    first_joint = system.bodies[0].joint.name
    joint_reactions(system, first_joint, Y[0], V[0])  # compile outside the timing
    nq = {"revolute": 1, "universal": 2, "spherical": 3}
    last_ids = [int(i) for i in np.cumsum([nq[b.joint.kind] for b in system.bodies])]
    zero = np.zeros(system.f)

    def ours() -> list[np.ndarray]:
        return [evaluate_reactions(system, y, v)["g"] for y, v in zip(Y, V, strict=True)]

    def one_joint() -> None:
        for y, v in zip(Y, V, strict=True):
            joint_reactions(system, first_joint, y, v)

    def theirs() -> list[list[np.ndarray]]:
        out = []
        for y, v in zip(Y, V, strict=True):
            a = pin.aba(model, data, y, v, zero)
            pin.rnea(model, data, y, v, a)
            out.append([data.f[i].vector.copy() for i in last_ids])
        return out

    times = {}
    for name, fn in (("jourdain_g", ours), ("jourdain_one", one_joint), ("pinocchio", theirs)):
        best = np.inf
        for _ in range(repeat):
            t0 = time.perf_counter()
            fn()
            best = min(best, time.perf_counter() - t0)
        times[name] = best / states
    # agreement: our wrench Σ g_k w_k against Pinocchio's data.f, in the same run
    g_all, f_all = ours()[:10], theirs()[:10]
    params = dict(zip(system.parameter_symbols, system.parameter_values.values(),
                      strict=True))
    diff = scale = 0.0
    for y, g, fs in zip(Y[:10], g_all, f_all, strict=True):
        vals = {**params, **dict(zip(system.y, y, strict=True))}
        for jr, f in zip(r.joints, fs, strict=True):
            W = np.array(graph_values([x for w in jr.wrenches for x in w], vals), float)
            ours_w = g[list(jr.columns)] @ W.reshape(len(jr.names), 6)
            diff = max(diff, float(np.abs(ours_w - f).max()))
            scale = max(scale, float(np.abs(f).max()))
    return {"n": n, "f": system.f, "q": len(r.g_names), "derive_s": t_derive,
                 "first_call_s": t_first, **times,
                 "ratio_g": times["jourdain_g"] / times["pinocchio"],
                 "ratio_one": times["jourdain_one"] / times["pinocchio"],
            "max_rel_diff": diff / scale}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="*", default=[6, 16])
    ap.add_argument("--states", type=int, default=200)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    rows = run(args.n, args.states, args.repeat)
    print(f"{'n':>3} {'f':>3} {'q':>4} {'derive':>8} {'1st call':>9} {'g (us)':>9} "
          f"{'1 joint':>9} {'pin (us)':>9} {'g/pin':>6} {'1j/pin':>7} {'max rel diff':>12}")
    for r in rows:
        print(f"{r['n']:>3} {r['f']:>3} {r['q']:>4} {r['derive_s']:>7.3f}s "
              f"{r['first_call_s']:>8.2f}s {r['jourdain_g'] * 1e6:>9.1f} "
              f"{r['jourdain_one'] * 1e6:>9.1f} {r['pinocchio'] * 1e6:>9.1f} "
              f"{r['ratio_g']:>6.1f} {r['ratio_one']:>7.1f} {r['max_rel_diff']:>12.1e}")


if __name__ == "__main__":
    main()
