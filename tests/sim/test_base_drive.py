"""Tests for base_drive.py: panda_mobile's holonomic base in its room scene, driven by
velocity commands and read back by odometry (``-s`` prints the measured numbers)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import load_scene
from openral_core.loaded import open_robot_by_id
from openral_hal.errors import ConfigurationError, EStopLatched
from openral_hal.factory import build_hal
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.errors import ActionRejected
from openral_sim.base_drive import BaseCommand, BaseDrive
from openral_sim.native_scene import NativeScene

from tests.conftest import ROBOTS

ROOM = ROBOTS / "panda_mobile" / "scenes" / "room.yaml"
PERIOD_S = 0.05
"""The room's control period (20 Hz) [s]."""
DISTANCE_TOLERANCE_M = 0.05


@pytest.fixture(scope="module")
def room() -> Iterator[NativeScene]:
    scene = NativeScene(
        load_scene(ROOM), open_robot_by_id("panda_mobile"), render_observations=False
    )
    yield scene
    scene.close()


@pytest.fixture
def scene(room: NativeScene) -> NativeScene:
    room.reset(0)
    return room


def _base(scene: NativeScene) -> BaseDrive:
    assert scene.base is not None
    return scene.base


def _drive(scene: NativeScene, velocity: tuple[float, float, float], seconds: float) -> None:
    """Command ``velocity`` every control period for ``seconds``, holding the arm."""
    hold = scene.hold_action()
    for _ in range(round(seconds / PERIOD_S)):
        _base(scene).command(*velocity)
        scene.step(hold)


def _coast(scene: NativeScene, seconds: float) -> None:
    hold = scene.hold_action()
    for _ in range(round(seconds / PERIOD_S)):
        scene.step(hold)


def _base_xy(scene: NativeScene) -> np.ndarray:
    """World position of the base body [m]."""
    body = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_BODY, "base")
    mujoco.mj_kinematics(scene.model, scene.data)
    return np.array(scene.data.xpos[body, :2])


def test_driving_forward_at_0_3_m_s_for_2_s_moves_the_base_0_6_m(scene: NativeScene) -> None:
    hold, setpoint = scene.hold_action(), scene.driver.setpoint
    _drive(scene, (0.3, 0.0, 0.0), 2.0)
    at_two = _base(scene).odometry()
    _base(scene).command(0.0, 0.0, 0.0)
    _coast(scene, 1.0)
    stopped = _base(scene).odometry()
    print(
        f"\nodometry at 2.0 s: x {at_two.x_m:.4f} m, vx {at_two.vx_m_s:.4f} m/s; stopped: x "
        f"{stopped.x_m:.4f} m, y {stopped.y_m:.2e} m, yaw {stopped.yaw_rad:.2e} rad"
    )
    assert stopped.x_m == pytest.approx(0.6, abs=DISTANCE_TOLERANCE_M)
    assert at_two.vx_m_s == pytest.approx(0.3, abs=0.01)
    assert abs(stopped.y_m) < 1e-3 and abs(stopped.yaw_rad) < 1e-3
    assert abs(stopped.vx_m_s) < 1e-3
    assert (stopped.odom_frame, stopped.base_frame) == ("odom", "base_link")
    assert _base(scene).root_in_base_frame == pytest.approx((0.21, 0.0, 0.0))
    np.testing.assert_array_equal(scene.hold_action(), hold)  # the arm's targets: untouched
    np.testing.assert_array_equal(scene.driver.setpoint, setpoint)


def test_a_base_turned_90_deg_drives_forward_along_world_y(scene: NativeScene) -> None:
    yaw = mujoco.mj_name2id(scene.model, mujoco.mjtObj.mjOBJ_JOINT, "joint_mobile_yaw")
    scene.data.qpos[scene.model.jnt_qposadr[yaw]] = math.pi / 2
    mujoco.mj_forward(scene.model, scene.data)
    start = _base_xy(scene)
    _drive(scene, (0.3, 0.0, 0.0), 2.0)
    _base(scene).command(0.0, 0.0, 0.0)
    _coast(scene, 1.0)
    moved = _base_xy(scene) - start
    odometry = _base(scene).odometry()
    print(
        f"\nturned 90 deg: world move {moved.round(4)} m; odometry ({odometry.x_m:.4f}, "
        f"{odometry.y_m:.4f}) m, yaw {odometry.yaw_rad:.4f} rad"
    )
    assert moved[1] == pytest.approx(0.6, abs=DISTANCE_TOLERANCE_M) and abs(moved[0]) < 0.01
    assert odometry.y_m == pytest.approx(0.6, abs=DISTANCE_TOLERANCE_M)
    assert odometry.yaw_rad == pytest.approx(math.pi / 2, abs=1e-3)


def test_a_scene_placing_the_base_at_90_deg_drives_it_along_world_y(tmp_path: Path) -> None:
    text = ROOM.read_text().replace("yaw_deg: 0.0}", "yaw_deg: 90.0}")
    (tmp_path / "room.yaml").write_text(text)
    scene = NativeScene(
        load_scene(tmp_path / "room.yaml"),
        open_robot_by_id("panda_mobile"),
        render_observations=False,
    )
    try:
        scene.reset(0)
        start = _base_xy(scene)
        _drive(scene, (0.3, 0.0, 0.0), 2.0)
        _base(scene).command(0.0, 0.0, 0.0)
        _coast(scene, 1.0)
        moved, odometry = _base_xy(scene) - start, _base(scene).odometry()
        assert moved[1] == pytest.approx(0.6, abs=DISTANCE_TOLERANCE_M) and abs(moved[0]) < 0.01
        assert odometry.x_m == pytest.approx(0.6, abs=DISTANCE_TOLERANCE_M)  # odom: the start
        assert abs(odometry.y_m) < 1e-3
    finally:
        scene.close()


def test_commands_are_clamped_to_the_limits_and_ramped_by_the_accelerations(
    scene: NativeScene,
) -> None:
    base = _base(scene)
    assert base.command(2.0, 0.0, -5.0) == BaseCommand(0.5, 0.0, -1.0, clamped=True)
    diagonal = base.command(0.4, 0.4, 0.0)
    assert math.hypot(diagonal.vx_m_s, diagonal.vy_m_s) == pytest.approx(0.5)
    assert diagonal.vx_m_s == pytest.approx(diagonal.vy_m_s) and diagonal.clamped
    assert base.command(0.1, -0.2, 0.3) == BaseCommand(0.1, -0.2, 0.3, clamped=False)
    base.command(2.0, 0.0, 5.0)
    scene.step(scene.hold_action())
    vx, _, wz = base.velocity_in_force
    assert vx == pytest.approx(1.0 * PERIOD_S) and wz == pytest.approx(2.0 * PERIOD_S)
    _drive(scene, (2.0, 0.0, 5.0), 1.0)
    odometry = base.odometry()
    print(f"\nat the limits: vx {odometry.vx_m_s:.4f} m/s, wz {odometry.wz_rad_s:.4f} rad/s")
    assert math.hypot(odometry.vx_m_s, odometry.vy_m_s) == pytest.approx(0.5, rel=0.02)
    assert odometry.wz_rad_s == pytest.approx(1.0, rel=0.02)


def test_the_command_times_out_after_its_timeout_of_simulated_time(scene: NativeScene) -> None:
    base = _base(scene)
    base.command(0.3, 0.0, 0.0)
    _coast(scene, 0.45)
    assert base.command_in_force == (0.3, 0.0, 0.0)
    _coast(scene, 0.1)
    assert base.command_in_force == (0.0, 0.0, 0.0)
    _coast(scene, 1.0)
    odometry = base.odometry()
    print(f"\nafter a timeout: stopped at x {odometry.x_m:.4f} m")
    assert abs(odometry.vx_m_s) < 1e-3 and odometry.x_m > 0.05


def test_a_command_that_is_not_a_finite_number_is_refused(scene: NativeScene) -> None:
    base = _base(scene)
    base.command(0.2, 0.0, 0.0)
    for bad in (math.nan, math.inf, "0.1", True):
        with pytest.raises(ActionRejected, match="base command vy_m_s"):
            base.command(0.0, bad, 0.0)  # type: ignore[arg-type]
    assert base.command_in_force == (0.2, 0.0, 0.0)


def test_an_estop_stops_the_base_and_refuses_its_commands() -> None:
    hal = build_hal(open_robot_by_id("panda_mobile"), mode="sim", scene=load_scene(ROOM))
    assert isinstance(hal, SimAttachedHAL)
    hal.connect()
    try:
        for _ in range(20):
            hal.command_base(0.3, 0.0, 0.0)
            hal.tick(None)
        assert hal.base_odometry().vx_m_s == pytest.approx(0.3, abs=0.01)
        hal.estop()
        base = hal.base
        assert base is not None and base.velocity_in_force == (0.0, 0.0, 0.0)
        assert hal.base_odometry().vx_m_s == 0.0  # braked: the frozen scene stands still
        handles = hal.mujoco_handles()
        assert handles is not None
        data = handles[1]
        assert not data.ctrl[base.geometry.actuator].any()
        with pytest.raises(EStopLatched):
            hal.command_base(0.3, 0.0, 0.0)
        assert hal.tick(None) is False
        hal.release_estop()
        assert hal.command_base(0.1, 0.0, 0.0).vx_m_s == 0.1
    finally:
        hal.disconnect()


def test_a_fixed_robot_has_no_base() -> None:
    scene = load_scene(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")
    hal = build_hal(open_robot_by_id("franka_panda"), mode="sim", scene=scene)
    assert isinstance(hal, SimAttachedHAL)
    hal.connect()
    try:
        assert hal.base is None
        with pytest.raises(ConfigurationError, match="franka_panda has no mobile base"):
            hal.command_base(0.1, 0.0, 0.0)
    finally:
        hal.disconnect()
