"""A real robot's model posed at its measured joints: where its frames are.

The robot's own MuJoCo model (alone, never stepped: only its kinematics are computed) is
put at the joint angles the driver measured, so ``/tf``, ``/robot_description`` and the
frame ids of a real robot come from the same model and the same code as a simulated one's
(:func:`~openral_sim.frame_tree.scene_frame_tree`). A real HAL serves it through
:class:`~openral_hal.protocol.FramesHal`.
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_hal.errors import HalError
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model
from openral_mujoco.robot_addresses import locate_robot
from openral_mujoco.state import FloatArray
from openral_sim.frame_tree import FrameTree, scene_frame_tree


class KinematicTwin:
    """The robot's model at its measured joint angles (see the module doc)."""

    def __init__(self, robot: LoadedRobot) -> None:
        """Compile the robot's model.

        Raises:
            HalError: The robot has no ``sim`` block, or its wiring does not fit its model.
            ManifestError: The model does not load (located).
        """
        wiring = robot.tables.hal_wiring
        if wiring is None:
            raise HalError(f"{robot.name} has no sim block: no model to publish its frames from")
        self.robot = robot
        self.model = compile_robot_model(
            robot.description, robot_model_file(robot.description, robot.folder)
        )
        self.data = mujoco.MjData(self.model)
        addresses = locate_robot(wiring, self.model, self.model)
        self._qpos = np.array([wiring.joint_qpos_addr[name] for name in wiring.joint_names])
        fingers = {g.joint: g.qpos_addrs for g in wiring.grippers}
        self._fingers: list[tuple[int, list[int]]] = []
        """(slot, the other fingers' qpos addresses) of each gripper: they follow the first."""
        for slot, name in enumerate(wiring.joint_names):
            if name in fingers:
                self._qpos[slot] = fingers[name][0]
                self._fingers.append((slot, list(fingers[name][1:])))
        self._dof = np.array([int(self.model.jnt_dofadr[j]) for j in self._joints_at(self._qpos)])
        self.addresses = addresses
        """Where the robot's joints, bodies and actuators sit in :attr:`model`."""
        self._tree: FrameTree | None = None

    def pose(
        self, angles: FloatArray, rates: FloatArray, efforts: FloatArray, time_s: float
    ) -> None:
        """Put every joint at ``angles`` [rad or m; a gripper's fingers all at its joint's
        position], moving at ``rates`` [rad/s or m/s] and pushing with ``efforts`` [N m or
        N], as of ``time_s`` [s, system clock]."""
        data = self.data
        data.qpos[self._qpos] = angles
        for slot, others in self._fingers:
            data.qpos[others] = angles[slot]
        data.qvel[self._dof] = rates
        data.qfrc_actuator[self._dof] = efforts
        data.time = time_s
        mujoco.mj_kinematics(self.model, data)

    def _joints_at(self, qpos: npt.NDArray[np.int64]) -> list[int]:
        """The model's joint at each qpos address."""
        starts = {int(address): j for j, address in enumerate(self.model.jnt_qposadr)}
        return [starts[int(address)] for address in qpos]

    def frame_tree(self) -> FrameTree:
        """The robot's frames in its model, laid out once.

        Raises:
            HalError: The model's layout cannot be stated as a tree.
        """
        if self._tree is None:
            self._tree = scene_frame_tree(self.model, self.robot, self.addresses, {}, None)
        return self._tree
