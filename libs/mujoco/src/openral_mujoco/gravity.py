"""Gravity compensation of a robot's model (``sim.gravity_compensation``), inside MuJoCo.

A torque-controlled arm's controller cancels gravity before its joint servo acts; MuJoCo
(>= 3.0) does the same at every physics step when a body has ``gravcomp`` 1 (an upward
force equal to its weight at its centre of mass) and its joints have ``actuatorgravcomp``
(that force is delivered through the joints' actuators, in ``qfrc_actuator``, instead of as a
passive buoyancy). The compensation is exact in every pose, and no Python runs per step.

``gravcomp`` gates a pass of MuJoCo's forward dynamics that is compiled in or out (the
model's ``ngravcomp``), so it must be set in the spec, before compiling: the robot's own
model (:func:`openral_mujoco.model_check.compile_robot_model`) and a scene composed around
it both apply :func:`apply_gravity_compensation` to the robot's spec
(:func:`openral_mujoco.robot_edits.edit_robot_spec`).
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.models import RobotDescription
from openral_core.tables import joint_name_map

from openral_mujoco.errors import HalError

_SCALAR_JOINTS = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)


def apply_gravity_compensation(spec: mujoco.MjSpec, robot: RobotDescription) -> mujoco.MjSpec:
    """``spec`` (the robot's own model), its gravity compensated if the manifest asks for
    it (see the module doc); unchanged otherwise.

    The robot is every tree under a world child that carries one of its manifest joints (as
    :func:`~openral_mujoco.robot_bodies.robot_bodies` says; not a table or a prop its file
    brings). Each body there gets ``gravcomp`` 1 and each hinge and slide joint
    ``actuatorgravcomp``; a body at or below a free joint (a loose object, a floating base)
    is left as it is, so it never floats.
    """
    if robot.sim is None or not robot.sim.gravity_compensation:
        return spec
    manifest_joints = set(joint_name_map(robot).values())
    for tree in spec.worldbody.bodies:
        joints = {joint.name for joint in tree.find_all(mujoco.mjtObj.mjOBJ_JOINT)}
        if joints & manifest_joints:
            _compensate(tree)
    return spec


def _compensate(body: mujoco.MjsBody) -> None:
    """``body`` and the bodies below it, down to any free joint."""
    if any(joint.type == mujoco.mjtJoint.mjJNT_FREE for joint in body.joints):
        return  # a loose body and everything it carries keep their weight
    body.gravcomp = 1.0
    for joint in body.joints:
        if joint.type in _SCALAR_JOINTS:
            joint.actgravcomp = True
    for child in body.bodies:
        _compensate(child)


def require_gravity_compensation(model: mujoco.MjModel, dofs: npt.NDArray[np.intp]) -> None:
    """Refuse ``model`` for a manifest with ``sim.gravity_compensation`` when a joint of
    ``dofs`` is not compensated (not ``actuatorgravcomp``, or its body without ``gravcomp``:
    a model compiled without :func:`apply_gravity_compensation`; the arm would sag).

    Raises:
        HalError: One line naming the joints.
    """
    joints = model.dof_jntid[dofs]
    compensated = (model.jnt_actgravcomp[joints] != 0) & (
        model.body_gravcomp[model.jnt_bodyid[joints]] > 0
    )
    if model.ngravcomp == 0:
        compensated[:] = False
    missing = [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, int(j)) or f"joint {int(j)}"
        for j in joints[~compensated]
    ]
    if missing:
        raise HalError(
            "sim.gravity_compensation is true, but the model does not compensate gravity at "
            f"{', '.join(missing)}; compile the robot's spec through "
            "openral_mujoco.gravity.apply_gravity_compensation"
        )
