"""Per-robot tables derived from a RobotDescription: the one place each derivation rule lives.

Four tables are derived by ``just schema-export``, which writes them to
``generated/openral_generated/tables/<id>.json``: the runtime input of a repository robot
(:mod:`openral_core.loaded` reads them; a robot without a committed file gets the same
tables computed in memory by :func:`robot_tables`):

* **HAL wiring** — the keyword arguments of ``MujocoArmHAL``: qpos/qvel/actuator index
  per joint (1:1 in canonical order by default, shifted by 7/6 with a floating base),
  gripper wiring with its actuator resolved, and the control law with per-joint gains.
* **VLA slots** — RGB sensor name → policy slot (suffix of ``vla_feature_key``, else the
  sensor's own name), in manifest order.
* **Joint-name map** — canonical joint name → MJCF joint name.
* **Mobile-base wiring** — a wheeled base's model, mount, drive joints and actuators,
  limits and frames (None for a robot without ``mobile_base``).
* **Frame names** — the world, base and odometry frames the ROS graph adds to the model's
  bodies.
* **Real wiring** — the real driver, its rate, E-stop and shutdown behaviour and, for a
  servo bus, one row per motor (:mod:`openral_core.real_wiring`); None without ``real``.

Each file also records its origin: the manifest's path and the SHA-256 of the validated
manifest's canonical JSON (:func:`manifest_sha256`), so a table made from an earlier
meaning of the manifest is detected while comments and formatting do not matter.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from openral_core.link_names import LinkNaming, link_naming
from openral_core.located import source_file
from openral_core.models import (
    Frames,
    MobileBase,
    RgbSensor,
    RobotDescription,
    SimDescription,
    TorquePdControl,
)
from openral_core.paths import repo_root
from openral_core.real_wiring import RealWiring, real_wiring
from openral_core.tcp_wiring import TcpWiring, tcp_wiring

FREE_JOINT_NQPOS = 7
"""qpos entries of a MuJoCo free joint: position (3) + unit quaternion (4)."""
FREE_JOINT_NDOF = 6
"""qvel entries of a MuJoCo free joint: linear (3) + angular (3) velocity."""


@dataclass(frozen=True)
class GripperWiring:
    """Resolved wiring of one gripper (see SimGripperDescription for field meanings)."""

    joint: str
    ctrl_range: tuple[float, float]
    qpos_addrs: tuple[int, ...]
    qpos_scale: float
    read_mode: str
    write_mode: str
    actuator_index: int
    mirror_actuator_index: int | None


@dataclass(frozen=True)
class HalWiring:
    """Keyword arguments that wire MujocoArmHAL to one robot's MJCF model."""

    mjcf_uri: str
    joint_names: tuple[str, ...]
    joint_qpos_addr: dict[str, int]
    joint_qvel_addr: dict[str, int]
    actuator_index: dict[str, int]
    grippers: tuple[GripperWiring, ...]
    floating_base: bool
    keyframe_index: int | None
    seed_ctrl_from_qpos: bool
    settle_steps_default: int
    control_mode: str
    kp: dict[str, float] = field(default_factory=dict)
    kd: dict[str, float] = field(default_factory=dict)
    velocity_limit: dict[str, float] = field(default_factory=dict)
    """Arm joint → fastest its target may move (rad/s or m/s); grippers are not limited."""
    start_pose: dict[str, float] = field(default_factory=dict)
    """Arm joint → its value after every reset (rad or m), over the keyframe's."""
    gravity_compensation: bool = False
    """MuJoCo cancels gravity on the robot's bodies, through its joints' actuators."""
    tcp: TcpWiring | None = None
    """The tool centre point (None: joint actions only)."""
    ik_collision_pairs: tuple[tuple[tuple[str, ...], tuple[str, ...]], ...] = ()
    """(bodies, bodies to avoid) pairs the end-effector IK keeps apart (MJCF body names)."""
    ik_collision_margin_m: float = 0.01
    """Smallest distance the IK leaves between those bodies' collision geoms [m]."""

    @property
    def first_gripper(self) -> str | None:
        """The first gripper's joint (the slot an action's ``gripper`` sets), or None."""
        return self.grippers[0].joint if self.grippers else None

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> HalWiring:
        """Inverse of ``dataclasses.asdict`` (the ``hal_wiring`` of a tables JSON file)."""
        grippers = tuple(
            GripperWiring(
                **{**g, "ctrl_range": tuple(g["ctrl_range"]), "qpos_addrs": tuple(g["qpos_addrs"])}
            )
            for g in data["grippers"]
        )
        tcp = data.get("tcp")
        if tcp is not None:
            tcp = TcpWiring(
                **{**tcp, "offset_m": tuple(tcp["offset_m"]), "quat_wxyz": tuple(tcp["quat_wxyz"])}
            )
        pairs = tuple(
            (tuple(bodies), tuple(avoid)) for bodies, avoid in data.get("ik_collision_pairs", ())
        )
        return cls(
            **{
                **data,
                "joint_names": tuple(data["joint_names"]),
                "grippers": grippers,
                "tcp": tcp,
                "ik_collision_pairs": pairs,
            }
        )


@dataclass(frozen=True)
class MobileBaseWiring:
    """A wheeled base, resolved for the simulation and the base drive (see MobileBase for
    field meanings; the joint and actuator triples are in (x, y, yaw) order)."""

    mjcf_uri: str
    mount_body: str
    mount_position_m: tuple[float, float, float]
    mount_quat_wxyz: tuple[float, float, float, float]
    drive: str
    joints: tuple[str, str, str]
    actuators: tuple[str, str, str]
    max_linear_velocity_m_s: float
    max_angular_velocity_rad_s: float
    max_linear_acceleration_m_s2: float
    max_angular_acceleration_rad_s2: float
    command_timeout_s: float
    odom_frame: str
    base_frame: str

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> MobileBaseWiring:
        """Inverse of ``dataclasses.asdict`` (the ``mobile_base`` of a tables JSON file)."""
        tuples = ("mount_position_m", "mount_quat_wxyz", "joints", "actuators")
        return cls(**{**data, **{key: tuple(data[key]) for key in tuples}})


@dataclass(frozen=True)
class FrameNames:
    """The TF frames that are not bodies of the model (see Frames and MobileBase)."""

    world: str
    """The simulated world's fixed frame."""
    base: str
    """The robot's base frame (a mobile base's ``base_frame``, else ``frames.base``)."""
    odom: str | None
    """A mobile base's odometry frame; None without a mobile base."""
    naming: LinkNaming = field(default_factory=LinkNaming)
    """The links' and joints' names in ROS (``frames.links``, ``joints``, ``extra_links``)."""


@dataclass(frozen=True)
class VlaSlot:
    """One RGB sensor and the policy slot its frames are delivered under."""

    sensor: str
    slot: str


@dataclass(frozen=True)
class RobotTables:
    """Every table derived from one manifest, and where they came from."""

    robot: str
    manifest: str | None
    """The manifest's path relative to the repository root (absolute outside it), or None
    for a model built in code."""
    manifest_sha256: str
    """:func:`manifest_sha256` of the manifest the tables were derived from."""
    hal_wiring: HalWiring | None
    vla_slots: tuple[VlaSlot, ...]
    joint_name_map: dict[str, str]
    frames: FrameNames
    mobile_base: MobileBaseWiring | None = None
    real: RealWiring | None = None
    """The real driver's table (None: the robot has no ``real`` section)."""

    def to_json(self) -> str:
        """Deterministic JSON text (sorted keys, 2-space indent, trailing newline)."""
        return json.dumps(asdict(self), indent=2, sort_keys=True) + "\n"

    @classmethod
    def from_json(cls, text: str) -> RobotTables:
        """Inverse of :meth:`to_json`."""
        data = json.loads(text)
        wiring = data["hal_wiring"]
        base = data.get("mobile_base")
        real = data.get("real")
        return cls(
            robot=data["robot"],
            manifest=data["manifest"],
            manifest_sha256=data["manifest_sha256"],
            hal_wiring=None if wiring is None else HalWiring.from_dict(wiring),
            vla_slots=tuple(VlaSlot(**slot) for slot in data["vla_slots"]),
            joint_name_map=dict(data["joint_name_map"]),
            mobile_base=None if base is None else MobileBaseWiring.from_dict(base),
            frames=FrameNames(
                **{**data["frames"], "naming": LinkNaming.from_dict(data["frames"]["naming"])}
            ),
            real=None if real is None else RealWiring.from_dict(real),
        )


def vla_slot(sensor: RgbSensor) -> str:
    """Policy slot of an RGB sensor: ``observation.images.<slot>`` → ``<slot>``, else its name."""
    key = sensor.vla_feature_key
    return key.rsplit(".", 1)[-1] if key else sensor.name


def vla_slots(robot: RobotDescription) -> tuple[VlaSlot, ...]:
    """RGB sensors and their slots, in manifest order."""
    return tuple(VlaSlot(s.name, vla_slot(s)) for s in robot.sensors if isinstance(s, RgbSensor))


def joint_name_map(robot: RobotDescription) -> dict[str, str]:
    """Canonical joint name → native MJCF joint name (``sim_joint_name`` or the name itself)."""
    return {j.name: j.sim_joint_name or j.name for j in robot.joints}


def hal_wiring(robot: RobotDescription) -> HalWiring | None:
    """Resolve the sim block into explicit MujocoArmHAL wiring, or None without a sim block."""
    sim = robot.sim
    if sim is None:
        return None
    names = tuple(j.name for j in robot.joints)
    qpos_offset = FREE_JOINT_NQPOS if sim.floating_base else 0
    qvel_offset = FREE_JOINT_NDOF if sim.floating_base else 0
    actuators = _with_defaults(names, sim.actuator_index, 0)
    grippers = tuple(
        GripperWiring(
            joint=g.joint,
            ctrl_range=(g.ctrl_range[0], g.ctrl_range[1]),
            qpos_addrs=tuple(g.qpos_addrs),
            qpos_scale=g.qpos_scale,
            read_mode=g.read_mode.value,
            write_mode=g.write_mode.value,
            actuator_index=g.actuator_index if g.actuator_index is not None else actuators[g.joint],
            mirror_actuator_index=g.mirror_actuator_index,
        )
        for g in sim.grippers
    )
    gripper_joints = {g.joint for g in grippers}
    kp, kd = _gains(sim, names, gripper_joints)
    return HalWiring(
        mjcf_uri=sim.mjcf_uri,
        joint_names=names,
        joint_qpos_addr=_with_defaults(names, sim.joint_qpos_addr, qpos_offset),
        joint_qvel_addr=_with_defaults(names, sim.joint_qvel_addr, qvel_offset),
        actuator_index=actuators,
        grippers=grippers,
        floating_base=sim.floating_base,
        keyframe_index=sim.keyframe_index,
        seed_ctrl_from_qpos=sim.seed_ctrl_from_qpos,
        settle_steps_default=sim.settle_steps_default,
        control_mode=sim.control.mode if sim.control else "position",
        kp=kp,
        kd=kd,
        velocity_limit={
            j.name: j.velocity_limit for j in robot.joints if j.name not in gripper_joints
        },
        start_pose=dict(sim.start_pose or {}),
        gravity_compensation=sim.gravity_compensation,
        tcp=tcp_wiring(sim.tcp),
        ik_collision_pairs=tuple(
            (tuple(p.bodies), tuple(p.avoid)) for p in sim.ik_collision_pairs or ()
        ),
        ik_collision_margin_m=sim.ik_collision_margin_m,
    )


def mobile_base_wiring(robot: RobotDescription) -> MobileBaseWiring | None:
    """The robot's wheeled base with every default filled in, or None without one."""
    base: MobileBase | None = robot.mobile_base
    if base is None:
        return None
    x, y, z = base.mount_position_m
    w, qx, qy, qz = base.mount_quat_wxyz
    return MobileBaseWiring(
        mjcf_uri=base.mjcf_uri,
        mount_body=base.mount_body,
        mount_position_m=(x, y, z),
        mount_quat_wxyz=(w, qx, qy, qz),
        drive=base.drive.value,
        joints=(base.joints.x, base.joints.y, base.joints.yaw),
        actuators=(base.actuators.x, base.actuators.y, base.actuators.yaw),
        max_linear_velocity_m_s=base.max_linear_velocity_m_s,
        max_angular_velocity_rad_s=base.max_angular_velocity_rad_s,
        max_linear_acceleration_m_s2=base.max_linear_acceleration_m_s2,
        max_angular_acceleration_rad_s2=base.max_angular_acceleration_rad_s2,
        command_timeout_s=base.command_timeout_s,
        odom_frame=base.odom_frame,
        base_frame=base.base_frame,
    )


def frame_names(robot: RobotDescription) -> FrameNames:
    """The robot's world, base and odometry frame names, defaults filled in."""
    frames, naming = robot.frames or Frames(), link_naming(robot)
    base = robot.mobile_base
    if base is None:
        return FrameNames(world=frames.world, base=frames.base, odom=None, naming=naming)
    return FrameNames(world=frames.world, base=base.base_frame, odom=base.odom_frame, naming=naming)


def manifest_sha256(robot: RobotDescription) -> str:
    """SHA-256 of the validated manifest's canonical JSON (sorted keys, defaults filled in):
    comments and formatting do not change it, any change of meaning does."""
    canonical = json.dumps(robot.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(canonical.encode()).hexdigest()


def manifest_label(robot: RobotDescription, root: Path | None = None) -> str | None:
    """The path ``robot`` was loaded from, relative to ``root`` (default: the repository
    root) when inside it, else absolute; None for a model built in code."""
    file = source_file(robot)
    if file is None:
        return None
    resolved = file.resolve()
    base = (root or repo_root()).resolve()
    return resolved.relative_to(base).as_posix() if resolved.is_relative_to(base) else str(resolved)


def robot_tables(robot: RobotDescription, *, root: Path | None = None) -> RobotTables:
    """All tables of ``robot``: what ``just schema-export`` writes and the in-memory fallback.

    Args:
        robot: A validated manifest.
        root: Repository root the manifest path is recorded relative to (default: this
            repository; the export passes the root it exports).
    """
    return RobotTables(
        robot=robot.name,
        manifest=manifest_label(robot, root),
        manifest_sha256=manifest_sha256(robot),
        hal_wiring=hal_wiring(robot),
        vla_slots=vla_slots(robot),
        joint_name_map=joint_name_map(robot),
        mobile_base=mobile_base_wiring(robot),
        frames=frame_names(robot),
        real=real_wiring(robot),
    )


def _with_defaults(
    names: tuple[str, ...], overrides: dict[str, int] | None, offset: int
) -> dict[str, int]:
    given = overrides or {}
    return {name: given.get(name, offset + index) for index, name in enumerate(names)}


def _gains(
    sim: SimDescription, names: tuple[str, ...], gripper_joints: set[str]
) -> tuple[dict[str, float], dict[str, float]]:
    control = sim.control
    if not isinstance(control, TorquePdControl):
        return {}, {}
    driven = [n for n in names if n not in gripper_joints]

    def per_joint(gains: Any) -> dict[str, float]:
        if isinstance(gains, dict):
            return {n: float(gains[n]) for n in driven if n in gains}
        return {n: float(gains) for n in driven}

    return per_joint(control.kp), per_joint(control.kd)
