"""Per-robot tables derived from a RobotDescription: the one place each derivation rule lives.

Three tables are derived, both at run time and by ``just schema-export`` (which writes
them to ``generated/openral_generated/tables/<id>.json`` for review and for consumers
that must not import the HAL):

* **HAL wiring** — the keyword arguments of ``MujocoArmHAL``: qpos/qvel/actuator index
  per joint (1:1 in canonical order by default, shifted by 7/6 with a floating base),
  gripper wiring with its actuator resolved, and the control law with per-joint gains.
* **VLA slots** — RGB sensor name → policy slot (suffix of ``vla_feature_key``, else the
  sensor's own name), in manifest order.
* **Joint-name map** — canonical joint name → MJCF joint name.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from typing import Any

from openral_core.models import RgbSensor, RobotDescription, SimDescription, TorquePdControl

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

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> HalWiring:
        """Inverse of ``dataclasses.asdict`` (the ``hal_wiring`` of a tables JSON file)."""
        grippers = tuple(
            GripperWiring(
                **{
                    **g,
                    "ctrl_range": tuple(g["ctrl_range"]),
                    "qpos_addrs": tuple(g["qpos_addrs"]),
                }
            )
            for g in data["grippers"]
        )
        return cls(**{**data, "joint_names": tuple(data["joint_names"]), "grippers": grippers})


@dataclass(frozen=True)
class VlaSlot:
    """One RGB sensor and the policy slot its frames are delivered under."""

    sensor: str
    slot: str


@dataclass(frozen=True)
class RobotTables:
    """Every table derived from one manifest."""

    robot: str
    hal_wiring: HalWiring | None
    vla_slots: tuple[VlaSlot, ...]
    joint_name_map: dict[str, str]

    def to_json(self) -> str:
        """Deterministic JSON text (sorted keys, 2-space indent, trailing newline)."""
        return json.dumps(asdict(self), indent=2, sort_keys=True) + "\n"

    @classmethod
    def from_json(cls, text: str) -> RobotTables:
        """Inverse of :meth:`to_json`."""
        data = json.loads(text)
        wiring = data["hal_wiring"]
        return cls(
            robot=data["robot"],
            hal_wiring=None if wiring is None else HalWiring.from_dict(wiring),
            vla_slots=tuple(VlaSlot(**slot) for slot in data["vla_slots"]),
            joint_name_map=dict(data["joint_name_map"]),
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
    )


def robot_tables(robot: RobotDescription) -> RobotTables:
    """All tables of ``robot``."""
    return RobotTables(robot.name, hal_wiring(robot), vla_slots(robot), joint_name_map(robot))


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
