"""The range sensors of a native scene: its depth cameras and its lidars.

Which of the manifest's sensors a scene serves:

- a :class:`~openral_core.models.DepthSensor` when the scene file names it among its
  ``cameras`` (it is placed like any camera; see :mod:`openral_sim.scene_cameras`);
- every :class:`~openral_core.models.LidarSensor` of the manifest (a lidar needs no
  placement beyond its site, which the robot's model or the scene provides).

Both leave the robot out (:func:`~openral_sim.scene_geometry.robot_bodies`): the depth
cloud by segmentation and a margin (:mod:`openral_sim.depth_cloud`), the lidar by casting
against a copy of the model without the robot (:mod:`openral_sim.lidar_scan`).
"""

from __future__ import annotations

import mujoco
from openral_core.located import error_at
from openral_core.models import DepthSensor, LidarSensor, RobotDescription

from openral_sim.depth_cloud import DepthCamera, DepthFrame
from openral_sim.gl_guard import close_renderer, open_renderer
from openral_sim.lidar_scan import LidarScanner, Ranges


class RangeSensors:
    """Depth cameras and lidars of one composed scene, by sensor name."""

    def __init__(
        self,
        model: mujoco.MjModel,
        robot: RobotDescription,
        cameras: dict[str, str],
        robot_bodies: frozenset[int],
        base_body: int,
    ) -> None:
        """Set up every depth camera in ``cameras`` (sensor → MJCF camera) and every lidar.

        Raises:
            ManifestError: At a lidar's ``site`` when the composed scene has no such site.
        """
        self.model = model
        self.depth: dict[str, DepthCamera] = {}
        self.lidars: dict[str, LidarScanner] = {}
        for index, sensor in enumerate(robot.sensors):
            if isinstance(sensor, DepthSensor) and sensor.name in cameras:
                camera = cameras[sensor.name]
                self.depth[sensor.name] = DepthCamera(
                    model, sensor, camera, robot_bodies, base_body
                )
            elif isinstance(sensor, LidarSensor):
                try:
                    self.lidars[sensor.name] = LidarScanner(model, sensor, robot_bodies)
                except ValueError as error:
                    raise error_at(robot, ("sensors", index, "site"), str(error)) from None
        self._renderers: dict[str, mujoco.Renderer] = {}

    def depth_frame(
        self, name: str, data: mujoco.MjData, renderer: mujoco.Renderer | None = None
    ) -> DepthFrame:
        """Depth image and self-filtered cloud of depth sensor ``name`` as ``data`` places
        the scene (read only; kinematics current, as after ``mj_step`` or
        ``mj_kinematics`` + ``mj_camlight``).

        Args:
            name: A key of :attr:`depth`.
            data: MjData of the scene's model.
            renderer: A renderer of the model at the sensor's (height, width), created on
                the calling thread; None uses this object's own for the sensor (made on
                first use, on the thread that first uses it).

        Raises:
            KeyError: A depth sensor the scene does not serve.
        """
        camera = self.depth[name]
        if renderer is None:
            renderer = self._renderers.get(name)
            if renderer is None:
                renderer = open_renderer(self.model, camera.height, camera.width)
                self._renderers[name] = renderer
        return camera.frame(renderer, data)

    def scan(self, name: str, data: mujoco.MjData) -> Ranges:
        """Ranges [m] of lidar ``name`` as ``data`` places the scene (REP 117 ±inf). Uses
        ``data``'s scratch memory: never while another thread steps the same data.

        Raises:
            KeyError: A lidar the manifest does not have.
        """
        return self.lidars[name].scan(data)

    def close(self) -> None:
        """Free the depth renderers."""
        for renderer in self._renderers.values():
            close_renderer(renderer)
        self._renderers.clear()
