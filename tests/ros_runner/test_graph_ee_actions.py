"""An ee_delta_pose action on a ROS graph becomes joint targets through the one IK, on the
robot's own model posed at the measured joints."""

from __future__ import annotations

import numpy as np
import pytest
from openral_core import open_robot_by_id
from openral_core.errors import OpenralError
from openral_nodes.graph_ee_actions import GraphEeActions

HOLD = np.array([0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398, 1.0])


def _measured(action: np.ndarray, names: tuple[str, ...]) -> dict[str, float]:
    """The arm's joints where the action puts them; the fingers 4 cm open (metres)."""
    joints = dict(zip(names[:7], action[:7].tolist(), strict=True))
    joints[names[7]] = 0.04
    return joints


def test_deltas_up_raise_the_tcp_and_open_the_gripper() -> None:
    ee = GraphEeActions(open_robot_by_id("franka_panda"), 0.1)
    ee.start(HOLD, _measured(HOLD, ee.names))
    start = ee.command.tcp_vector(ee.twin.data)[:3]
    action = HOLD
    for _ in range(10):
        action = ee.joint_action(np.array([0, 0, 0.5, 0, 0, 0, -1.0]), _measured(action, ee.names))
    ee.start(action, _measured(action, ee.names))  # poses the model there
    end = ee.command.tcp_vector(ee.twin.data)[:3]
    assert end[2] - start[2] == pytest.approx(0.25, abs=0.01)  # 10 x 0.5 x 0.05 m
    np.testing.assert_allclose(end[:2], start[:2], atol=2e-3)
    assert action[7] == 1.0  # robosuite: -1 opens


def test_a_bad_action_or_a_robot_without_a_tcp_is_one_line() -> None:
    ee = GraphEeActions(open_robot_by_id("franka_panda"), 0.1)
    with pytest.raises(OpenralError, match="no start pose"):
        ee.joint_action(np.zeros(7), {})
    ee.start(HOLD, _measured(HOLD, ee.names))
    for bad in (np.zeros(6), np.array([np.nan] * 7)):
        with pytest.raises(OpenralError, match="7 finite values"):
            ee.joint_action(bad, {})
    with pytest.raises(OpenralError, match="ur5e has no tool centre point"):
        GraphEeActions(open_robot_by_id("ur5e"), 0.1)


def test_an_ee_pose_puts_the_tcp_where_asked() -> None:
    ee = GraphEeActions(open_robot_by_id("franka_panda"), 0.1, mode="ee_pose")
    ee.start(HOLD, _measured(HOLD, ee.names))
    start = ee.command.tcp_vector(ee.twin.data)
    target = np.concatenate([start[:3] + np.array([0.05, 0.0, 0.10]), start[3:], [0.0]])
    action = HOLD
    for _ in range(20):
        action = ee.joint_action(target, _measured(action, ee.names))
    ee.start(action, _measured(action, ee.names))
    end = ee.command.tcp_vector(ee.twin.data)
    np.testing.assert_allclose(end[:3], target[:3], atol=5e-3)
    assert action[7] == 0.0
    for bad in (np.zeros(7), np.array([0.3, 0, 0.5, 0, 0, 0, 0, 1.0])):  # short; no turn
        with pytest.raises(OpenralError, match="ee_pose"):
            ee.joint_action(bad, {})
