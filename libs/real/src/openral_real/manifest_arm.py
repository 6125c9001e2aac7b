"""What every real arm HAL of the manifest shares: its names, its period, its motion
envelope, and the rule that refuses an all-zero action (one place for both drivers, Feetech
and ros2_control)."""

from __future__ import annotations

import sys
from collections.abc import Mapping

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.models import LimitedJoint, RobotDescription
from openral_core.real_wiring import RealWiring
from openral_hal.attached_sensors import AttachedSensors
from openral_hal.errors import ActionRejected
from openral_hal.protocol import EStopLatch
from openral_hal.realtime import SWITCH_INTERVAL_S
from openral_mujoco.state import FloatArray
from openral_sim.frame_tree import FrameTree
from openral_sim.sensor_sources import StateSpec

from openral_real.kinematic_twin import KinematicTwin
from openral_real.motion_envelope import MotionEnvelope

__all__ = ["SWITCH_INTERVAL_S", "ManifestArm"]


class ManifestArm(AttachedSensors, EStopLatch):
    """A real arm driven through the manifest: one action slot per joint (a mixin; the HAL
    sets :attr:`robot` and :attr:`real`). With a twin scene it serves the scene's sensors,
    rendered at the measured pose (:meth:`attach_twin`)."""

    robot: LoadedRobot
    real: RealWiring
    _twin: KinematicTwin | None

    @property
    def description(self) -> RobotDescription:
        """The manifest this HAL drives."""
        return self.robot.description

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Canonical joint names in manifest order."""
        return tuple(joint.name for joint in self.robot.description.joints)

    @property
    def action_names(self) -> tuple[str, ...]:
        """One action slot per manifest joint (a gripper in its write mode)."""
        return self.joint_names

    @property
    def control_period_s(self) -> float:
        """One read-and-write cycle of the driver [s]."""
        return self.real.control_period_s

    def quicker_switches(self, on: bool) -> None:
        """Shorten Python's thread switch interval to :data:`SWITCH_INTERVAL_S` (``on``, at
        connect) or put back the one found then (at disconnect; idempotent)."""
        previous: float | None = getattr(self, "_switch_before", None)
        if on and previous is None:
            self._switch_before: float | None = sys.getswitchinterval()
            sys.setswitchinterval(min(sys.getswitchinterval(), SWITCH_INTERVAL_S))
        elif not on and previous is not None:
            sys.setswitchinterval(previous)
            self._switch_before = None

    def attach_twin(self, twin: KinematicTwin | None) -> None:
        """Make ``twin`` the HAL's model (its scene's sensors the HAL's own)."""
        self._twin = twin
        self._suite = twin.sensors if twin is not None else None

    def path_contact(self, rows: FloatArray) -> str | None:
        """Where the joint path from the measured pose through ``rows`` (action values,
        one row per point) first touches the twin scene's fixed geometry, in one line;
        None: nowhere, or no twin scene (see :mod:`openral_real.twin_contacts`)."""
        return self._twin.first_contact(rows) if self._twin is not None else None

    def read_images(self) -> dict[str, npt.NDArray[np.uint8]]:
        """No camera of its own (a driver with devices serves theirs)."""
        return {}

    def camera_fovy_deg(self, sensor: str) -> float | None:
        """Vertical field of view [deg] of the twin scene's camera that renders ``sensor``."""
        scene = self._twin.scene if self._twin is not None else None
        camera = scene.camera_models.get(sensor) if scene is not None else None
        if scene is None or camera is None:
            return None
        model = self._twin.model  # type: ignore[union-attr]
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        return float(model.cam_fovy[index]) if index >= 0 else None

    def state_sensors(self) -> Mapping[str, StateSpec]:
        """None: a twin is never stepped, so an IMU or force-torque reading from it would
        be made up."""
        return {}

    def frame_tree(self) -> FrameTree | None:
        """The robot's frames in its own model (None without a sim block); known before
        connecting."""
        return self._twin.frame_tree() if self._twin is not None else None

    def manifest_envelope(self) -> MotionEnvelope:
        """A new envelope of the manifest's position and velocity limits at the control
        period (a continuous joint unbounded), the first motion as slow as ``real`` says."""
        joints = self.description.joints
        low = [j.position_limits[0] if isinstance(j, LimitedJoint) else -np.inf for j in joints]
        high = [j.position_limits[1] if isinstance(j, LimitedJoint) else np.inf for j in joints]
        return MotionEnvelope(
            np.array(low, dtype=np.float64),
            np.array(high, dtype=np.float64),
            np.array([j.velocity_limit for j in joints], dtype=np.float64),
            self.control_period_s,
            self.real.first_motion_speed_scale,
        )

    def screen_action(self, values: FloatArray) -> None:
        """Refuse an all-zero action (unless the manifest allows it), any action while
        the E-stop is latched, and one whose way from the measured pose touches the twin
        scene; ``values`` already has the right width and is finite.

        Raises:
            ActionRejected: All zeros, or the way there touches the twin scene's fixed
                geometry (the pair named). EStopLatched: The E-stop is latched.
        """
        if self.real.refuse_zero_action and not np.any(values):
            raise ActionRejected(
                "an all-zero action commands every joint to 0 and the gripper shut on an "
                "absolute-position arm; zero is not hold on a real robot: send the hold "
                "action (/openral/action_spec) or the measured positions"
            )
        self._refuse_when_estopped()
        contact = self.path_contact(values)
        if contact is not None:
            raise ActionRejected(contact)
