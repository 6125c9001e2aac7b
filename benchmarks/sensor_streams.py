"""The sensor streams ``openral deploy sim`` publishes for a scene, as the benchmarks watch
them: each topic with its message class and nominal rate, from the scene and its manifest.

- an RGB sensor the scene lists: its image;
- a depth sensor the scene lists: its depth image and its cloud;
- every lidar: its scan (``/scan``, or ``/scan/<name>`` with several);
- a mobile base: ``/odom``, at the joint-state rate.

Sensor rates follow deploy sim's one rule (:func:`~openral_sim.sensor_schedule.sensor_rates`):
the ``--camera-rate`` the bench passes, if any, sets every RGB camera, depth camera and lidar
alike, capped at the scene's control rate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from openral_bridge.topics import ODOM, depth_image, depth_points, scan
from openral_core.loader import load_scene
from openral_core.models import DepthSensor, LidarSensor, RgbSensor
from openral_sim.scene import scene_robot
from openral_sim.sensor_schedule import sensor_rates

from benchmarks.deploy_launch import camera_topic

JOINT_STATE_RATE_HZ = 100.0
"""deploy sim's default /joint_states (and /odom) rate [Hz]: the state rate."""


@dataclass(frozen=True)
class Stream:
    """One watched topic: its name, message class and nominal rate [Hz]."""

    topic: str
    kind: type[Any]
    rate_hz: float


def sensor_streams(scene_file: Path, camera_rate_hz: float | None) -> list[Stream]:
    """Every sensor stream of ``scene_file`` (see the module doc), in manifest order
    (``camera_rate_hz`` None: no ``--camera-rate``, each sensor at its own rate)."""
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Image, LaserScan, PointCloud2

    scene = load_scene(scene_file)
    robot = scene_robot(scene)
    listed = set(scene.scene.cameras)
    options = scene.scene.options
    control_hz = options.control_freq_hz if options and options.control_freq_hz else 20.0
    rates = sensor_rates(robot.description, control_hz, frame_rate_hz=camera_rate_hz)
    lidars = [s for s in robot.description.sensors if isinstance(s, LidarSensor)]
    streams = []
    for sensor in robot.description.sensors:
        if isinstance(sensor, RgbSensor) and sensor.name in listed:
            streams.append(Stream(camera_topic(sensor.name), Image, rates[sensor.name]))
        elif isinstance(sensor, DepthSensor) and sensor.name in listed:
            streams.append(Stream(depth_image(sensor.name), Image, rates[sensor.name]))
            streams.append(Stream(depth_points(sensor.name), PointCloud2, rates[sensor.name]))
        elif isinstance(sensor, LidarSensor):
            topic = scan(sensor.name, len(lidars) == 1)
            streams.append(Stream(topic, LaserScan, rates[sensor.name]))
    if robot.description.mobile_base is not None:
        streams.append(Stream(ODOM, Odometry, JOINT_STATE_RATE_HZ))
    return streams
