"""URDF import (jourdain.io.urdf): the model it builds, the data it keeps, its errors and the
command line on a .urdf. The numbers against Pinocchio are in
tests/reference/test_urdf_pinocchio.py."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("yourdfpy", reason="the URDF reader needs jourdain[urdf] (yourdfpy)")

from scipy.spatial.transform import Rotation  # noqa: E402

import jourdain as jd  # noqa: E402
from jourdain.cli import main  # noqa: E402
from jourdain.extras import MissingDependency  # noqa: E402
from jourdain.io.urdf import UrdfError, load_urdf  # noqa: E402
from jourdain.numeric import evaluate  # noqa: E402
from tests.tolerance import EPS  # noqa: E402

DATA = Path(__file__).resolve().parent / "data" / "urdf"
ARM = DATA / "two_link_arm.urdf"


def _T(xyz, rpy) -> np.ndarray:
    """URDF origin: R = Rz(yaw)·Ry(pitch)·Rx(roll), i.e. extrinsic x-y-z (SciPy's "xyz")."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:3, 3] = xyz
    return T


def test_fixed_joint_merges_mass_data_into_the_parent():
    """link1 carries the tool (fixed joint): mass, centre of mass and inertia of the merged
    body, from the file's numbers by the parallel-axis theorem (SciPy's rotations)."""
    model = load_urdf(ARM)
    system = model.system
    assert system.body_names == ["link1", "link2", "hand"]
    assert system.coordinate_names == ["shoulder", "elbow", "wrist"]
    p = system.parameter_values
    # link1: inertial at (0.02, -0.01, 0.25), rpy (0.3, 0.2, -0.4)
    I1 = np.array([[0.04, 0.001, -0.002], [0.001, 0.035, 0.0015], [-0.002, 0.0015, 0.01]])
    T1 = _T([0.02, -0.01, 0.25], [0.3, 0.2, -0.4])
    # tool: joint origin (0.05, 0, 0.3), rpy (0, π/2, 0.2); inertial (0.03, 0.01, 0), rpy (0.5,0,0)
    It = np.array([[0.002, 0.0001, 0], [0.0001, 0.003, 0], [0, 0, 0.0025]])
    Tt = _T([0.05, 0, 0.3], [0, np.pi / 2, 0.2]) @ _T([0.03, 0.01, 0], [0.5, 0, 0])
    parts = [(2.0, T1, I1), (0.7, Tt, It)]
    m = sum(mi for mi, _, _ in parts)
    c = sum(mi * T[:3, 3] for mi, T, _ in parts) / m
    I = sum(T[:3, :3] @ Ii @ T[:3, :3].T + mi * ((T[:3, 3] - c) @ (T[:3, 3] - c) * np.eye(3)
                                                   - np.outer(T[:3, 3] - c, T[:3, 3] - c))
            for mi, T, Ii in parts)
    assert p["m_link1"] == pytest.approx(m, rel=4 * EPS)
    got_c = [p["cx_link1"], p["cy_link1"], p["cz_link1"]]
    np.testing.assert_allclose(got_c, c, rtol=0, atol=20 * EPS * np.abs(c).max())
    got_I = np.array([[p[f"I{'xyz'[min(a, b)]}{'xyz'[max(a, b)]}_link1"] for b in range(3)]
                      for a in range(3)])
    np.testing.assert_allclose(got_I, I, rtol=0, atol=50 * EPS * np.abs(I).max())
    # the base is welded to the world: its mass is in no body
    assert not any(k.endswith("_base") for k in p)
    assert p["g"] == 9.81 and load_urdf(ARM, gravity=3.7).system.parameter_values["g"] == 3.7


def test_joints_links_and_geometry_kept_as_data():
    model = load_urdf(ARM)
    sh = model.joint("shoulder")
    assert (sh.type, sh.parent, sh.child, sh.body, sh.coordinates) == (
        "revolute", "base", "link1", "link1", ("shoulder",))
    assert (sh.lower, sh.upper, sh.effort, sh.velocity) == (-2.9, 2.9, 80.0, 2.5)
    assert (sh.damping, sh.friction) == (0.5, 0.1)
    el = model.joint("elbow")
    np.testing.assert_allclose(el.axis, [0, 0.6, 0.8], rtol=0, atol=2 * EPS)
    assert el.damping is None and model.joint("wrist").lower is None
    tm = model.joint("tool_mount")
    assert tm.type == "fixed" and tm.body == "link1" and tm.joint is None and not tm.coordinates
    links = {lk.name: lk for lk in model.links}
    assert links["base"].body == "world" and links["tool"].body == "link1"
    np.testing.assert_allclose(links["tool"].pose, _T([0.05, 0, 0.3], [0, np.pi / 2, 0.2]),
                               atol=4 * EPS)
    np.testing.assert_allclose(links["link2"].pose, np.eye(4), atol=0)
    kinds = [(g.link, g.kind) for g in model.visual_geometry]
    assert kinds == [("base", "cylinder"), ("link1", "box"), ("tool", "mesh"),
                     ("hand", "sphere")]
    mesh = model.visual_geometry[2]
    assert mesh.filename == "meshes/tool.stl" and mesh.path is None  # not shipped
    assert mesh.scale == (0.001, 0.001, 0.001) and mesh.body == "link1"
    np.testing.assert_allclose(mesh.pose, links["tool"].pose, atol=0)
    assert model.visual_geometry[0].size == (0.1, 0.1) and model.visual_geometry[0].rgba == (0.5, 0.5, 0.5, 1.0)
    assert model.visual_geometry[3].size == (0.04,)
    np.testing.assert_allclose(model.visual_geometry[3].pose, _T([0.05, 0, 0], [0, np.pi / 2, 0]),
                               atol=4 * EPS)
    assert model.collision_geometry == ()
    # the meshes as the 3-D view takes them: per moving body, pose in the body frame
    (mv,) = model.visuals["link1"]
    assert list(model.visuals) == ["link1"] and mv.scale == (0.001, 0.001, 0.001)
    np.testing.assert_allclose(mv.rotation, np.asarray(links["tool"].pose)[:3, :3], atol=0)
    np.testing.assert_allclose(mv.position, np.asarray(links["tool"].pose)[:3, 3], atol=0)


def test_actuators_and_joint_damping_act_on_their_coordinates(rng):
    """tau_<joint> adds to its row of q; with joint_damping=True, −damping·ẏ does."""
    plain = load_urdf(ARM, actuated=False).system
    model = load_urdf(ARM, joint_damping=True)
    system = model.system
    assert system.input_names == ["tau_shoulder", "tau_elbow", "tau_wrist"]
    y, yd, tau = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3), rng.uniform(-5, 5, 3)
    q0 = evaluate(plain, y, yd)["q"]
    q1 = evaluate(system, y, yd, inputs=tau)["q"]
    expected = tau - np.array([0.5, 0.0, 0.0]) * yd  # only the shoulder has a damping
    np.testing.assert_allclose(q1 - q0, expected, rtol=0, atol=100 * EPS * np.abs(q0).max())


def test_floating_base_coordinates():
    system = load_urdf(DATA / "walker.urdf", floating_base=True, actuated=False).system
    assert system.coordinate_names[:6] == ["root_x", "root_y", "root_z", "root_yaw",
                                           "root_pitch", "root_roll"]
    assert system.coordinate_names[-6:] == [f"tail_mount_{s}" for s in
                                            ("x", "y", "z", "yaw", "pitch", "roll")]
    assert system.f == 16 and system.bodies[0].joint.kind == "free"
    # a free-falling body: ÿ of the base is gravity at rest, whatever the pose
    y = np.zeros(16)
    y[3:6] = (0.3, -0.2, 0.5)
    out = evaluate(system, y, np.zeros(16))
    ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
    np.testing.assert_allclose(ydd[:3], [0, 0, -9.81], rtol=0, atol=1e-12 * 9.81 * 1e3)


ROBOT = """<?xml version="1.0"?>
<robot name="r">
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  {extra}
</robot>
"""
LINK_C = """<link name="c"><inertial><mass value="1"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>"""


@pytest.mark.parametrize("extra, match, line", [
    (LINK_C + '<joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>'
     '<axis xyz="1 0 0"/><mimic joint="ghost" multiplier="2"/></joint>',
     r'joint "j2": it mimics joint "ghost", which is not declared', 10),
    (LINK_C + '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/></joint>'
     '<joint name="j3" type="revolute"><parent link="a"/><child link="c"/></joint>',
     r'joint "j3": link "c" is already the child of joint "j2"; .* closes a kinematic loop', 10),
    ('<joint name="j2" type="revolute"><parent link="ghost"/><child link="b"/></joint>',
     r'joint "j2": its parent link "ghost" is not declared', 9),
    ('<loop_joint name="close" type="revolute"/>', r'<loop_joint> "close": closed kinematic '
     'loops are not supported', 9),
    ('<link name="tip"/><joint name="j2" type="revolute"><parent link="b"/><child link="tip"/>'
     '</joint>', r'link "tip" \(joint "j2"\) and every link it carries have no mass', 9),
    ('<link name="lone"/>', r'the links do not form one tree: 2 root links \("a", "lone"\)', 9),
    ('<joint name="j2" type="screw"><parent link="a"/><child link="b"/></joint>',
     r'joint "j2": unknown joint type "screw"', 9),
    ("<link name='x'>", r"malformed XML", None),
])
def test_unsupported_urdf_is_a_located_error(tmp_path, extra, match, line):
    path = tmp_path / "robot.urdf"
    path.write_text(ROBOT.format(extra=extra))
    with pytest.raises(UrdfError, match=match) as info:
        load_urdf(path)
    assert str(info.value).startswith(f"{path}:")
    assert isinstance(info.value, jd.ModelError)
    if line is not None:
        assert info.value.line == line


def test_mimic_read_as_independent_joint_on_request(tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(ROBOT.format(extra=LINK_C + (
        '<joint name="j2" type="prismatic"><parent link="b"/><child link="c"/>'
        '<axis xyz="1 0 0"/><mimic joint="j1" multiplier="2" offset="0.1"/></joint>')))
    model = load_urdf(path, mimic="independent")
    assert model.system.coordinate_names == ["j1", "j2"]
    assert model.joint("j2").mimic == ("j1", 2.0, 0.1)


def test_doctype_and_names(tmp_path):
    path = tmp_path / "robot.urdf"
    text = ROBOT.format(extra="")
    path.write_text(text.replace('<?xml version="1.0"?>', '<?xml version="1.0"?>\n'
                                 '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>'))
    with pytest.raises(UrdfError, match="DOCTYPE/ENTITY declarations are not read"):
        load_urdf(path)
    # names that are not identifiers become identifiers; the URDF names stay in the data
    path.write_text(text.replace('"b"', '"arm/link-1"').replace('"j1"', '"1st joint"'))
    model = load_urdf(path)
    assert model.system.body_names == ["arm_link_1"]
    assert model.system.coordinate_names == ["joint_1st_joint"]
    assert model.joint("1st joint").coordinates == ("joint_1st_joint",)


def test_missing_yourdfpy_names_the_extra(monkeypatch, tmp_path):
    arm = tmp_path / "arm.urdf"  # not read before: not in the cache of built models
    arm.write_bytes(ARM.read_bytes() + b"<!-- not in the cache -->\n")
    monkeypatch.setitem(sys.modules, "yourdfpy", None)
    with pytest.raises(MissingDependency, match=r"URDF import needs the extra: pip install "
                       r"'jourdain\[urdf\]' \(the package yourdfpy is not installed\)"):
        load_urdf(arm)


def test_model_read_again_comes_from_the_cache_without_yourdfpy(tmp_path):
    """A file read before is not parsed again: a fresh process gives the same model (equal
    System, joints, links, geometry) with yourdfpy never imported; other bytes or options are
    another model."""
    import subprocess

    arm = tmp_path / "arm.urdf"
    arm.write_bytes(ARM.read_bytes())
    first = load_urdf(arm)
    code = ("import pickle, sys; from jourdain.io.urdf import load_urdf; "
            f"m = load_urdf({str(arm)!r}); "
            "sys.stdout.buffer.write(pickle.dumps((m, 'yourdfpy' in sys.modules)))")
    import pickle

    out = subprocess.run([sys.executable, "-c", code], capture_output=True, check=True).stdout
    again, imported = pickle.loads(out)
    assert again == first and again.system == first.system and not imported
    assert load_urdf(arm, floating_base=True).system.f == first.system.f + 6
    arm.write_bytes(ARM.read_bytes().replace(b'name="elbow"', b'name="elbow_2"', 1))
    renamed = load_urdf(arm)
    assert renamed != first


def test_cli_reads_urdf(capsys):
    assert main(["check", str(ARM)]) == 0
    out = capsys.readouterr().out
    assert "OK — two_link_arm" in out and "degrees of freedom f = 3" in out
    assert main(["eval", str(ARM), "--json", "--at", "shoulder=0.3, elbow=-0.4"]) == 0
    data = json.loads(capsys.readouterr().out)
    M = np.array(data["values"]["M"])
    assert M.shape == (3, 3) and data["coordinates"] == ["shoulder", "elbow", "wrist"]
    assert main(["check", str(DATA / "missing.urdf")]) == 2


def test_run_reports_a_urdf_example(tmp_path, capsys):
    """``jourdain run`` on the example: a complete report with a copy of the URDF as
    model.urdf (not model.toml); ``jd.load_urdf`` is the same function."""
    assert jd.load_urdf is load_urdf
    example = Path(__file__).resolve().parents[1] / "examples" / "planar_arm.urdf"
    out = tmp_path / "report"
    assert main(["run", str(example), "--out", str(out), "--t-end", "0.2"]) == 0
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "complete" and "model.urdf" in run["files"]
    assert (out / "model.urdf").read_bytes() == example.read_bytes()
    assert not (out / "model.toml").exists() and (out / "report.html").stat().st_size > 0
