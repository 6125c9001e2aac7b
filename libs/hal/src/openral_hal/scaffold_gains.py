"""PD gains a drafted manifest gives a motor-driven robot, from its model's inertia.

Each joint is tuned as a second-order system of its own effective inertia, the diagonal
``M_ii`` of the joint-space mass matrix (rotor armature included) in the pose
a reset leaves (the first keyframe, else ``qpos0``): ``kp = M_ii·ωn²`` and
``kd = 2·ζ·M_ii·ωn`` with the bandwidth ωn = :data:`BANDWIDTH_RAD_S` and ζ = 1 (critically
damped: a step is reached without overshoot in about 5/ωn seconds). Then, per joint:

* **Friction.** A joint with friction loss ``f`` stops wherever the servo's force falls
  below ``f``, so up to ``f/kp`` short of its target: kp is raised to
  ``f / STATIC_ERROR_RAD`` (and kd to critical damping of the raised kp).
* **The physics step.** With an integrator that treats actuator damping implicitly
  (``implicit``, ``implicitfast``), kd is at least ``kp·dt``, which keeps the stiff servo of
  a light joint stable at the model's time step. With an explicit one (``Euler``, ``RK4``)
  the servo's own frequency stays below :data:`EXPLICIT_STEP_FRACTION` / dt, however much
  friction asks for.
* **The actuator.** kp is at most ``effort / SATURATION_ERROR_RAD``: a servo that saturates
  its motor for errors smaller than that behaves as a bang-bang controller.

Gravity is not the servo's job: a drafted motor-driven arm also gets
``sim.gravity_compensation: true`` (:mod:`openral_mujoco.gravity`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from openral_hal.scaffold_text import REVIEW, num, scalar

BANDWIDTH_RAD_S = 2.0 * math.pi * 5.0
"""ωn of every joint's servo [rad/s]: 5 Hz, a joint servo of an industrial arm."""
DAMPING_RATIO = 1.0
"""ζ: critically damped."""
STATIC_ERROR_RAD = 0.002
"""Largest distance [rad or m] friction loss may stop a joint short of its target."""
SATURATION_ERROR_RAD = 0.01
"""Smallest error [rad or m] at which the servo may ask for the motor's whole effort."""
GAIN_BOUND = 100000.0
"""Largest gain the schema accepts."""
EXPLICIT_STEP_FRACTION = 0.2
"""Largest ωn·dt of a servo under an explicit integrator (Euler, RK4)."""
IMPLICIT_INTEGRATORS = (
    int(mujoco.mjtIntegrator.mjINT_IMPLICIT),
    int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
)
SIGNIFICANT_DIGITS = 4


@dataclass(frozen=True)
class JointGains:
    """A joint's PD gains and why they differ from the bandwidth rule (empty: they do not)."""

    kp: float
    """Proportional gain [N·m/rad or N/m]."""
    kd: float
    """Derivative gain [N·m·s/rad or N·s/m]."""
    note: str


def inertia_diagonal(model: mujoco.MjModel) -> np.ndarray:
    """``M_ii`` of every dof in the pose a reset leaves (first keyframe, else ``qpos0``)."""
    data = mujoco.MjData(model)
    if model.nkey > 0:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    diagonal, unit, column = np.empty(model.nv), np.zeros(model.nv), np.empty(model.nv)
    for dof in range(model.nv):  # M·e_i is M's column i (mj_fullM's signature varies)
        unit[dof] = 1.0
        mujoco.mj_mulM(model, data, column, unit)
        diagonal[dof], unit[dof] = column[dof], 0.0
    return diagonal


def joint_gains(
    model: mujoco.MjModel, jid: int, inertia: float, effort: float | None
) -> JointGains:
    """The gains of joint ``jid`` (see the module doc) whose ``M_ii`` is ``inertia``
    [kg·m² or kg] and whose motor gives at most ``effort`` (None: unknown)."""
    dt = float(model.opt.timestep)
    implicit = int(model.opt.integrator) in IMPLICIT_INTEGRATORS
    omega = BANDWIDTH_RAD_S if implicit else min(BANDWIDTH_RAD_S, EXPLICIT_STEP_FRACTION / dt)
    kp = inertia * omega**2
    notes = []
    friction = float(model.dof_frictionloss[model.jnt_dofadr[jid]])
    needed = friction / STATIC_ERROR_RAD
    if needed > kp:
        ceiling = math.inf if implicit else inertia * (EXPLICIT_STEP_FRACTION / dt) ** 2
        if min(needed, ceiling) > kp:
            kp = min(needed, ceiling)
            notes.append(f"raised for its friction loss {friction:g}")
        if needed > kp:
            notes.append(f"friction loss {friction:g} may stop it {friction / kp:.2g} short")
    if effort is not None and kp > effort / SATURATION_ERROR_RAD:
        kp = effort / SATURATION_ERROR_RAD
        notes.append(f"capped by its effort {effort:g}")
    kp = min(kp, GAIN_BOUND)
    kd = 2.0 * DAMPING_RATIO * math.sqrt(kp * inertia)
    if implicit:
        kd = max(kd, kp * dt)
    return JointGains(_significant(kp), _significant(min(kd, GAIN_BOUND)), "; ".join(notes))


def control_lines(
    model: mujoco.MjModel, joints: Sequence[tuple[int, str]], efforts: Sequence[float | None]
) -> list[str]:
    """The ``control`` block of a draft: a ``torque_pd`` law with the gains of each
    ``(joint id, manifest name)`` in ``joints``, whose motors give ``efforts``."""
    inertia = inertia_diagonal(model)
    gains = [
        joint_gains(model, jid, float(inertia[model.jnt_dofadr[jid]]), effort)
        for (jid, _), effort in zip(joints, efforts, strict=True)
    ]
    lines = [
        "  control:",
        "    mode: torque_pd",
        f"    # kp = M_ii wn^2, kd = 2 M_ii wn (wn = {BANDWIDTH_RAD_S:.3g} rad/s) at the start",
        "    # pose, bounded by friction, the physics step and the motor (scaffold_gains)",
    ]
    for name in ("kp", "kd"):
        lines.append(f"    {name}:{REVIEW} from the model's inertia; tune on the real robot")
        for (_, joint), gain in zip(joints, gains, strict=True):
            note = f"  # {gain.note}" if gain.note and name == "kp" else ""
            lines.append(f"      {scalar(joint)}: {num(getattr(gain, name))}{note}")
    return lines


def _significant(value: float) -> float:
    """``value`` rounded to :data:`SIGNIFICANT_DIGITS` significant digits (0 stays 0)."""
    if value <= 0.0:
        return 0.0
    return round(value, SIGNIFICANT_DIGITS - 1 - math.floor(math.log10(value)))
