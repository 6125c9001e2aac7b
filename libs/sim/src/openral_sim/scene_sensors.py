"""The sensors of a native scene, served through the sensor Protocols and into observations.

:class:`SceneSensors` implements :class:`~openral_sim.sensor_sources.CameraSource`,
:class:`~openral_sim.sensor_sources.DepthSource`,
:class:`~openral_sim.sensor_sources.LidarSource` and
:class:`~openral_sim.sensor_sources.StateSensorSource` on one scene's model and live data,
and fills an :class:`~openral_sim.observation.Observation` with the frames a
:class:`~openral_sim.sensor_schedule.SensorSchedule` says are due.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import mujoco
import numpy as np
from openral_core.models import RgbSensor, RobotDescription
from openral_core.tables import FrameNames

from openral_sim.depth_cloud import DepthFrame
from openral_sim.gl_guard import close_renderer, gl_turn, open_renderer
from openral_sim.mujoco_capture import MujocoCapture
from openral_sim.observation import ImageArray, LidarScan
from openral_sim.range_sensors import RangeSensors
from openral_sim.sensor_schedule import SensorSchedule, sensor_rates
from openral_sim.sensor_sources import DepthSpec, LidarSpec, StateSpec
from openral_sim.state_sensors import Reading, StateSensors


class SceneSensors:
    """RGB cameras, depth cameras, lidars and state sensors of one composed scene."""

    def __init__(
        self,
        model: mujoco.MjModel,
        data: mujoco.MjData,
        robot: RobotDescription,
        cameras: Mapping[str, str],
        ranges: RangeSensors,
        size: tuple[int, int],
        frames: FrameNames,
        cloud_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> None:
        """Args:
        model, data: The scene's model and live data.
        robot: The manifest.
        cameras: RGB sensor name → MJCF camera of ``model``.
        ranges: The scene's depth cameras and lidars.
        size: (height, width) of every RGB frame [px].
        frames: The robot's frame names (clouds in ``base``, poses in ``world``).
        cloud_offset_m: Where the robot's root body is in its base frame [m] (a mobile
            base's offset; depth clouds are moved by it).
        """
        self.model, self.data, self.robot = model, data, robot
        self.frames = frames
        self.cloud_offset = np.asarray(cloud_offset_m, dtype=np.float32)
        self.cameras = dict(cameras)
        self.ranges = ranges
        self.state = StateSensors(model, robot)
        self.size = size
        self._renderer: mujoco.Renderer | None = None
        self.schedule = SensorSchedule({})

    def names(self) -> tuple[str, ...]:
        """Every sensor served, in manifest order."""
        served = {*self.cameras, *self.ranges.depth, *self.ranges.lidars, *self.state.sensors}
        return tuple(s.name for s in self.robot.sensors if s.name in served)

    def reschedule(self, control_rate_hz: float, frame_rate_hz: float | None = None) -> None:
        """Sample every sensor at :func:`~openral_sim.sensor_schedule.sensor_rates`'s rate."""
        rates = sensor_rates(
            self.robot, control_rate_hz, frame_rate_hz=frame_rate_hz, sensors=self.names()
        )
        self.schedule = SensorSchedule(rates)

    # -- CameraSource ----------------------------------------------------------------------

    def camera_sensors(self) -> dict[str, RgbSensor]:
        """The RGB sensors the scene renders."""
        sensors = self.robot.sensors
        return {s.name: s for s in sensors if isinstance(s, RgbSensor) and s.name in self.cameras}

    def camera_size(self) -> tuple[int, int]:
        """(height, width) of every RGB frame [px]."""
        return self.size

    def camera_capture(
        self, out: Mapping[str, ImageArray] | None = None
    ) -> MujocoCapture[ImageArray]:
        """Snapshots of the live data rendered by every RGB camera (into ``out``'s buffers
        when given)."""
        cameras, buffers = self.cameras, dict(out or {})

        def render(renderer: mujoco.Renderer, data: mujoco.MjData, sensor: str) -> ImageArray:
            with gl_turn():
                renderer.update_scene(data, camera=cameras[sensor])
                return renderer.render(out=buffers.get(sensor))

        return MujocoCapture(self.model, self.data, tuple(cameras), self.size, render)

    def render(
        self,
        data: mujoco.MjData,
        sensors: Iterable[str],
        renderer: mujoco.Renderer | None = None,
    ) -> dict[str, ImageArray]:
        """Fresh frames of the RGB ``sensors`` as ``data`` places them (see
        :meth:`NativeScene.render_cameras <openral_sim.native_scene.NativeScene.render_cameras>`).

        Raises:
            KeyError: A sensor this scene does not render.
        """
        names = tuple(sensors)
        unknown = [name for name in names if name not in self.cameras]
        if unknown:
            raise KeyError(f"the scene renders no camera {unknown}; it has {tuple(self.cameras)}")
        if renderer is None and names:
            if self._renderer is None:
                self._renderer = open_renderer(self.model, *self.size)
            renderer = self._renderer
        images: dict[str, ImageArray] = {}
        for name in names:
            assert renderer is not None
            with gl_turn():
                renderer.update_scene(data, camera=self.cameras[name])
                images[name] = renderer.render().copy()
        return images

    # -- DepthSource -----------------------------------------------------------------------

    def depth_sensors(self) -> dict[str, DepthSpec]:
        """The depth sensors the scene file names."""
        base = self.frames.base
        return {
            name: DepthSpec(camera.sensor, camera.width, camera.height, camera.fovy_deg, base)
            for name, camera in self.ranges.depth.items()
        }

    def depth_capture(self, name: str) -> MujocoCapture[DepthFrame]:
        """Snapshots of the live data developed into depth frames of sensor ``name``.

        Raises:
            KeyError: A depth sensor the scene does not serve.
        """
        camera = self.ranges.depth[name]
        size = (camera.height, camera.width)

        def render(renderer: mujoco.Renderer, data: mujoco.MjData, _: str) -> DepthFrame:
            return self._in_base_frame(camera.frame(renderer, data))

        return MujocoCapture(self.model, self.data, (name,), size, render)

    def depth_frame(self, name: str) -> DepthFrame:
        """A depth frame of sensor ``name`` of the live data, cloud in the base frame."""
        return self._in_base_frame(self.ranges.depth_frame(name, self.data))

    def _in_base_frame(self, frame: DepthFrame) -> DepthFrame:
        if not self.cloud_offset.any():
            return frame
        return DepthFrame(frame.depth_m, frame.points + self.cloud_offset, frame.sim_time_s)

    # -- LidarSource -----------------------------------------------------------------------

    def lidar_sensors(self) -> dict[str, LidarSpec]:
        """Every lidar of the manifest."""
        return {
            name: LidarSpec(s.sensor, s.angle_min, s.angle_max, s.range_min, s.range_max)
            for name, s in self.ranges.lidars.items()
        }

    def scan(self, name: str) -> LidarScan:
        """One scan of lidar ``name`` of the live data (never while it is being stepped)."""
        return LidarScan(self.ranges.scan(name, self.data), float(self.data.time))

    # -- StateSensorSource -----------------------------------------------------------------

    def state_sensors(self) -> dict[str, StateSpec]:
        """Every IMU, force-torque and pose sensor of the manifest (a pose in the world
        frame, the others in their own)."""
        world = self.frames.world
        return {
            name: StateSpec(s, world if s.kind == "pose" else s.frame_id)
            for name, s in self.state.sensors.items()
        }

    def read_sensor(self, name: str) -> Reading:
        """The reading of state sensor ``name`` as the last step left the live data."""
        return self.state.read(name, self.data)

    # -- observations ----------------------------------------------------------------------

    def due_frames(
        self, wanted: frozenset[str] | None
    ) -> tuple[
        dict[str, ImageArray], dict[str, DepthFrame], dict[str, LidarScan], dict[str, Reading]
    ]:
        """(images, depth, scans, readings) of the sensors due now among ``wanted`` (None:
        all), rendered from the live data with the scene's own renderers."""
        due = self.schedule.due(float(self.data.time))
        if wanted is not None:
            due &= wanted
        cameras = [n for n in self.cameras if n in due]
        images = self.render(self.data, cameras) if cameras else {}
        depth = {n: self.depth_frame(n) for n in self.ranges.depth if n in due}
        scans = {n: self.scan(n) for n in self.ranges.lidars if n in due}
        readings = {n: self.read_sensor(n) for n in self.state.sensors if n in due}
        return images, depth, scans, readings

    def close(self) -> None:
        """Free the renderers."""
        if self._renderer is not None:
            close_renderer(self._renderer)
            self._renderer = None
        self.ranges.close()
