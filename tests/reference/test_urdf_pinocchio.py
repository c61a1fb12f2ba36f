"""URDF files read by jourdain (:func:`jourdain.io.urdf.load_urdf`) against the same files read
by Pinocchio's ``buildModelFromUrdf`` (a ``JointModelFreeFlyer`` root for a floating base).

At random states: M against CRBA (symmetrized from its upper triangle), k − q against the
nonlinear effects, ÿ = M⁻¹(q − k) against ABA, RNEA at that ÿ (zero: no inputs), and every
joint's reaction wrench ``Σ g_k·w_k`` against RNEA's ``data.f`` (the wrench the joint transmits,
in the child link frame at the joint, which is jourdain's body frame). Tolerances come from the
problem (tests/tolerance.py through :func:`tests.reference.tree_crosscheck.judge`).

Coordinates. Pinocchio's joints are found by their URDF names. Its continuous joints have
``q = (cos θ, sin θ)`` and ``v = θ̇``; its free-flyer has ``q = (p, quaternion)`` and
``v = (Rᵀṗ, ω)`` in the body frame, while jourdain's free joint has ``y = (p, yaw, pitch,
roll)`` with ``R = Rz·Ry·Rx``; its planar joint has ``q = (x, y, cos θ, sin θ)`` and ``v =
(R(θ)ᵀ·(ẋ, ẏ), θ̇)``, jourdain's ``y = (x, y, θ)``. With ``ν = T(y)·ẏ`` (T square: nv = f) the two sets of equations
are related by ``M = TᵀM_pT`` and ``k − q = Tᵀ(nle_p + M_p·Ṫẏ)``, ``ν̇ = T·ÿ + Ṫẏ``;
:class:`Twin` computes T and Ṫẏ in closed form (body-frame angular velocity of the z-y-x
angles and its derivative).

Small URDFs of tests/data/urdf always run; the robots of ``example-robot-data`` (UR5, 6 joints;
Panda, 7 joints and 2 fingers, its mimic finger read as an independent joint as Pinocchio does
by default; Solo-12, a quadruped with a floating base, f = 18) run where that package is
installed (the test extra installs it) and are skipped with the reason otherwise. Each robot
takes about 1 s here (derivation, C compilation, 4 states).
"""

from __future__ import annotations

import importlib.metadata
from pathlib import Path

import numpy as np
import pytest

from tests.reference.tree_crosscheck import judge

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy", reason="the URDF reader needs jourdain[urdf] (yourdfpy)")

from jourdain.io.urdf import ROOT_JOINT, load_urdf  # noqa: E402
from jourdain.stages.reactions import graph_values  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"


def robots_dir() -> Path:
    """The robots folder of the ``example-robot-data`` package (skip if not installed)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data; "
                    "part of jourdain's test extra)")
    path = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    if not path.is_dir():
        pytest.skip(f"example-robot-data is installed but has no robots folder at {path}")
    return path


def _rot(axis: str, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def zyx_rates(angles: np.ndarray, rates: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body-frame angular velocity ``ω = E·θ̇`` of ``R = Rz(a)·Ry(b)·Rx(c)`` and ``Ė·θ̇``.

    ``ω = Rxᵀ·Ryᵀ·e_z·ȧ + Rxᵀ·e_y·ḃ + e_x·ċ``, so the columns of E are
    ``(−sin b, sin c cos b, cos c cos b)``, ``(0, cos c, −sin c)``, ``(1, 0, 0)``.
    """
    _, b, c = angles
    ad, bd, cd = rates
    sb, cb, sc, cc = np.sin(b), np.cos(b), np.sin(c), np.cos(c)
    E = np.array([[-sb, 0.0, 1.0], [sc * cb, cc, 0.0], [cc * cb, -sc, 0.0]])
    Edot = (bd * ad * np.array([-cb, -sc * sb, -cc * sb])
            + cd * (ad * np.array([0.0, cc * cb, -sc * cb]) + bd * np.array([0.0, -sc, -cc])))
    return E @ rates, Edot


class Twin:
    """Pinocchio's model of the same URDF and the map of states between the two."""

    def __init__(self, urdf: Path, floating_base: bool = False, **options) -> None:
        # no actuator inputs: Pinocchio's model has none (their q is checked in test_urdf.py)
        self.model = load_urdf(urdf, floating_base=floating_base, actuated=False, **options)
        self.system = self.model.system
        self.pin = (pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
                    if floating_base else pin.buildModelFromUrdf(str(urdf)))
        assert self.pin.nv == self.system.f
        names = self.system.coordinate_names
        # (Pinocchio joint id, jourdain coordinate indices) per moving joint
        self.blocks = []
        if floating_base:
            self.blocks.append((self.pin.getJointId(ROOT_JOINT), list(range(6))))
        for j in self.model.joints:
            if j.coordinates:
                self.blocks.append((self.pin.getJointId(j.name),
                                    [names.index(c) for c in j.coordinates]))
        # the Pinocchio joint whose frame is each jourdain body's frame
        jid = {j.joint: self.pin.getJointId(j.name) for j in self.model.joints if j.joint}
        jid[ROOT_JOINT] = self.pin.getJointId(ROOT_JOINT) if floating_base else 0
        self.joint_of_body = [jid[b.joint.name] for b in self.system.bodies]

    def state(self, y: np.ndarray, yd: np.ndarray):
        """Pinocchio's ``q``, ``v``, and T, Ṫẏ (``ν = T·ẏ``)."""
        f = self.system.f
        q, T, Tdot = np.zeros(self.pin.nq), np.zeros((f, f)), np.zeros(f)
        for jid, ix in self.blocks:
            jm = self.pin.joints[jid]
            iq, iv = jm.idx_q, jm.idx_v
            if jm.nv == 1:
                T[iv, ix[0]] = 1.0
                th = y[ix[0]]
                q[iq:iq + jm.nq] = [th] if jm.nq == 1 else [np.cos(th), np.sin(th)]
                continue
            if jm.shortname() == "JointModelPlanar":
                # q = (x, y, cos θ, sin θ), v = (R(θ)ᵀ·(ẋ, ẏ), θ̇): velocity in the body frame
                x, yy, th = y[ix]
                xd, yyd, thd = yd[ix]
                c, s = np.cos(th), np.sin(th)
                q[iq:iq + 4] = (x, yy, c, s)
                T[iv:iv + 3, ix] = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
                vx, vy = c * xd + s * yyd, -s * xd + c * yyd
                Tdot[iv:iv + 3] = (thd * vy, -thd * vx, 0.0)
                continue
            assert jm.shortname() == "JointModelFreeFlyer", jm.shortname()
            p, ang, pd, angd = y[ix[:3]], y[ix[3:]], yd[ix[:3]], yd[ix[3:]]
            R = _rot("z", ang[0]) @ _rot("y", ang[1]) @ _rot("x", ang[2])
            q[iq:iq + 7] = pin.SE3ToXYZQUAT(pin.SE3(R, p))
            E_rates, Edot = zyx_rates(ang, angd)
            a, b, c = ang
            sb, cb, sc, cc = np.sin(b), np.cos(b), np.sin(c), np.cos(c)
            T[iv:iv + 3, ix[:3]] = R.T
            T[iv + 3:iv + 6, ix[3:]] = np.array([[-sb, 0, 1], [sc * cb, cc, 0], [cc * cb, -sc, 0]])
            v_lin = R.T @ pd
            Tdot[iv:iv + 3] = -np.cross(E_rates, v_lin)
            Tdot[iv + 3:iv + 6] = Edot
        return q, T @ yd, T, Tdot

    def compare(self, y: np.ndarray, yd: np.ndarray) -> dict:
        """Both tools' numbers in jourdain's coordinates, in the form of
        :func:`benchmarks.crosscheck.compare` (for :func:`judge`)."""
        system, model = self.system, self.pin
        data = model.createData()
        out = system.evaluate(y, yd)
        assert "reactions_error" not in out, out.get("reactions_error")
        M, k, q_gen = out["M"], out["k"], out["q"]
        ydd = np.linalg.solve(M, q_gen - k)
        qp, vp, T, Tdot = self.state(y, yd)
        Mp = pin.crba(model, data, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        nle = pin.nonLinearEffects(model, data, qp, vp)
        res = {"out": out, "ydd": ydd, "M_pin": T.T @ Mp @ T,
               "nle_pin": T.T @ (nle + Mp @ Tdot)}
        res["aba"] = np.linalg.solve(T, pin.aba(model, data, qp, vp, np.zeros(model.nv)) - Tdot)
        res["tau"] = T.T @ pin.rnea(model, data, qp, vp, T @ ydd + Tdot)
        fs = [data.f[j].copy() for j in self.joint_of_body]
        pin.forwardKinematics(model, data, qp)
        res["points"] = np.array([x for j in self.joint_of_body for x in (
            data.oMi[j].translation, data.oMi[j].act(model.inertias[j].lever))])
        values = {**dict(zip(system.parameter_symbols, system.parameter_values.values(),
                             strict=True)), **dict(zip(system.y, y, strict=True))}
        res["W"], res["g"], res["wrench"], res["wrench_pin"] = [], [], [], []
        for jr, fp in zip(system.reactions().joints, fs, strict=True):
            exprs = [x for w in jr.wrenches for x in w]
            W = np.array(graph_values(exprs, values), dtype=float).reshape(len(jr.names), 6)
            g = out["g"][list(jr.columns)]
            res["W"].append(W)
            res["g"].append(g)
            res["wrench"].append(g @ W)
            res["wrench_pin"].append(np.concatenate([fp.linear, fp.angular]))
        return res


def _states(twin: Twin, n: int, seed: int):
    """``n`` random states: angles in (−π, π), pitch of free joints in (−1, 1) (away from the
    z-y-x angles' singularity at ±π/2, where T is singular), rates in (−3, 3)."""
    rng = np.random.default_rng(seed)
    f = twin.system.f
    names = twin.system.coordinate_names
    pitch = [i for i, c in enumerate(names) if c.endswith("pitch")]
    for _ in range(n):
        y = rng.uniform(-np.pi, np.pi, f)
        y[pitch] = rng.uniform(-1.0, 1.0, len(pitch))
        yield y, rng.uniform(-3.0, 3.0, f)


def _check(twin: Twin, n_states: int = 4, seed: int = 0) -> dict[str, float]:
    worst: dict[str, float] = {}
    for y, yd in _states(twin, n_states, seed):
        c = twin.compare(y, yd)
        for name, (err, tol) in judge(c).items():
            assert err <= tol, f"{twin.model.robot}: {name} error {err:.3e} > tolerance {tol:.3e}"
            worst[name] = max(worst.get(name, 0.0), err / tol if tol > 0 else 0.0)
        # the comparison is not empty: the wrenches are loads of the size of the forces
        assert max(np.abs(w).max() for w in c["wrench_pin"]) > 0.0
    return worst


def test_zyx_rates_against_finite_differences():
    """E·θ̇ is the body-frame angular velocity of R = Rz·Ry·Rx, and Ė·θ̇ its derivative
    (central differences; truncation error O(h²))."""
    rng = np.random.default_rng(3)
    th, thd = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)

    def R(a):
        return _rot("z", a[0]) @ _rot("y", a[1]) @ _rot("x", a[2])

    h = 1e-6
    Rd = (R(th + h * thd) - R(th - h * thd)) / (2 * h)
    W = R(th).T @ Rd  # ω̃ in the body frame
    w, Edot = zyx_rates(th, thd)
    assert np.allclose(w, [W[2, 1], W[0, 2], W[1, 0]], atol=1e-8)
    dw = (zyx_rates(th + h * thd, thd)[0] - zyx_rates(th - h * thd, thd)[0]) / (2 * h)
    assert np.allclose(Edot, dw, atol=1e-8)


@pytest.mark.parametrize("name, floating", [("two_link_arm", False), ("slider_crank", False),
                                            ("walker", True), ("puck", False)])
def test_small_urdfs_match_pinocchio(name, floating):
    twin = Twin(DATA / f"{name}.urdf", floating_base=floating)
    worst = _check(twin, n_states=4, seed=1)
    assert set(worst) >= {"M", "nle", "aba", "tau", "rnea"}


ROBOTS = {
    "ur5": ("ur_description/urdf/ur5_robot.urdf", False, {}, 6),
    "panda": ("panda_description/urdf/panda.urdf", False, {"mimic": "independent"}, 9),
    "solo12": ("solo_description/robots/solo12.urdf", True, {}, 18),
}


@pytest.mark.parametrize("robot", list(ROBOTS))
def test_example_robot_data_matches_pinocchio(robot):
    path, floating, options, f = ROBOTS[robot]
    twin = Twin(robots_dir() / path, floating_base=floating, **options)
    assert twin.system.f == f
    _check(twin, n_states=4, seed=2)
