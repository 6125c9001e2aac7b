"""Tests for rules.py: each cross-field rule fails on its own violation and only then."""

from __future__ import annotations

from pathlib import Path

import pytest
from openral_core import ManifestError, load_robot

from tests.conftest import FRANKA, REPO, ManifestWriter


def _findings(path: object) -> dict[str, str]:
    with pytest.raises(ManifestError) as info:
        load_robot(path)  # type: ignore[arg-type]
    return {issue.field: issue.message for issue in info.value.issues}


def test_mock_arm_passes_every_rule(write_manifest: ManifestWriter) -> None:
    assert load_robot(write_manifest()).name == "mock_arm"


@pytest.mark.parametrize(
    ("edit", "field", "fragment"),
    [
        (
            ("name: wrist_roll", "name: shoulder"),
            "joints[1].name",
            "duplicate joint name 'shoulder'",
        ),
        (
            ("name: jaw, type", "name: jaw, sim_joint_name: roll, type"),
            "joints[2].sim_joint_name",
            "duplicate sim_joint_name 'roll'",
        ),
        (
            ("name: hand, kind", "name: overhead, kind"),
            "sensors[1].name",
            "duplicate sensor name 'overhead'",
        ),
        (
            ("position_limits: [-1.5, 1.5]", "position_limits: [1.5, -1.5]"),
            "joints[0].position_limits",
            "lower limit 1.5 must be below upper limit -1.5",
        ),
        (
            ("ctrl_range: [0.0, 1.0]", "ctrl_range: [1.0, 1.0]"),
            "sim.grippers[0].ctrl_range",
            "lower bound 1.0 must be below upper bound 1.0",
        ),
        (
            ("joint_qpos_addr: {jaw: 3}", "joint_qpos_addr: {elbow: 3}"),
            "sim.joint_qpos_addr.elbow",
            "'elbow' is not a joint",
        ),
        (
            ("joint_qpos_addr: {jaw: 3}", "joint_qvel_addr: {elbow: 3}"),
            "sim.joint_qvel_addr.elbow",
            "'elbow' is not a joint",
        ),
        (
            ("joint_qpos_addr: {jaw: 3}", "actuator_index: {elbow: 3}"),
            "sim.actuator_index.elbow",
            "'elbow' is not a joint",
        ),
        (
            (
                "frame_id: hand_optical}",
                "frame_id: hand_optical, vla_feature_key: observation.images.camera1}",
            ),
            "sensors[1]",
            "duplicate VLA slot 'camera1'",
        ),
        (
            (
                "vla_feature_key: observation.images.camera1}",
                "vla_feature_key: observation.images.hand}",
            ),
            "sensors[1]",
            "duplicate VLA slot 'hand'",
        ),
        (
            (
                "frame_id: overhead_optical,",
                "frame_id: overhead_optical, mount_position_m: [0, 0, 1],",
            ),
            "sensors[0].mount_position_m",
            "mount_position_m is a position on mount_body",
        ),
    ],
    ids=[
        "duplicate-joint",
        "duplicate-sim-joint-name",
        "duplicate-sensor",
        "limits-order",
        "ctrl-range-order",
        "qpos-map-key",
        "qvel-map-key",
        "actuator-map-key",
        "duplicate-vla-slot",
        "vla-slot-collides-with-sensor-name",
        "mount-position-without-mount-body",
    ],
)
def test_rule_violation_is_reported(
    write_manifest: ManifestWriter, edit: tuple[str, str], field: str, fragment: str
) -> None:
    findings = _findings(write_manifest(edit))
    assert list(findings) == [field]
    assert fragment in findings[field]


def test_second_gripper_on_the_same_joint_is_rejected(write_manifest: ManifestWriter) -> None:
    entry = (
        "{joint: jaw, ctrl_range: [0.0, 1.0], qpos_addrs: [3, 4], qpos_scale: 0.1, "
        "mirror_actuator_index: 3}"
    )
    path = write_manifest(
        (entry, entry + "\n    - " + entry.replace(", mirror_actuator_index: 3", ""))
    )
    assert _findings(path) == {"sim.grippers[1].joint": "joint 'jaw' already has a gripper entry"}


def test_torque_pd_gain_maps_must_name_every_driven_joint(write_manifest: ManifestWriter) -> None:
    control = "  control: {mode: torque_pd, kp: {shoulder: 100.0, elbow: 5.0}, kd: 2.0}\n"
    path = write_manifest(("  grippers:\n", control + "  grippers:\n"))
    findings = _findings(path)
    assert "'elbow' is not a joint" in findings["sim.control.kp.elbow"]
    assert findings["sim.control.kp"] == "no gain for joint(s) wrist_roll; give every joint one"


def test_torque_pd_needs_gains_and_position_forbids_them(write_manifest: ManifestWriter) -> None:
    torque = write_manifest(
        ("  grippers:\n", "  control: {mode: torque_pd, kp: 1.0}\n  grippers:\n")
    )
    assert _findings(torque) == {
        "sim.control": "missing required field 'kd' (because mode is 'torque_pd')"
    }
    position = write_manifest(
        ("  grippers:\n", "  control: {mode: position, kp: 1.0}\n  grippers:\n")
    )
    assert _findings(position) == {
        "sim.control.kp": "unknown field 'kp'; expected one of: mode (because mode is 'position')"
    }


def test_scene_object_sizes_must_fit_their_shape(tmp_path: Path) -> None:
    from openral_core.loader import load_scene

    scene = REPO / "robots" / "franka_panda" / "scenes" / "tabletop.yaml"
    bad = tmp_path / "scene.yaml"
    bad.write_text(scene.read_text().replace("size_m: [0.02, 0.02, 0.02]", "size_m: [0.02]", 1))
    with pytest.raises(ManifestError) as error:
        load_scene(bad)
    (issue,) = error.value.issues
    assert issue.field == "scene.options.objects[1].size_m"
    assert issue.message == "a box takes 3 size value(s), got 1"


def test_an_issue_is_always_one_printable_line() -> None:
    from openral_core.errors import Issue

    issue = Issue(Path("f.yaml"), 3, 4, "a\u2028b", "does not compile: Error: x\nElement 'y'")
    assert issue.format() == "f.yaml:3:4: a\\u2028b: does not compile: Error: x; Element 'y'"


MOBILE_BASE = """mobile_base:
  mjcf_uri: robosuite:bases/omron_mobile_base.xml
  mount_body: support
  drive: holonomic
  joints: {x: joint_mobile_forward, y: joint_mobile_side, yaw: joint_mobile_yaw}
  actuators: {x: actuator_mobile_forward, y: actuator_mobile_side, yaw: actuator_mobile_yaw}
  max_linear_velocity_m_s: 0.5
  max_angular_velocity_rad_s: 1.0
  max_linear_acceleration_m_s2: 1.0
  max_angular_acceleration_rad_s2: 2.0
joints:
"""


def _only_issue(path: Path) -> str:
    """The one located line a manifest that breaks one rule is refused with."""
    with pytest.raises(ManifestError) as info:
        load_robot(path)
    (issue,) = info.value.issues
    line = issue.format()
    assert "\n" not in line
    return line


def test_a_mobile_robot_without_a_mobile_base_is_refused_at_base(
    write_manifest: ManifestWriter,
) -> None:
    path = write_manifest(("base: fixed", "base: mobile"))
    assert _only_issue(path) == (
        f"{path}:6:1: base: a mobile robot needs a mobile_base (its wheeled drive), or "
        "sim.floating_base: true for a legged one"
    )


def test_a_mobile_base_on_a_fixed_robot_is_refused_at_the_mobile_base(
    write_manifest: ManifestWriter,
) -> None:
    path = write_manifest(("joints:\n", MOBILE_BASE))
    assert _only_issue(path) == (
        f"{path}:7:1: mobile_base: a mobile_base needs base: mobile (base is 'fixed')"
    )


def test_a_mobile_robot_with_its_mobile_base_passes(write_manifest: ManifestWriter) -> None:
    robot = load_robot(write_manifest(("base: fixed", "base: mobile"), ("joints:\n", MOBILE_BASE)))
    assert robot.mobile_base is not None
    assert (robot.mobile_base.odom_frame, robot.mobile_base.base_frame) == ("odom", "base_link")
    assert robot.mobile_base.command_timeout_s == 0.5


def test_a_legged_robot_is_mobile_without_a_mobile_base_and_cannot_ride_one(
    write_manifest: ManifestWriter,
) -> None:
    legged = (
        ("base: fixed", "base: mobile"),
        ("joint_qpos_addr:", "floating_base: true\n  joint_qpos_addr:"),
    )
    assert load_robot(write_manifest(*legged)).base.value == "mobile"
    findings = _findings(write_manifest(*legged, ("joints:\n", MOBILE_BASE)))
    assert findings == {
        "mobile_base": (
            "a floating-base model cannot ride a mobile_base (the base carries its root body)"
        )
    }


START_POSE = ("  joint_qpos_addr:", "  start_pose: {POSE}\n  joint_qpos_addr:")


def _with_start_pose(pose: str) -> tuple[str, str]:
    return START_POSE[0], START_POSE[1].replace("POSE", pose)


def test_a_start_pose_of_arm_joints_inside_their_limits_passes(
    write_manifest: ManifestWriter,
) -> None:
    """A continuous joint takes any value; an integer is a number like any other."""
    robot = load_robot(write_manifest(_with_start_pose("shoulder: -1.5, wrist_roll: 12")))
    assert robot.sim is not None
    assert robot.sim.start_pose == {"shoulder": -1.5, "wrist_roll": 12.0}


@pytest.mark.parametrize(
    ("pose", "field", "message"),
    [
        (
            "elbow: 0.1",
            "sim.start_pose.elbow",
            "'elbow' is not a joint of this robot; expected one of: shoulder, wrist_roll, jaw",
        ),
        (
            "jaw: 0.01",
            "sim.start_pose.jaw",
            "'jaw' is a gripper; a start pose sets arm joints only",
        ),
        (
            "shoulder: 1.6",
            "sim.start_pose.shoulder",
            "1.6 is outside the joint's position_limits [-1.5, 1.5]",
        ),
    ],
    ids=["unknown-joint", "gripper-joint", "outside-the-limits"],
)
def test_a_start_pose_is_refused_at_its_joint(
    write_manifest: ManifestWriter, pose: str, field: str, message: str
) -> None:
    path = write_manifest(_with_start_pose(pose))
    assert _findings(path) == {field: message}
    assert _only_issue(path).startswith(f"{path}:18:16: {field}: ")  # at the key


def test_gravity_compensation_is_refused_on_a_floating_base(
    write_manifest: ManifestWriter,
) -> None:
    switch = "gravity_compensation: true\n  joint_qpos_addr:"
    robot = load_robot(write_manifest(("joint_qpos_addr:", switch)))
    assert robot.sim is not None and robot.sim.gravity_compensation
    legged = write_manifest(
        ("base: fixed", "base: mobile"), ("joint_qpos_addr:", "floating_base: true\n  " + switch)
    )
    assert _findings(legged) == {
        "sim.gravity_compensation": (
            "a floating-base robot cannot compensate gravity: its whole body would float; "
            "leave it out (or false)"
        )
    }


TCP = "tcp: {body: hand, offset_m: [0.0, 0.0, 0.1034]}"


def _franka_tcp(write_manifest: ManifestWriter, tcp: str) -> Path:
    return write_manifest((TCP, tcp), base=FRANKA, folder="franka_panda")


def test_a_tool_frame_quaternion_must_be_unit_and_is_stored_normalised(
    write_manifest: ManifestWriter,
) -> None:
    path = _franka_tcp(write_manifest, "tcp: {body: hand, quat_wxyz: [0.0, 0.5, 0.5, 0.0]}")
    assert _findings(path) == {
        "sim.tcp.quat_wxyz": "norm 0.7071; expected a unit quaternion (norm 1)"
    }
    near = _franka_tcp(write_manifest, "tcp: {body: hand, quat_wxyz: [0.0, 0.9995, 0.0, 0.0]}")
    from openral_core.tables import TcpWiring, hal_wiring

    wiring = hal_wiring(load_robot(near))
    assert wiring is not None and wiring.tcp == TcpWiring("hand", "body", quat_wxyz=(0, 1, 0, 0))


@pytest.mark.parametrize(
    ("tcp", "words"),
    [
        ("tcp: {body: hand, site: grip}", "names both body and site; expected exactly one"),
        ("tcp: {offset_m: [0.0, 0.0, 0.1]}", "names neither body and site; expected exactly one"),
    ],
)
def test_a_tool_centre_point_names_one_body_or_one_site(
    write_manifest: ManifestWriter, tcp: str, words: str
) -> None:
    assert words in _findings(_franka_tcp(write_manifest, tcp))["sim.tcp"]
