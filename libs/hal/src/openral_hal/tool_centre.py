"""The end-effector command of a simulated HAL: its tool centre point and the one IK.

One place finds it for every consumer (the gymnasium env, episodes, ``sim run`` and deploy
sim's ``/openral/ee_target``), so an end-effector action means the same thing everywhere.
"""

from __future__ import annotations

from openral_core.loaded import LoadedRobot
from openral_sim.ee_modes import EeCommand
from openral_sim.end_effector import EndEffector
from openral_sim.rollout import SceneRollout

from openral_hal.sim_attached import SimAttachedHAL


def ee_command(hal: SimAttachedHAL, robot: LoadedRobot) -> EeCommand | None:
    """The TCP of ``robot`` in the HAL's native scene (None: not a native scene, not
    connected, or the manifest declares no ``sim.tcp``).

    Raises:
        HalError: The manifest declares a TCP the scene's model cannot place (a missing
            ``sim.tcp`` frame or a body of ``sim.ik_collision_pairs``; the message says which).
    """
    scene = hal.env if isinstance(hal.env, SceneRollout) else None
    handles = hal.mujoco_handles()
    wiring = robot.tables.hal_wiring
    if scene is None or handles is None or wiring is None or wiring.tcp is None:
        return None
    ee = EndEffector(handles[0], scene.addresses, robot)
    return EeCommand(ee, scene.frames(), hal.control_period_s)
