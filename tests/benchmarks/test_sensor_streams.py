"""The streams bench-deploy watches follow the scene and its manifest."""

from __future__ import annotations

from benchmarks.sensor_streams import JOINT_STATE_RATE_HZ, sensor_streams
from tests.conftest import ROBOTS


def test_the_franka_tabletop_has_two_cameras_at_the_benchs_rate_and_its_depth_camera() -> None:
    streams = sensor_streams(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml", 12.0)
    assert [(s.topic, s.kind.__name__, s.rate_hz) for s in streams] == [
        ("/openral/cameras/agentview/image", "Image", 12.0),
        ("/openral/cameras/wrist/image", "Image", 12.0),
        ("/openral/cameras/front_depth/depth", "Image", 5.0),
        ("/openral/cameras/front_depth/points", "PointCloud2", 5.0),
    ]


def test_the_room_adds_depth_cloud_scan_and_odometry_at_their_own_rates() -> None:
    streams = sensor_streams(ROBOTS / "panda_mobile" / "scenes" / "room.yaml", 12.0)
    assert [(s.topic, s.kind.__name__, s.rate_hz) for s in streams] == [
        ("/openral/cameras/head_depth/depth", "Image", 5.0),
        ("/openral/cameras/head_depth/points", "PointCloud2", 5.0),
        ("/openral/cameras/wrist/image", "Image", 12.0),
        ("/scan", "LaserScan", 10.0),
        ("/odom", "Odometry", JOINT_STATE_RATE_HZ),
    ]
