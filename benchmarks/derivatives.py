"""Cost per state of jourdain's compiled derivatives of the dynamics beside Pinocchio's, in one
run, at the same states (issue 37).

Robots from ``example-robot-data``, read by jourdain (:func:`jourdain.io.urdf.load_urdf`, a
torque input on every joint) and by Pinocchio (``buildModelFromUrdf``, a
``JointModelFreeFlyer`` root for a floating base):

* ``panda``: the Franka Panda arm, 7 joints; its two finger joints are made ``fixed`` in a
  copy of the file that both tools read (f = 7);
* ``solo12``: the Solo-12 quadruped, floating base, f = 18;
* ``talos``: the Talos humanoid (``talos_reduced.urdf``), floating base, f = 38.

``--tree N`` adds ``random_tree(N)`` (no example-robot-data needed; no inputs).

Measured per state, at ``--states`` random states (y uniform in (-π, π), the free joint's pitch
in (-1, 1), ẏ and ÿ in (-3, 3), torques in (-2, 2)), each measurement one pass over all states:

* **forward**: jourdain's ``d.forward`` (ÿ, ∂ÿ/∂y, ∂ÿ/∂ẏ, ∂ÿ/∂u = M⁻¹B) against
  ``pin.computeABADerivatives`` (ddq_dq, ddq_dv, ddq_dtau = M⁻¹; ÿ in ``data.ddq``);
* **inverse**: jourdain's ``d.inverse`` (τ, ∂τ/∂y, ∂τ/∂ẏ, ∂τ/∂ÿ = M, ∂τ/∂u) against
  ``pin.computeRNEADerivatives`` (dtau_dq, dtau_dv, M; τ in ``data.tau``).

jourdain three ways: ``py 1/call`` — one state per Python call of the API (argument checks,
output arrays, the C function); ``py batch`` — all states in one call of the API (the loop runs
in C); ``C batch`` — the library's ``jd_forward_derivatives_batch`` /
``jd_inverse_derivatives_batch`` called through ctypes into a preallocated array: the C cost
per state, nothing of Python per state. The throughput of the batched call is ``1/py batch``
states per second (one core).

Pinocchio is called from Python, one call per state (``pin 1/call``): its times include the
interpreter's loop and Boost.Python's argument conversion. Its C++ cost is estimated as that
time less the same call on a model of one revolute joint (``pin net``, the per-call floor:
conversion, dispatch, a trivial algorithm). Pinocchio's published C++ figures (Carpentier &
Mansard, RSS 2018) are about 3 µs for a 7-DOF arm and 17 µs for a 36-DOF humanoid. Pinocchio
works in its own coordinates (quaternion, body-frame velocity); jourdain's derivatives are with
respect to its coordinates (z-y-x angles of the free joint): neither side is charged for the
map between them. Ratios are jourdain / Pinocchio: below 1, jourdain is faster.

Timing: rounds interleave all contenders (A B C … A B C …), best of ``--rounds`` per
contender. The numbers are checked in the same run on the first ``--check`` states, against
Pinocchio's mapped to jourdain's coordinates (tests/reference/pinocchio_derivatives.py; the
reference test tests/reference/test_derivatives_pinocchio.py holds the tolerances): the largest
difference relative to the largest entry of Pinocchio's, per quantity.

Measured on the 2-core development machine (µs per state, 1000 states, best of 7; load
average about 3 from other work; Pinocchio 4.1.0 net of its per-call floor of 1.2-1.3 µs).
jourdain's derivatives as of commit 17fdac9 (the recursions of screw joints,
``numeric/derivative_screw.h``, and the forward derivatives' solves with M = LᵀL in the tree's
sparsity, compiled at -O3):

    robot    f   forward: C batch / py 1 call / pin net   inverse: C batch / py 1 call / pin net
    panda    7             2.19 / 7.34 / 4.78                       1.35 / 7.34 / 3.68
    solo12  18             7.40 / 16.4 / 18.3                       4.55 / 13.9 / 12.4
    talos   38             30.3 / 36.1 / 43.4                       12.3 / 17.5 / 21.7

so jourdain's C takes 0.37-0.70 times Pinocchio's C++ time (forward 0.46, 0.41, 0.70; inverse
0.37, 0.37, 0.56); one state per Python call adds 5-6 µs (Pinocchio's floor: 1.2 µs), so the
Panda's single calls take 1.5-2.0 times Pinocchio's from Python. Batched throughput forward
426 000, 85 000 and 33 000 states/s, inverse 653 000, 222 000 and 57 000 states/s.
(Before the recursions of screw joints, at commit 6cac064, the forward mode of every
intermediate quantity took 4.3-8.0 times Pinocchio's time; it still serves the models whose
joints are not screws: absolute angles, general joints, springs between bodies.)

    .venv/bin/python benchmarks/derivatives.py                        # panda, solo12, talos
    .venv/bin/python benchmarks/derivatives.py --robot solo12 --states 2000
    .venv/bin/python benchmarks/derivatives.py --robot --tree 10      # a random tree only
    .venv/bin/python benchmarks/derivatives.py --quick                # panda, 100 states
    .venv/bin/python benchmarks/derivatives.py --json out.json
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import re
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from benchmarks.per_state import interleaved  # noqa: E402

#: example-robot-data: path below robots/, floating base, expected f
ROBOTS = {"panda": ("panda_description/urdf/panda.urdf", False, 7),
          "solo12": ("solo_description/robots/solo12.urdf", True, 18),
          "talos": ("talos_data/robots/talos_reduced.urdf", True, 38)}


def robots_dir() -> Path:
    """The robots folder of the ``example-robot-data`` package (RuntimeError if absent)."""
    import importlib.metadata

    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        raise RuntimeError("example-robot-data is not installed (pip install "
                           "example-robot-data; part of jourdain's test extra)") from None
    return Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))


def _fixed_fingers(path: Path, tmp: Path) -> Path:
    """A copy of the Panda's URDF with both finger joints ``fixed`` (and no mimic)."""
    text = path.read_text()
    for k in (1, 2):
        text = re.sub(rf'(<joint name="panda_finger_joint{k}" type=)"prismatic"', r'\1"fixed"',
                      text)
    text = re.sub(r"<mimic [^>]*/>", "", text)
    out = tmp / "panda_fixed_fingers.urdf"
    out.write_text(text)
    return out


def robot(name: str, tmp: Path) -> dict[str, Any]:
    """The jourdain system (torque inputs), Pinocchio's model, the map between their states
    (tests.reference.test_urdf_pinocchio.Twin) and ``B = ∂q/∂u``."""
    from jourdain.io.urdf import load_urdf
    from tests.reference.test_urdf_pinocchio import Twin

    rel, floating, f = ROBOTS[name]
    path = robots_dir() / rel
    if name == "panda":
        path = _fixed_fingers(path, tmp)
    twin = Twin(path, floating_base=floating)
    urdf = load_urdf(path, floating_base=floating)
    system = urdf.system
    assert system.f == f == twin.pin.nv, (name, system.f, twin.pin.nv)
    assert system.coordinate_names == twin.system.coordinate_names
    names = system.coordinate_names
    coordinate_of = {j.name: names.index(j.coordinates[0]) for j in urdf.joints if j.coordinates}
    B = np.zeros((f, len(system.inputs)))
    for k, inp in enumerate(system.input_names):
        B[coordinate_of[inp.removeprefix("tau_")], k] = 1.0
    return {"name": name, "system": system, "model": twin.pin, "twin": twin, "B": B}


def tree(n: int, seed: int = 0) -> dict[str, Any]:
    """``random_tree(n, seed)`` and its Pinocchio twin (benchmarks/pinocchio_models.py)."""
    from benchmarks.crosscheck import build

    system, model, index = build("tree", n, seed)
    return {"name": f"random_tree({n}, {seed})", "system": system, "model": model,
            "index": index, "B": np.zeros((system.f, 0))}


def pinocchio_states(r: dict, Y: np.ndarray, YD: np.ndarray, YDD: np.ndarray,
                     U: np.ndarray) -> tuple[np.ndarray, ...]:
    """Pinocchio's ``q, v, a, τ`` (rows) of jourdain's states: ``ν = T·ẏ``,
    ``ν̇ = T·ÿ + Ṫẏ``, ``τ_p = T⁻ᵀ·B·u``."""
    rows = []
    for y, yd, ydd, u in zip(Y, YD, YDD, U, strict=True):
        if "twin" in r:
            q, v, T, Tdot = r["twin"].state(y, yd)
            rows.append((q, v, T @ ydd + Tdot, np.linalg.solve(T.T, r["B"] @ u)))
        else:
            ix = r["index"]
            rows.append((ix.to_pinocchio(y), ix.to_pinocchio(yd), ix.to_pinocchio(ydd),
                         np.zeros(len(y))))
    return tuple(np.ascontiguousarray(np.array(x)) for x in zip(*rows, strict=True))


def agreement(r: dict, d: Any, Y, YD, YDD, U, n: int) -> dict[str, float]:
    """Largest relative differences (to the largest entry of Pinocchio's) of jourdain's
    derivatives against Pinocchio's mapped to jourdain's coordinates, over the first ``n``
    states."""
    from tests.reference.pinocchio_derivatives import (
        Chart,
        forward_dynamics,
        inverse_dynamics,
        tree_tangent,
        urdf_tangent,
    )

    model, B = r["model"], r["B"]
    data = model.createData()
    if "twin" in r:
        tangent = urdf_tangent(r["twin"])

        def q_of(y, yd):
            return r["twin"].state(y, yd)[0]
    else:
        tangent = tree_tangent(r["index"])

        def q_of(y, yd):
            return r["index"].to_pinocchio(y)
    nu = B.shape[1]
    worst: dict[str, float] = {}

    def rel(name: str, ours: np.ndarray, ref: np.ndarray) -> None:
        e = float(np.abs(ours - ref).max() / max(np.abs(ref).max(), np.finfo(float).tiny))
        worst[name] = max(worst.get(name, 0.0), e)

    for i in range(min(n, len(Y))):
        y, yd, ydd, u = Y[i], YD[i], YDD[i], U[i]
        uu = u if nu else None
        ch = Chart.at(q_of(y, yd), tangent, y, yd)
        fwd, inv = d.forward(y, yd, u=uu), d.inverse(y, yd, ydd, u=uu)
        pf = forward_dynamics(model, data, ch, B @ u)
        pi = inverse_dynamics(model, data, ch, ydd)
        # Pinocchio's ∂ÿ/∂y moved to jourdain's ÿ (as the reference test does)
        shift = (inverse_dynamics(model, data, ch, fwd.ydd)["tau_y"]
                 - inverse_dynamics(model, data, ch, pf["ydd"])["tau_y"])
        rel("ydd", fwd.ydd, pf["ydd"])
        rel("ydd_y", fwd.ydd_y, pf["ydd_y"] - pf["Minv"] @ shift)
        rel("ydd_yd", fwd.ydd_yd, pf["ydd_yd"])
        if nu:
            rel("ydd_u", fwd.ydd_u, pf["Minv"] @ B)
        rel("tau", inv.tau, pi["tau"] - B @ u)
        rel("tau_y", inv.tau_y, pi["tau_y"])
        rel("tau_yd", inv.tau_yd, pi["tau_yd"])
        rel("M", inv.tau_ydd, pi["tau_ydd"])
        worst["cond_M_max"] = max(worst.get("cond_M_max", 0.0),
                                  float(np.linalg.cond(inv.tau_ydd)))
    return worst


def pinocchio_floor(n_states: int, rounds: int) -> dict[str, float]:
    """Seconds per state of a bare Python loop over ``n_states`` rows and of each Pinocchio
    call of the benchmark on a model of one revolute joint (the per-call floor)."""
    import pinocchio as pin

    model = pin.Model()
    jid = model.addJoint(0, pin.JointModelRX(), pin.SE3.Identity(), "j")
    model.appendBodyToJoint(jid, pin.Inertia.Random(), pin.SE3.Identity())
    data = model.createData()
    Q = np.random.default_rng(0).uniform(-1, 1, (n_states, 1))

    def bare() -> None:
        for i in range(n_states):
            Q[i], Q[i], Q[i]

    def aba_d() -> None:
        for i in range(n_states):
            pin.computeABADerivatives(model, data, Q[i], Q[i], Q[i])

    def rnea_d() -> None:
        for i in range(n_states):
            pin.computeRNEADerivatives(model, data, Q[i], Q[i], Q[i])

    best = interleaved({"bare": bare, "aba_derivatives": aba_d, "rnea_derivatives": rnea_d},
                       rounds)
    return {k: v / n_states for k, v in best.items()}


def case(r: dict, n_states: int = 1000, rounds: int = 7, check: int = 5,
         floor: dict[str, float] | None = None) -> dict:
    """Timings (seconds per state) and agreement for one robot; see the module docstring."""
    import pinocchio as pin

    import jourdain
    from jourdain.numeric import parameter_vector

    system, model, B = r["system"], r["model"], r["B"]
    f, nu = system.f, B.shape[1]
    t0 = time.perf_counter()
    d = jourdain.derivatives(system)
    t_compile = time.perf_counter() - t0
    rng = np.random.default_rng(1)
    Y = rng.uniform(-np.pi, np.pi, (n_states, f))
    pitch = [i for i, c in enumerate(system.coordinate_names) if c.endswith("pitch")]
    Y[:, pitch] = rng.uniform(-1.0, 1.0, (n_states, len(pitch)))
    YD, YDD = rng.uniform(-3, 3, (n_states, f)), rng.uniform(-3, 3, (n_states, f))
    U = rng.uniform(-2, 2, (n_states, nu))
    Uj = U if nu else None
    Qp, Vp, Ap, Tp = pinocchio_states(r, Y, YD, YDD, U)
    data = model.createData()

    # --- agreement (also compiles and warms everything up) ---
    worst = agreement(r, d, Y, YD, YDD, U, check)

    # --- timing ---
    lib = d.lib
    Tt = np.zeros(n_states)
    P = np.ascontiguousarray(parameter_vector(system, None))
    P = P if P.size else np.zeros(1)
    Uc = np.ascontiguousarray(U if nu else np.zeros((n_states, 1)))
    us = nu if nu else 0
    out_f = np.zeros((n_states, f + 2 * f * f + f * nu))
    out_i = np.zeros((n_states, f + 3 * f * f + f * nu))
    status = ctypes.c_int(0)

    def jd_fwd_1() -> None:
        for i in range(n_states):
            d.forward(Y[i], YD[i], u=None if Uj is None else Uj[i])

    def jd_inv_1() -> None:
        for i in range(n_states):
            d.inverse(Y[i], YD[i], YDD[i], u=None if Uj is None else Uj[i])

    def jd_fwd_c() -> None:
        lib.jd_forward_derivatives_batch(n_states, Y.ctypes.data, YD.ctypes.data,
                                         Tt.ctypes.data, P.ctypes.data, 0, Uc.ctypes.data, us,
                                         out_f.ctypes.data, ctypes.byref(status))

    def jd_inv_c() -> None:
        lib.jd_inverse_derivatives_batch(n_states, Y.ctypes.data, YD.ctypes.data,
                                         YDD.ctypes.data, Tt.ctypes.data, P.ctypes.data, 0,
                                         Uc.ctypes.data, us, out_i.ctypes.data,
                                         ctypes.byref(status))

    def pin_aba_d() -> None:
        for i in range(n_states):
            pin.computeABADerivatives(model, data, Qp[i], Vp[i], Tp[i])

    def pin_rnea_d() -> None:
        for i in range(n_states):
            pin.computeRNEADerivatives(model, data, Qp[i], Vp[i], Ap[i])

    # the C batch writes what the Python batch returns
    jd_fwd_c()
    assert status.value == 0 and np.array_equal(
        out_f[:, :f], d.forward(Y, YD, u=Uj).ydd), "C batch != API"
    fns: dict[str, Callable[[], object]] = {
        "jd_fwd_1": jd_fwd_1,
        "jd_fwd_batch": lambda: d.forward(Y, YD, u=Uj),
        "jd_fwd_c": jd_fwd_c,
        "pin_aba_d": pin_aba_d,
        "jd_inv_1": jd_inv_1,
        "jd_inv_batch": lambda: d.inverse(Y, YD, YDD, u=Uj),
        "jd_inv_c": jd_inv_c,
        "pin_rnea_d": pin_rnea_d,
    }
    best = {k: v / n_states for k, v in interleaved(fns, rounds).items()}
    return {"name": r["name"], "f": f, "inputs": nu, "bodies": len(system.bodies),
            "states": n_states, "rounds": rounds, "compile_s": t_compile, "times": best,
            "check": worst, "check_states": min(check, n_states), "floor": floor or {}}


def report(r: dict) -> dict[str, float]:
    """Print one robot's table; return its ratios jourdain / Pinocchio."""
    t, fl, c = r["times"], r["floor"], r["check"]
    us = 1e6
    net = {"pin_aba_d": t["pin_aba_d"] - fl.get("aba_derivatives", math.nan),
           "pin_rnea_d": t["pin_rnea_d"] - fl.get("rnea_derivatives", math.nan)}
    print(f"\n### {r['name']}: f = {r['f']}, {r['inputs']} inputs, {r['bodies']} bodies; "
          f"{r['states']} states, best of {r['rounds']} interleaved rounds; derivatives "
          f"compiled (or loaded) in {r['compile_s']:.1f} s\n")
    head = (f"| {'derivatives':<11} | {'jourdain':<14} | {'µs/state':>8} "
            f"| {'Pinocchio (1 call/state)':<24} | {'µs/state':>8} | {'ratio':>5} "
            f"| {'pin net of floor µs':>19} | {'ratio':>5} |")
    print(head)
    print("|" + "|".join("-" * len(x) if i in (0, 1, 3) else "-" * (len(x) - 1) + ":"
                         for i, x in enumerate(head.strip().strip("|").split("|"))) + "|")
    ratios: dict[str, float] = {}
    for label, pkey, pname, keys in (
            ("forward", "pin_aba_d", "computeABADerivatives",
             (("jd_fwd_1", "py 1/call"), ("jd_fwd_batch", "py batch"), ("jd_fwd_c", "C batch"))),
            ("inverse", "pin_rnea_d", "computeRNEADerivatives",
             (("jd_inv_1", "py 1/call"), ("jd_inv_batch", "py batch"), ("jd_inv_c", "C batch")))):
        pn = t[pkey]
        for jkey, jname in keys:
            j = t[jkey]
            ratios[jkey], ratios[jkey + "_net"] = j / pn, j / net[pkey]
            print(f"| {label:<11} | {jname:<14} | {us * j:>8.2f} | {pname:<24} | {us * pn:>8.2f} "
                  f"| {j / pn:>5.2f} | {us * net[pkey]:>19.2f} | {j / net[pkey]:>5.2f} |")
    print(f"\nthroughput of the batched call (one core): forward {1 / t['jd_fwd_batch']:,.0f} "
          f"states/s, inverse {1 / t['jd_inv_batch']:,.0f} states/s")
    print(f"agreement with Pinocchio mapped to jourdain's coordinates (max relative difference "
          f"over {r['check_states']} states): " + ", ".join(
              f"{k} {v:.1e}" for k, v in c.items() if k != "cond_M_max")
          + f" (largest cond(M) {c['cond_M_max']:.1e})")
    return ratios


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--robot", nargs="*", choices=list(ROBOTS), default=None,
                    help=f"robots (default {' '.join(ROBOTS)}; none with --robot alone)")
    ap.add_argument("--tree", type=int, nargs="*", default=(),
                    help="also random_tree(N) for each N (seed 0)")
    ap.add_argument("--states", type=int, default=1000, help="states (default 1000)")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds, best taken (7)")
    ap.add_argument("--check", type=int, default=5,
                    help="states checked against Pinocchio (default 5)")
    ap.add_argument("--quick", action="store_true",
                    help="panda only, 100 states, 2 rounds (a smoke test)")
    ap.add_argument("--json", type=Path, help="also write the results to this JSON file")
    a = ap.parse_args(argv)
    robots = list(ROBOTS) if a.robot is None else a.robot
    if a.quick:
        robots = ["panda"] if a.robot is None else robots
        a.states, a.rounds = min(a.states, 100), min(a.rounds, 2)
    floor = pinocchio_floor(a.states, a.rounds)
    print("Pinocchio from Python, per state: bare loop over the rows "
          f"{1e6 * floor['bare']:.3f} µs; on a model of one revolute joint (the per-call floor) "
          f"computeABADerivatives {1e6 * floor['aba_derivatives']:.2f} µs, "
          f"computeRNEADerivatives {1e6 * floor['rnea_derivatives']:.2f} µs. 'net of floor' "
          "subtracts these from Pinocchio's times; jourdain's batches run their loop in C.")
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        models = [robot(name, Path(tmp)) for name in robots] + [tree(n) for n in a.tree]
        for r in models:
            res = case(r, a.states, a.rounds, a.check, floor)
            res["ratios"] = report(res)
            results.append(res)
    if a.json:
        a.json.write_text(json.dumps(results, indent=2))
    return results


if __name__ == "__main__":
    main()
