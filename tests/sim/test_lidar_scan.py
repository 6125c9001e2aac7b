"""Planar lidar scans (openral_sim.lidar_scan) against a small scene of known geometry.

The lidar's site sits at the centre of the robot's torso sphere (radius 0.1 m), on a body
that yaws about z. The robot's arm, a 10 cm box, reaches 0.95 to 1.05 m along the site's x
axis; a static wall's near face is 2.000 m ahead along x, 0.6 m wide, so it fills the rays
within 8.5 deg of the centre ray and nothing else is in the scene.
"""

from __future__ import annotations

import math
import time
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_core.models import LidarSensor
from openral_sim.lidar_scan import VISIBLE_GROUPS, LidarScanner, to_ranges

WALL_M = 2.0
TOL_M = 0.005

SCENE = """
<mujoco>
  <worldbody>
    <body name="robot" pos="0 0 1">
      <joint name="yaw" type="hinge" axis="0 0 1"/>
      <geom name="torso" type="sphere" size="0.1" group="2"/>
      <site name="lidar_site"/>
      <body name="arm" pos="1 0 0">
        <geom name="arm" type="box" size="0.05 0.05 0.05"/>
      </body>
    </body>
    <geom name="wall" type="box" size="0.05 0.3 0.5" pos="2.05 0 1" {wall}/>
  </worldbody>
</mujoco>
"""

CULLED = """
<mujoco>
  <worldbody>
    <body name="turned" pos="3 0 1" euler="0 0 90">
      <geom type="box" size=".1 .1 .1" pos="1 0 0"/>
      <geom name="offset_ball" type="sphere" size=".05" pos="-1 0 0"/>
    </body>
    <body name="decorated" pos="-3 0 1">
      <geom type="box" size=".05 .05 .05"/>
      <geom name="visual_ball" type="sphere" size=".2" pos="0 2 0" contype="0" conaffinity="0"/>
    </body>
    <site name="lidar_site" pos="0 0 1"/>
  </worldbody>
</mujoco>
"""
"""Bodies whose bounding volume MuJoCo 3.8's mj_multiRay culls wrongly: one turned with a
geom off its centre, one with a visual-only geom outside its collision geoms."""


def lidar(**fields: Any) -> LidarSensor:
    """The test lidar: 181 rays, one per degree from -90 to 90, 0.05 to 30 m."""
    values: dict[str, Any] = {
        "name": "lidar",
        "kind": "lidar",
        "site": "lidar_site",
        "width": 181,
        "height": 1,
        "rate_hz": 10.0,
        "frame_id": "lidar_link",
        "range_m": [0.05, 30.0],
        "angle_range_deg": [-90.0, 90.0],
    }
    return LidarSensor.model_validate(values | fields)


def scene(wall: str = "", yaw_deg: float = 0.0) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """The test scene (``wall``: extra attributes of the wall geom), the robot turned by
    ``yaw_deg`` about z."""
    model = mujoco.MjModel.from_xml_string(SCENE.format(wall=wall))
    data = mujoco.MjData(model)
    data.qpos[0] = math.radians(yaw_deg)
    mujoco.mj_forward(model, data)
    return model, data


def bodies(model: mujoco.MjModel, *names: str) -> frozenset[int]:
    return frozenset(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, n) for n in names)


def robot(model: mujoco.MjModel) -> frozenset[int]:
    return bodies(model, "robot", "arm")


def ray_angles_deg(scanner: LidarScanner) -> npt.NDArray[np.float64]:
    steps = np.arange(scanner.width, dtype=np.float64)
    return np.rad2deg(scanner.angle_min + scanner.angle_increment * steps)


def test_wall_reads_its_distance_and_the_empty_rays_read_inf() -> None:
    model, data = scene()
    scanner = LidarScanner(model, lidar(), robot(model))
    ranges = scanner.scan(data)
    angles = ray_angles_deg(scanner)
    assert ranges.dtype == np.float32 and ranges.shape == (181,)
    assert ranges[90] == pytest.approx(WALL_M, abs=TOL_M)
    on_wall = np.abs(angles) <= 8.0
    expected = WALL_M / np.cos(np.radians(angles[on_wall]))
    np.testing.assert_allclose(ranges[on_wall], expected, atol=TOL_M)
    assert np.all(np.isposinf(ranges[np.abs(angles) >= 9.0]))


@pytest.mark.parametrize(("range_m", "centre"), [([2.5, 30.0], -math.inf), ([0.05, 1.5], math.inf)])
def test_hits_outside_the_range_read_minus_inf_when_too_close_plus_inf_when_too_far(
    range_m: list[float], centre: float
) -> None:
    model, data = scene()
    ranges = LidarScanner(model, lidar(range_m=range_m), robot(model)).scan(data)
    assert ranges[90] == centre
    assert np.all(np.isposinf(ranges[:80]))


def test_a_geom_on_an_excluded_body_is_passed_through_one_on_another_body_is_seen() -> None:
    model, data = scene()
    through = LidarScanner(model, lidar(), robot(model)).scan(data)
    arm_seen = LidarScanner(model, lidar(), bodies(model, "robot")).scan(data)
    nothing_excluded = LidarScanner(model, lidar(), frozenset()).scan(data)
    assert through[90] == pytest.approx(WALL_M, abs=TOL_M)
    assert arm_seen[90] == pytest.approx(0.95, abs=TOL_M)
    assert np.all(np.isposinf(arm_seen[:80]))
    np.testing.assert_allclose(nothing_excluded, 0.1, atol=TOL_M)  # the torso, from inside


@pytest.mark.parametrize("yaw_deg", [90.0, 45.0, -30.0])
def test_the_sites_rotation_turns_the_scan(yaw_deg: float) -> None:
    model, data = scene(yaw_deg=yaw_deg)
    ranges = LidarScanner(model, lidar(), robot(model)).scan(data)
    wall_index = 90 - round(yaw_deg)  # the wall stays along world x
    assert ranges[wall_index] == pytest.approx(WALL_M, abs=TOL_M)
    assert ranges[90] == math.inf


@pytest.mark.parametrize("wall", ['group="3"', 'rgba="1 0 0 0"'])
def test_geoms_the_renderer_does_not_draw_are_not_seen(wall: str) -> None:
    model, data = scene(wall)
    ranges = LidarScanner(model, lidar(), robot(model)).scan(data)
    assert np.all(np.isposinf(ranges))


def test_visible_groups_are_mujocos_default_geom_groups() -> None:
    np.testing.assert_array_equal(VISIBLE_GROUPS, mujoco.MjvOption().geomgroup)


def test_the_scanner_leaves_the_scenes_model_as_it_was() -> None:
    model, data = scene()
    groups, bvh = model.geom_group.copy(), model.body_bvhadr.copy()
    LidarScanner(model, lidar(), robot(model)).scan(data)
    np.testing.assert_array_equal(model.geom_group, groups)
    np.testing.assert_array_equal(model.body_bvhadr, bvh)


def test_scans_agree_with_mj_ray_where_mj_multirays_culling_would_miss_hits() -> None:
    model = mujoco.MjModel.from_xml_string(CULLED)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scanner = LidarScanner(model, lidar(width=1440, angle_range_deg=[-180.0, 179.75]), ())
    ranges = scanner.scan(data)
    origin = data.site_xpos[scanner.site_id]
    geom = np.zeros(1, dtype=np.int32)
    dist, seen = np.empty(scanner.width), set()
    for i, direction in enumerate(scanner.directions):  # the site is not turned
        dist[i] = mujoco.mj_ray(model, data, origin, direction, VISIBLE_GROUPS, True, -1, geom)
        seen.add(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, int(geom[0])))
    assert {"offset_ball", "visual_ball"} <= seen
    np.testing.assert_allclose(ranges, to_ranges(dist, 0.05, 30.0), rtol=0, atol=1e-6)


def test_angles_follow_angle_range_deg_and_width() -> None:
    model, _ = scene()
    scanner = LidarScanner(model, lidar(width=271, angle_range_deg=[-135.0, 135.0]), ())
    assert scanner.angle_min == pytest.approx(math.radians(-135.0))
    assert scanner.angle_max == pytest.approx(math.radians(135.0))
    assert scanner.angle_increment == pytest.approx(math.radians(1.0))
    last = scanner.angle_min + (scanner.width - 1) * scanner.angle_increment
    assert last == pytest.approx(scanner.angle_max)
    assert (scanner.range_min, scanner.range_max) == (0.05, 30.0)


@pytest.mark.parametrize(("first_deg", "reading"), [(0.0, WALL_M), (-45.0, math.inf)])
def test_a_single_ray_points_at_the_first_angle(first_deg: float, reading: float) -> None:
    model, data = scene()
    sensor = lidar(width=1, angle_range_deg=[first_deg, first_deg + 90.0])
    scanner = LidarScanner(model, sensor, robot(model))
    assert scanner.angle_min == scanner.angle_max == pytest.approx(math.radians(first_deg))
    assert scanner.angle_increment == 0.0
    ranges = scanner.scan(data)
    assert ranges.shape == (1,)
    assert ranges[0] == pytest.approx(reading, abs=TOL_M)


def test_a_missing_site_is_a_one_line_error_naming_sensor_and_site() -> None:
    model, _ = scene()
    message = r"^lidar sensor 'lidar': the scene has no site 'nowhere'$"
    with pytest.raises(ValueError, match=message):
        LidarScanner(model, lidar(site="nowhere"), ())


def test_data_of_another_model_is_refused() -> None:
    model, _ = scene()
    other = mujoco.MjModel.from_xml_string(CULLED)
    scanner = LidarScanner(model, lidar(), ())
    with pytest.raises(ValueError, match="data has 4 geoms, the scene 3"):
        scanner.scan(mujoco.MjData(other))


@pytest.mark.parametrize("width", [180, 1024])
def test_scan_time(width: int) -> None:
    model, data = scene()
    scanner = LidarScanner(model, lidar(width=width), robot(model))
    scanner.scan(data)
    runs = 200
    start = time.perf_counter()
    for _ in range(runs):
        ranges = scanner.scan(data)
    elapsed_ms = (time.perf_counter() - start) / runs * 1e3
    print(f"\n{width}-ray scan: {elapsed_ms:.3f} ms")
    assert float(np.min(ranges)) == pytest.approx(WALL_M, abs=TOL_M)
