"""The sensor streams ``openral deploy sim`` publishes for a scene, as the benchmarks watch
them: each topic with its message class and nominal rate, from the scene and its manifest.

- an RGB sensor the scene lists: its image, at the ``--camera-rate`` the bench passes;
- a depth sensor the scene lists: its depth image and its cloud, at the sensor's rate;
- every lidar: its scan (``/scan``, or ``/scan/<name>`` with several), at its rate;
- a mobile base: ``/odom``, at the joint-state rate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from openral_bridge.topics import ODOM, depth_image, depth_points, scan
from openral_core.loader import load_scene
from openral_core.models import DepthSensor, LidarSensor, RgbSensor
from openral_sim.scene import scene_robot

from benchmarks.deploy_launch import camera_topic

JOINT_STATE_RATE_HZ = 50.0
"""deploy sim's default /joint_states (and /odom) rate [Hz]."""


@dataclass(frozen=True)
class Stream:
    """One watched topic: its name, message class and nominal rate [Hz]."""

    topic: str
    kind: type[Any]
    rate_hz: float


def sensor_streams(scene_file: Path, camera_rate_hz: float) -> list[Stream]:
    """Every sensor stream of ``scene_file`` (see the module doc), in manifest order."""
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Image, LaserScan, PointCloud2

    scene = load_scene(scene_file)
    robot = scene_robot(scene)
    listed = set(scene.scene.cameras)
    lidars = [s for s in robot.description.sensors if isinstance(s, LidarSensor)]
    streams = []
    for sensor in robot.description.sensors:
        if isinstance(sensor, RgbSensor) and sensor.name in listed:
            streams.append(Stream(camera_topic(sensor.name), Image, camera_rate_hz))
        elif isinstance(sensor, DepthSensor) and sensor.name in listed:
            streams.append(Stream(depth_image(sensor.name), Image, sensor.rate_hz))
            streams.append(Stream(depth_points(sensor.name), PointCloud2, sensor.rate_hz))
        elif isinstance(sensor, LidarSensor):
            topic = scan(sensor.name, len(lidars) == 1)
            streams.append(Stream(topic, LaserScan, sensor.rate_hz))
    if robot.description.mobile_base is not None:
        streams.append(Stream(ODOM, Odometry, JOINT_STATE_RATE_HZ))
    return streams
