"""The sensors of a scene a HAL is attached to, served as the HAL's own.

:class:`AttachedSensors` (a mixin of :class:`~openral_hal.sim_attached.SimAttachedHAL`)
implements the sensor Protocols of :mod:`openral_sim.sensor_sources` by handing each call
to the scene's :class:`~openral_sim.rollout.SensorSuite`; a backend that serves none
(robosuite renders inside its own step) serves no sensor through them, and its camera
frames come with its observations instead.
"""

from __future__ import annotations

from collections.abc import Mapping

from openral_core.models import RgbSensor
from openral_sim.depth_cloud import DepthFrame
from openral_sim.observation import ImageArray, LidarScan
from openral_sim.rollout import SensorSuite
from openral_sim.sensor_sources import DepthSpec, FrameCapture, LidarSpec, StateSpec
from openral_sim.state_sensors import Reading

from openral_hal.errors import ConfigurationError


class AttachedSensors:
    """Sensor sources delegated to ``_suite`` (None: the scene serves none)."""

    _suite: SensorSuite | None = None

    def camera_sensors(self) -> Mapping[str, RgbSensor]:
        """The RGB sensors the scene renders off its step (empty: none)."""
        return {} if self._suite is None else self._suite.camera_sensors()

    def camera_size(self) -> tuple[int, int]:
        """(height, width) of every camera frame [px]."""
        return self._served().camera_size()

    def camera_capture(
        self, out: Mapping[str, ImageArray] | None = None
    ) -> FrameCapture[ImageArray]:
        """A capture of every camera (see :class:`~openral_sim.sensor_sources.CameraSource`)."""
        return self._served().camera_capture(out)

    def depth_sensors(self) -> Mapping[str, DepthSpec]:
        """The depth sensors the scene serves (empty: none)."""
        return {} if self._suite is None else self._suite.depth_sensors()

    def depth_capture(self, name: str) -> FrameCapture[DepthFrame]:
        """A capture of depth sensor ``name``."""
        return self._served().depth_capture(name)

    def lidar_sensors(self) -> Mapping[str, LidarSpec]:
        """The lidars the scene serves (empty: none)."""
        return {} if self._suite is None else self._suite.lidar_sensors()

    def scan(self, name: str) -> LidarScan:
        """One scan of lidar ``name`` now."""
        return self._served().scan(name)

    def state_sensors(self) -> Mapping[str, StateSpec]:
        """The IMU, force-torque and pose sensors the scene serves (empty: none)."""
        return {} if self._suite is None else self._suite.state_sensors()

    def read_sensor(self, name: str) -> Reading:
        """The reading of state sensor ``name`` now."""
        return self._served().read_sensor(name)

    def _served(self) -> SensorSuite:
        if self._suite is None:
            raise ConfigurationError("this scene serves no sensor outside its observations")
        return self._suite
