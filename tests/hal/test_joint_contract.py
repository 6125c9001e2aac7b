"""The action contract's reporting side: clamps are counted and warned about, a refused
action changes nothing, and a gripper's velocity is the rate of its reading."""

from __future__ import annotations

import logging

import numpy as np
import pytest
from openral_core.loaded import open_robot_by_id
from openral_hal.errors import ActionRejected
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_mujoco import command_limits


def _panda() -> MujocoArmHAL:
    hal = MujocoArmHAL.from_robot(open_robot_by_id("franka_panda"))
    hal.connect()
    return hal


def test_a_target_beyond_the_limits_is_clamped_counted_and_warned_once(
    caplog: pytest.LogCaptureFixture,
) -> None:
    hal = _panda()
    action = hal.hold_action()
    action[0] = 1e12
    with caplog.at_level(logging.WARNING, logger=command_limits.__name__):
        hal.send_action(action)
        hal.send_action(action)  # within WARN_EVERY_S: counted, not logged again
    assert hal.driver.limits.clamped["panda_joint1"] == 2
    assert sum(hal.driver.limits.clamped.values()) == 2
    (record,) = caplog.records
    assert record.getMessage().startswith("panda_joint1: command 1e+12 is outside its limits")
    assert "[-2.8973, 2.8973]" in record.getMessage() and "(1 so far)" in record.getMessage()
    hal.step(3000)  # six seconds: arrived at the clamped target, never beyond it
    assert hal.read_state().positions[0] == pytest.approx(2.8973, abs=0.01)
    assert hal.hold_action()[0] == pytest.approx(2.8973)


def test_a_refused_action_leaves_targets_counters_and_ctrl_as_they_were() -> None:
    hal = _panda()
    _, data = hal.mujoco_handles()
    hold, ctrl = hal.hold_action(), data.ctrl.copy()
    for bad in ([1.0] * 7, [float("nan")] * 8, "eight", np.zeros((2, 4))):
        with pytest.raises(ActionRejected):
            hal.send_action(bad)
    np.testing.assert_array_equal(hal.hold_action(), hold)
    np.testing.assert_array_equal(data.ctrl, ctrl)
    assert not any(hal.driver.limits.clamped.values())


def test_a_repeated_command_is_applied_again_after_an_estop_release() -> None:
    hal = _panda()
    action = hal.hold_action()
    action[0] += 0.2
    hal.send_action(action)
    hal.step(100)
    hal.estop()
    hal.release_estop()  # targets <- the pose now, short of the target
    assert hal.hold_action()[0] < action[0] - 1e-3
    hal.send_action(action.copy())  # the same bytes as the command before the E-stop
    assert hal.hold_action()[0] == action[0]


def test_a_repeated_clamped_command_is_counted_each_time() -> None:
    hal = _panda()
    action = hal.hold_action()
    action[7] = 1.5  # the gripper, beyond open
    for _ in range(3):
        hal.send_action(action)
    assert hal.driver.limits.clamped == {
        **dict.fromkeys(hal.joint_names, 0),
        "panda_finger_joint1": 3,
    }


@pytest.mark.parametrize("robot_id", ["franka_panda", "so101", "aloha"])
def test_a_gripper_velocity_is_the_rate_of_its_reading(robot_id: str) -> None:
    """sum_over_scale, affine_low_high and passthrough: d(reading)/dt = reported velocity."""
    hal = MujocoArmHAL.from_robot(open_robot_by_id(robot_id))
    hal.connect()
    model, _ = hal.mujoco_handles()
    gripper = hal.wiring.grippers[0]
    slot = hal.joint_names.index(gripper.joint)
    action = hal.hold_action()
    low, high = (0.0, 1.0) if gripper.write_mode == "normalised" else gripper.ctrl_range
    action[slot] = low if abs(action[slot] - high) < abs(action[slot] - low) else high
    hal.send_action(action)
    moving = 0
    for _ in range(100):
        before = hal.read_state()
        hal.step(1)
        after = hal.read_state()
        rate = (after.positions[slot] - before.positions[slot]) / model.opt.timestep
        # MuJoCo's Euler step moves qpos by dt * the new qvel
        reported = after.velocities[slot]
        assert reported == pytest.approx(rate, rel=1e-3, abs=1e-6), (rate, reported)
        moving += abs(rate) > 0.05
    assert moving > 10, "the gripper did not move"
