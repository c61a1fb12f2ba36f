"""The 3-D view (jourdain.io.viewer): the poses in the page against closed forms, the equivalent
shapes against the bodies' inertia, meshes, and the page itself in headless Chromium (loads
from file:// without console errors, draws different pictures at two times, and its three.js
objects stand where the simulation puts the bodies).

The browser tests use headless Chromium as tests/test_report.py does (Debian's ``chromium``;
``make test`` installs it when missing and it runs as root) and are skipped with the same reason
without it. WebGL there is SwiftShader (software).
"""

from __future__ import annotations

import html
import json
import os
import re
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import jourdain as jd
from jourdain.io import capabilities, load_model
from jourdain.io.viewer import (
    MeshVisual,
    Visual,
    decode_poses,
    equivalent_shape,
    frame_times,
    quaternions,
    rpy_matrix,
    view,
)
from tests.test_report import _chromium
from tests.tolerance import eval_tol

ROOT = Path(__file__).resolve().parents[1]
EPS32 = float(np.finfo(np.float32).eps)
NO_CHROMIUM = ("headless Chromium not found (Debian: apt-get install chromium; `make test` "
               "installs it when run as root); the browser rendering check is skipped")


def _scene_of(page: str) -> dict:
    m = re.search(r"<script type='application/json' id='jourdain-scene'>(.*?)</script>", page,
                  re.S)
    assert m, "no scene in the page"
    return json.loads(m.group(1))


@pytest.fixture(scope="module")
def pendulum():
    model = load_model(ROOT / "examples" / "double_pendulum.toml")
    res = capabilities.simulate(model, {})
    return model, res, view(res)


def _rz(theta: np.ndarray) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    R = np.zeros(theta.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1
    return R


def _same_rotation(q: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """q and ref (…, 4) up to the sign of a quaternion."""
    return np.minimum(np.abs(q - ref), np.abs(q + ref)).max(axis=-1)


def test_poses_in_the_page_are_the_double_pendulum_closed_form(pendulum):
    """Planar double pendulum, rods hanging from z hinges: r_O,1 = 0, S_1 = R_z(φ1),
    r_O,2 = (l1 sin φ1, −l1 cos φ1, 0), S_2 = R_z(φ1 + φ2); the centres of mass l/2 down each rod.
    The page holds float32: each number within half a float32 unit of its value (plus the
    round-off of evaluating it in float64)."""
    model, res, v = pendulum
    sc = _scene_of(v.html)
    times, poses = decode_poses(sc)
    assert times[0] == res.t[0] and times[-1] == res.t[-1]
    assert len(times) == len(frame_times(res)) > 100
    pv = model.system.parameter_values
    l1, l2 = pv["l1"], pv["l2"]
    y = res.interpolate(times)["y"]
    p1, p2 = y[:, 0], y[:, 1]
    ref_r = {"rod1": np.zeros((len(times), 3)),
             "rod2": np.stack([l1 * np.sin(p1), -l1 * np.cos(p1), 0 * p1], axis=1)}
    ref_S = {"rod1": _rz(p1), "rod2": _rz(p1 + p2)}
    names = [b["name"] for b in sc["bodies"]]
    assert names == ["rod1", "rod2"]
    worst = 0.0
    for i, name in enumerate(names):
        r = poses[:, i, :3].astype(float)
        tol = 0.5 * EPS32 * np.abs(ref_r[name]) + eval_tol(3, l1)
        assert np.all(np.abs(r - ref_r[name]) <= tol), name
        q = poses[:, i, 3:].astype(float)
        qref = Rotation.from_matrix(ref_S[name]).as_quat()
        assert np.all(_same_rotation(q, qref) <= EPS32), name
        worst = max(worst, float(np.abs(r - ref_r[name]).max()))
        # the centre of mass: the equivalent shape's place in the body frame, moved by the pose
        com = np.array(sc["bodies"][i]["shape"]["position"])
        length = {"rod1": l1, "rod2": l2}[name]
        ref_com = ref_r[name] + np.einsum("nij,j->ni", ref_S[name], [0, -length / 2, 0])
        got = r + Rotation.from_quat(q).apply(com)
        assert np.all(np.abs(got - ref_com) <= 10 * EPS32 * (l1 + length)), name
    print(f"largest |r_O(page) - r_O(closed form)| = {worst:.2e} m")


def test_equivalent_rod_box_and_frames_of_the_pendulum(pendulum):
    """A uniform rod of length l (inertia m l²/12 across, 0 along): its equivalent box is l long
    along the rod (the body's y axis) with a small drawn thickness; the joint frame of hinge2
    sits at (0, −l1, 0) in rod1's frame."""
    model, _, v = pendulum
    sc = _scene_of(v.html)
    l1 = model.system.parameter_values["l1"]
    rod1 = sc["bodies"][0]
    assert rod1["shape"]["kind"] == "box"
    size = np.array(rod1["shape"]["size"])
    R = Rotation.from_quat(rod1["shape"]["quaternion"]).as_matrix()
    long_axis = R[:, int(np.argmax(size))]
    assert abs(size.max() - l1) <= eval_tol(3, l1)
    assert abs(abs(long_axis[1]) - 1) <= eval_tol(3, 1.0)
    assert size.min() < 0.1 * l1
    assert sc["bodies"][1]["joint"]["position"] == [0.0, -l1, 0.0]
    assert sc["bodies"][1]["parent"] == "rod1" and sc["up"] == pytest.approx([0, 1, 0])


def _spatial_system():
    """A box on a free joint (translations, then x-y-z rotations) with a full inertia tensor,
    a point mass on a z hinge of it, and a spring from the world to the box."""
    x, y, z, a, b, c, phi = jd.symbols("x y z a b c phi")
    inertia = [[0.30, 0.05, 0.02], [0.05, 0.25, 0.01], [0.02, 0.01, 0.20]]
    box = jd.Body("box", "world", jd.Free("free", [x, y, z, a, b, c]), mass=2.0,
                  com=[0.1, -0.05, 0.02], inertia=inertia)
    bob = jd.Body("bob", "box", jd.Revolute("hinge", phi, "z", position=[0.3, 0, 0]),
                  mass=0.2, com=[0.1, 0, 0], inertia=[0, 0, 0])
    spring = jd.SpringDamper("spring", "world", [0, 0, 1], "box", [0.05, 0.05, 0.05],
                             stiffness=10)
    system = jd.System([x, y, z, a, b, c, phi], [box, bob],
                       [spring, jd.Gravity([0, 0, -9.81])], name="spatial")
    return system, np.array(inertia)


def _made_up_motion(system, n: int = 41):
    """Results of a prescribed smooth motion (the view does not care where it came from):
    y_i = A_i sin(w_i t + p_i) with its exact rates and accelerations."""
    t = np.linspace(0.0, 2.0, n)
    A = np.array([0.2, -0.1, 0.3, 1.1, 0.7, -1.3, 2.0])
    w = np.array([1.0, 2.0, 0.5, 1.5, 2.5, 0.8, 3.0])
    p = np.array([0.0, 0.3, 0.6, 0.9, 1.2, 1.5, 1.8])
    arg = w * t[:, None] + p
    yv, ydv, yddv = A * np.sin(arg), A * w * np.cos(arg), -A * w**2 * np.sin(arg)
    return jd.Results(system, t, yv, ydv, yddv, np.zeros((n, 0)), np.zeros(n),
                      system.parameter_values, status="finished")


@pytest.fixture(scope="module")
def spatial():
    system, inertia = _spatial_system()
    res = _made_up_motion(system)
    return system, inertia, res


def test_spatial_poses_against_euler_angles(spatial):
    """Free joint with x-y-z rotations about the moving axes: S = R_x(a)·R_y(b)·R_z(c), SciPy's
    intrinsic "XYZ"; the bob's frame at r_O + S·(0.3, 0, 0) turned by R_z(φ)."""
    system, _, res = spatial
    v = view(res, max_frames=60)
    times, poses = decode_poses(v.scene)
    y = res.interpolate(times)["y"]
    S1 = Rotation.from_euler("XYZ", y[:, 3:6])
    S2 = S1 * Rotation.from_euler("z", y[:, 6:7])
    r1 = y[:, :3]
    r2 = r1 + S1.apply([0.3, 0.0, 0.0])
    scale = float(np.abs(r2).max())
    for i, (r, S) in enumerate(((r1, S1), (r2, S2))):
        got = poses[:, i, :3].astype(float)
        assert np.all(np.abs(got - r) <= 0.5 * EPS32 * np.abs(r) + eval_tol(9, scale))
        assert np.all(_same_rotation(poses[:, i, 3:].astype(float), S.as_quat())
                      <= EPS32 + eval_tol(27, 1.0))


def test_composed_poses_equal_the_symbolic_kinematics_of_a_random_tree():
    """body_poses composes the joints' relative motions along the tree in NumPy; the symbolic
    kinematics composes the same steps as expressions (kinematics().bodies[i].r_O, .S), here
    compiled separately: both agree at random states of a branching tree with every joint
    type, to the round-off of one product per level."""
    from jourdain.io.viewer import body_poses
    from jourdain.models import random_tree
    from jourdain.numeric import lambdify

    system = random_tree(7, seed=3)
    rng = np.random.default_rng(11)
    n = 5
    y = rng.uniform(-1.5, 1.5, (n, system.f))
    res = jd.Results(system, np.linspace(0, 1, n), y, np.zeros_like(y), np.zeros_like(y),
                     np.zeros((n, 0)), np.zeros(n), system.parameter_values)
    r, S = body_poses(res, res.t)
    kin = system.kinematics()
    fn = lambdify(system, {**{f"r{i}": bk.r_O for i, bk in enumerate(kin.bodies)},
                           **{f"S{i}": bk.S for i, bk in enumerate(kin.bodies)}})
    p = np.array([system.parameter_values[k] for k, _ in system.parameters])
    ref = fn.batch(y, np.zeros_like(y), res.t, p, None)
    depth = {}
    for b in system.bodies:
        depth[b.name] = 1 if b.parent == "world" else depth[b.parent] + 1
    scale = float(np.abs(r).max())
    for i, b in enumerate(system.bodies):
        tol = eval_tol(3 * depth[b.name], scale)
        assert np.abs(r[:, i] - ref[f"r{i}"][:, :, 0]).max() <= tol, b.name
        assert np.abs(S[:, i] - ref[f"S{i}"]).max() <= eval_tol(3 * depth[b.name], 1.0), b.name


@pytest.mark.parametrize("shape", ["box", "ellipsoid"])
def test_equivalent_shape_has_the_bodys_mass_and_inertia(spatial, shape):
    """The homogeneous box (ellipsoid) drawn for the body has its inertia tensor: with sides
    (diameters) a, b, c along the principal axes R, I = R·diag(m(b² + c²)/k, …)·Rᵀ, k = 12 for
    the box and 20 for the ellipsoid (semi-axes a/2: m((b/2)² + (c/2)²)/5)."""
    system, inertia, res = spatial
    sc = view(res, shape=shape, max_frames=10).scene
    body = sc["bodies"][0]
    assert body["shape"]["kind"] == shape
    a, b, c = body["shape"]["size"]
    k = 12.0 if shape == "box" else 20.0
    m = body["mass"]
    R = Rotation.from_quat(body["shape"]["quaternion"]).as_matrix()
    got = R @ np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / k @ R.T
    np.testing.assert_allclose(got, inertia, rtol=0,
                               atol=eval_tol(3 * 9, float(np.abs(inertia).max())))
    assert body["shape"]["position"] == [0.1, -0.05, 0.02]
    # the point mass is a sphere; the spring joins the inertial point and the box's point
    assert sc["bodies"][1]["shape"]["kind"] == "sphere"
    assert sc["springs"] == [{"name": "spring", "body_a": "world", "body_b": "box",
                              "point_a": [0.0, 0.0, 1.0], "point_b": [0.05, 0.05, 0.05]}]
    assert sc["up"] == [0.0, 0.0, 1.0]


def test_equivalent_shape_of_principal_moments():
    """Textbook: a 2×1×0.5 box of 3 kg has I = diag(1.25/4, 4.25/4, 5/4)·3/3 ... (m(b²+c²)/12)."""
    m, dims = 3.0, np.array([2.0, 1.0, 0.5])
    Ivals = m / 12 * np.array([dims[1] ** 2 + dims[2] ** 2, dims[0] ** 2 + dims[2] ** 2,
                               dims[0] ** 2 + dims[1] ** 2])
    sides, V = equivalent_shape(m, np.diag(Ivals), "box")
    order = np.argmax(np.abs(V), axis=0)  # which body axis each principal axis is
    np.testing.assert_allclose(sides[np.argsort(order)], dims, rtol=10 * 3 * np.finfo(float).eps)
    assert np.linalg.det(V) > 0
    with pytest.raises(jd.ModelError, match="shape must be one of box, ellipsoid"):
        equivalent_shape(m, np.diag(Ivals), "cone")


def test_quaternions_and_rpy_against_scipy():
    rng = np.random.default_rng(7)
    R = Rotation.random(200, random_state=rng)
    ref = R.as_quat()
    assert _same_rotation(quaternions(R.as_matrix()), ref).max() <= eval_tol(9, 1.0)
    # the half-turns, where the trace is −1 and w = 0
    for axis in np.eye(3):
        Rh = Rotation.from_rotvec(np.pi * axis)
        assert _same_rotation(quaternions(Rh.as_matrix()), Rh.as_quat()) <= eval_tol(9, 1.0)
    rpy = [0.3, -0.7, 1.9]
    np.testing.assert_allclose(rpy_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(),
                               rtol=0, atol=eval_tol(9, 1.0))


def _binary_stl(tri: np.ndarray) -> bytes:
    out = [b"jourdain test".ljust(80, b" "), struct.pack("<I", len(tri))]
    for t in tri:
        out.append(struct.pack("<12fH", 0, 0, 0, *t.reshape(-1), 0))
    return b"".join(out)


def _triangles(spec: dict) -> np.ndarray:
    """The (n, 3, 3) corners of a mesh in the page (float32 vertices, uint32 indices)."""
    import base64

    v = np.frombuffer(base64.b64decode(spec["vertices"]), "<f4").reshape(-1, 3)
    i = np.frombuffer(base64.b64decode(spec["indices"]), "<u4").reshape(-1, 3)
    return v[i]


_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_effects>
    <effect id="red-fx"><profile_COMMON><technique sid="t"><phong>
      <diffuse><color>0.8 0.1 0.1 1</color></diffuse></phong></technique></profile_COMMON>
    </effect>
  </library_effects>
  <library_materials>
    <material id="red" name="red"><instance_effect url="#red-fx"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="quad"><mesh>
      <source id="quad-pos"><float_array id="quad-arr" count="12">0 0 0 10 0 0 10 20 0 0 20 0
        </float_array><technique_common><accessor source="#quad-arr" count="4" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/>
        <param name="Z" type="float"/></accessor></technique_common></source>
      <vertices id="quad-vtx"><input semantic="POSITION" source="#quad-pos"/></vertices>
      <polylist material="mat" count="1"><input semantic="VERTEX" source="#quad-vtx"
        offset="0"/><input semantic="NORMAL" source="#quad-pos" offset="1"/>
        <vcount>4</vcount><p>0 0 1 1 2 2 3 3</p></polylist>
      <triangles count="1"><input semantic="VERTEX" source="#quad-vtx" offset="0"/>
        <p>0 1 3</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="outer"><translate>100 0 0</translate>
      <node id="inner"><rotate>0 0 1 90</rotate>
        <instance_geometry url="#quad"><bind_material><technique_common>
          <instance_material symbol="mat" target="#red"/></technique_common></bind_material>
        </instance_geometry>
      </node>
    </node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"""


def test_collada_mesh_with_nodes_units_and_colours(tmp_path):
    """A COLLADA quad (polylist of 4 corners, as a fan of 2 triangles, with a red material)
    and one more triangle (no material), in millimetres, placed by a node that translates by
    100 mm along x and a child node that turns 90° about z: the corners land at
    (0.1, 0, 0) + R_z(90°)·corner/1000."""
    from jourdain.io.viewer.meshes import read_mesh

    path = tmp_path / "part.dae"
    path.write_text(_DAE)
    m = read_mesh(path)
    corners = np.array([[0, 0, 0], [10, 0, 0], [10, 20, 0], [0, 20, 0]], float) / 1000
    R = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    placed = corners @ R.T + [0.1, 0, 0]
    ref = placed[[[0, 1, 2], [0, 2, 3], [0, 1, 3]]]
    np.testing.assert_allclose(m.triangles, ref, rtol=0, atol=eval_tol(3, 0.1))
    assert [(a, n) for a, n, _ in m.groups] == [(0, 2), (2, 1)]
    assert m.groups[0][2] == pytest.approx((0.8, 0.1, 0.1)) and m.groups[1][2] is None
    bad = tmp_path / "bad.dae"
    bad.write_text(_DAE.replace("<p>0 1 3</p>", "<p>0 1 9</p>"))
    with pytest.raises(jd.ModelError, match="bad.dae.*a face refers to a vertex"):
        read_mesh(bad)
    bad.write_text('<?xml version="1.0"?><!DOCTYPE x [<!ENTITY a "b">]>' + _DAE.split("?>", 1)[1])
    with pytest.raises(jd.ModelError, match="with a DTD"):
        read_mesh(bad)
    bad.write_text(_DAE.replace("10 20 0 0 20 0", "10 20 zero 0 20 0"))
    with pytest.raises(jd.ModelError, match="not a number"):
        read_mesh(bad)


def test_meshes_are_embedded_and_bad_ones_noted(spatial, tmp_path):
    system, _, res = spatial
    tet = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 0], [0, 1, 0], [0, 0, 1]],
                    [[0, 0, 0], [0, 0, 1], [1, 0, 0]], [[1, 0, 0], [0, 0, 1], [0, 1, 0]]],
                   float) * 0.1
    (tmp_path / "tet.stl").write_bytes(_binary_stl(tet))
    (tmp_path / "tri.stl").write_text(
        "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n"
        "  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n")
    (tmp_path / "quad.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    vis = {"box": [MeshVisual(tmp_path / "tet.stl", scale=(2, 2, 2), position=(0, 0, 0.1),
                              rotation=rpy_matrix([0, 0, np.pi / 2]).tolist()),
                   MeshVisual(tmp_path / "tri.stl"), MeshVisual(tmp_path / "quad.obj"),
                   MeshVisual(tmp_path / "missing.stl"), MeshVisual("package://robot/a.dae")],
           "bob": [MeshVisual(tmp_path / "part.dae")]}
    v = view(res, visuals=vis, max_frames=5)
    meshes = v.scene["bodies"][0]["visuals"]
    assert len(meshes) == 3 and {m["kind"] for m in meshes} == {"mesh"}
    got = [_triangles(m) for m in meshes]
    np.testing.assert_array_equal(got[0], tet.astype(np.float32))
    np.testing.assert_array_equal(got[1], [[[0, 0, 0], [1, 0, 0], [0, 1, 0]]])
    np.testing.assert_array_equal(got[2], [[[0, 0, 0], [1, 0, 0], [1, 1, 0]],
                                           [[0, 0, 0], [1, 1, 0], [0, 1, 0]]])
    assert meshes[0]["scale"] == [2.0, 2.0, 2.0] and meshes[0]["position"] == [0.0, 0.0, 0.1]
    assert _same_rotation(np.array(meshes[0]["quaternion"]),
                          Rotation.from_euler("z", np.pi / 2).as_quat()) <= eval_tol(9, 1.0)
    notes = "\n".join(v.notes)
    assert "missing.stl" in notes and "cannot be read" in notes
    assert "package://robot/a.dae" in notes and "resolve package://" in notes
    assert "part.dae" in notes and "cannot be read" in notes
    assert v.scene["bodies"][1]["visuals"] == []  # the bob keeps its sphere
    assert "missing.stl" in v.html  # the notes are shown in the page
    with pytest.raises(jd.ModelError, match="'wheel', which is not a body of 'spatial'"):
        view(res, visuals={"wheel": [MeshVisual(tmp_path / "tet.stl")]})
    with pytest.raises(jd.ModelError, match="visual 0 of body 'box': rotation is not a rotation"):
        view(res, visuals={"box": [MeshVisual(tmp_path / "tet.stl", rotation=np.eye(3) * 2)]})
    with pytest.raises(jd.ModelError, match="visual 0 of body 'box': size must be \\(3,\\)"):
        view(res, visuals={"box": [Visual("box", size=(1.0, 2.0))]})
    with pytest.raises(jd.ModelError, match="kind must be one of mesh, box, cylinder, sphere"):
        view(res, visuals={"box": [Visual("cone", size=(1.0,))]})
    (tmp_path / "bad.obj").write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(jd.ModelError, match="bad.obj.*a face refers to a vertex"):
        jd.io.viewer.read_mesh(tmp_path / "bad.obj")


def test_view_object_page_and_results_without_system(pendulum, tmp_path):
    _, res, v = pendulum
    assert jd.view is view
    frag = v._repr_html_()
    m = re.fullmatch(r"<iframe class='jourdain-view' srcdoc=\"([^\"]*)\" sandbox='allow-scripts'"
                     r" title='3-D view' style='[^']*'></iframe>", frag)
    assert m and html.unescape(m.group(1)) == v.html
    path = v.save(tmp_path / "view.html")
    assert path.read_text(encoding="utf-8") == v.html
    # one file: no address the page would load (scripts and data inline)
    urls = set(re.findall(r"(?:src|href)=['\"]([^'\"]+)", v.html))
    assert urls == set(), urls
    assert v.html.count("<script") == 3 and "three.js 0.187.0" in v.html
    assert "Permission is hereby granted" in v.html  # three.js's MIT license kept
    bare = jd.Results(None, res.t, res.y, res.yd, res.ydd, res.u, res.W, res.parameters,
                      coordinate_names=res.coordinate_names, input_names=[], units={})
    with pytest.raises(jd.ModelError, match="needs the system of the results"):
        view(bare)


# ------------------------------------------------------------------------------------------
# in the browser
# ------------------------------------------------------------------------------------------

_CAPTURE = ("<script>window.__jvErrors=[];(function(){var e=console.error,w=console.warn;"
            "console.error=function(){__jvErrors.push('error: '+[].join.call(arguments,' '));"
            "e.apply(console,arguments)};console.warn=function(){__jvErrors.push('warning: '+"
            "[].join.call(arguments,' '));w.apply(console,arguments)};window.addEventListener("
            "'error',function(ev){__jvErrors.push('uncaught: '+ev.message)})})();</script>")

_PROBE = """<script>(function(){
var out={errors:window.__jvErrors,viewer:!!window.jourdainViewer};var v=window.jourdainViewer;
if(v){var ks=%s;out.times=ks.map(function(k){return v.times[k]});out.origin={};out.com={};
out.quat={};v.bodies.forEach(function(b){
out.origin[b]=ks.map(function(k){return v.bodyPosition(b,v.times[k])});
out.com[b]=ks.map(function(k){return v.comPosition(b,v.times[k])});
out.quat[b]=ks.map(function(k){return v.bodyQuaternion(b,v.times[k])});});
try{v.bodyPosition('nobody',0)}catch(err){out.unknown=String(err.message)}
var sl=document.querySelector('.jv-slider'),bt=document.querySelector('.jv-play');
sl.value=String(v.times[ks[2]]);sl.dispatchEvent(new Event('input'));
out.slider=[v.time(),document.querySelector('.jv-time').textContent];
bt.click();out.button=[bt.textContent];bt.click();out.button.push(bt.textContent);}
var pre=document.createElement('pre');pre.id='probe';pre.textContent=JSON.stringify(out);
document.body.appendChild(pre);})();</script>"""


def _run_chromium(exe: str, url: str, tmp: Path, *args: str) -> subprocess.CompletedProcess:
    cmd = [exe, "--headless", "--no-sandbox", "--use-angle=swiftshader",
           "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
           "--disable-component-update", "--disable-sync", "--hide-scrollbars",
           "--enable-logging=stderr", "--v=0", f"--user-data-dir={tmp / 'profile'}", *args, url]
    env = {**os.environ, "HOME": str(tmp), "DBUS_SESSION_BUS_ADDRESS": "disabled:"}
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120, env=env)


def _console(stderr: str) -> list[str]:
    return [ln for ln in stderr.splitlines() if ":CONSOLE" in ln]


def test_view_in_headless_chromium_positions_equal_the_simulation(pendulum, tmp_path):
    """The page's three.js objects, read back at frame times, stand where the simulation puts
    the bodies: body frame origins equal r_O of the compiled kinematics rounded to float32 (the
    world matrix of an object at the scene's top carries its position unchanged), centres of
    mass within the float32 quaternion's rounding; no console errors or warnings."""
    exe = _chromium()
    if exe is None:
        pytest.skip(NO_CHROMIUM)
    _, res, v = pendulum
    n = v.scene["n_frames"]
    ks = sorted({0, 1, n // 3, n // 2, n - 2, n - 1})
    page = v.html.replace("<head>", "<head>" + _CAPTURE, 1)
    head, tail = page.rsplit("</body>", 1)
    probe_page = tmp_path / "probe.html"
    probe_page.write_text(head + _PROBE % json.dumps(ks) + "</body>" + tail, encoding="utf-8")
    run = _run_chromium(exe, probe_page.as_uri(), tmp_path, "--window-size=800,600",
                        "--dump-dom")
    m = re.search(r'<pre id="probe">(.*?)</pre>', run.stdout, re.S)
    assert m, f"the page did not run: {run.stderr[-2000:]}"
    out = json.loads(html.unescape(m.group(1)))
    if not out["viewer"] and "cannot draw WebGL" in run.stdout:
        pytest.skip("this Chromium has no WebGL (SwiftShader); the 3-D view cannot be checked")
    assert out["errors"] == [] and _console(run.stderr) == [], (out["errors"], run.stderr)
    assert out["unknown"] == 'no body named "nobody"'
    # the slider sets the time, the button plays and pauses
    # (the range input keeps the shortest decimal that reads back as a nearby double)
    assert out["slider"][0] == pytest.approx(out["times"][2], rel=1e-15, abs=1e-15)
    assert out["slider"][1] == f"t = {out['times'][2]:.3f} s"
    assert out["button"] == ["❚❚ pause", "▶ play"]
    t = np.array(out["times"])
    worst = 0.0
    for name in ("rod1", "rod2"):
        r_sim = res.positions(name, "origin", t=t)
        com_sim = res.positions(name, "com", t=t)
        r_page = np.array(out["origin"][name])
        np.testing.assert_array_equal(r_page, r_sim.astype(np.float32).astype(float))
        com_page = np.array(out["com"][name])
        tol = 10 * EPS32 * (np.abs(r_sim).max() + np.abs(com_sim - r_sim).max())
        assert np.abs(com_page - com_sim).max() <= tol, name
        worst = max(worst, float(np.abs(com_page - com_sim).max()))
        q = np.array(out["quat"][name])
        assert np.allclose(np.linalg.norm(q, axis=1), 1, atol=4 * EPS32)
    print(f"largest |com(page) - com(simulation)| = {worst:.2e} m over {len(ks)} frames")


def test_view_screenshots_differ_between_two_times(pendulum, tmp_path):
    """The unchanged page opened from file:// at #t=0 and #t=1.2 (paused there): both show the
    bodies (pixels of rod1's colour) and the two pictures differ; no console message."""
    from PIL import Image

    exe = _chromium()
    if exe is None:
        pytest.skip(NO_CHROMIUM)
    _, res, v = pendulum
    page = v.save(tmp_path / "view.html")
    colour = np.array([int(v.scene["bodies"][0]["color"][k:k + 2], 16) for k in (1, 3, 5)])
    shots = []
    for t in (0.0, 1.2):
        png = tmp_path / f"t{t}.png"
        run = _run_chromium(exe, page.as_uri() + f"#t={t}", tmp_path, "--window-size=640,480",
                            f"--screenshot={png}")
        assert png.is_file(), run.stderr[-2000:]
        assert _console(run.stderr) == [], run.stderr
        a = np.asarray(Image.open(png).convert("RGB")).astype(int)
        # the canvas, without the bar of controls at the bottom
        shots.append(a[: int(0.7 * a.shape[0])])
    body_px = [int((np.abs(s - colour).sum(axis=2) < 60).sum()) for s in shots]
    changed = int((np.abs(shots[0] - shots[1]).sum(axis=2) > 60).sum())
    print("pixels of rod1's colour at the two times:", body_px, "; pixels changed:", changed)
    assert min(body_px) > 100, body_px
    assert changed > 500, changed


def test_primitive_visuals_and_a_urdf_models_geometry(spatial):
    """Boxes, cylinders and spheres are drawn with their size and origin; "world" visuals stand
    still. A URDF model's <visual> elements (jourdain.io.urdf) are taken as they are: each at
    the pose the import gives in its body frame, the base's cylinder in the world, the mesh
    that is not on this machine noted."""
    system, _, res = spatial
    R = rpy_matrix([0.2, 0.0, 0.0])
    vis = {"box": [Visual("box", size=(0.1, 0.2, 0.3), position=(0, 0, 0.1),
                          rotation=R.tolist(), color=(1, 0, 0, 1))],
           "world": [Visual("cylinder", size=(0.05, 0.5))],
           "bob": [Visual("sphere", size=(0.03,))]}
    sc = view(res, visuals=vis, max_frames=5).scene
    box = sc["bodies"][0]["visuals"][0]
    assert (box["kind"], box["size"], box["position"], box["color"]) == (
        "box", [0.1, 0.2, 0.3], [0.0, 0.0, 0.1], [1.0, 0.0, 0.0])
    assert _same_rotation(np.array(box["quaternion"]),
                          Rotation.from_matrix(R).as_quat()) <= eval_tol(9, 1.0)
    assert [(w["kind"], w["size"]) for w in sc["world_visuals"]] == [("cylinder", [0.05, 0.5])]
    assert sc["bodies"][1]["visuals"][0]["size"] == [0.03]

    pytest.importorskip("yourdfpy", reason="URDF import needs yourdfpy (jourdain[urdf])")
    from jourdain.io.urdf import load_urdf
    from jourdain.io.viewer import model_visuals

    model = load_urdf(ROOT / "tests" / "data" / "urdf" / "two_link_arm.urdf")
    s = model.system
    n = 5
    t = np.linspace(0, 1, n)
    y = np.outer(t, np.arange(1, s.f + 1) * 0.3)
    urdf_res = jd.Results(s, t, y, np.zeros_like(y), np.zeros_like(y),
                          np.zeros((n, len(s.inputs))), np.zeros(n), s.parameter_values)
    v = view(urdf_res, visuals=model_visuals(model))
    drawn = {b["name"]: b["visuals"] for b in v.scene["bodies"]}
    geo = {(g.body, g.kind): g for g in model.visual_geometry}
    for body, specs in [*drawn.items(), ("world", v.scene["world_visuals"])]:
        for spec in specs:
            g = geo[(body, spec["kind"])]
            T = np.asarray(g.pose)
            assert spec["position"] == pytest.approx(T[:3, 3], abs=eval_tol(3, 1.0))
            assert _same_rotation(np.array(spec["quaternion"]),
                                  Rotation.from_matrix(T[:3, :3]).as_quat()) <= eval_tol(9, 1.0)
            assert spec["size"] == list(g.size)
    kinds = sorted((b, s_["kind"]) for b, specs in drawn.items() for s_ in specs)
    kinds += [("world", w["kind"]) for w in v.scene["world_visuals"]]
    assert sorted(kinds) == sorted(k for k, g in geo.items() if g.kind != "mesh")
    assert any("tool.stl" in n_ and "not found" in n_ for n_ in v.notes), v.notes


def test_a_mesh_file_is_parsed_once_and_stored_bit_for_bit(tmp_path, monkeypatch):
    """read_mesh parses a file once: a second read in the process (the four legs of a
    quadruped) and a read by a later process (the stored arrays in the cache folder) give the
    parsed arrays bit for bit without parsing; a file changed on disk is parsed again."""
    from jourdain.io.viewer import mesh_store, meshes

    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(mesh_store, "_memory", type(mesh_store._memory)())
    path = tmp_path / "part.dae"
    path.write_text(_DAE)
    first = meshes.read_mesh(path)
    assert len(list((tmp_path / "cache" / "meshes").glob("*.npz"))) == 1
    assert not first.vertices.flags.writeable and not first.faces.flags.writeable

    def no_parse(data, where):
        raise AssertionError("parsed again")

    monkeypatch.setattr(meshes, "_dae", no_parse)
    again = meshes.read_mesh(path)  # this process: the same arrays
    assert again.vertices is first.vertices and again.groups == first.groups
    mesh_store._memory.clear()  # as a later process: from the stored file
    stored = meshes.read_mesh(path)
    assert stored.vertices is not first.vertices
    assert stored.vertices.tobytes() == first.vertices.tobytes()
    assert stored.faces.tobytes() == first.faces.tobytes()
    assert stored.faces.dtype == first.faces.dtype and stored.groups == first.groups
    path.write_text(_DAE.replace("<p>0 1 3</p>", "<p>0 1 9</p>"))  # changed: parsed again
    with pytest.raises(AssertionError, match="parsed again"):
        meshes.read_mesh(path)
