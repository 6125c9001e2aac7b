"""A real robot's model posed at its measured joints: where its frames are.

The robot's MuJoCo model is never stepped: each reading puts its joints at the angles the
driver measured and only its kinematics are computed, so ``/tf``, ``/robot_description``
and the frame ids of a real robot come from the same model and the same code as a
simulated one's (:func:`~openral_sim.frame_tree.scene_frame_tree`). A real HAL serves it
through :class:`~openral_hal.protocol.FramesHal`.

With a scene (``deploy real --twin SCENE``) the model is the scene's (the robot on its
pedestal at its table, the scene's cameras): its cameras render the measured pose, its
frames include theirs, and :class:`~openral_real.twin_contacts.TwinContacts` screens
commands against its fixed geometry. The scene's objects stay where its seed put them.
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import DeployScene
from openral_hal.errors import ConfigurationError, HalError
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model
from openral_mujoco.robot_addresses import RobotAddresses, locate_robot
from openral_mujoco.state import FloatArray
from openral_sim.frame_tree import FrameTree, scene_frame_tree
from openral_sim.rollout import SceneRollout, SensorSuite
from openral_sim.scene import build_scene

from openral_real.twin_contacts import TwinContacts


class KinematicTwin:
    """The robot's model, or its scene's, at its measured joint angles (see the module doc)."""

    def __init__(self, robot: LoadedRobot, scene: DeployScene | None = None) -> None:
        """Compile the robot's model, or build ``scene`` for it (placed by its seed).

        Raises:
            HalError: The robot has no ``sim`` block, or its wiring does not fit its model.
            ConfigurationError: ``scene`` is not a native scene.
            ManifestError: The model does not load, or the scene is for another robot
                (located).
        """
        wiring = robot.tables.hal_wiring
        if wiring is None:
            raise HalError(f"{robot.name} has no sim block: no model to publish its frames from")
        self.robot = robot
        self.scene: SceneRollout | None = None
        if scene is None:
            model = compile_robot_model(
                robot.description, robot_model_file(robot.description, robot.folder)
            )
            addresses = locate_robot(wiring, model, model)
            self.model, self.data = model, mujoco.MjData(model)
        else:
            self.scene = _scene_of(scene, robot)
            handles = self.scene.mujoco_handles()
            if handles is None:  # never for a native scene
                raise ConfigurationError(f"the twin scene {scene.scene.id} has no MuJoCo model")
            self.model, self.data = handles
            addresses = self.scene.addresses
        self.addresses: RobotAddresses = addresses
        """Where the robot's joints, bodies and actuators sit in :attr:`model`."""
        self._qpos = np.array(addresses.qpos, dtype=np.intp)
        self._fingers: list[tuple[int, list[int]]] = []
        """(slot, the other fingers' qpos addresses) of each gripper: they follow the first."""
        for gripper in addresses.grippers:
            self._qpos[gripper.slot] = gripper.finger_qpos[0]
            self._fingers.append((gripper.slot, [int(a) for a in gripper.finger_qpos[1:]]))
        joints = _joints_at(self.model, self._qpos)
        self._dof = np.array([int(self.model.jnt_dofadr[j]) for j in joints])
        self.contacts: TwinContacts | None = None
        """The scene's contact screen (None: no scene, nothing to touch)."""
        if self.scene is not None:
            grippers = [g.slot for g in addresses.grippers]
            self.contacts = TwinContacts(self.model, joints, grippers)
        self.posed: FloatArray | None = None
        """The joint angles of the last :meth:`pose` (None: never posed)."""
        self._tree: FrameTree | None = None

    @property
    def sensors(self) -> SensorSuite | None:
        """The scene's sensors (cameras render the posed robot); None without a scene."""
        return self.scene.sensors if self.scene is not None else None

    def pose(
        self, angles: FloatArray, rates: FloatArray, efforts: FloatArray, time_s: float
    ) -> None:
        """Put every joint at ``angles`` [rad or m; a gripper's fingers all at its joint's
        position], moving at ``rates`` [rad/s or m/s] and pushing with ``efforts`` [N m or
        N], as of ``time_s`` [s, system clock]."""
        model, data = self.model, self.data
        self.set_joints(data, angles)
        data.qvel[self._dof] = rates
        data.qfrc_actuator[self._dof] = efforts
        data.time = time_s
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_camlight(model, data)  # where the scene's cameras look from
        self.posed = np.array(angles, dtype=np.float64)

    def set_joints(self, data: mujoco.MjData, angles: FloatArray) -> None:
        """Write ``angles`` (one per manifest joint) into ``data``'s joint positions."""
        data.qpos[self._qpos] = angles
        for slot, others in self._fingers:
            data.qpos[others] = angles[slot]

    def first_contact(self, rows: FloatArray) -> str | None:
        """Where the joint path through ``rows`` (one row of manifest joint values per
        point, from the posed joints) first touches the scene's fixed geometry, as one
        line naming the pair; None: nowhere, or no scene, or not posed yet."""
        if self.contacts is None or self.posed is None:
            return None
        return self.contacts.first(self.data, self.posed, rows, self.set_joints)

    def frame_tree(self) -> FrameTree:
        """The robot's frames (and its scene's cameras'), laid out once.

        Raises:
            HalError: The model's layout cannot be stated as a tree.
        """
        if self._tree is None:
            if self.scene is not None:
                self._tree = self.scene.frames()
            else:
                self._tree = scene_frame_tree(self.model, self.robot, self.addresses, {}, None)
        return self._tree


def twin_for(robot: LoadedRobot, scene: DeployScene | None) -> KinematicTwin | None:
    """The twin of a real HAL: the robot's model (None without a sim block), or ``scene``.

    Raises:
        ConfigurationError: A scene for a robot without a sim block. See
            :class:`KinematicTwin` for the rest.
    """
    if robot.tables.hal_wiring is None:
        if scene is not None:
            raise ConfigurationError(
                f"{robot.name} has no sim block: its manifest cannot pose it in a twin scene"
            )
        return None
    return KinematicTwin(robot, scene)


def _scene_of(scene: DeployScene, robot: LoadedRobot) -> SceneRollout:
    """``scene`` built for ``robot``, reset once (never stepped)."""
    built = build_scene(scene, robot, render_observations=False)
    if not isinstance(built, SceneRollout):
        built.close()
        raise ConfigurationError(
            f"the twin needs a native scene; {scene.scene.id} is a "
            f"{scene.scene.backend.value} scene"
        )
    built.reset(scene.seed)
    return built


def _joints_at(model: mujoco.MjModel, qpos: npt.NDArray[np.intp]) -> list[int]:
    """The model's joint at each qpos address."""
    starts = {int(address): j for j, address in enumerate(model.jnt_qposadr)}
    return [starts[int(address)] for address in qpos]
