"""Drift guards for tables.py: exported tables equal the runtime resolution, and the slot rule."""

from __future__ import annotations

import json
from typing import Any

from hypothesis import HealthCheck, Phase, assume, given, settings
from hypothesis import strategies as st
from openral_core.models import RgbSensor, RobotDescription, Sensor
from openral_core.rules import robot_findings
from openral_core.schemas import SchemaName
from openral_core.tables import (
    FREE_JOINT_NDOF,
    FREE_JOINT_NQPOS,
    RobotTables,
    robot_tables,
    vla_slots,
)
from pydantic import TypeAdapter

from tests.properties.schema_strategy import documents

SETTINGS = settings(
    max_examples=40,
    deadline=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


def _ordered(limits: list[float]) -> list[float]:
    """Two drawn bounds as lower < upper (rules 5 and 9), kept inside position_limits' +-1000."""
    lower, upper = sorted(limits)
    if lower == upper:
        lower, upper = (lower - 1.0, upper) if lower > -1000 else (lower, upper + 1.0)
    return [lower, upper]


def _distinct_joints(joints: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Keep the first joint of each name and sim_joint_name (rules 2 and 3); one always stays."""
    seen: set[tuple[str, str]] = set()
    kept = []
    for joint in joints:
        keys = {("name", joint["name"]), ("sim", joint.get("sim_joint_name", ""))} - {("sim", "")}
        if not keys & seen:
            kept.append(joint)
            seen |= keys
    return kept


def _repair_real(document: dict[str, Any]) -> None:
    """Wire a drawn real section to the drawn joints (rules 20-29), so the rules can pass:
    a Feetech bus with one motor per joint, ids 1..n, protocol 0, 1 Mbaud, revolute joints
    within one turn; or a ros2_control driver whose E-stop and shutdown hold the arm."""
    real = document.get("real")
    if real is None:
        return
    if real.get("driver") == "ros2_control":
        real.pop("feetech", None)
        real["estop"], real["shutdown"] = "hold", "hold"
        names = real.get("ros2_control", {}).get("joint_names")
        if names is not None:  # distinct driver names of the drawn joints (rule 29)
            joints = [j["name"] for j in document["joints"]]
            real["ros2_control"]["joint_names"] = {j: f"driver_{j}" for j in joints[: len(names)]}
        return
    real.pop("ros2_control", None)
    bus = real.setdefault("feetech", {"servo_model": "sts3215", "motors": []})
    joints = document["joints"]
    bus["motors"] = [{"joint": j["name"], "id": i + 1} for i, j in enumerate(joints)]
    bus["protocol"], bus["baud_rate"] = 0, 1_000_000
    bus.pop("joint_settings", None)
    for joint in joints:
        low = max(-3.0, min(joint.get("position_limits", [-1.0, 1.0])[0], 2.0))
        joint.update(type="revolute", position_limits=[low, low + 1.0])


def _repair_base(document: dict[str, Any]) -> None:
    """A mobile base and ``base: mobile`` together (rules 11 and 12), its base frame named
    by the mobile base only (rule 14); a sensor's mount position on a named body (13)."""
    legged = bool(document.get("sim", {}).get("floating_base"))
    if "mobile_base" in document and not legged:
        document["base"] = "mobile"
        document.get("frames", {}).pop("base", None)
    else:
        document.pop("mobile_base", None)
        if document.get("base") == "mobile" and not legged:
            document["base"] = "fixed"
    for sensor in document.get("sensors", []):
        if "mount_body" not in sensor:
            sensor.pop("mount_position_m", None)


def _repair(document: dict[str, Any]) -> dict[str, Any]:
    """Point a drawn sim block's joint references at the drawn joints, so rules can pass."""
    document["joints"] = _distinct_joints(document["joints"])
    for joint in document["joints"]:
        if "position_limits" in joint:
            joint["position_limits"] = _ordered(joint["position_limits"])
    _repair_real(document)
    _repair_base(document)
    for extra in document.get("frames", {}).get("extra_links", []):
        extra["quat_wxyz"] = [1.0, 0.0, 0.0, 0.0]  # rule 27
    sim = document.get("sim")
    if sim is None:
        return document
    joints = [j["name"] for j in document["joints"]]
    for field in ("joint_qpos_addr", "joint_qvel_addr", "actuator_index"):
        if field in sim:
            values = list(sim[field].values())
            sim[field] = dict(zip(joints, values, strict=False))
    tcp = sim.get("tcp")
    if tcp is not None:  # one body or one site, a unit quaternion (rules 19 and 27)
        if "body" in tcp or "site" not in tcp:
            tcp["body"] = tcp.get("body", "hand")
            tcp.pop("site", None)
        tcp.pop("quat_wxyz", None)
    if "start_pose" in sim:  # joints of this robot only
        values = list(sim["start_pose"].values())
        sim["start_pose"] = dict(zip(joints, values, strict=False))
    grippers = sim.get("grippers", [])[: len(joints)]
    for gripper, joint in zip(grippers, reversed(joints), strict=False):
        gripper["joint"] = joint
        gripper["ctrl_range"] = _ordered(gripper["ctrl_range"])
    sim["grippers"] = grippers
    control = sim.get("control", {})
    for gain in ("kp", "kd"):
        if isinstance(control.get(gain), dict):
            control[gain] = {j: 1.0 + i for i, j in enumerate(joints)}
    return document


@SETTINGS
@given(documents(SchemaName.ROBOT).map(_repair))
def test_exported_tables_equal_runtime_resolution(document: Any) -> None:
    robot = RobotDescription.model_validate_json(json.dumps(document), strict=True)
    assume(not robot_findings(robot, None))
    tables = robot_tables(robot)
    # What `just schema-export` writes, read back, is what the runtime computes.
    assert RobotTables.from_json(tables.to_json()) == tables
    wiring, sim = tables.hal_wiring, robot.sim
    if sim is None:
        assert wiring is None
        return
    assert wiring is not None
    for index, joint in enumerate(robot.joints):
        qpos_default = index + (FREE_JOINT_NQPOS if sim.floating_base else 0)
        qvel_default = index + (FREE_JOINT_NDOF if sim.floating_base else 0)
        assert wiring.joint_qpos_addr[joint.name] == (sim.joint_qpos_addr or {}).get(
            joint.name, qpos_default
        )
        assert wiring.joint_qvel_addr[joint.name] == (sim.joint_qvel_addr or {}).get(
            joint.name, qvel_default
        )
        assert wiring.actuator_index[joint.name] == (sim.actuator_index or {}).get(
            joint.name, index
        )


SLOT_NAMES = st.sampled_from(["camera1", "camera2", "agentview", "wrist", "image"])


@st.composite
def sensor_lists(draw: st.DrawFn) -> list[Sensor]:
    count = draw(st.integers(min_value=0, max_value=5))
    names = draw(st.lists(SLOT_NAMES, min_size=count, max_size=count, unique=True))
    sensors = []
    for name in names:
        kind = draw(st.sampled_from(["rgb", "rgb", "depth"]))
        entry: dict[str, Any] = {
            "name": name,
            "kind": kind,
            "width": 16,
            "height": 16,
            "rate_hz": 10.0,
            "frame_id": "f",
        }
        if kind == "rgb" and draw(st.booleans()):
            entry["vla_feature_key"] = f"observation.images.{draw(SLOT_NAMES)}"
        sensors.append(TypeAdapter(Sensor).validate_python(entry))
    return sensors


@SETTINGS
@given(sensor_lists())
def test_slot_rule_gives_unique_slots_in_manifest_order(sensors: list[Sensor]) -> None:
    robot = RobotDescription.model_validate(
        {
            "schema_version": "0.1",
            "name": "arm",
            "display_name": "Arm",
            "base": "fixed",
            "joints": [
                {"name": "j", "type": "continuous", "velocity_limit": 1.0, "effort_limit": 1.0}
            ],
            "sensors": [s.model_dump(exclude_none=True) for s in sensors],
        }
    )
    slots = vla_slots(robot)
    rgb = [s for s in sensors if isinstance(s, RgbSensor)]
    assert [slot.sensor for slot in slots] == [s.name for s in rgb]
    for slot, sensor in zip(slots, rgb, strict=True):
        key = sensor.vla_feature_key
        assert slot.slot == (key.removeprefix("observation.images.") if key else sensor.name)
    names = [slot.slot for slot in slots]
    duplicate_findings = [f for f in robot_findings(robot, None) if "duplicate VLA slot" in f[1]]
    # The rules reject exactly the lists whose slots collide; accepted lists have unique slots.
    assert (len(set(names)) == len(names)) == (not duplicate_findings)
