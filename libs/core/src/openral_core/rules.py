"""Cross-field rules of the robot contract that JSON Schema cannot state.

This module is the one place these rules live; ``schema/robot.schema.json`` lists them in
its ``$comment``. Each rule returns the field path and a message; the loader locates them
in the file. The rules run only on documents that already passed the schema.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence

from openral_core.episode_rules import episode_findings
from openral_core.models import (
    Base,
    DeployScene,
    LimitedJoint,
    RgbSensor,
    RobotDescription,
    SceneObject,
    Shape,
    SimDescription,
    TorquePdControl,
)
from openral_core.real_rules import real_findings
from openral_core.tables import frame_names, vla_slot
from openral_core.yaml_source import PathKey, format_field

Finding = tuple[PathKey, str]


def robot_findings(robot: RobotDescription, folder_name: str | None) -> list[Finding]:
    """Every cross-field rule violation in ``robot``.

    Args:
        robot: A description that already passed schema validation.
        folder_name: Name of the folder holding the file, or None when not checked.
    """
    rgb = [(i, s) for i, s in enumerate(robot.sensors) if isinstance(s, RgbSensor)]
    return [
        *_name_matches_folder(robot, folder_name),
        *_unique(
            [(("joints", i, "name"), j.name) for i, j in enumerate(robot.joints)], "joint name"
        ),
        *_unique(
            [
                (("joints", i, "sim_joint_name"), j.sim_joint_name)
                for i, j in enumerate(robot.joints)
                if j.sim_joint_name is not None
            ],
            "sim_joint_name",
        ),
        *_unique(
            [(("sensors", i, "name"), s.name) for i, s in enumerate(robot.sensors)], "sensor name"
        ),
        *_unique([(("sensors", i), vla_slot(s)) for i, s in rgb], "VLA slot"),
        *_limits_ordered(robot),
        *_sim_findings(robot),
        *_base_findings(robot),
        *_mount_findings(robot),
        *_frame_findings(robot),
        *_extra_link_findings(robot),
        *real_findings(robot),
    ]


def scene_findings(scene: DeployScene, folder_robot: str | None = None) -> list[Finding]:
    """Every cross-field rule violation of a deploy scene that needs no robot manifest.

    Args:
        scene: A scene that already passed schema validation.
        folder_robot: ``<id>`` when the file is under ``robots/<id>/scenes/``, else None.
    """
    options = scene.scene.options
    objects = options.objects if options is not None and options.objects else []
    located = [(("scene", "options", "objects", i, "name"), o.name) for i, o in enumerate(objects)]
    return [
        *_robot_matches_folder(scene, folder_robot),
        *_unique(located, "object name"),
        *_object_sizes(objects),
        *episode_findings(scene),
    ]


def _robot_matches_folder(scene: DeployScene, folder_robot: str | None) -> Iterator[Finding]:
    """A scene under ``robots/<id>/scenes/`` is for robot ``<id>`` (a copied robot folder
    must not drive the robot it was copied from)."""
    if folder_robot is not None and scene.robot_id not in (None, folder_robot):
        yield (
            ("robot_id",),
            f"must be {folder_robot!r}, the robot whose folder robots/{folder_robot}/scenes/ "
            f"holds this scene, or be left out; got {scene.robot_id!r}",
        )


SIZE_VALUES = {Shape.box: 3, Shape.sphere: 1, Shape.cylinder: 2}
"""How many ``size_m`` values each object shape takes (half-extents; radius; radius and
half-height)."""


def _object_sizes(objects: Sequence[SceneObject]) -> Iterator[Finding]:
    for index, obj in enumerate(objects):
        wanted = SIZE_VALUES[obj.shape]
        if len(obj.size_m) != wanted:
            yield (
                ("scene", "options", "objects", index, "size_m"),
                f"a {obj.shape} takes {wanted} size value(s), got {len(obj.size_m)}",
            )


def _name_matches_folder(robot: RobotDescription, folder_name: str | None) -> Iterator[Finding]:
    if folder_name is not None and robot.name != folder_name:
        yield ("name",), f"name {robot.name!r} must equal the folder name {folder_name!r}"


def _unique(located: Sequence[tuple[PathKey, str]], what: str) -> Iterator[Finding]:
    """Flag the second and later occurrences of a value."""
    first_seen: dict[str, PathKey] = {}
    for path, value in located:
        if value in first_seen:
            where = format_field(first_seen[value])
            yield path, f"duplicate {what} {value!r} (also at {where}); each must be unique"
        else:
            first_seen[value] = path


def _limits_ordered(robot: RobotDescription) -> Iterator[Finding]:
    for index, joint in enumerate(robot.joints):
        if not isinstance(joint, LimitedJoint):
            continue
        limits = joint.position_limits
        if not limits[0] < limits[1]:
            yield (
                ("joints", index, "position_limits"),
                f"lower limit {limits[0]} must be below upper limit {limits[1]}",
            )


def _base_findings(robot: RobotDescription) -> Iterator[Finding]:
    """Rules 11 and 12: ``base: mobile`` and ``mobile_base`` go together (a legged robot,
    ``sim.floating_base``, is mobile without one and cannot ride one)."""
    legged = robot.sim is not None and robot.sim.floating_base
    if robot.base is Base.mobile and robot.mobile_base is None and not legged:
        yield (
            ("base",),
            "a mobile robot needs a mobile_base (its wheeled drive), or sim.floating_base: "
            "true for a legged one",
        )
    if robot.mobile_base is None:
        return
    if robot.base is not Base.mobile:
        yield ("mobile_base",), f"a mobile_base needs base: mobile (base is {robot.base.value!r})"
    if legged:
        yield (
            ("mobile_base",),
            "a floating-base model cannot ride a mobile_base (the base carries its root body)",
        )


def _mount_findings(robot: RobotDescription) -> Iterator[Finding]:
    """Rule 13: a sensor's mount_position_m is a position on its mount_body."""
    for index, sensor in enumerate(robot.sensors):
        if sensor.mount_position_m is not None and sensor.mount_body is None:
            yield (
                ("sensors", index, "mount_position_m"),
                "mount_position_m is a position on mount_body; name the mount_body",
            )


def _frame_findings(robot: RobotDescription) -> Iterator[Finding]:
    """Rules 14 and 15: a mobile robot's base frame is named by its mobile_base, and the
    frames the graph adds (world, odometry, base, every sensor's frame_id) are distinct."""
    frames = robot.frames
    if robot.mobile_base is not None and frames is not None and "base" in frames.model_fields_set:
        yield (
            ("frames", "base"),
            "a robot with a mobile_base names its base frame in mobile_base.base_frame",
        )
    names = frame_names(robot)
    located: list[tuple[PathKey, str]] = [(("frames", "world"), names.world)]
    if robot.mobile_base is not None:
        located.append((("mobile_base", "odom_frame"), robot.mobile_base.odom_frame))
        located.append((("mobile_base", "base_frame"), names.base))
    else:
        located.append((("frames", "base"), names.base))
    located += [(("sensors", i, "frame_id"), s.frame_id) for i, s in enumerate(robot.sensors)]
    yield from _unique(located, "frame")


def _extra_link_findings(robot: RobotDescription) -> Iterator[Finding]:
    """Rule 27: an extra link's quaternion is a unit quaternion."""
    extras = robot.frames.extra_links if robot.frames is not None else []
    for index, extra in enumerate(extras):
        norm = math.hypot(*extra.quat_wxyz)
        if abs(norm - 1.0) > 1e-3:
            yield (
                ("frames", "extra_links", index, "quat_wxyz"),
                f"norm {norm:.4g}; expected a unit quaternion (norm 1)",
            )


def _tcp_findings(sim: SimDescription) -> Iterator[Finding]:
    """Rules 18 and 19: the tool centre point's quaternion and its one frame."""
    tcp = sim.tcp
    if tcp is None:
        return
    if (tcp.body is None) == (tcp.site is None):  # rule 19
        both = "names both" if tcp.body is not None else "names neither"
        yield (
            ("sim", "tcp"),
            f"{both} body and site; expected exactly one (the frame it is fixed to)",
        )
    quat = tcp.quat_wxyz
    if quat is not None and abs(math.hypot(*quat) - 1.0) > 1e-3:  # rule 18
        norm = math.hypot(*quat)
        yield ("sim", "tcp", "quat_wxyz"), f"norm {norm:.4g}; expected a unit quaternion (norm 1)"


def _sim_findings(robot: RobotDescription) -> Iterator[Finding]:
    sim = robot.sim
    if sim is None:
        return
    joints = [j.name for j in robot.joints]
    known = set(joints)
    for field in ("joint_qpos_addr", "joint_qvel_addr", "actuator_index"):
        yield from _keys_known(getattr(sim, field), joints, ("sim", field))
    gripper_joints: set[str] = set()
    for index, gripper in enumerate(sim.grippers):
        path: PathKey = ("sim", "grippers", index)
        if gripper.joint not in known:
            yield (*path, "joint"), _not_a_joint(gripper.joint, joints)
        elif gripper.joint in gripper_joints:
            yield (*path, "joint"), f"joint {gripper.joint!r} already has a gripper entry"
        gripper_joints.add(gripper.joint)
        low, high = gripper.ctrl_range
        if not low < high:
            yield (*path, "ctrl_range"), f"lower bound {low} must be below upper bound {high}"
    yield from _tcp_findings(sim)
    yield from _start_pose_findings(robot, gripper_joints)
    if sim.gravity_compensation and sim.floating_base:  # rule 17
        yield (
            ("sim", "gravity_compensation"),
            "a floating-base robot cannot compensate gravity: its whole body would float; "
            "leave it out (or false)",
        )
    control = sim.control
    if isinstance(control, TorquePdControl):
        driven = [j for j in joints if j not in gripper_joints]
        for gain_name in ("kp", "kd"):
            gains = getattr(control, gain_name)
            if isinstance(gains, Mapping):
                path = ("sim", "control", gain_name)
                yield from _keys_known(gains, joints, path)
                missing = [j for j in driven if j not in gains]
                if missing:
                    yield path, f"no gain for joint(s) {', '.join(missing)}; give every joint one"


def _start_pose_findings(robot: RobotDescription, gripper_joints: set[str]) -> Iterator[Finding]:
    """Rule 16: sim.start_pose names arm joints of this robot, each inside its limits."""
    assert robot.sim is not None
    joints = {j.name: j for j in robot.joints}
    for name, value in (robot.sim.start_pose or {}).items():
        path: PathKey = ("sim", "start_pose", name)
        joint = joints.get(name)
        if joint is None:
            yield path, _not_a_joint(name, list(joints))
        elif name in gripper_joints:
            yield path, f"{name!r} is a gripper; a start pose sets arm joints only"
        elif isinstance(joint, LimitedJoint):
            low, high = joint.position_limits
            if not low <= value <= high:
                yield path, f"{value} is outside the joint's position_limits [{low}, {high}]"


def _keys_known(
    mapping: Mapping[str, object] | None, joints: Sequence[str], path: PathKey
) -> Iterator[Finding]:
    """A finding for each key of ``mapping`` that is not a joint (listed in manifest order)."""
    known = set(joints)
    for key in mapping or {}:
        if key not in known:
            yield (*path, key), _not_a_joint(key, joints)


def _not_a_joint(name: str, joints: Sequence[str]) -> str:
    return f"{name!r} is not a joint of this robot; expected one of: {', '.join(joints)}"
