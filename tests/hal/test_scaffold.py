"""Tests for scaffold.py: drafts of every robot's own model load and match that model."""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from openral_core.loader import load_robot
from openral_core.models import LimitedJoint, RgbSensor, RobotDescription, TorquePdControl
from openral_core.registry import load_robot_by_id, manifest_path, robot_ids
from openral_hal.errors import HalError
from openral_hal.scaffold import SCHEMA_LINE, scaffold_manifest
from openral_hal.scaffold_gains import BANDWIDTH_RAD_S, inertia_diagonal
from openral_mujoco.mjcf_uri import MjcfUriError, resolve_mjcf_uri
from openral_mujoco.model_check import check_robot

IDS = robot_ids()


def _source_uri(robot_id: str) -> str:
    """The robot's own ``sim.mjcf_uri``, with ``file:`` made absolute (outside the draft's
    folder, so drafting and loading it need ``allow_outside``)."""
    robot = load_robot_by_id(robot_id)
    assert robot.sim is not None
    uri = robot.sim.mjcf_uri
    if uri.startswith("file:"):
        return f"file:{resolve_mjcf_uri(uri, manifest_path(robot_id).parent)}"
    return uri


def _write_draft(uri: str, name: str, tmp_path: Path) -> tuple[Path, str]:
    folder = tmp_path / name
    folder.mkdir(parents=True, exist_ok=True)
    text = scaffold_manifest(uri, name, folder, allow_outside=True)
    file = folder / "robot.yaml"
    file.write_text(text, encoding="utf-8")
    return file, text


def _load_draft(
    uri: str, name: str, tmp_path: Path
) -> tuple[RobotDescription, mujoco.MjModel, str]:
    file, text = _write_draft(uri, name, tmp_path)
    draft = load_robot(file)
    assert draft.sim is not None
    path = resolve_mjcf_uri(draft.sim.mjcf_uri, file.parent, allow_outside=True)
    model = mujoco.MjModel.from_xml_path(str(path))
    return draft, model, text


def _draft_of(robot_id: str, tmp_path: Path) -> tuple[RobotDescription, mujoco.MjModel, str]:
    return _load_draft(_source_uri(robot_id), f"draft_{robot_id}", tmp_path)


def _distinct_driven_joints(model: mujoco.MjModel) -> set[int]:
    """Joint ids the actuators drive: a joint's own, or a fixed tendon's first joint."""
    joints: set[int] = set()
    for actuator in range(model.nu):
        kind = model.actuator_trntype[actuator]
        target = int(model.actuator_trnid[actuator, 0])
        if kind in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT):
            joints.add(target)
        elif kind == mujoco.mjtTrn.mjTRN_TENDON:
            joints.add(int(model.wrap_objid[model.tendon_adr[target]]))
    return joints


def _qpos(model: mujoco.MjModel, joint: str) -> int:
    return int(model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)])


def test_every_repository_robot_is_covered() -> None:
    assert len(IDS) >= 10


@pytest.mark.parametrize("robot_id", IDS)
def test_draft_loads_and_matches_its_model(robot_id: str, tmp_path: Path) -> None:
    draft, model, text = _draft_of(robot_id, tmp_path)
    assert draft.name == f"draft_{robot_id}"
    assert text.splitlines()[0] == SCHEMA_LINE
    assert "openral robot scaffold" in text.splitlines()[1]
    failures = [row for row in check_robot(draft, model) if not row.ok]
    assert not failures, failures
    assert len(draft.joints) == len(_distinct_driven_joints(model))
    assert all(j.velocity_limit == 1.0 for j in draft.joints)
    assert "# REVIEW: not in the MJCF" in text


def test_franka_draft_has_a_tendon_gripper_over_both_fingers(tmp_path: Path) -> None:
    draft, model, text = _draft_of("franka_panda", tmp_path)
    assert draft.sim is not None
    assert [g.joint for g in draft.sim.grippers] == ["finger_joint1"]
    gripper = draft.sim.grippers[0]
    assert gripper.read_mode.value == "sum_over_scale"
    assert gripper.write_mode.value == "normalised"
    assert gripper.qpos_addrs == [_qpos(model, "finger_joint1"), _qpos(model, "finger_joint2")]
    assert gripper.qpos_scale == pytest.approx(0.08)
    assert gripper.ctrl_range == [0.0, 255.0]
    assert "finger_joint2" not in [j.name for j in draft.joints]
    assert "finger_joint1  # REVIEW: guessed gripper" in text
    comments = "\n".join(line for line in text.splitlines() if line.startswith("#"))
    assert "finger_joint2" in comments


def test_h1_draft_has_torque_pd_gains_per_joint_and_no_gravity_compensation(
    tmp_path: Path,
) -> None:
    draft, model, text = _draft_of("h1", tmp_path)
    assert draft.sim is not None
    control = draft.sim.control
    assert isinstance(control, TorquePdControl)
    assert control.mode == "torque_pd"
    assert isinstance(control.kp, dict) and isinstance(control.kd, dict)
    inertia = inertia_diagonal(model)
    for joint in draft.joints:  # no friction loss: the bandwidth law, joint by joint
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint.name)
        m_ii = inertia[model.jnt_dofadr[jid]]
        assert control.kp[joint.name] == pytest.approx(m_ii * BANDWIDTH_RAD_S**2, rel=1e-3)
        assert control.kd[joint.name] == pytest.approx(2 * m_ii * BANDWIDTH_RAD_S, rel=1e-3)
    assert "    kp:  # REVIEW: from the model's inertia" in text
    assert not draft.sim.gravity_compensation  # a floating base would float
    assert draft.sim.keyframe_index is None  # h1.xml has no keyframe
    assert not draft.sim.seed_ctrl_from_qpos
    # Motor actuators: effort is ctrlrange upper x gear (left_knee: 300 N·m).
    efforts = {j.name: j.effort_limit for j in draft.joints}
    assert efforts["left_knee"] == 300.0
    assert efforts["left_ankle"] == 40.0


def test_g1_draft_has_a_floating_base_and_mjcf_names(tmp_path: Path) -> None:
    draft, model, _ = _draft_of("g1", tmp_path)
    assert draft.sim is not None
    assert draft.sim.floating_base is True
    assert draft.base.value == "mobile"
    driven = [int(model.actuator_trnid[a, 0]) for a in range(model.nu)]
    mjcf_names = [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in driven]
    assert [j.name for j in draft.joints] == mjcf_names
    assert all(j.sim_joint_name is None for j in draft.joints)
    # Joints sit right after the free joint, so no override is needed.
    assert draft.sim.joint_qpos_addr is None
    assert draft.sim.joint_qvel_addr is None
    assert draft.sim.actuator_index is None
    # Joint actuator-force ranges give the effort limits.
    assert {j.name: j.effort_limit for j in draft.joints}["left_knee_joint"] == 139.0


def test_aloha_draft_sanitises_names_and_keeps_mjcf_names(tmp_path: Path) -> None:
    draft, _, text = _draft_of("aloha", tmp_path)
    by_name = {j.name: j for j in draft.joints}
    waist = by_name["vx300s_left_waist"]
    assert waist.sim_joint_name == "vx300s_left/waist"
    assert isinstance(waist, LimitedJoint)
    assert waist.position_limits == [-3.14158, 3.14158]
    assert "red_box_joint" in text  # the cube's free joint is named in a comment
    assert "red_box_joint" not in {j.sim_joint_name for j in draft.joints}
    cameras = [s for s in draft.sensors if isinstance(s, RgbSensor)]
    assert [s.name for s in cameras][:3] == ["left_pillar", "right_pillar", "top"]
    assert all(s.camera == s.name and s.frame_id == f"{s.name}_optical_frame" for s in cameras)


def test_overrides_only_where_the_model_differs(tmp_path: Path) -> None:
    """openarm lists one finger per hand, so the right arm sits one qpos further on."""
    draft, model, _ = _draft_of("openarm", tmp_path)
    assert draft.sim is not None
    right = [j.name for j in draft.joints if j.name.startswith("openarm_right_")]
    expected = {name: _qpos(model, name) for name in right}
    assert draft.sim.joint_qpos_addr == expected
    assert draft.sim.joint_qvel_addr == expected
    assert draft.sim.actuator_index is None  # actuators are 1:1 with the listed joints
    assert draft.sim.seed_ctrl_from_qpos is True
    assert draft.sim.keyframe_index is None


SYNTHETIC = """
<mujoco>
  <worldbody>
    <camera name="Top-Cam" pos="0 0 2"/>
    <camera name="top_cam" pos="0 0 3"/>
    <body name="link1">
      <joint name="arm-1.pitch" type="hinge" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.1"/>
      <body name="link2" pos="0 0 0.3">
        <joint name="slider" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.05 0.05 0.05"/>
        <body name="link3" pos="0 0 0.3">
          <joint name="9th" type="hinge" axis="0 1 0" range="-1 1"/>
          <geom type="box" size="0.05 0.05 0.05"/>
        </body>
        <body name="link4" pos="0 0.2 0">
          <joint name="Finger" type="slide" axis="0 1 0"/>
          <geom type="box" size="0.02 0.02 0.02"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="arm-1.pitch" gear="-2" ctrlrange="-3 3"/>
    <motor joint="slider"/>
    <motor joint="arm-1.pitch"/>
    <motor joint="9th" ctrlrange="-1 1"/>
    <motor joint="Finger"/>
  </actuator>
</mujoco>
"""


def test_synthetic_model_edge_cases(tmp_path: Path) -> None:
    (tmp_path / "synthetic.xml").write_text(SYNTHETIC, encoding="utf-8")
    uri = f"file:{tmp_path / 'synthetic.xml'}"
    draft, model, text = _load_draft(uri, "synthetic_arm", tmp_path)
    assert not [row for row in check_robot(draft, model) if not row.ok]
    assert draft.display_name == "Synthetic Arm"
    # The third actuator repeats the first joint; "9th" cannot be a sim_joint_name.
    first, second, finger = draft.joints
    assert (first.name, first.sim_joint_name) == ("arm_1_pitch", "arm-1.pitch")
    assert first.type == "continuous"
    assert first.effort_limit == 6.0  # ctrlrange upper 3 x |gear -2|
    assert isinstance(second, LimitedJoint)
    assert (second.name, second.sim_joint_name) == ("slider", None)
    assert second.type.value == "prismatic"
    assert second.position_limits == [-1.0, 1.0]
    assert second.effort_limit == 1.0
    assert "position_limits: [-1.0, 1.0]  # REVIEW:" in text
    assert "effort_limit: 1.0  # REVIEW:" in text
    assert "# REVIEW: actuators left out of joints: actuator 3 (drives joint '9th'" in text
    assert [s.name for s in draft.sensors] == ["top_cam"]  # "top_cam" repeats "Top-Cam"
    assert isinstance(draft.sensors[0], RgbSensor)
    assert draft.sensors[0].camera == "Top-Cam"
    assert draft.sim is not None and isinstance(draft.sim.control, TorquePdControl)
    # "Finger" looks like a gripper, but neither its actuator nor its joint has a range.
    assert finger.name == "Finger"
    assert draft.sim.grippers == []
    assert "# REVIEW: Finger looks like a gripper, but its control range is empty" in text
    # Only Finger is off the default wiring: "9th" sits before it in qpos and actuators.
    assert draft.sim.actuator_index == {"Finger": 4}
    assert draft.sim.joint_qpos_addr == {"Finger": 3}
    assert draft.sim.joint_qvel_addr == {"Finger": 3}


def test_relative_file_uri_resolves_from_the_manifest_folder(tmp_path: Path) -> None:
    folder = tmp_path / "relative_arm"
    folder.mkdir()
    (folder / "arm.xml").write_text(SYNTHETIC, encoding="utf-8")
    text = scaffold_manifest("file:arm.xml", "relative_arm", folder)
    assert "  mjcf_uri: file:arm.xml" in text.splitlines()


def test_a_model_outside_the_draft_folder_needs_allow_outside(tmp_path: Path) -> None:
    (tmp_path / "arm.xml").write_text(SYNTHETIC, encoding="utf-8")
    folder = tmp_path / "outside_arm"
    with pytest.raises(MjcfUriError, match="outside the robot folder"):
        scaffold_manifest("file:../arm.xml", "outside_arm", folder)
    text = scaffold_manifest("file:../arm.xml", "outside_arm", folder, allow_outside=True)
    assert "  mjcf_uri: file:../arm.xml" in text.splitlines()


def test_unknown_scheme_raises(tmp_path: Path) -> None:
    with pytest.raises(MjcfUriError, match="unknown scheme"):
        scaffold_manifest("nope:arm.xml", "some_arm", tmp_path)


def test_missing_file_raises(tmp_path: Path) -> None:
    with pytest.raises(MjcfUriError, match="not a file"):
        scaffold_manifest("file:missing.xml", "some_arm", tmp_path)


def test_model_without_driving_actuators_raises(tmp_path: Path) -> None:
    (tmp_path / "passive.xml").write_text(
        """
        <mujoco><worldbody><body><joint name="hinge" type="hinge"/>
        <geom type="sphere" size="0.1"/></body></worldbody></mujoco>
        """,
        encoding="utf-8",
    )
    with pytest.raises(HalError, match="none of the 0 actuator"):
        scaffold_manifest("file:passive.xml", "passive_arm", tmp_path)


def test_invalid_robot_name_raises(tmp_path: Path) -> None:
    with pytest.raises(HalError, match="snake case"):
        scaffold_manifest(_source_uri("ur5e"), "UR5e", tmp_path)
