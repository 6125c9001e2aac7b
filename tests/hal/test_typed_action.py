"""A typed action (slots by name, the gripper, a base twist) goes through the same single
validation as a plain vector, on the arm alone and on a scene with a mobile base; a refused
one changes nothing."""

from __future__ import annotations

import math

import numpy as np
import pytest
from openral_core import load_scene, open_robot_by_id
from openral_hal.errors import ActionRejected
from openral_hal.factory import HalMode, build_hal
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.action import Action, BaseTwist

from tests.conftest import ROBOTS


def test_named_slots_and_the_gripper_fill_the_hold_on_the_arm_alone() -> None:
    hal = MujocoArmHAL.from_robot(open_robot_by_id("franka_panda"))
    hal.connect()
    try:
        hold = hal.hold_action()
        names = hal.action_names
        hal.send_action(Action(slots={"panda_joint1": 0.3}, gripper=0.0))
        driver = hal.driver
        _, data, _ = hal._handles()
        sent = driver.hold_action(data)
        expected = hold.copy()
        expected[names.index("panda_joint1")] = 0.3
        expected[names.index("panda_finger_joint1")] = 0.0
        np.testing.assert_allclose(sent, expected)
        with pytest.raises(ActionRejected, match="not action slots; the slots are: panda_joint1"):
            hal.send_action(Action(slots={"elbow": 1.0}))
        with pytest.raises(ActionRejected, match="not the arm alone"):
            hal.send_action(Action(base=BaseTwist(0.1)))
        with pytest.raises(ActionRejected, match="both by name and as the gripper"):
            hal.send_action(Action(slots={"panda_finger_joint1": 1.0}, gripper=0.5))
        with pytest.raises(ActionRejected, match=r"action\[0\] \(panda_joint1\) is nan"):
            hal.send_action(Action(slots={"panda_joint1": math.nan}))
        np.testing.assert_allclose(driver.hold_action(data), expected)  # refusals changed nothing
    finally:
        hal.disconnect()


def test_a_twist_drives_the_base_with_the_joints_in_one_action() -> None:
    scene = load_scene(ROBOTS / "panda_mobile" / "scenes" / "room.yaml")
    hal = build_hal(open_robot_by_id("panda_mobile"), mode=HalMode.SIM, scene=scene)
    assert isinstance(hal, SimAttachedHAL)
    hal.connect()
    try:
        assert hal.base is not None
        for _ in range(20):
            hal.send_action(Action(gripper=1.0, base=BaseTwist(vx_m_s=0.3)))
        moved = hal.base_odometry()
        assert moved.vx_m_s > 0.1 and moved.x_m > 0.01
        with pytest.raises(ActionRejected, match="base twist vy_m_s is inf"):
            Action(base=BaseTwist(vy_m_s=math.inf))
        hal.estop()
        before = hal.last_env_action
        with pytest.raises(Exception, match="E-stop"):
            hal.send_action(Action(base=BaseTwist(vx_m_s=0.3)))
        np.testing.assert_array_equal(hal.last_env_action, before)
        assert hal.base.command_in_force == (0.0, 0.0, 0.0)  # the E-stop halted it
    finally:
        hal.disconnect()
