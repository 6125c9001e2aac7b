"""Which joints of an MJCF model a drafted manifest lists, and under which names.

One joint per actuator, in actuator order: a joint transmission drives its joint; a
fixed-tendon transmission drives the tendon's first joint (the others are coupled fingers).
Actuators of other transmissions, and repeats, are skipped with a note. Canonical names are
the MJCF names with every character outside ``[A-Za-z0-9_]`` replaced by ``_``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import mujoco
from openral_mujoco.mjcf_model import fixed_tendon_joints, is_scalar_joint

from openral_hal.errors import HalError

MJCF_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_/.-]{0,126}")
MAX_NAME = 63

_TRANSMISSION_NAMES = {
    int(mujoco.mjtTrn.mjTRN_JOINT): "joint",
    int(mujoco.mjtTrn.mjTRN_JOINTINPARENT): "joint in parent",
    int(mujoco.mjtTrn.mjTRN_SLIDERCRANK): "slider-crank",
    int(mujoco.mjtTrn.mjTRN_TENDON): "tendon",
    int(mujoco.mjtTrn.mjTRN_SITE): "site",
    int(mujoco.mjtTrn.mjTRN_BODY): "body",
}


@dataclass(frozen=True)
class Driven:
    """A joint the manifest lists, and what drives it."""

    jid: int
    mjcf_name: str
    name: str
    actuator: int
    coupled: tuple[int, ...]
    """Joints of the fixed tendon the actuator drives (this joint first), or () for a joint."""


def driven_joints(model: mujoco.MjModel) -> tuple[list[Driven], list[str], set[int]]:
    """Listed joints in actuator order, notes on skipped actuators, and every joint id an
    actuator drives (listed or not)."""
    driven: list[Driven] = []
    skipped: list[str] = []
    seen: set[int] = set()
    names: set[str] = set()
    for actuator in range(model.nu):
        label = actuator_label(model, actuator)
        kind = int(model.actuator_trntype[actuator])
        target = int(model.actuator_trnid[actuator, 0])
        coupled: tuple[int, ...] = ()
        if kind in (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT)):
            jid = target
        elif kind == int(mujoco.mjtTrn.mjTRN_TENDON):
            coupled = fixed_tendon_joints(model, target)
            if not coupled:
                skipped.append(f"{label} (spatial tendon)")
                continue
            jid = coupled[0]
        else:
            skipped.append(f"{label} ({_TRANSMISSION_NAMES.get(kind, 'other')} transmission)")
            continue
        if jid in seen:
            continue
        seen.add(jid)
        mjcf_name = joint_name(model, jid)
        if not is_scalar_joint(model, jid):
            skipped.append(f"{label} (drives the ball or free joint {mjcf_name or jid})")
            continue
        if not MJCF_NAME.fullmatch(mjcf_name):
            skipped.append(
                f"{label} (drives joint {mjcf_name or jid!r}, whose name a manifest cannot "
                "reference as sim_joint_name)"
            )
            continue
        canonical = unique_name(canonical_joint_name(mjcf_name), names)
        names.add(canonical)
        driven.append(Driven(jid, mjcf_name, canonical, actuator, coupled))
    return driven, skipped, seen


def canonical_joint_name(mjcf_name: str) -> str:
    name = re.sub(r"[^A-Za-z0-9_]", "_", mjcf_name)
    if not name[:1].isalpha() or not name[:1].isascii():
        name = f"j_{name}"
    return name[:MAX_NAME]


def sensor_name(camera: str) -> str:
    name = re.sub(r"[^a-z0-9_]", "_", camera.lower())
    if not name[:1].isalpha() or not name[:1].isascii():
        name = f"cam_{name}"
    return name[:MAX_NAME]


def unique_name(name: str, taken: set[str]) -> str:
    if name not in taken:
        return name
    for n in range(2, 10_000):
        suffix = f"_{n}"
        candidate = name[: MAX_NAME - len(suffix)] + suffix
        if candidate not in taken:
            return candidate
    raise HalError(f"cannot make joint name {name!r} unique")  # pragma: no cover


def joint_name(model: mujoco.MjModel, jid: int) -> str:
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, jid) or ""


def actuator_label(model: mujoco.MjModel, actuator: int) -> str:
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator)
    return f"actuator {actuator} ({name})" if name else f"actuator {actuator}"
