"""Work-precision against the peers (issue 35, item 2): CPU time against error over a fixed span.

Every tool simulates the same model from the same state over ``T`` seconds at several settings
(jourdain: its adaptive C integrators at a grid of tolerances; MuJoCo: RK4, ``implicit`` and
``implicitfast`` at a grid of time steps; Exudyn: its explicit RK44, RK67, adaptive DOPRI5 and
implicit generalized-α / trapezoidal solvers), and each run's error is the largest distance of
its final joint coordinates from a reference (radians). Per model and error level 1e-2 … 1e-8
the table gives each tool's fastest run reaching that level and the ratio peer / jourdain.

Models (the same masses, lengths, inertias, gravity and initial state in every tool):

* ``chain4``, ``chain12``, ``chain32``: a planar pendulum of n uniform links (1 kg, 1 m,
  centre of mass at mid-length, inertia (1e-3, 1/12, 1/12) kg m² about it) joined by hinges
  about z, gravity 9.81 along −y; coordinates the relative joint angles, released at rest from
  the first link horizontal and every further joint at 0.1 rad;
* ``arm``: :func:`jourdain.models.robot_arm` (7 revolute joints z-y-z-y-z-y-z, full inertia
  tensors; gravity along −z; 1 s: over 2 s it spins up to 18 rad and the references part by
  1e-9), with MJCF and Exudyn models generated from the same
  :func:`jourdain.models.robot_arm_data`;
* ``fourbar``: :func:`jourdain.models.four_bar` (a loop closed by a revolute joint; jourdain's
  coordinate partitioning), MuJoCo with a ``connect`` equality between two sites (soft, as
  MuJoCo's constraints are: ``solimp`` 0.9999, ``solref`` 2 ms), Exudyn with a
  ``KinematicTree`` closed by a spherical joint constraining x and y (implicit solvers only:
  Exudyn's explicit ones do not take such constraints). Rod inertia about the rod axis: 0 in
  jourdain, 1e-6 in the peers (MuJoCo refuses 0; it does not enter a planar motion).

Peers are the same as their users run them: MuJoCo through ``mujoco.rollout`` (its C loop, in
chunks of 10 000 steps; no Python per step; fixed steps), Exudyn through ``exu.SolveDynamic`` on
a ``KinematicTree`` (minimal coordinates, the dense solver, one thread, no solution file, no
end-of-step accelerations; fixed steps except DOPRI5, whose relative and absolute tolerances
are both the setting and whose largest step is T/10; Newton tolerances 1e-10 / 1e-12 for the
implicit ones). jourdain through ``System.simulate(..., rtol=r, atol=r, t_eval=[T])`` with
the model compiled beforehand. Each run's time is ``time.process_time()`` around that one call
(the per-call set-up of each tool included, its model building and compilation not).

Before timing, per model: one evaluation of the accelerations at a random state in every tool
(MuJoCo ``mj_forward``, Exudyn's mass matrix and right-hand side, jourdain's M⁻¹(q − k); for
the four-bar at a random assembled state: MuJoCo's loop, whose soft constraint leaves ~1e-5 of
relative difference, and the trees with the closing joint cut in both peers); the reference is jourdain's DOP853
at rtol = atol = 1e-13, checked against a second integration: SciPy's ``solve_ivp`` (DOP853,
1e-13) on jourdain's compiled M, k, q for the trees, jourdain's redundant (index-1)
formulation stepped by SciPy at 1e-13 for the four-bar, and MuJoCo RK4 at a small step where
MuJoCo is installed (trees). Their distances are printed.

A run reaches an error level when it and every finer run of the same integrator (smaller
step or tolerance) are within it, so that no lucky cancellation counts. Each integrator is
refined (step halved, tolerance by √10) until its error is below 1e-9 or one run takes more
than ``--cap`` seconds, and made coarser first where its first setting (a step of 10 ms,
20 ms for RK67; a tolerance of 1e-2) is already within 1e-2; a level it did not reach shows as "> t" (its slowest run's time) and
the ratio as a lower bound. Timing: the first round finds the runs and their errors, then
``--rounds`` − 1 more rounds run them all again, interleaved across tools, and the best CPU
time of each is kept.

    .venv/bin/python benchmarks/peers.py                      # every model (about 10 minutes)
    .venv/bin/python benchmarks/peers.py --models chain4 arm --rounds 2
    .venv/bin/python benchmarks/peers.py --tiny               # n = 2 chain, 0.5 s (a smoke test)
    .venv/bin/python benchmarks/peers.py --json peers.json    # the file is rewritten per model

Peers are optional: ``pip install 'jourdain[bench]'`` installs MuJoCo and Exudyn; a missing one
is skipped with a message.

Measured 2026-11-26 (MuJoCo 4.0.0, Exudyn 1.13.6; a 2-core AMD EPYC shared with other sessions,
load average 2-3; best of 3 rounds, cap 1 s; the whole run 7 minutes): jourdain's CPU time (ms)
and each peer's fastest time at the level over it, "> r" where the peer did not reach the level
within the cap (its slowest run over jourdain's time).

| model | tool | 1e-2 | 1e-3 | 1e-4 | 1e-5 | 1e-6 | 1e-7 | 1e-8 |
| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |
| chain4, 5 s | jourdain ms | 0.395 | 0.633 | 0.767 | 0.767 | 1.01 | 1.2 | 1.43 |
| | MuJoCo / jourdain | 18.5 | 22.6 | 37.3 | 74.2 | 56.1 | 95.0 | 159 |
| | Exudyn / jourdain | 17.5 | 12.2 | 19.6 | 20.1 | 30.4 | 51.1 | 43.0 |
| chain12, 3 s | jourdain ms | 2.48 | 3.45 | 4.46 | 5.72 | 7.69 | 8.49 | 9.99 |
| | MuJoCo / jourdain | 3.1 | 4.4 | 3.4 | 5.3 | 7.8 | 14.1 | 12.0 |
| | Exudyn / jourdain | 5.8 | 5.9 | 7.2 | 8.5 | 9.5 | 12.8 | 14.8 |
| chain32, 2 s | jourdain ms | 1.95 | 2.26 | 3.19 | 4.05 | 5.13 | 6.12 | 8.68 |
| | MuJoCo / jourdain | 1.7 | 2.8 | 2.0 | 3.1 | 4.9 | 8.2 | 11.4 |
| | Exudyn / jourdain | 9.0 | 12.5 | 11.3 | 14.6 | 16.6 | 20.8 | 22.7 |
| arm, 1 s | jourdain ms | 0.511 | 0.663 | 0.825 | 1.18 | 1.19 | 1.58 | 1.74 |
| | MuJoCo / jourdain | 2.1 | 2.9 | 2.3 | 3.1 | 6.1 | 9.2 | 16.6 |
| | Exudyn / jourdain | 2.6 | 2.9 | 3.5 | 3.5 | 5.1 | 4.9 | 6.8 |
| fourbar, 5 s | jourdain ms | 1.44 | 1.72 | 1.95 | 1.99 | 2.15 | 3.09 | 3.35 |
| | MuJoCo / jourdain | 2.1 | 3.3 | 5.8 | 11.2 | 41.2 | 57.9 | > 432 |
| | Exudyn / jourdain | 38.8 | 62.1 | 205 | 737 | > 801 | > 559 | > 514 |

jourdain was the fastest at every level of every model. The peers' winners: MuJoCo's RK4
everywhere (its ``implicit`` and ``implicitfast``, first order, stayed above 1e-3 within the
cap: 0.1-1.7 rad on chain4), Exudyn's RK67 or DOPRI5 on the trees, its implicit solvers (the
only ones that take its closing joint) on the four-bar. MuJoCo's soft loop stops near 1.6e-8
(dt 39 µs). The references agreed to 2.4e-10 (chain4, SciPy; MuJoCo RK4 at dt 2e-5: 2.2e-12),
2.7e-12, 1.4e-11, 9.9e-13 and 5.8e-12 (the four-bar's redundant formulation); the
accelerations to 1e-12 relative or better (MuJoCo's soft four-bar 1.1e-5). The smallest
margins are at 1e-2: chain32 1.7× (MuJoCo's RK4 in 100 steps of 20 ms, 3.2 ms against 1.95
ms), the arm and the four-bar 2.1×. There a call's fixed cost weighs: ``simulate()`` over
1e-9 s (one step) takes 0.09 ms for chain4, 0.13 ms for the arm, 0.22 ms for chain32, and
0.6 ms for the closed four-bar, of its 1.44 ms at 1e-2.

Again on 2026-11-27 for the chains (``--models chain4 chain12 chain32 --rounds 3``), after
issue 35's evaluation path by cost (chain12 and chain32 now on the recursion in planar vectors)
and ``simulate()``'s 19 µs per call: MuJoCo / jourdain 20–140 (chain4), 10–49 (chain12),
6.0–44 (chain32) across 1e-2 … 1e-8; Exudyn / jourdain 11–55, 18–51, 31–87.
"""

from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import re
import sys
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

# the planar chains: jourdain's model and the link data the peers' models are built from
from jourdain.models.planar import (  # noqa: E402
    GRAVITY,
    LINK_I_AXIAL,
    LINK_LENGTH,
    LINK_MASS,
)
from jourdain.models.planar import planar_chain as chain_system  # noqa: E402

LEVELS = (1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)
#: refinement stops below this error (every level is then reached)
STOP_ERROR = 1e-9
REF_TOL = 1e-13

MUJOCO_CHUNK = 10_000
BENCH_EXTRA = "pip install 'jourdain[bench]'"
MODELS = ("chain4", "chain12", "chain32", "arm", "fourbar")


# --------------------------------------------------------------------------------------- models

def _chain_links(n: int) -> list[dict]:
    """The chain in the form of :func:`jourdain.models.spatial_chain_data` (for the peers)."""
    J = LINK_MASS * LINK_LENGTH ** 2 / 12
    return [{"joint": "revolute", "axes": ("z",), "mass": LINK_MASS,
             "com": np.array([LINK_LENGTH / 2, 0.0, 0.0]),
             "inertia": np.diag([LINK_I_AXIAL, J, J]),
             "offset": np.array([LINK_LENGTH, 0.0, 0.0])} for _ in range(n)]


def _vec(v: Any) -> str:
    return " ".join(repr(float(x)) for x in v)


def mjcf_serial(data: list[dict], gravity: tuple[float, float, float]) -> str:
    """MJCF of a serial chain of revolute joints given as :func:`spatial_chain_data` dicts:
    body i at the previous body's ``offset``, its hinge about its axis, full inertia."""
    body = ""
    for i, d in reversed(list(enumerate(data))):
        prev = data[i - 1]["offset"] if i else (0.0, 0.0, 0.0)
        axis = " ".join("1" if d["axes"][0] == c else "0" for c in "xyz")
        I = np.asarray(d["inertia"], dtype=float)
        full = _vec((I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]))
        body = (f'<body name="b{i}" pos="{_vec(prev)}"><joint type="hinge" axis="{axis}"/>'
                f'<inertial pos="{_vec(d["com"])}" mass="{float(d["mass"])!r}" '
                f'fullinertia="{full}"/>{body}</body>')
    return (f'<mujoco><option gravity="{_vec(gravity)}"/><worldbody>{body}</worldbody>'
            "</mujoco>")


def exudyn_serial(data: list[dict], gravity: tuple[float, float, float], q0: np.ndarray,
                  qd0: np.ndarray):  # noqa: ANN201 - (SystemContainer, MainSystem)
    """Exudyn ``KinematicTree`` of the same serial chain (minimal coordinates)."""
    import exudyn as exu
    from exudyn.itemInterface import NodeGenericODE2, ObjectKinematicTree

    n = len(data)
    kinds = {"x": exu.JointType.RevoluteX, "y": exu.JointType.RevoluteY,
             "z": exu.JointType.RevoluteZ}
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * n,
                                       initialCoordinates=[float(x) for x in q0],
                                       initialCoordinates_t=[float(x) for x in qd0],
                                       numberOfODE2Coordinates=n))
    offsets = [[0.0, 0.0, 0.0]] + [[float(x) for x in d["offset"]] for d in data[:-1]]
    mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[kinds[d["axes"][0]] for d in data],
        linkParents=list(range(-1, n - 1)),
        jointTransformations=exu.Matrix3DList([np.eye(3)] * n),
        jointOffsets=exu.Vector3DList(offsets),
        linkInertiasCOM=exu.Matrix3DList([np.asarray(d["inertia"], float) for d in data]),
        linkCOMs=exu.Vector3DList([[float(x) for x in d["com"]] for d in data]),
        linkMasses=[float(d["mass"]) for d in data], gravity=list(gravity)))
    mbs.Assemble()
    return sc, mbs


FOURBAR_EPS = 1e-6  # the peers' rod inertia about the rod axis (MuJoCo refuses 0)


def _fourbar_values(system) -> dict[str, float]:  # noqa: ANN001
    return {str(k): float(v) for k, v in system.parameter_values.items()}


def mjcf_fourbar(P: dict[str, float]) -> str:
    """The four-bar in MJCF: crank and coupler a chain, the rocker from the ground, the loop
    closed by a ``connect`` equality between a site at the coupler's end and one at the
    rocker's end (as stiff as MuJoCo allows: solimp 0.9999)."""
    a, b, c, d = P["a"], P["b"], P["c"], P["d"]

    def inertial(m: float, L: float) -> str:
        J = m * L * L / 12
        return (f'<inertial pos="{L / 2!r} 0 0" mass="{m!r}" '
                f'diaginertia="{FOURBAR_EPS!r} {J!r} {J!r}"/>')

    hinge = '<joint type="hinge" axis="0 0 1"/>'
    return (f'<mujoco><option gravity="0 {-P["g"]!r} 0"/><worldbody>'
            f'<body name="crank">{hinge}{inertial(P["m1"], a)}'
            f'<body name="coupler" pos="{a!r} 0 0">{hinge}{inertial(P["m2"], b)}'
            f'<site name="s1" pos="{b!r} 0 0"/></body></body>'
            f'<body name="rocker" pos="{d!r} 0 0">{hinge}{inertial(P["m3"], c)}'
            f'<site name="s2" pos="{c!r} 0 0"/></body></worldbody>'
            '<equality><connect site1="s1" site2="s2" solimp="0.9999 0.9999 0.001 0.5 2" '
            'solref="0.002 1"/></equality></mujoco>')


def exudyn_fourbar(P: dict[str, float], q0: np.ndarray, qd0: np.ndarray, close: bool = True):
    """The four-bar in Exudyn: a ``KinematicTree`` (crank, coupler on the crank, rocker) and,
    with ``close``, a spherical joint holding x and y of the coupler's end on the rocker's."""
    import exudyn as exu
    from exudyn.itemInterface import (
        MarkerKinematicTreeRigid,
        NodeGenericODE2,
        ObjectJointSpherical,
        ObjectKinematicTree,
    )

    a, b, c, d = P["a"], P["b"], P["c"], P["d"]
    links = ((P["m1"], a), (P["m2"], b), (P["m3"], c))
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    node = mbs.AddNode(NodeGenericODE2(referenceCoordinates=[0.0] * 3,
                                       initialCoordinates=[float(x) for x in q0],
                                       initialCoordinates_t=[float(x) for x in qd0],
                                       numberOfODE2Coordinates=3))
    kt = mbs.AddObject(ObjectKinematicTree(
        nodeNumber=node, jointTypes=[exu.JointType.RevoluteZ] * 3, linkParents=[-1, 0, -1],
        jointTransformations=exu.Matrix3DList([np.eye(3)] * 3),
        jointOffsets=exu.Vector3DList([[0.0, 0.0, 0.0], [a, 0.0, 0.0], [d, 0.0, 0.0]]),
        linkInertiasCOM=exu.Matrix3DList([np.diag([FOURBAR_EPS, m * L * L / 12, m * L * L / 12])
                                          for m, L in links]),
        linkCOMs=exu.Vector3DList([[L / 2, 0.0, 0.0] for _, L in links]),
        linkMasses=[m for m, _ in links], gravity=[0.0, -P["g"], 0.0]))
    if close:
        m1 = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=kt, linkNumber=1,
                                                    localPosition=[b, 0.0, 0.0]))
        m2 = mbs.AddMarker(MarkerKinematicTreeRigid(objectNumber=kt, linkNumber=2,
                                                    localPosition=[c, 0.0, 0.0]))
        mbs.AddObject(ObjectJointSpherical(markerNumbers=[m1, m2], constrainedAxes=[1, 1, 0]))
    mbs.Assemble()
    return sc, mbs


@dataclass
class Model:
    """One benchmark model in every tool."""

    name: str
    title: str
    T: float
    system: Any  # the jourdain System
    q0: np.ndarray
    qd0: np.ndarray
    mjcf: str
    exudyn: Callable[[np.ndarray, np.ndarray], Any]  # (q0, qd0) -> (sc, mbs)
    closed: bool = False
    #: MuJoCo RK4's step for the third reference (trees); None: none
    mujoco_ref_dt: float | None = None
    #: for the accelerations check of the four-bar: Exudyn's tree without its closing joint
    exudyn_tree: Callable[[np.ndarray, np.ndarray], Any] | None = None
    extra: dict = field(default_factory=dict)


def make_model(name: str, tiny: bool = False) -> Model:
    if name.startswith("chain"):
        n = int(name[5:])
        q0 = np.full(n, 0.1)
        q0[0] = 0.0
        links = _chain_links(n)
        g = (0.0, -GRAVITY, 0.0)
        T = 0.5 if tiny else {4: 5.0, 12: 3.0}.get(n, 2.0)
        return Model(name, f"planar {n}-link pendulum, {T:g} s", T, chain_system(n), q0,
                     np.zeros(n), mjcf_serial(links, g),
                     lambda y, yd: exudyn_serial(links, g, y, yd),
                     mujoco_ref_dt=None if tiny else {4: 2e-5, 12: 5e-5}.get(n, 1e-4))
    if name == "arm":
        from jourdain.models import robot_arm, robot_arm_data

        data = robot_arm_data()
        g = (0.0, 0.0, -9.81)
        q0 = np.array([0.3, -0.5, 0.4, -1.2, 0.2, 0.8, -0.3])
        qd0 = np.array([0.5, -0.3, 0.8, 0.2, -0.6, 0.4, 1.0])
        T = 0.5 if tiny else 1.0  # at 2 s its references part by 1e-9 (it spins, 18 rad)
        return Model(name, f"7-joint arm (robot_arm), {T:g} s", T, robot_arm(), q0, qd0,
                     mjcf_serial(data, g), lambda y, yd: exudyn_serial(data, g, y, yd),
                     mujoco_ref_dt=None if tiny else 2e-5)
    if name == "fourbar":
        from jourdain.models import four_bar

        system = four_bar()
        P = _fourbar_values(system)
        start = system.evaluate([0.5, 0.8, 1.9], [1.0, 0.0, 0.0])  # assembled
        T = 0.5 if tiny else 5.0
        return Model(name, f"four-bar (closed loop), {T:g} s", T, system,
                     np.asarray(start["y"], float), np.asarray(start["yd"], float),
                     mjcf_fourbar(P), lambda y, yd: exudyn_fourbar(P, y, yd), closed=True,
                     exudyn_tree=lambda y, yd: exudyn_fourbar(P, y, yd, close=False))
    raise ValueError(f"unknown model {name!r}; models: {', '.join(MODELS)}")


# ------------------------------------------------------------------------- the tools' runs

@dataclass
class Integrator:
    """One tool's integrator: its settings from coarse to fine and one run of a setting."""

    tool: str
    label: str
    settings: list[float]
    unit: str  # "dt", "rtol" or "tol"
    run: Callable[[float], tuple]  # setting -> (CPU s, wall s, final coordinates)
    T: float = 1.0
    runs: list[dict] = field(default_factory=list)

    def coarser(self, setting: float) -> float | None:
        """The next coarser setting: half as many steps, or the tolerance times √10 (below
        0.5); None where there is none."""
        if self.unit == "dt":
            n = round(self.T / setting)
            return self.T / (n // 2) if n >= 2 else None
        up = float(f"{setting * math.sqrt(10):.3g}")
        return up if up < 0.5 else None


def _timed(fn: Callable[[], np.ndarray]) -> tuple[float, float, np.ndarray]:
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    c1, w1 = time.process_time(), time.perf_counter()
    return c1 - c0, w1 - w0, out


def _rtols(lo_exp: float, hi_exp: float) -> list[float]:
    """10^(-k/2) from 10^-lo_exp down to 10^-hi_exp."""
    return [float(f"{10 ** (-k / 2):.3g}") for k in range(int(2 * lo_exp), int(2 * hi_exp) + 1)]


def _steps(T: float, dt0: float, count: int) -> list[float]:
    """Time steps T/N, N = ceil(T/dt0)·2^k."""
    n0 = max(1, math.ceil(T / dt0 - 1e-9))
    return [T / (n0 * 2 ** k) for k in range(count)]


def jourdain_integrators(m: Model) -> list[Integrator]:
    s, T = m.system, m.T
    y0, yd0 = m.q0, m.qd0
    s.simulate((0.0, min(T, 0.01)), y0, yd0, rtol=1e-6, atol=1e-6)  # compiled before timing

    def make(method: str) -> Callable[[float], np.ndarray]:
        def run(rtol: float) -> tuple[float, float, np.ndarray]:
            def call() -> np.ndarray:
                return s.simulate((0.0, T), y0, yd0, method=method, rtol=rtol, atol=rtol,
                                  t_eval=[T]).y[-1]
            return _timed(call)
        return run

    return [Integrator("jourdain", "DOP853", _rtols(2, 12), "rtol", make("DOP853")),
            Integrator("jourdain", "RK45", _rtols(2, 10), "rtol", make("RK45"))]


def mujoco_integrators(m: Model) -> list[Integrator]:
    import mujoco
    from mujoco import rollout

    model = mujoco.MjModel.from_xml_string(m.mjcf)
    if m.closed:
        model.opt.tolerance = 1e-12
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    data.qpos[:], data.qvel[:] = m.q0, m.qd0
    s0 = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, s0, spec)
    buf = np.zeros((1, MUJOCO_CHUNK, s0.size))
    nq = model.nq

    def make(kind: str) -> Callable[[float], tuple]:
        integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{kind.upper()}")

        def run(dt: float) -> tuple[float, float, np.ndarray]:
            model.opt.integrator = integrator
            model.opt.timestep = dt
            nstep = round(m.T / dt)

            def call() -> np.ndarray:
                state = s0[None].copy()
                left = nstep
                while left:
                    k = min(left, MUJOCO_CHUNK)
                    out = buf[:, :k]
                    rollout.rollout(model, data, state, nstep=k, state=out)
                    state = out[:, k - 1].copy()
                    left -= k
                return state[0, 1:1 + nq].copy()
            return _timed(call)
        return run

    return [Integrator("MuJoCo", "RK4", _steps(m.T, 1e-2, 14), "dt", make("RK4"), m.T),
            Integrator("MuJoCo", "implicit", _steps(m.T, 1e-3, 12), "dt", make("implicit"),
                       m.T),
            Integrator("MuJoCo", "implicitfast", _steps(m.T, 1e-3, 12), "dt",
                       make("implicitfast"), m.T)]


def _exudyn_settings(T: float, solver: str, setting: float):  # noqa: ANN202
    import exudyn as exu

    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = T
    ti.verboseMode = 0
    ss.solution.file.write = False
    ss.solution.sensors.active = False
    ss.show.computationTime = False
    ss.show.statistics = False
    ss.linearSolver.solverType = exu.LinearSolverType.EXUdense
    ss.parallel.numberOfThreads = 1
    ti.explicit.computeEndOfStepAccelerations = False
    # Newton tightened from 1e-8 / 1e-10, so that it does not bound the accuracy
    ti.newton.relativeTolerance = 1e-10
    ti.newton.absoluteTolerance = 1e-12
    if solver == "DOPRI5":
        ti.automaticStepSize = True
        ti.relativeTolerance = ti.absoluteTolerance = setting
        # the largest step is T / numberOfSteps; 1 lets its first step be T (it diverges)
        ti.numberOfSteps = 10
        ti.minimumStepSize = 1e-12
    else:
        ti.automaticStepSize = False
        ti.numberOfSteps = round(T / setting)
    return ss


def exudyn_integrators(m: Model) -> list[Integrator]:
    import exudyn as exu

    _sc, mbs = m.exudyn(m.q0, m.qd0)
    m.extra["_exudyn_keep"] = _sc  # the container owns the system

    def make(solver: str) -> Callable[[float], tuple]:
        kind = getattr(exu.DynamicSolverType, solver)

        def run(setting: float) -> tuple[float, float, np.ndarray]:
            ss = _exudyn_settings(m.T, solver, setting)

            def call() -> np.ndarray:
                exu.SolveDynamic(mbs, ss, solverType=kind)
                return np.array(mbs.systemData.GetODE2Coordinates())
            return _timed(call)
        return run

    implicit = [Integrator("Exudyn", "GeneralizedAlpha", _steps(m.T, 1e-2, 12), "dt",
                           make("GeneralizedAlpha"), m.T)]
    if m.closed:
        return implicit + [Integrator("Exudyn", "TrapezoidalIndex2", _steps(m.T, 1e-2, 12),
                                      "dt", make("TrapezoidalIndex2"), m.T)]
    return [Integrator("Exudyn", "RK44", _steps(m.T, 1e-2, 14), "dt", make("RK44"), m.T),
            Integrator("Exudyn", "RK67", _steps(m.T, 2e-2, 12), "dt", make("RK67"), m.T),
            Integrator("Exudyn", "DOPRI5", _rtols(2, 12), "tol", make("DOPRI5"))] + implicit


# -------------------------------------------------------------- references and the check

def jourdain_accelerations(m: Model, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
    out = m.system.evaluate(y, yd)
    if "ydd" in out:
        return np.asarray(out["ydd"], float)
    M, k, q = (np.asarray(out[x], float) for x in ("M", "k", "q"))
    return np.linalg.solve(M, (q - k).reshape(-1))


def _tree_accelerations(m: Model, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
    """ÿ of the closed system's tree (its closing joints cut): M⁻¹(q − k)."""
    out = m.system.tree.evaluate(y, yd)
    M, k, q = (np.asarray(out[x], float) for x in ("M", "k", "q"))
    return np.linalg.solve(M, (q - k).reshape(-1))


def exudyn_accelerations(builder: Callable, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
    import exudyn as exu

    _sc, mbs = builder(y, yd)
    ss = _exudyn_settings(1.0, "RK44", 1.0)  # no solution file
    ss.timeIntegration.solverType = exu.DynamicSolverType.RK44
    solver = exu.MainSolverExplicit()
    solver.InitializeSolver(mbs, ss)
    solver.ComputeMassMatrix(mbs)
    solver.ComputeODE2RHS(mbs)
    M = np.array(solver.GetSystemMassMatrix())
    rhs = np.array(solver.GetSystemResidual())[:len(y)]
    return np.linalg.solve(M, rhs)


def mujoco_accelerations(mjcf: str, y: np.ndarray, yd: np.ndarray) -> np.ndarray:
    import mujoco

    model = mujoco.MjModel.from_xml_string(mjcf)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = y, yd
    mujoco.mj_forward(model, data)
    return data.qacc.copy()


def check_models(m: Model, peers: dict[str, bool]) -> dict[str, float]:
    """Relative difference max|ÿ_peer − ÿ_jourdain| / max|ÿ_jourdain| at one random state."""
    rng = np.random.default_rng(11)
    f = len(m.q0)
    out: dict[str, float] = {}
    if m.closed:  # a random assembled state: the independent angle and rate drawn
        start = m.system.evaluate([float(rng.uniform(0, 2 * np.pi)), 0.8, 1.9],
                                  [float(rng.uniform(-2, 2)), 0.0, 0.0])
        y, yd = np.asarray(start["y"], float), np.asarray(start["yd"], float)
    else:
        y, yd = rng.uniform(-np.pi, np.pi, f), rng.uniform(-2, 2, f)
    a = jourdain_accelerations(m, y, yd)

    def rel(b: np.ndarray, a: np.ndarray = a) -> float:
        return float(np.abs(b - a).max() / np.abs(a).max())

    if peers.get("MuJoCo"):
        out["MuJoCo"] = rel(mujoco_accelerations(m.mjcf, y, yd))
    if m.closed:  # the trees, closing joints cut: exact; MuJoCo's soft loop above: ~1e-5
        at = _tree_accelerations(m, y, yd)
        if peers.get("MuJoCo"):
            tree = re.sub(r"<equality>.*</equality>", "", m.mjcf)
            out["MuJoCo (tree)"] = rel(mujoco_accelerations(tree, y, yd), at)
        if peers.get("Exudyn"):
            out["Exudyn (tree)"] = rel(exudyn_accelerations(m.exudyn_tree, y, yd), at)
    elif peers.get("Exudyn"):
        out["Exudyn"] = rel(exudyn_accelerations(m.exudyn, y, yd))
    return out


def references(m: Model, peers: dict[str, bool]) -> tuple[np.ndarray, dict]:
    """The reference final coordinates (jourdain DOP853 at 1e-13) and its distance from the
    other integrations."""
    s, T = m.system, m.T
    c, w, ref = _timed(lambda: s.simulate((0.0, T), m.q0, m.qd0, rtol=REF_TOL, atol=REF_TOL,
                                          t_eval=[T]).y[-1])
    info: dict[str, Any] = {"reference": "jourdain DOP853 rtol = atol = 1e-13",
                            "reference_cpu_s": c, "agreement": {}}
    if m.closed:
        r = s.simulate((0.0, T), m.q0, m.qd0, rtol=REF_TOL, atol=REF_TOL, t_eval=[0.0, T],
                       formulation="redundant")
        info["agreement"]["jourdain redundant formulation (SciPy DOP853, 1e-13)"] = float(
            np.abs(r.y[-1] - ref).max())
    else:
        info["agreement"]["SciPy DOP853 (1e-13) on jourdain's M, k, q"] = float(
            np.abs(scipy_reference(m) - ref).max())
        if peers.get("MuJoCo") and m.mujoco_ref_dt:
            (mj,) = [i for i in mujoco_integrators(m) if i.label == "RK4"]
            _, _, yT = mj.run(m.mujoco_ref_dt)
            info["agreement"][f"MuJoCo RK4, dt = {m.mujoco_ref_dt:g}"] = float(
                np.abs(yT - ref).max())
    return ref, info


def scipy_reference(m: Model) -> np.ndarray:
    from scipy.integrate import solve_ivp

    from jourdain.numeric import mkq_function, parameter_vector

    fn = mkq_function(m.system)
    p = parameter_vector(m.system, None)
    f = len(m.q0)

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        o = fn.batch(x[None, :f], x[None, f:], t, p, None)
        ydd = np.linalg.solve(o["M"][0], o["q"][0, :, 0] - o["k"][0, :, 0])
        return np.concatenate([x[f:], ydd])

    sol = solve_ivp(rhs, (0.0, m.T), np.concatenate([m.q0, m.qd0]), method="DOP853",
                    rtol=REF_TOL, atol=REF_TOL)
    return sol.y[:f, -1]


# ---------------------------------------------------------------------------- the sweep

def _run_one(integ: Integrator, setting: float, ref: np.ndarray) -> dict:
    try:
        cpu, wall, yT = integ.run(setting)
        err = float(np.abs(np.asarray(yT, float) - ref).max())
    except Exception as e:  # a peer's solver failing at a coarse step: an infinite error
        cpu, wall, err = math.nan, math.nan, math.inf
        print(f"    {integ.tool} {integ.label} {integ.unit} {setting:.3g}: "
              f"{type(e).__name__}: {str(e).splitlines()[0][:120]}", flush=True)
    return {"setting": setting, "error": err if math.isfinite(err) else math.inf,
            "cpu_s": cpu, "wall_s": wall}


def discover(integ: Integrator, ref: np.ndarray, cap: float) -> None:
    """Run the settings from coarse to fine until the error is below :data:`STOP_ERROR` or a
    run takes more than ``cap`` CPU seconds. Where the first setting is already within the
    loosest level, coarser ones (``integ.coarser``) are run first until one is not, so that
    the fastest run at each level is found whatever the grid's start."""
    first = _run_one(integ, integ.settings[0], ref)
    integ.runs.append(first)
    setting, r = integ.settings[0], first
    for _ in range(12):
        coarser = integ.coarser(setting)
        if r["error"] > LEVELS[0] or coarser is None:
            break
        setting = coarser
        r = _run_one(integ, setting, ref)
        integ.runs.insert(0, r)
    for setting in integ.settings[1:]:
        last = integ.runs[-1]
        if last["error"] < STOP_ERROR or not last["cpu_s"] <= cap:
            break
        integ.runs.append(_run_one(integ, setting, ref))


def retime(integrators: list[Integrator], rounds: int) -> None:
    """``rounds`` more passes over every run that reaches a level (interleaved across the
    integrators, so that a slow phase of the machine falls on all), keeping the best time of
    each; runs that reach none only bound the table's "> t" and are not repeated."""
    queues = [[(i, r) for k, r in enumerate(i.runs)
               if math.isfinite(r["cpu_s"]) and max(x["error"] for x in i.runs[k:]) <= LEVELS[0]]
              for i in integrators]
    for _ in range(rounds):
        for i, r in (x for batch in itertools.zip_longest(*queues) for x in batch if x):
            cpu, wall, _ = i.run(r["setting"])
            r["cpu_s"], r["wall_s"] = min(r["cpu_s"], cpu), min(r["wall_s"], wall)


def best_at_levels(integrators: list[Integrator]) -> dict[str, dict[str, dict]]:
    """Per tool and level: the fastest run reaching it (it and every finer run of its
    integrator within the level), or the slowest run tried where none does."""
    out: dict[str, dict[str, dict]] = {}
    for tool in dict.fromkeys(i.tool for i in integrators):
        mine = [i for i in integrators if i.tool == tool]
        slowest = max((r["cpu_s"] for i in mine for r in i.runs if math.isfinite(r["cpu_s"])),
                      default=math.nan)
        per: dict[str, dict] = {}
        for level in LEVELS:
            best: dict | None = None
            for i in mine:
                for k, r in enumerate(i.runs):
                    if not math.isfinite(r["cpu_s"]):
                        continue
                    if all(x["error"] <= level for x in i.runs[k:]):
                        if best is None or r["cpu_s"] < best["cpu_s"]:
                            best = {"cpu_s": r["cpu_s"], "integrator": i.label,
                                    i.unit: r["setting"], "error": r["error"]}
            per[f"{level:.0e}"] = best or {"reached": False, "slowest_cpu_s": slowest}
        out[tool] = per
    return out


def _fmt_time(s: float) -> str:
    return f"{s * 1e3:.3g} ms" if s < 1 else f"{s:.3g} s"


def table(name: str, best: dict[str, dict[str, dict]]) -> str:
    tools = list(best)
    head = "| error | " + " | ".join(
        f"{t} | {t} setting" + ("" if t == "jourdain" else f" | {t}/jourdain") for t in tools)
    cols = sum(2 if t == "jourdain" else 3 for t in tools)
    lines = [f"\n### {name}\n", head + " |", "| ---: |" + " ---: |" * cols]
    for level in LEVELS:
        key = f"{level:.0e}"
        jd = best.get("jourdain", {}).get(key, {})
        cells = [key]
        for t in tools:
            b = best[t][key]
            if "cpu_s" in b:
                unit = "rtol" if "rtol" in b else "tol" if "tol" in b else "dt"
                cells += [_fmt_time(b["cpu_s"]), f"{b['integrator']} {unit} {b[unit]:.3g}"]
                if t != "jourdain":
                    cells.append(f"{b['cpu_s'] / jd['cpu_s']:.1f}" if "cpu_s" in jd else "—")
            else:
                cells += [f"> {_fmt_time(b['slowest_cpu_s'])}", "not reached"]
                if t != "jourdain":
                    cells.append(f"> {b['slowest_cpu_s'] / jd['cpu_s']:.1f}"
                                 if "cpu_s" in jd and math.isfinite(b["slowest_cpu_s"])
                                 else "—")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def available_peers(wanted: list[str]) -> dict[str, bool]:
    peers: dict[str, bool] = {}
    for tool, module in (("MuJoCo", "mujoco"), ("Exudyn", "exudyn")):
        if tool.lower() not in wanted:
            continue
        try:
            __import__(module)
            peers[tool] = True
        except ImportError:
            print(f"{tool} is not installed: skipped ({BENCH_EXTRA} installs the peers)")
            peers[tool] = False
    return peers


def run_model(m: Model, peers: dict[str, bool], rounds: int, cap: float) -> dict:
    print(f"\n## {m.title}: f = {len(m.q0)}", flush=True)
    check = check_models(m, peers)
    for tool, d in check.items():
        print(f"  accelerations at a random state, {tool} against jourdain: {d:.1e} (relative)")
    ref, info = references(m, peers)
    for how, d in info["agreement"].items():
        print(f"  reference (jourdain DOP853 at 1e-13, {_fmt_time(info['reference_cpu_s'])}) "
              f"against {how}: {d:.1e}")
    worst = max(info["agreement"].values(), default=0.0)
    if worst > LEVELS[-1] / 10:
        print(f"  WARNING: the references part by {worst:.1e}: the levels below "
              f"{10 * worst:.0e} are not resolved")
    integrators = jourdain_integrators(m)
    if peers.get("MuJoCo"):
        integrators += mujoco_integrators(m)
    if peers.get("Exudyn"):
        integrators += exudyn_integrators(m)
    for integ in integrators:
        discover(integ, ref, cap)
        last = integ.runs[-1]
        print(f"  {integ.tool} {integ.label}: {len(integ.runs)} runs, finest {integ.unit} "
              f"{last['setting']:.3g}: error {last['error']:.1e} in "
              f"{_fmt_time(last['cpu_s']) if math.isfinite(last['cpu_s']) else '—'}",
              flush=True)
    retime(integrators, rounds - 1)
    best = best_at_levels(integrators)
    print(table(m.title, best), flush=True)
    return {"model": m.name, "title": m.title, "T": m.T, "f": len(m.q0),
            "q0": m.q0.tolist(), "qd0": m.qd0.tolist(), "accelerations_check": check,
            "reference": info, "rounds": rounds, "cap_s": cap,
            "runs": [{"tool": i.tool, "integrator": i.label, "unit": i.unit, "runs": i.runs}
                     for i in integrators],
            "best": best}


def _write(path: Path, results: list[dict]) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps({"levels": list(LEVELS), "models": results}, indent=1,
                              default=float))
    os.replace(tmp, path)


def main(argv: list[str] | None = None) -> list[dict]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--models", nargs="*", default=list(MODELS),
                    help=f"models (default: {' '.join(MODELS)})")
    ap.add_argument("--peers", nargs="*", default=["mujoco", "exudyn"],
                    help="peers to run (default: mujoco exudyn; none: jourdain alone)")
    ap.add_argument("--rounds", type=int, default=3, help="timing rounds, best kept (3)")
    ap.add_argument("--cap", type=float, default=1.0,
                    help="stop refining an integrator after a run of this many CPU s (1.0)")
    ap.add_argument("--tiny", action="store_true",
                    help="a 2-link chain over 0.5 s, one round, cap 0.05 s (a smoke test)")
    ap.add_argument("--json", type=Path, default=Path("peers.json"),
                    help="results file, rewritten after each model (default peers.json)")
    a = ap.parse_args(argv)
    warnings.filterwarnings("ignore", category=DeprecationWarning, module="exudyn")
    models = ["chain2"] if a.tiny else a.models
    rounds, cap = (1, min(a.cap, 0.05)) if a.tiny else (a.rounds, a.cap)
    peers = available_peers([p.lower() for p in a.peers])
    print(f"CPU time (process_time) of one simulate/rollout/SolveDynamic call, best of {rounds} "
          f"round(s); error: max |q(T) − q_ref(T)| (rad); refinement stops below "
          f"{STOP_ERROR:.0e} or after a run over {cap:g} s; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    results: list[dict] = []
    for name in models:
        results.append(run_model(make_model(name, a.tiny), peers, rounds, cap))
        _write(a.json, results)
    print(f"\nresults written to {a.json}")
    return results


if __name__ == "__main__":
    main()
