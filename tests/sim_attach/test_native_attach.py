"""SimAttachedHAL on the real native scene: the project's default franka tabletop.

The native scene is position-controlled, so its hold action is the targets in force; idle
steps keep the robot where it was last sent (never towards 0 rad) while time and pictures
go on.
"""

from __future__ import annotations

from collections.abc import Iterator

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_core import load_scene, open_robot_by_id
from openral_hal.factory import build_hal
from openral_hal.sim_attached import SimAttachedHAL

from tests.conftest import ROBOTS

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


@pytest.fixture
def hal() -> Iterator[SimAttachedHAL]:
    built = build_hal(open_robot_by_id("franka_panda"), mode="sim", scene=load_scene(SCENE))
    assert isinstance(built, SimAttachedHAL)
    built.connect()
    yield built
    built.disconnect()


def _changed(a: npt.NDArray[np.uint8], b: npt.NDArray[np.uint8]) -> float:
    return float(np.abs(a.astype(int) - b.astype(int)).mean())


def test_action_slots_are_the_scene_actuators(hal: SimAttachedHAL) -> None:
    model, _ = hal.mujoco_handles() or (None, None)
    assert model is not None
    assert hal.action_dim == model.nu == len(hal.action_names)
    assert len(set(hal.action_names)) == hal.action_dim


def test_hold_ticks_keep_the_start_pose(hal: SimAttachedHAL) -> None:
    start = hal.read_state()
    hold = hal.hold_action()
    for _ in range(40):  # two seconds of scene time
        assert hal.tick(None)
    later = hal.read_state()
    assert later.sim_time_s is not None and start.sim_time_s is not None
    assert later.sim_time_s == pytest.approx(start.sim_time_s + 2.0, abs=0.01)
    arm = slice(0, 7)
    np.testing.assert_allclose(later.positions[arm], start.positions[arm], atol=0.02)
    assert np.abs(start.positions[arm]).max() > 0.5  # a bent pose, far from all-zeros
    np.testing.assert_array_equal(hal.hold_action(), hold)


def test_hold_ticks_finish_the_last_move_and_the_frame_follows(hal: SimAttachedHAL) -> None:
    target = hal.hold_action()
    target[0] += 0.6  # swing the base joint
    hal.send_action(target)
    moved_once = hal.read_state().positions[0]
    frames = [hal.read_images()["agentview"]]
    for _ in range(30):
        assert hal.tick(None)
        frames.append(hal.read_images()["agentview"])
    settled = hal.read_state().positions[0]
    np.testing.assert_allclose(hal.hold_action(), target)  # hold ticks keep the command
    np.testing.assert_allclose(hal.last_env_action, target)
    assert abs(settled - target[0]) < 0.05 < abs(moved_once - target[0])
    assert _changed(frames[0], frames[10]) > 0.1, "hold ticks did not advance the picture"


def test_estop_freezes_the_scene(hal: SimAttachedHAL) -> None:
    target = hal.hold_action()
    target[0] -= 0.5
    hal.send_action(target)  # still moving when the E-stop latches
    hal.estop()
    frame, state = hal.read_images()["wrist"], hal.read_state()
    for _ in range(5):
        assert not hal.tick(None)
    np.testing.assert_array_equal(hal.read_images()["wrist"], frame)
    np.testing.assert_array_equal(hal.read_state().positions, state.positions)


def test_camera_fovy_comes_from_the_camera_that_renders_the_sensor(hal: SimAttachedHAL) -> None:
    handles = hal.mujoco_handles()
    assert handles is not None
    model = handles[0]
    for sensor, camera in hal.env.camera_models.items():
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        assert index >= 0, camera
        assert hal.camera_fovy_deg(sensor) == pytest.approx(float(model.cam_fovy[index]))
    assert hal.camera_fovy_deg("wrist") == pytest.approx(75.0)  # the manifest's, mounted
    assert hal.camera_fovy_deg("belly") is None


def test_a_period_stepped_in_parts_is_the_whole_step_bit_for_bit() -> None:
    """Fresh state at the state rate changes nothing of the motion: a control period stepped
    in its parts (the command, then holds) ends exactly where one whole step does, and every
    part is a new instant."""
    scene = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
    whole, parted = (
        build_hal(open_robot_by_id("franka_panda"), mode="sim", scene=load_scene(scene))
        for _ in range(2)
    )
    assert isinstance(whole, SimAttachedHAL) and isinstance(parted, SimAttachedHAL)
    whole.connect()
    parted.connect()
    try:
        assert parted.state_parts == 5  # 20 Hz actions, 100 Hz state on the tabletop
        times = []
        for offset in (0.3, -0.2, 0.1):
            target = whole.hold_action()
            target[0] += offset
            whole.send_action(target)
            assert parted.tick_part(target)
            times.append(parted.read_state().sim_time_s)
            for _ in range(parted.state_parts - 1):
                assert parted.tick_part(None)
                times.append(parted.read_state().sim_time_s)
            np.testing.assert_array_equal(
                parted.read_state().positions, whole.read_state().positions
            )
        steps = np.diff(np.asarray(times, dtype=np.float64))
        np.testing.assert_allclose(steps, whole.control_period_s / parted.state_parts, atol=1e-9)
    finally:
        whole.disconnect()
        parted.disconnect()
