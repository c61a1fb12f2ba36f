"""Joint wrenches as numbers (issue 12, item 5): force and torque vectors per joint, in the
joint frame and the inertial frame, by joint name — in System.evaluate, `jourdain eval --json`
and along a simulation (Results.joint_wrenches, the report's wrench-<joint>.csv).

References: a physical pendulum's pivot force in closed form, F = m·(a_c − g) with
φ̈ = −m·g·s·sin φ / (I_c + m·s²); Pinocchio's RNEA ``data.f`` (the force the parent transmits to
a joint's sub-tree, in the joint frame), for random trees of every joint kind."""

import json
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.cli import main
from jourdain.io import capabilities
from jourdain.wrenches import joint_wrenches
from tests.reference.tree_crosscheck import wrench_tol
from tests.tolerance import reactions_tol, tree_extent

ROOT = Path(__file__).resolve().parents[1]
M, S, IC, G = 2.0, 0.5, 0.03, 9.81


def physical_pendulum():
    phi, m, s, Ic, g = jd.symbols("phi m s Ic g")
    bob = jd.Body("bob", "world", jd.Revolute("pivot", phi, "z"), mass=m, com=(0, -s, 0),
                  inertia=(Ic, Ic, Ic))
    return jd.System([phi], [bob], [jd.Gravity((0, -g, 0))],
                     parameters={"m": M, "s": S, "Ic": IC, "g": G}, name="physical pendulum")


def _closed_form(phi, phid):
    """Inertial force on the pendulum at the pivot: m·(a_c − g_vec); its components in the
    body frame (turned by phi about z)."""
    phidd = -M * G * S * np.sin(phi) / (IC + M * S ** 2)
    # centre of mass at s·(sin φ, −cos φ)
    a = S * phidd * np.array([np.cos(phi), np.sin(phi), 0.0]) \
        + S * phid ** 2 * np.array([-np.sin(phi), np.cos(phi), 0.0])
    F = M * (a - np.array([0.0, -G, 0.0]))
    c, s = np.cos(phi), np.sin(phi)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return F, R.T @ F


@pytest.mark.parametrize("phi, phid", [(0.0, 0.0), (0.4, 1.3), (2.5, -3.0), (-1.2, 0.7)])
def test_pendulum_pivot_force_closed_form(phi, phid):
    system = physical_pendulum()
    out = system.evaluate([phi], [phid])
    w = out["joint_wrenches"]["pivot"]
    assert (w.joint, w.parent, w.child) == ("pivot", "world", "bob")
    F_inertial, F_body = _closed_form(phi, phid)
    tol = reactions_tol(out)
    assert np.abs(w.force_inertial - F_inertial).max() <= tol
    assert np.abs(w.force - F_body).max() <= tol
    # a planar pendulum: no torque about the pivot (about z the joint is free)
    assert np.abs(w.torque).max() <= tol and np.abs(w.torque_inertial).max() <= tol
    # the components of g are the joint-frame vector's components
    g = dict(zip(out["g_names"], out["g"], strict=True))
    np.testing.assert_array_equal(w.force, [g["pivot.F_x"], g["pivot.F_y"], g["pivot.F_z"]])
    np.testing.assert_array_equal(w.torque, [g["pivot.T_x"], g["pivot.T_y"], 0.0])


def _tree(kind_joints, seed):
    from benchmarks.crosscheck import build

    opts = {} if kind_joints is None else {"joints": kind_joints}
    return build("tree", 5, seed, **opts)


@pytest.mark.parametrize("joints, seed", [(None, 2), (("spherical",), 1), (("universal",), 4)],
                         ids=["mixed", "spherical", "universal"])
def test_joint_wrenches_match_pinocchio_rnea(joints, seed, rng):
    """Each joint's force and torque against RNEA's data.f (joint frame) and data.oMi's
    rotation times it (inertial frame), at random states; tolerance: the sub-tree residual
    (tests/README.md), with the extent of the tree from jourdain's own frames."""
    pin = pytest.importorskip("pinocchio")
    system, model, index = _tree(joints, seed)
    data = model.createData()
    for _ in range(3):
        y, yd = rng.uniform(-np.pi, np.pi, system.f), rng.uniform(-3, 3, system.f)
        out = system.evaluate(y, yd)
        ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
        qp, vp = index.to_pinocchio(y), index.to_pinocchio(yd)
        pin.rnea(model, data, qp, vp, index.to_pinocchio(ydd))
        pin.forwardKinematics(model, data, qp)
        tol = wrench_tol(out, ydd, tree_extent(system, y))
        wrenches = out["joint_wrenches"]
        assert list(wrenches) == [b.joint.name for b in system.bodies]
        for b, pid in zip(system.bodies, index.joint, strict=True):
            w, f = wrenches[b.joint.name], data.f[int(pid)]
            R = data.oMi[int(pid)].rotation
            assert np.abs(w.force - f.linear).max() <= tol, b.joint.name
            assert np.abs(w.torque - f.angular).max() <= tol, b.joint.name
            assert np.abs(w.force_inertial - R @ f.linear).max() <= tol, b.joint.name
            assert np.abs(w.torque_inertial - R @ f.angular).max() <= tol, b.joint.name


def test_joint_wrenches_along_a_simulation():
    """Results.joint_wrenches at every sample equals the single-state evaluation (same g,
    compiled directions and orientations), and follows the closed form of the pendulum."""
    system = physical_pendulum()
    res = system.simulate((0.0, 1.0), [1.0], [0.0], t_eval=np.linspace(0, 1, 21), rtol=1e-10,
                          atol=1e-12)
    w = res.joint_wrenches["pivot"]
    assert w.force.shape == (21, 3) and w.torque_inertial.shape == (21, 3)
    for i in (0, 7, 20):
        one = joint_wrenches(system, res.g[i], res.y[i], res.yd[i], res.t[i])
        out = system.evaluate(res.y[i], res.yd[i], res.t[i])
        tol = reactions_tol(out)
        for key in ("force", "torque", "force_inertial", "torque_inertial"):
            assert np.abs(getattr(w, key)[i] - getattr(one["pivot"], key)).max() <= tol
        F_inertial, _ = _closed_form(res.y[i, 0], res.yd[i, 0])
        assert np.abs(w.force_inertial[i] - F_inertial).max() <= tol
    cols, table = res.joint_wrench_table("pivot")
    assert cols[:4] == ["t", "pivot.F_x", "pivot.F_y", "pivot.F_z"]
    assert cols[-1] == "pivot.T_z_inertial" and table.shape == (21, 13)
    np.testing.assert_array_equal(table[:, 7:10], w.force_inertial)
    with pytest.raises(jd.EvaluationError, match="unknown joint"):
        res.joint_wrench_table("hinge9")


def test_eval_json_and_report_files(tmp_path, capsys):
    """`jourdain eval --json` has joint_wrenches by the documented contract; the report writes
    one table per joint and plots them."""
    path = ROOT / "examples" / "double_pendulum.toml"
    assert main(["eval", str(path), "--at", "phi1=0.3, phi1_d=1.0", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert list(data["joint_wrenches"]) == ["hinge1", "hinge2"]
    w = data["joint_wrenches"]["hinge2"]
    assert (w["parent"], w["child"], w["frame"]) == ("rod1", "rod2", "rod2")
    g = dict(zip(data["g_names"], data["values"]["g"], strict=True))
    assert w["force"] == [g["hinge2.F_x"], g["hinge2.F_y"], g["hinge2.F_z"]]
    assert np.linalg.norm(w["force_inertial"]) == pytest.approx(np.linalg.norm(w["force"]),
                                                                rel=1e-14)
    from jourdain.cli import _wrench_text

    model = jd.load_model(path)
    out = model.system.evaluate([0.3, 0.0], [1.0, 0.0])
    text = _wrench_text(model.system, out["joint_wrenches"])
    assert "joint wrenches on the child body" in text and text.count("inertial") == 2
    # the report's section: one table per joint, a plot, and the files listed for --force
    from jourdain.io import report

    model = jd.load_model(ROOT / "examples" / "simple_pendulum.toml")
    res = capabilities.simulate(model, t_end=0.3, samples=31)
    info = report.ReportInfo(tmp_path / "report.html")
    html = report._wrench_section(res, tmp_path, info)
    assert "joint wrenches along the motion" in html and "<svg" in html
    files = [p.name for p in info.files]
    assert files == [f"wrench-{b.joint.name}.csv" for b in model.system.bodies]
    assert set(files) <= set(report.report_files(model))
    lines = (tmp_path / files[0]).read_text().splitlines()
    assert lines[0].startswith("t,") and lines[0].endswith("_inertial") and len(lines) == 32
    name = files[0][len("wrench-"):-len(".csv")]
    np.testing.assert_array_equal(np.loadtxt(tmp_path / files[0], delimiter=",", skiprows=1),
                                  res.joint_wrench_table(name)[1])


def test_models_with_inputs():
    """The directions and orientations do not depend on the inputs: a model with inputs gets
    its joint wrenches at one state and along a simulation (the quarter car's road input)."""
    model = jd.load_model(ROOT / "examples" / "quarter_car.toml")
    system = model.system
    out = system.evaluate([0.01, 0.02], [0.1, -0.2], inputs={"z_r": 0.03})
    assert set(out["joint_wrenches"]) == {b.joint.name for b in system.bodies}
    res = system.simulate((0.0, 0.2), [0.0, 0.0], [0.0, 0.0], inputs={"z_r": 0.01},
                          t_eval=np.linspace(0, 0.2, 5))
    for name, w in res.joint_wrenches.items():
        i = 3
        one = joint_wrenches(system, res.g[i], res.y[i], res.yd[i], res.t[i])[name]
        o = system.evaluate(res.y[i], res.yd[i], res.t[i], inputs={"z_r": 0.01})
        assert np.abs(w.force_inertial[i] - one.force_inertial).max() <= reactions_tol(o)
