"""Verify a manifest's wiring against the MJCF model it names (`openral robot check`)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import mujoco
from openral_core.errors import Issue, ManifestError, OpenralError, did_you_mean, parse_field
from openral_core.located import error_at, issue_at
from openral_core.models import (
    DepthSensor,
    RgbSensor,
    RobotDescription,
    SiteSensor,
    StateSensor,
)
from openral_core.tables import HalWiring, hal_wiring, mobile_base_wiring

from openral_mujoco.mjcf_model import actuator_joints, is_velocity_servo, root_is_free
from openral_mujoco.mobile_base import (
    base_model_file,
    compile_base_model,
    drive_problems,
    mount_problem,
)
from openral_mujoco.model_cache import cached_mjcf
from openral_mujoco.robot_edits import UNEDITED, edit_robot_spec, robot_cache_kind
from openral_mujoco.state_sensor_check import state_sensor_rows


@dataclass(frozen=True)
class CheckRow:
    """One comparison between the manifest and the model."""

    field: str
    expected: str
    actual: str
    ok: bool


def check_robot(
    description: RobotDescription,
    model: mujoco.MjModel,
    base_model: mujoco.MjModel | None = None,
) -> list[CheckRow]:
    """Every check of ``description`` against ``model``; a robot passes when all rows are ok.

    A robot with a ``mobile_base`` is also checked against its base's model (``base_model``,
    else the one its ``mobile_base.mjcf_uri`` names): the mount body, a holonomic drive's
    joints and velocity actuators; its sensors may name bodies and sites of either model.
    """
    wiring = hal_wiring(description)
    if wiring is None:
        return [CheckRow("sim", "a sim block", "none", ok=False)]
    rows = [
        *_joint_rows(description, wiring, model),
        *_gripper_rows(wiring, model),
        *_keyframe_and_base_rows(wiring, model),
        *_ik_collision_rows(wiring, model),
    ]
    models = [model]
    if description.mobile_base is not None:
        if base_model is None:
            try:
                base_model = compile_base_model(description, base_model_file(description))
            except OpenralError as error:
                uri = description.mobile_base.mjcf_uri
                return [*rows, CheckRow("mobile_base.mjcf_uri", uri, str(error), ok=False)]
        rows += _mobile_base_rows(description, base_model)
        models.append(base_model)
    return rows + list(_sensor_rows(description, models))


def require_agreement(
    description: RobotDescription,
    model: mujoco.MjModel,
    base_model: mujoco.MjModel | None = None,
) -> None:
    """Refuse ``model`` (and ``base_model``, the robot's mobile base) for ``description``
    unless every check of :func:`check_robot` passes.

    The HAL and the native scene call this before they use a model: a manifest whose
    addresses, actuators, base or cameras disagree with its model would drive the wrong
    joint or crash later, so it is refused at the fields that are wrong.

    Raises:
        ManifestError: One located issue per failed check.
    """
    failed = [row for row in check_robot(description, model, base_model) if not row.ok]
    if not failed:
        return
    issues = [
        issue_at(
            description,
            parse_field(row.field),
            f"the manifest says {row.expected}, the model has {row.actual}; "
            "`openral robot check` lists every check",
        )
        for row in failed
    ]
    raise ManifestError(issues[0].file, issues)


def compile_robot_model(description: RobotDescription, path: Path) -> mujoco.MjModel:
    """Compile the robot's MJCF at ``path`` (or load it from :mod:`~openral_mujoco.model_cache`
    when neither it nor any file it reads has changed).

    Raises:
        ManifestError: At ``sim.mjcf_uri`` when MuJoCo cannot load the file.
    """
    return cached_robot_model(description, path)[0]


def cached_robot_model(
    description: RobotDescription, path: Path
) -> tuple[mujoco.MjModel, str | None]:
    """:func:`compile_robot_model` and the fingerprint of the files it read (None: none),
    with the edits its manifest asks for (:mod:`~openral_mujoco.robot_edits`)."""

    def refused(error: ValueError) -> ManifestError:
        return unloadable_model(description, path, error)

    def edit(spec: mujoco.MjSpec) -> None:
        edit_robot_spec(spec, description)

    kind = robot_cache_kind(description)
    return cached_mjcf(path, kind, refused, None if kind == UNEDITED else edit)


def unloadable_model(description: RobotDescription, path: Path, error: Exception) -> ManifestError:
    """The located error for an MJCF file MuJoCo refuses (one line of its message)."""
    first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    message = f"{path} does not load in MuJoCo: {first_line}"
    return error_at(description, ("sim", "mjcf_uri"), message)


def _joint_rows(
    description: RobotDescription, wiring: HalWiring, model: mujoco.MjModel
) -> Iterator[CheckRow]:
    for index, joint in enumerate(description.joints):
        native = joint.sim_joint_name or joint.name
        name_field = "sim_joint_name" if joint.sim_joint_name else "name"
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, native)
        missing = "no such joint in the model" + did_you_mean(
            native, model_names([model], mujoco.mjtObj.mjOBJ_JOINT)
        )
        yield CheckRow(
            f"joints[{index}].{name_field}", native, "found" if jid >= 0 else missing, ok=jid >= 0
        )
        if jid < 0:
            continue
        qpos, qvel = int(model.jnt_qposadr[jid]), int(model.jnt_dofadr[jid])
        yield _equal(f"sim.joint_qpos_addr.{joint.name}", wiring.joint_qpos_addr[joint.name], qpos)
        yield _equal(f"sim.joint_qvel_addr.{joint.name}", wiring.joint_qvel_addr[joint.name], qvel)
        yield _actuator_row(
            f"sim.actuator_index.{joint.name}",
            wiring.actuator_index[joint.name],
            jid,
            native,
            model,
        )


def _actuator_row(
    field: str, actuator: int, jid: int, native: str, model: mujoco.MjModel
) -> CheckRow:
    expected = f"{actuator} drives {native}"
    if not 0 <= actuator < model.nu:
        return CheckRow(field, expected, f"the model has {model.nu} actuators", ok=False)
    driven = actuator_joints(model, actuator)
    names = ", ".join(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "?" for j in driven)
    return CheckRow(field, expected, f"{actuator} drives {names or 'no joint'}", ok=jid in driven)


def _gripper_rows(wiring: HalWiring, model: mujoco.MjModel) -> Iterator[CheckRow]:
    for index, gripper in enumerate(wiring.grippers):
        prefix = f"sim.grippers[{index}]"
        for k, addr in enumerate(gripper.qpos_addrs):
            yield CheckRow(
                f"{prefix}.qpos_addrs[{k}]",
                f"{addr} < nq",
                f"nq = {model.nq}",
                ok=0 <= addr < model.nq,
            )
        yield _equal(
            f"{prefix}.qpos_addrs[0]", gripper.qpos_addrs[0], wiring.joint_qpos_addr[gripper.joint]
        )
        yield _ctrl_range_row(
            f"{prefix}.ctrl_range", gripper.ctrl_range, gripper.actuator_index, model
        )
        if gripper.mirror_actuator_index is not None:
            low, high = gripper.ctrl_range
            yield _ctrl_range_row(
                f"{prefix}.mirror_actuator_index",
                (-high, -low),
                gripper.mirror_actuator_index,
                model,
            )


def _ctrl_range_row(
    field: str, ctrl_range: tuple[float, float], actuator: int, model: mujoco.MjModel
) -> CheckRow:
    expected = f"[{ctrl_range[0]:g}, {ctrl_range[1]:g}] inside actuator {actuator}"
    if not 0 <= actuator < model.nu:
        return CheckRow(field, expected, f"the model has {model.nu} actuators", ok=False)
    if not model.actuator_ctrllimited[actuator]:
        return CheckRow(field, expected, "ctrl unlimited", ok=True)
    low, high = (float(v) for v in model.actuator_ctrlrange[actuator])
    inside = low - 1e-9 <= ctrl_range[0] and ctrl_range[1] <= high + 1e-9
    return CheckRow(field, expected, f"ctrlrange [{low:g}, {high:g}]", ok=inside)


def _keyframe_and_base_rows(wiring: HalWiring, model: mujoco.MjModel) -> Iterator[CheckRow]:
    if wiring.keyframe_index is not None:
        yield CheckRow(
            "sim.keyframe_index",
            str(wiring.keyframe_index),
            f"the model has {model.nkey} keyframe(s)",
            ok=0 <= wiring.keyframe_index < model.nkey,
        )
    root_free = root_is_free(model)
    yield CheckRow(
        "sim.floating_base",
        str(wiring.floating_base).lower(),
        "free joint at qpos 0" if root_free else "no free joint at qpos 0",
        ok=wiring.floating_base == root_free,
    )


def _mobile_base_rows(description: RobotDescription, model: mujoco.MjModel) -> Iterator[CheckRow]:
    """The mount body, and a holonomic drive: its joints' layout and velocity actuators."""
    wiring = mobile_base_wiring(description)
    assert wiring is not None
    problem = mount_problem(model, wiring)
    yield CheckRow("mobile_base.mount_body", wiring.mount_body, problem or "found", ok=not problem)
    layout = "slides x, y then hinge yaw about the vertical, on one child body of the world"
    problems = drive_problems(model, wiring)
    for field, problem in problems:
        yield CheckRow(field, layout, problem, ok=False)
    if not problems:
        yield CheckRow("mobile_base.joints", layout, "found", ok=True)
    for axis, name, joint in zip(("x", "y", "yaw"), wiring.actuators, wiring.joints, strict=True):
        expected = f"{name}: a velocity actuator of {joint}"
        actuator = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
        if actuator < 0:
            kind = mujoco.mjtObj.mjOBJ_ACTUATOR
            actual, ok = "no such actuator" + did_you_mean(name, model_names([model], kind)), False
        elif jid < 0 or actuator_joints(model, actuator) != (jid,):
            actual, ok = "it drives another joint", False
        else:
            ok = is_velocity_servo(model, actuator)
            actual = "found" if ok else "not a velocity servo (kv·(ctrl - q̇))"
        yield CheckRow(f"mobile_base.actuators.{axis}", expected, actual, ok=ok)


def _sensor_rows(description: RobotDescription, models: list[mujoco.MjModel]) -> Iterator[CheckRow]:
    """Cameras, mount bodies and sites, each found in one of ``models`` (the robot's, its
    base's); a site sensor with a mount body gets its site from the scene, so none may have
    its name yet; the MJCF sensors an IMU, force-torque or pose sensor names."""
    body, camera, site = (
        mujoco.mjtObj.mjOBJ_BODY,
        mujoco.mjtObj.mjOBJ_CAMERA,
        mujoco.mjtObj.mjOBJ_SITE,
    )
    for index, sensor in enumerate(description.sensors):
        field = f"sensors[{index}]"
        if isinstance(sensor, RgbSensor | DepthSensor) and sensor.camera is not None:
            yield _exists(f"{field}.camera", sensor.camera, camera, models)
        if sensor.mount_body is not None:
            yield _exists(f"{field}.mount_body", sensor.mount_body, body, models)
        if isinstance(sensor, SiteSensor) and sensor.mount_body is None:
            yield _exists(f"{field}.site", sensor.site, site, models)
        elif isinstance(sensor, SiteSensor):  # the scene creates it: the name must be free
            taken = any(mujoco.mj_name2id(m, site, sensor.site) >= 0 for m in models)
            actual = "a site of that name already" if taken else "no site of that name"
            yield CheckRow(f"{field}.site", f"{sensor.site}, a new site", actual, ok=not taken)
        if isinstance(sensor, StateSensor):
            for row in state_sensor_rows(field, sensor, models):
                yield CheckRow(*row)


def _ik_collision_rows(wiring: HalWiring, model: mujoco.MjModel) -> Iterator[CheckRow]:
    """The tool centre point's body or site, and each body of ``sim.ik_collision_pairs``,
    are in the robot's model."""
    tcp = wiring.tcp
    if tcp is not None:
        kind = mujoco.mjtObj.mjOBJ_BODY if tcp.kind == "body" else mujoco.mjtObj.mjOBJ_SITE
        yield _exists(f"sim.tcp.{tcp.kind}", tcp.frame, kind, [model])
    for index, groups in enumerate(wiring.ik_collision_pairs):
        for field, bodies in zip(("bodies", "avoid"), groups, strict=True):
            for position, body in enumerate(bodies):
                where = f"sim.ik_collision_pairs[{index}].{field}[{position}]"
                yield _exists(where, body, mujoco.mjtObj.mjOBJ_BODY, [model])


def _exists(field: str, name: str, kind: mujoco.mjtObj, models: list[mujoco.MjModel]) -> CheckRow:
    found = any(mujoco.mj_name2id(model, kind, name) >= 0 for model in models)
    missing = "not in the model" + did_you_mean(name, model_names(models, kind))
    return CheckRow(field, name, "found" if found else missing, ok=found)


_COUNTS = {
    mujoco.mjtObj.mjOBJ_JOINT: "njnt",
    mujoco.mjtObj.mjOBJ_CAMERA: "ncam",
    mujoco.mjtObj.mjOBJ_BODY: "nbody",
    mujoco.mjtObj.mjOBJ_SITE: "nsite",
    mujoco.mjtObj.mjOBJ_ACTUATOR: "nu",
}
"""The ``MjModel`` count of each kind of element a check looks a name up in."""


def model_names(models: list[mujoco.MjModel], kind: mujoco.mjtObj) -> list[str]:
    """Every named element of ``kind`` (a key of :data:`_COUNTS`) in ``models``."""
    names = (
        mujoco.mj_id2name(model, kind, index)
        for model in models
        for index in range(int(getattr(model, _COUNTS[kind])))
    )
    return [name for name in names if name]


def row_location(description: RobotDescription, row: CheckRow) -> Issue:
    """Where in the manifest ``row`` points: the line and column of its field (of the
    nearest field the file spells out, for a value derived from it)."""
    return issue_at(description, parse_field(row.field), row.actual)


def _equal(field: str, expected: int, actual: int) -> CheckRow:
    return CheckRow(field, str(expected), str(actual), ok=expected == actual)
