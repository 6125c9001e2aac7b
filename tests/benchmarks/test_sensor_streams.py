"""The streams bench-deploy watches follow the scene, its manifest and deploy sim's one rate
rule: ``--camera-rate`` sets RGB, depth and lidar alike, capped at the control rate."""

from __future__ import annotations

from benchmarks.sensor_streams import JOINT_STATE_RATE_HZ, sensor_streams
from tests.conftest import ROBOTS


def test_the_franka_tabletop_has_two_cameras_and_its_depth_camera_at_the_benchs_rate() -> None:
    streams = sensor_streams(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml", 12.0)
    assert [(s.topic, s.kind.__name__, s.rate_hz) for s in streams] == [
        ("/openral/cameras/agentview/image", "Image", 12.0),
        ("/openral/cameras/wrist/image", "Image", 12.0),
        ("/openral/cameras/front_depth/depth", "Image", 12.0),
        ("/openral/cameras/front_depth/points", "PointCloud2", 12.0),
    ]
    own = sensor_streams(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml", None)
    assert [s.rate_hz for s in own] == [10.0, 10.0, 5.0, 5.0]  # no override: the manifest's


def test_the_room_adds_depth_cloud_scan_and_odometry() -> None:
    streams = sensor_streams(ROBOTS / "panda_mobile" / "scenes" / "room.yaml", 12.0)
    assert [(s.topic, s.kind.__name__, s.rate_hz) for s in streams] == [
        ("/openral/cameras/head_depth/depth", "Image", 12.0),
        ("/openral/cameras/head_depth/points", "PointCloud2", 12.0),
        ("/openral/cameras/wrist/image", "Image", 12.0),
        ("/scan", "LaserScan", 12.0),
        ("/odom", "Odometry", JOINT_STATE_RATE_HZ),
    ]
    capped = sensor_streams(ROBOTS / "panda_mobile" / "scenes" / "room.yaml", 60.0)
    assert [s.rate_hz for s in capped[:4]] == [20.0] * 4  # the room's control rate
