"""Draft a ``robot.yaml`` from an MJCF model (`openral robot scaffold`).

The draft is written by hand, line by line, so it can carry ``# REVIEW:`` comments on
every value that is a guess or a placeholder (velocity limits, guessed grippers) or a first
estimate (PD gains from the model's inertia, :mod:`openral_hal.scaffold_gains`). It is
built so that it loads (:func:`openral_core.loader.load_robot`) and passes
:func:`openral_mujoco.model_check.check_robot` against the model it came from; a human
still has to read it before it describes a real robot.

How the model becomes a manifest:

- Which joints are listed, and under which canonical names, is
  :mod:`openral_hal.scaffold_joints`; ``sim_joint_name`` keeps the MJCF name where it
  differs from the canonical one.
- qpos/qvel/actuator overrides are written only where the model differs from the
  default wiring (1:1 in manifest order, +7/+6 with a floating base).
- A model whose actuators are all motors gets a ``torque_pd`` law with per-joint gains
  from its inertia and, on a fixed or wheeled base, ``gravity_compensation: true``.
"""

from __future__ import annotations

import math
import re
import textwrap
from collections.abc import Sequence
from pathlib import Path

import mujoco
from openral_mujoco.mjcf_model import (
    is_motor,
    is_position_servo,
    root_is_free,
)
from openral_mujoco.mjcf_uri import resolve_mjcf_uri

from openral_hal.errors import HalError
from openral_hal.scaffold_gains import control_lines
from openral_hal.scaffold_joints import (
    MJCF_NAME,
    Driven,
    driven_joints,
    joint_name,
    sensor_name,
)
from openral_hal.scaffold_text import DIGITS, REVIEW, num, scalar

SCHEMA_LINE = "# yaml-language-server: $schema=../../schema/robot.schema.json"
"""First line of every manifest under ``robots/<name>/``."""

ROBOT_NAME = re.compile(r"[a-z][a-z0-9_]{1,62}")
GRIPPER_WORDS = ("finger", "gripper", "jaw", "hand")

FREE_JOINT_NQPOS = 7
FREE_JOINT_NDOF = 6
MAX_QPOS_ADDRS = 8
LIMIT_BOUND = 1000.0
EFFORT_BOUND = 100000.0
CTRL_BOUND = 10000.0
QPOS_SCALE_BOUND = 1000.0

PLACEHOLDER_VELOCITY = 1.0
PLACEHOLDER_EFFORT = 1.0
CAMERA_SIZE = 128
CAMERA_RATE_HZ = 10.0


def scaffold_manifest(
    mjcf_uri: str, name: str, manifest_dir: Path, *, allow_outside: bool = False
) -> str:
    """Draft robot.yaml text for the MJCF model `mjcf_uri` names.

    Args:
        mjcf_uri: A ``sim.mjcf_uri`` (see :mod:`openral_mujoco.mjcf_uri`), written into the draft
            as given.
        name: Robot id; the draft belongs in ``robots/<name>/robot.yaml``.
        manifest_dir: Folder the draft will be written to (``file:`` URIs start there and
            must stay inside it).
        allow_outside: Accept a model, or files it loads, outside its confinement root
            (see :func:`openral_mujoco.mjcf_uri.resolve_mjcf_uri`).

    Raises:
        MjcfUriError: The URI cannot be resolved to a confined MJCF file.
        HalError: Invalid robot id, a model MuJoCo cannot load, or no actuator that drives
            a joint.
    """
    if not ROBOT_NAME.fullmatch(name):
        raise HalError(
            f"robot name {name!r} must be lower-case snake case, 2 to 63 characters "
            "(^[a-z][a-z0-9_]{1,62}$)"
        )
    path = resolve_mjcf_uri(mjcf_uri, manifest_dir, allow_outside=allow_outside)
    try:
        model = mujoco.MjModel.from_xml_path(str(path))
    except ValueError as error:
        raise HalError(f"{mjcf_uri}: MuJoCo cannot load {path}: {error}") from None
    driven, skipped, actuated = driven_joints(model)
    if not driven:
        why = f" ({'; '.join(skipped)})" if skipped else ""
        raise HalError(
            f"{mjcf_uri}: none of the {model.nu} actuator(s) of {path} drives a hinge or "
            f"slide joint a manifest can list (through a joint or a fixed tendon){why}; "
            "there is nothing to put under joints"
        )
    return "\n".join(_manifest_lines(model, mjcf_uri, name, driven, skipped, actuated)) + "\n"


# --------------------------------------------------------------------------- writing


def _manifest_lines(
    model: mujoco.MjModel,
    mjcf_uri: str,
    name: str,
    driven: Sequence[Driven],
    skipped: Sequence[str],
    actuated: set[int],
) -> list[str]:
    floating = root_is_free(model)
    one_line_uri = mjcf_uri.replace("\n", " ")
    lines = [
        SCHEMA_LINE,
        f"# Drafted by `openral robot scaffold` from {one_line_uri}.",
        "# Lines marked `# REVIEW:` are guesses or placeholders and need a human.",
    ]
    if floating:
        root = joint_name(model, 0) or "(unnamed)"
        lines.append(f"# The root free joint {root} is the floating base (sim.floating_base).")
    unlisted = [
        joint_name(model, j) or f"(unnamed joint {j})"
        for j in range(model.njnt)
        if j not in actuated and not (floating and j == 0)
    ]
    lines += _comment_block(
        "Joints no actuator drives (free joints of objects, passive or coupled fingers) "
        "are not listed:",
        unlisted,
    )
    lines += _comment_block("REVIEW: actuators left out of joints:", skipped)
    lines += [
        'schema_version: "0.1"',
        f"name: {scalar(name)}",
        f"display_name: {scalar(name.replace('_', ' ').title())}",
        f"base: {'mobile' if floating else 'fixed'}",
        "joints:",
    ]
    for joint in driven:
        lines += _joint_lines(model, joint)
    lines += _sensor_lines(model)
    lines += _sim_lines(model, mjcf_uri, driven, floating)
    return lines


def _comment_block(title: str, items: Sequence[str]) -> list[str]:
    if not items:
        return []
    text = f"{title} {', '.join(items)}."
    return [f"# {line}" for line in textwrap.wrap(text, width=96, break_on_hyphens=False)]


def _joint_lines(model: mujoco.MjModel, joint: Driven) -> list[str]:
    lines = [f"  - name: {scalar(joint.name)}"]
    if joint.name != joint.mjcf_name:
        lines.append(f"    sim_joint_name: {scalar(joint.mjcf_name)}")
    jid = joint.jid
    limited = bool(model.jnt_limited[jid])
    low, high = (float(v) for v in model.jnt_range[jid])
    if int(model.jnt_type[jid]) == int(mujoco.mjtJoint.mjJNT_HINGE):
        limits = _limits(low, high) if limited else None
        if limits is None:
            lines.append("    type: continuous")
            if limited:
                lines[-1] += f"{REVIEW} its MJCF range [{low:g}, {high:g}] is empty"
        else:
            lines.append("    type: revolute")
            lines.append(_limits_line(limits, low, high))
    else:
        lines.append("    type: prismatic")
        limits = _limits(low, high) if limited else None
        if limits is None:
            lines.append(
                f"    position_limits: [-1.0, 1.0]{REVIEW} the MJCF slide joint has no range"
            )
        else:
            lines.append(_limits_line(limits, low, high))
    lines.append(f"    velocity_limit: {num(PLACEHOLDER_VELOCITY)}{REVIEW} not in the MJCF")
    effort, source = _effort(model, joint)
    if effort is None:
        lines.append(f"    effort_limit: {num(PLACEHOLDER_EFFORT)}{REVIEW} {source}")
    elif effort > EFFORT_BOUND:
        lines.append(
            f"    effort_limit: {num(EFFORT_BOUND)}{REVIEW} clipped; the MJCF {source} "
            f"gives {effort:g}"
        )
    else:
        lines.append(f"    effort_limit: {num(effort)}")
    return lines


def _limits(low: float, high: float) -> tuple[float, float] | None:
    """Rounded limits, unrounded where rounding would collapse them, None when empty."""
    rounded = (round(low, DIGITS), round(high, DIGITS))
    if rounded[0] < rounded[1]:
        return rounded
    return (low, high) if low < high else None


def _limits_line(limits: tuple[float, float], low: float, high: float) -> str:
    lower, upper = max(limits[0], -LIMIT_BOUND), min(limits[1], LIMIT_BOUND)
    mjcf_range = f"the MJCF range is [{low:g}, {high:g}]"
    if not lower < upper:
        return f"    position_limits: [-1.0, 1.0]{REVIEW} {mjcf_range}, outside +-1000"
    line = f"    position_limits: [{num(lower, rounded=False)}, {num(upper, rounded=False)}]"
    if (lower, upper) != limits:
        line += f"{REVIEW} clipped to +-1000; {mjcf_range}"
    return line


def _effort(model: mujoco.MjModel, joint: Driven) -> tuple[float | None, str]:
    """Effort limit and where it came from; (None, why) when the MJCF gives none."""
    jid, actuator = joint.jid, joint.actuator
    candidates: list[tuple[float, str]] = []
    if model.jnt_actfrclimited[jid]:
        candidates.append((float(model.jnt_actfrcrange[jid, 1]), "actuatorfrcrange"))
    if model.actuator_forcelimited[actuator]:
        candidates.append((float(model.actuator_forcerange[actuator, 1]), "forcerange"))
    if is_motor(model, actuator) and model.actuator_ctrllimited[actuator]:
        gear = abs(float(model.actuator_gear[actuator, 0]))
        ctrl_high = float(model.actuator_ctrlrange[actuator, 1])
        candidates.append((ctrl_high * gear, "motor ctrlrange x gear"))
    for value, source in candidates:
        if math.isfinite(value) and round(value, DIGITS) > 0:
            return value, source
    if candidates:
        return None, "the MJCF effort bound is not positive"
    return None, "not in the MJCF"


def _sensor_lines(model: mujoco.MjModel) -> list[str]:
    lines: list[str] = []
    taken: set[str] = set()
    for cam in range(model.ncam):
        camera = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_CAMERA, cam) or ""
        if not MJCF_NAME.fullmatch(camera):
            continue
        sensor = sensor_name(camera)
        if sensor in taken:
            continue
        taken.add(sensor)
        lines += [
            f"  - name: {scalar(sensor)}",
            "    kind: rgb",
            f"    camera: {scalar(camera)}",
            f"    width: {CAMERA_SIZE}",
            f"    height: {CAMERA_SIZE}",
            f"    rate_hz: {num(CAMERA_RATE_HZ)}",
            f"    frame_id: {sensor}_optical_frame",
        ]
    return ["sensors:", *lines] if lines else ["sensors: []"]


def _sim_lines(
    model: mujoco.MjModel, mjcf_uri: str, driven: Sequence[Driven], floating: bool
) -> list[str]:
    lines = ["sim:", f"  mjcf_uri: {scalar(mjcf_uri)}"]
    if floating:
        lines.append("  floating_base: true")
    qpos_offset = FREE_JOINT_NQPOS if floating else 0
    qvel_offset = FREE_JOINT_NDOF if floating else 0
    overrides = {
        "joint_qpos_addr": [
            (d.name, int(model.jnt_qposadr[d.jid]), qpos_offset + i) for i, d in enumerate(driven)
        ],
        "joint_qvel_addr": [
            (d.name, int(model.jnt_dofadr[d.jid]), qvel_offset + i) for i, d in enumerate(driven)
        ],
        "actuator_index": [(d.name, d.actuator, i) for i, d in enumerate(driven)],
    }
    for field, rows in overrides.items():
        differing = [(joint, real) for joint, real, default in rows if real != default]
        if differing:
            lines.append(f"  {field}:")
            lines += [f"    {scalar(joint)}: {real}" for joint, real in differing]
    if model.nkey > 0:
        lines.append("  keyframe_index: 0")
    actuators = [d.actuator for d in driven]
    if any(is_position_servo(model, a) for a in actuators):
        lines.append("  seed_ctrl_from_qpos: true")
    gripper_lines = [line for d in driven for line in _gripper_lines(model, d)]
    notes = [line for line in gripper_lines if line.startswith("  #")]
    entries = [line for line in gripper_lines if not line.startswith("  #")]
    lines += notes
    if entries:
        lines += ["  grippers:", *entries]
    if all(is_motor(model, a) for a in actuators):
        if not floating:
            lines.append("  gravity_compensation: true  # motors: the servo does not hold gravity")
        efforts = [_effort(model, d)[0] for d in driven]
        lines += control_lines(model, [(d.jid, d.name) for d in driven], efforts)
    return lines


def _gripper_lines(model: mujoco.MjModel, joint: Driven) -> list[str]:
    if not (joint.coupled or any(w in joint.mjcf_name.lower() for w in GRIPPER_WORDS)):
        return []
    actuator = joint.actuator
    ctrl_limited = bool(model.actuator_ctrllimited[actuator])
    ctrl = tuple(float(v) for v in model.actuator_ctrlrange[actuator])
    if joint.coupled:
        fingers = joint.coupled[:MAX_QPOS_ADDRS]
        addrs = [int(model.jnt_qposadr[j]) for j in fingers]
        opened = sum(float(model.jnt_range[j, 1]) for j in fingers if model.jnt_limited[j])
        scale = round(opened, DIGITS)
        if not 0 < scale <= QPOS_SCALE_BOUND:
            scale = 1.0
        ctrl_range = _inward(ctrl[0], ctrl[1]) if ctrl_limited else (0.0, 1.0)
        modes = ("sum_over_scale", "normalised")
    else:
        addrs = [int(model.jnt_qposadr[joint.jid])]
        scale = 1.0
        if ctrl_limited:
            ctrl_range = _inward(ctrl[0], ctrl[1])
        else:
            low, high = (float(v) for v in model.jnt_range[joint.jid])
            ctrl_range = _inward(low, high) if model.jnt_limited[joint.jid] else (0.0, 0.0)
        modes = ("passthrough", "passthrough")
    ctrl_range = (max(ctrl_range[0], -CTRL_BOUND), min(ctrl_range[1], CTRL_BOUND))
    if not ctrl_range[0] < ctrl_range[1]:
        return [
            f"  # REVIEW: {joint.name} looks like a gripper, but its control range is empty; "
            "no gripper entry was drafted"
        ]
    shown_low, shown_high = (num(v, rounded=False) for v in ctrl_range)
    return [
        f"    - joint: {scalar(joint.name)}{REVIEW} guessed gripper",
        f"      ctrl_range: [{shown_low}, {shown_high}]",
        f"      qpos_addrs: [{', '.join(str(a) for a in addrs)}]",
        f"      qpos_scale: {num(scale)}",
        f"      read_mode: {modes[0]}",
        f"      write_mode: {modes[1]}",
    ]


def _inward(low: float, high: float) -> tuple[float, float]:
    """``(low, high)`` rounded to DIGITS decimals without leaving the interval."""
    step = 10.0**DIGITS
    rounded_low, rounded_high = round(low, DIGITS), round(high, DIGITS)
    if rounded_low < low:
        rounded_low = math.ceil(low * step) / step
    if rounded_high > high:
        rounded_high = math.floor(high * step) / step
    return rounded_low, rounded_high
