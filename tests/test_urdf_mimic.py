"""URDF ``<mimic>`` joints (issue 38, item 5): a mimic joint follows the coordinate of the joint
it mimics, ``q_f = k·q_d + o``, one coordinate for both (``load_urdf(mimic="coupled")``, the
default).

The gripper below: a wrist (revolute z) carries a left finger (prismatic +y, coordinate q) and a
right finger (prismatic −y) that mimics it with k = 1.5, o = 3 mm. Closed form: the fingers'
kinetic energy ``½·m_l·q̇² + ½·m_r·(k·q̇)²`` gives ``M[q, q] = m_l + k²·m_r``, and the wrist's
``M[wrist, wrist]`` holds the fingers at ``y = 0.02 + q`` and ``−(0.02 + k·q + o)``. Against
Pinocchio's ``buildModelFromUrdf(..., mimic=True)``: M (CRBA) and the bias forces
(``nonLinearEffects``) at random states.
"""

import numpy as np
import pytest

import jourdain as jd
from jourdain.io.urdf import UrdfError, load_urdf
from tests.tolerance import assert_close_eval

pytest.importorskip("yourdfpy", reason="the URDF reader needs jourdain[urdf] (yourdfpy)")

K, O = 1.5, 0.003
M_PALM, M_WRIST, M_LEFT, M_RIGHT = 0.5, 0.4, 0.1, 0.15
I_F = 1e-5  # each finger's moment about its centre of mass (isotropic)

GRIPPER = f"""<?xml version="1.0"?>
<robot name="gripper">
  <link name="palm"><inertial><mass value="{M_PALM}"/>
    <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="wrist_link"><inertial><origin xyz="0 0 0.05"/><mass value="{M_WRIST}"/>
    <inertia ixx="2e-3" ixy="0" ixz="0" iyy="2e-3" iyz="0" izz="1e-3"/></inertial></link>
  <link name="left"><inertial><origin xyz="0 0 0.02"/><mass value="{M_LEFT}"/>
    <inertia ixx="{I_F}" ixy="0" ixz="0" iyy="{I_F}" iyz="0" izz="{I_F}"/></inertial></link>
  <link name="right"><inertial><origin xyz="0 0 0.02"/><mass value="{M_RIGHT}"/>
    <inertia ixx="{I_F}" ixy="0" ixz="0" iyy="{I_F}" iyz="0" izz="{I_F}"/></inertial></link>
  <joint name="wrist" type="revolute">
    <parent link="palm"/><child link="wrist_link"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="finger_left" type="prismatic">
    <parent link="wrist_link"/><child link="left"/><origin xyz="0 0.02 0.1"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="0.1"/></joint>
  <joint name="finger_right" type="prismatic">
    <parent link="wrist_link"/><child link="right"/><origin xyz="0 -0.02 0.1"/>
    <axis xyz="0 -1 0"/><limit lower="0" upper="0.04" effort="10" velocity="0.1"/>
    <mimic joint="finger_left" multiplier="{K}" offset="{O}"/></joint>
</robot>
"""


@pytest.fixture(scope="module")
def gripper(tmp_path_factory):
    path = tmp_path_factory.mktemp("mimic") / "gripper.urdf"
    path.write_text(GRIPPER)
    return path


def numbers(system: jd.System, y, yd) -> dict:
    return system.evaluate(y, yd, inputs=dict.fromkeys(system.input_names, 0.0))


def test_a_mimic_joint_shares_the_coordinate_it_follows(gripper):
    model = load_urdf(gripper)
    s = model.system
    assert s.coordinate_names == ["wrist", "finger_left"]
    assert s.input_names == ["tau_wrist", "tau_finger_left"]  # no actuator of its own
    right = model.joint("finger_right")
    assert right.coordinates == () and right.mimic == ("finger_left", K, O)
    out = numbers(s, [0.7, 0.01], [0.3, -0.2])
    # the fingers slide along the wrist's y axis, the wrist turns about y: decoupled
    assert_close_eval(out["M"][1, 1], M_LEFT + K**2 * M_RIGHT, 4, scale=1.0)
    assert_close_eval(out["M"][0, 1], 0.0, 4, scale=1.0)


def test_mimic_against_pinocchio(gripper):
    pin = pytest.importorskip("pinocchio")
    try:
        pm = pin.buildModelFromUrdf(str(gripper), mimic=True)
    except TypeError:
        pytest.skip("this Pinocchio reads no mimic joints")
    assert pm.nv == 2
    pd = pm.createData()
    s = load_urdf(gripper).system
    rng = np.random.default_rng(38)
    for _ in range(5):
        y = np.array([rng.uniform(-3, 3), rng.uniform(0, 0.04)])
        yd = rng.uniform(-1, 1, 2)
        out = numbers(s, y, yd)
        M = pin.crba(pm, pd, y)
        M = np.triu(M) + np.triu(M, 1).T
        nle = pin.nonLinearEffects(pm, pd, y, yd)
        # evaluated directly, no solve: sums over 4 bodies of terms of size ≤ m·(g + ẏ²·r)
        assert_close_eval(out["M"], M, 24, scale=1.0, err_msg="M")
        assert_close_eval(out["k"] - out["q"], nle, 24, scale=2.0 * 9.81, err_msg="bias")


def test_mimic_options_and_refusals(tmp_path, gripper):
    independent = load_urdf(gripper, mimic="independent").system
    assert independent.coordinate_names == ["wrist", "finger_left", "finger_right"]
    with pytest.raises(UrdfError, match=r'joint "finger_right": a mimic joint .* refused as '
                       r'asked \(mimic="error"\)'):
        load_urdf(gripper, mimic="error")
    with pytest.raises(jd.ModelError, match='mimic must be "coupled", "independent" or "error"'):
        load_urdf(gripper, mimic="yes")
    fixed = tmp_path / "fixed.urdf"
    fixed.write_text(GRIPPER.replace('<joint name="finger_left" type="prismatic">',
                                     '<joint name="finger_left" type="fixed">'))
    with pytest.raises(UrdfError, match=r'joint "finger_right": it mimics joint "finger_left", '
                       r"which has no single coordinate"):
        load_urdf(fixed)
