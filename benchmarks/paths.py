"""The integrator's evaluation paths on a sweep of models, and the cost model that picks one
(issue 35, item 1): ``jd_accel`` (ÿ = M⁻¹(q − k), what the integrator calls per right-hand side)
by each path a model can take, in one run.

Paths (:mod:`jourdain.numeric.cost`): ``symbolic`` (the straight-line code of the symbolic
projection and LDLᵀ; measured where f ≤ 24 and its graph has at most ``--max-nodes`` nodes),
``planar`` (the recursion in planar vectors; planar models) and ``spatial`` (the recursion in
spatial vectors; every model). Models: planar chains (:func:`jourdain.models.planar_chain`,
relative angles: articulated bodies), pendulums on a cart (absolute angles: coordinates shared
between joints, LDLᵀ), planar trees (:func:`jourdain.models.planar_tree`), spatial chains
(:func:`jourdain.models.spatial_chain`, f = 2n − 1 … ) and random trees
(:func:`jourdain.models.random_tree`), f from 1 to 128, and the 7-joint arm.

Per model and path: µs per state, best of ``--rounds`` interleaved rounds (every path of the
model in turn), each a C loop over ``--states`` random states (y uniform in (−π, π), ẏ in
(−2, 2)) calling the path's ``jd_accel`` through its address. Printed: each path's time, the
path :func:`jourdain.numeric.cost.evaluation_path` chooses (that is what ``mkq_function``
compiles), its predicted cost, and the ratio of the chosen path's measured time to the fastest
measured (issue 35's target: at most 1.2 on every model). With ``--fit`` the constants of
:data:`jourdain.numeric.cost.COST_NS` are fitted to the run by non-negative least squares
(relative errors) and printed, with the choice the fitted model would make. The paths' ÿ are
compared with each other in the same run (relative to the largest entry).

With MuJoCo installed (the ``bench`` extra), the planar chains' rows also give ``mj_forward``
per state from a Python loop, and that loop's floor (the same loop setting qpos and qvel
without the call): ``mj_forward`` net = the difference.

    .venv/bin/python benchmarks/paths.py                 # the sweep (a few minutes)
    .venv/bin/python benchmarks/paths.py --quick         # four small models
    .venv/bin/python benchmarks/paths.py --fit --json paths.json
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.per_state import interleaved  # noqa: E402 - the interleaved rounds, best of each

LOOP = r"""
typedef int (*jd_accel_t)(const double *, const double *, double, const double *,
                          const double *, double *, double *);
int jd_loop_accel(void *fn, long n, long f, const double *Y, const double *YD,
                  const double *p, const double *u, double *YDD) {
    jd_accel_t accel = (jd_accel_t)fn;
    double power;
    int bad = 0;
    for (long i = 0; i < n; ++i) bad |= accel(Y + i * f, YD + i * f, 0.0, p, u, YDD + i * f, &power);
    return bad;
}
"""


def sweep(quick: bool) -> list[tuple[str, object]]:
    from jourdain import models

    if quick:
        return [("planar chain 4", lambda: models.planar_chain(4)),
                ("planar tree 6", lambda: models.planar_tree(6)),
                ("cart pendulum 3", lambda: models.n_link_pendulum_on_cart(3)),
                ("spatial chain 2", lambda: models.spatial_chain(2))]
    out: list[tuple[str, object]] = []
    for n in (1, 2, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128):
        out.append((f"planar chain {n}", lambda n=n: models.planar_chain(n)))
    for n in (2, 4, 8, 12, 16, 23):
        out.append((f"cart pendulum {n}", lambda n=n: models.n_link_pendulum_on_cart(n)))
    for n in (4, 8, 16, 32, 64, 128):
        out.append((f"planar tree {n}", lambda n=n: models.planar_tree(n, seed=n)))
    for n in (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64):
        out.append((f"spatial chain {n}", lambda n=n: models.spatial_chain(n)))
    for n in (2, 4, 8, 16, 32, 60):
        out.append((f"random tree {n}", lambda n=n: models.random_tree(n, seed=n)))
    for n in (16, 60):
        out.append((f"hinge tree {n}", lambda n=n: models.random_tree(n, seed=n, joints=HINGES)))
    out.append(("7-joint arm", models.robot_arm))
    return out


#: the joints of the trees also built in MuJoCo (hinges and slides about random axes)
HINGES = ("revolute", "prismatic")


def mjcf_tree(data: list[dict]) -> str:
    """MJCF of a :func:`jourdain.models.random_tree_data` tree of revolute and prismatic joints
    (hinges and slides at each body's origin, full inertia; gravity 9.81 along −z)."""
    from benchmarks.peers import _vec

    children: dict[int, list[int]] = {}
    for i, d in enumerate(data):
        children.setdefault(d["parent"], []).append(i)

    def body(i: int) -> str:
        d = data[i]
        I = np.asarray(d["inertia"], dtype=float)
        kind = "hinge" if d["joint"] == "revolute" else "slide"
        inner = "".join(body(c) for c in children.get(i, []))
        return (f'<body pos="{_vec(d["position"])}"><joint name="j{i}" type="{kind}" '
                f'axis="{_vec(d["axes"][0])}"/><inertial pos="{_vec(d["com"])}" '
                f'mass="{float(d["mass"])!r}" fullinertia="'
                f'{_vec((I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))}"/>{inner}</body>')

    roots = "".join(body(c) for c in children.get(-1, []))
    return (f'<mujoco><option gravity="0 0 -9.81"/><worldbody>{roots}</worldbody></mujoco>')


def loop_library() -> ctypes.CDLL:
    from jourdain.numeric.toolchain import build, content_key

    lib = build(content_key("benchmark-paths-loop", LOOP), LOOP)
    vp = ctypes.c_void_p
    lib.jd_loop_accel.restype = ctypes.c_int
    lib.jd_loop_accel.argtypes = [vp, ctypes.c_long, ctypes.c_long, vp, vp, vp, vp, vp]
    return lib


def functions(system, max_nodes: int) -> tuple[dict, dict, tuple[int, int]]:  # noqa: ANN001
    """The compiled function of every path ``system`` can take, their build seconds, and the
    nodes of the symbolic graph (up to ``max_nodes`` + 1; 0 where not derived) and its calls
    of the C library (:func:`jourdain.graph.count_graph`)."""
    from jourdain.graph import count_graph
    from jourdain.numeric.compiled import dynamics_function, planar_function, symbolic_mkq
    from jourdain.numeric.cost import SYMBOLIC_MAX_F
    from jourdain.numeric.planar_recursion import is_planar
    from jourdain.stages.kinematics import kinematics
    from jourdain.stages.newton_euler import newton_euler
    from jourdain.stages.projection import projection

    fns, secs, nodes = {}, {}, (0, 0)
    if system.f <= SYMBOLIC_MAX_F:
        t0 = time.perf_counter()
        eom = projection(newton_euler(kinematics(system)))
        nodes = count_graph([*eom.M.entries(), *eom.k.entries(), *eom.q.entries()], max_nodes)
        if nodes[0] <= max_nodes:
            fns["symbolic"] = symbolic_mkq(system, eom)
            secs["symbolic"] = time.perf_counter() - t0
    if is_planar(system):
        t0 = time.perf_counter()
        fns["planar"] = planar_function(system)
        secs["planar"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    fn = dynamics_function(system)
    if fn.accel_address:
        fns["spatial"] = fn
        secs["spatial"] = time.perf_counter() - t0
    return fns, secs, nodes


def mujoco_row(mjcf: str, Y: np.ndarray, YD: np.ndarray, rounds: int,
               ydd: np.ndarray) -> dict[str, float]:
    """mj_forward per state on the model of ``mjcf``, the Python loop's floor, and the largest
    difference of MuJoCo's ÿ from ``ydd`` (relative to its largest entry) at these states."""
    try:
        import mujoco
    except ImportError:
        return {}
    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    # MuJoCo numbers the joints depth-first; jourdain's coordinate i is MuJoCo's joint "j<i>"
    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"j{i}") for i in range(len(Y[0]))]
    order = np.array([model.jnt_qposadr[k] for k in ids] if min(ids) >= 0
                     else range(len(Y[0])))
    Y, YD = np.ascontiguousarray(Y[:, np.argsort(order)]), np.ascontiguousarray(YD[:, np.argsort(order)])
    diff = 0.0
    for y, yd, a in zip(Y[:20], YD[:20], ydd[:20], strict=True):
        data.qpos[:], data.qvel[:] = y, yd
        mujoco.mj_forward(model, data)
        diff = max(diff, float(np.abs(data.qacc[order] - a).max() / max(np.abs(a).max(), 1.0)))
    def loop(call: bool) -> None:
        for y, yd in zip(Y, YD, strict=True):
            data.qpos[:], data.qvel[:] = y, yd
            if call:
                mujoco.mj_forward(model, data)

    best = interleaved({"call": lambda: loop(True), "floor": lambda: loop(False)}, rounds)
    return {"mj_forward_us": best["call"] / len(Y) * 1e6,
            "mj_floor_us": best["floor"] / len(Y) * 1e6, "mj_agreement": diff}


def measure(name: str, make, lib: ctypes.CDLL, n_states: int, rounds: int,  # noqa: ANN001
            max_nodes: int) -> dict:
    from jourdain.numeric import parameter_vector
    from jourdain.numeric.cost import evaluation_path

    system = make()
    fns, secs, nodes = functions(system, max_nodes)
    choice = evaluation_path(system)
    f = system.f
    rng = np.random.default_rng(f)
    Y, YD = rng.uniform(-np.pi, np.pi, (n_states, f)), rng.uniform(-2, 2, (n_states, f))
    p = parameter_vector(system, None)
    u = np.zeros(max(1, len(system.inputs)))
    out = {k: np.empty_like(Y) for k in fns}
    def run(k: str) -> None:
        bad = lib.jd_loop_accel(fns[k].accel_address, n_states, f, Y.ctypes.data,
                                YD.ctypes.data, p.ctypes.data, u.ctypes.data, out[k].ctypes.data)
        if bad:
            raise RuntimeError(f"{name}: the {k} path failed at a random state ({bad})")

    best = interleaved({k: lambda k=k: run(k) for k in fns}, rounds)
    us = {k: v / n_states * 1e6 for k, v in best.items()}
    ref = out[min(us, key=us.get)]
    scale = max(float(np.abs(ref).max()), 1.0)  # relative to the largest entry, or absolute
    M = fns["spatial"].batch(Y[:500], YD[:500], 0.0, p, None)["M"]
    row = {"model": name, **{k: int(v) for k, v in choice.features.items()},
           "sym_nodes": nodes[0], "sym_calls": nodes[1],
           "us": us, "build_s": secs, "chosen": choice.path,
           "predicted_us": {k: v / 1e3 for k, v in choice.cost.items()},
           "agreement": max(float(np.abs(o - ref).max()) / scale for o in out.values()),
           "cond_M": float(np.linalg.cond(M).max()),
           "ratio": us.get(choice.path, math.nan) / min(us.values())}
    mjcf = None
    if name.startswith("planar chain"):
        from benchmarks.peers import _chain_links, mjcf_serial

        mjcf = mjcf_serial(_chain_links(f), (0.0, -9.81, 0.0))
    elif name.startswith("hinge tree"):
        from jourdain.models import random_tree_data

        mjcf = mjcf_tree(random_tree_data(system.f, seed=system.f, joints=HINGES))
    if mjcf is not None:
        row.update(mujoco_row(mjcf, Y[:2000], YD[:2000], rounds, ref))
    return row


def fit(rows: list[dict]) -> dict[str, dict[str, float]]:
    """Non-negative least squares of each path's times on its features, relative errors."""
    from scipy.optimize import nnls

    terms = {"planar": ("base", "body", "column", "local", "solve"),
             "spatial": ("base", "body", "column", "local", "solve"),
             "symbolic": ("base", "node", "call", "entry", "solve")}
    out = {}
    for path, names in terms.items():
        A, b = [], []
        for r in rows:
            if path not in r["us"]:
                continue
            feat = {"base": 1.0, "body": r["bodies"], "column": r["columns"],
                    "local": r["local"], "solve": r["shared"] * r["f"] ** 3 if path != "symbolic"
                    else r["f"] ** 3, "node": r["sym_nodes"], "call": r["sym_calls"],
                    "entry": r["f"] ** 2}
            t = r["us"][path] * 1e3
            A.append([feat[n] / t for n in names])
            b.append(1.0)
        if len(A) >= len(names):
            x, _ = nnls(np.array(A), np.array(b))
            out[path] = {n: float(v) for n, v in zip(names, x, strict=True)}
    return out


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--states", type=int, default=4000)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--max-nodes", type=int, default=None,
                    help="the largest symbolic graph measured (default: the cost model's "
                         "SYMBOLIC_MAX_NODES, the largest it takes)")
    ap.add_argument("--fit", action="store_true")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--from-json", type=Path, default=None,
                    help="fit to the rows of an earlier --json run instead of measuring")
    ap.add_argument("--models", nargs="*", default=None,
                    help="only the models whose names contain one of these words")
    a = ap.parse_args(argv)
    if a.max_nodes is None:
        from jourdain.numeric.cost import SYMBOLIC_MAX_NODES

        a.max_nodes = SYMBOLIC_MAX_NODES
    if a.quick:
        a.states, a.rounds = min(a.states, 200), min(a.rounds, 2)
    if a.from_json:
        rows = json.loads(a.from_json.read_text())
        fitted = fit(rows)
        print("fitted COST_NS:", json.dumps(fitted, indent=1))
        refit(rows, fitted, a.quick)
        return rows
    lib = loop_library()
    rows = []
    print(f"{'model':18} {'f':>4} {'sym µs':>8} {'planar µs':>9} {'spatial µs':>10} "
          f"{'chosen':>9} {'pred µs':>8} {'ratio':>6} {'mj_fwd net':>10}")
    for name, make in sweep(a.quick):
        if a.models and not any(w in name for w in a.models):
            continue
        r = measure(name, make, lib, a.states, a.rounds, a.max_nodes)
        rows.append(r)
        us = r["us"]
        cell = {k: f"{us[k]:.3f}" if k in us else "-" for k in ("symbolic", "planar", "spatial")}
        mj = (f"{r['mj_forward_us'] - r['mj_floor_us']:.3f}" if "mj_forward_us" in r else "-")
        print(f"{name:18} {r['f']:>4} {cell['symbolic']:>8} {cell['planar']:>9} "
              f"{cell['spatial']:>10} {r['chosen']:>9} "
              f"{r['predicted_us'][r['chosen']]:>8.3f} {r['ratio']:>6.2f} {mj:>10}", flush=True)
        if a.json:
            a.json.write_text(json.dumps(rows, indent=1))
    worst = max(rows, key=lambda r: r["ratio"])
    agree = max(rows, key=lambda r: r["agreement"] / (r["cond_M"] * 2.2e-16))
    print(f"\nworst chosen/fastest: {worst['ratio']:.2f} ({worst['model']}); the paths' ÿ "
          f"agree to cond(M)·eps times {agree['agreement'] / (agree['cond_M'] * 2.2e-16):.2g} "
          f"at worst ({agree['model']}: {agree['agreement']:.1e} relative, largest cond(M) "
          f"{agree['cond_M']:.1e} at the first 500 states)")
    mj = [r for r in rows if "mj_forward_us" in r]
    if mj:
        print("MuJoCo mj_forward net / jourdain's chosen path: " + ", ".join(
            f"{r['model']} {(r['mj_forward_us'] - r['mj_floor_us']) / r['us'][r['chosen']]:.2f}"
            f" (ÿ agree to {r['mj_agreement']:.0e})" for r in mj))
    if a.fit:
        fitted = fit(rows)
        print("fitted COST_NS:", json.dumps(fitted, indent=1))
        refit(rows, fitted, a.quick)
    return rows


def refit(rows: list[dict], fitted: dict, quick: bool) -> None:
    """The path each model would get with the ``fitted`` constants (the cost model run again
    on every model), and its measured time over the fastest measured."""
    from types import MappingProxyType

    from jourdain.numeric import cost

    if set(fitted) != set(cost.COST_NS):
        return
    old = cost.COST_NS
    cost.COST_NS = MappingProxyType({k: MappingProxyType(v) for k, v in fitted.items()})
    try:
        makes = dict(sweep(quick))
        ratios = []
        for r in rows:
            cost.evaluation_path.cache_clear()
            path = cost.evaluation_path(makes[r["model"]]()).path
            ratios.append((r["us"].get(path, math.nan) / min(r["us"].values()), r["model"], path))
        print("with the fitted constants, chosen/fastest: " + ", ".join(
            f"{m} {x:.2f} ({p})" for x, m, p in ratios if x > 1.0))
        print(f"worst: {max(ratios)[0]:.2f} ({max(ratios)[1]})")
    finally:
        cost.COST_NS = old
        cost.evaluation_path.cache_clear()


if __name__ == "__main__":
    main()
