"""EeTargetFollower and checked_pose on the franka tabletop's real HAL: a target is checked
and normalised, each step moves only the arm (the gripper keeps its command), stays inside
the manifest's limits, and cancel ends it once."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from openral_bridge.ee_target import EeTargetFollower, EeTargetRefused, checked_pose
from openral_eval.scene_env import attached_hal
from openral_hal.sim_attached import SimAttachedHAL
from openral_hal.tool_centre import ee_command

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
DOWN = (0.0, 1.0, 0.0, 0.0)
"""Half a turn about x (w, x, y, z): the TCP pointing down."""


@pytest.fixture(scope="module")
def franka() -> Iterator[tuple[SimAttachedHAL, EeTargetFollower]]:
    hal, robot = attached_hal(SCENE)
    hal.connect()
    ee = ee_command(hal, robot)
    assert ee is not None
    yield hal, EeTargetFollower(hal, ee)
    hal.disconnect()


@pytest.mark.parametrize(
    ("position", "quat", "expected"),
    [
        ((np.nan, 0.0, 0.4), DOWN, "pose.position.x is nan; expected a finite number"),
        ((0.4, 0.0, 0.4), (0.0, 0.0, np.inf, 0.0), "pose.orientation.y is inf"),
        ((0.4, 0.0, 0.4), (0.0, 0.0, 0.0, 0.0), "pose.orientation has norm 0"),
    ],
)
def test_a_bad_pose_is_refused_naming_the_field(
    position: tuple[float, ...], quat: tuple[float, ...], expected: str
) -> None:
    with pytest.raises(EeTargetRefused, match=expected.replace(".", r"\.")):
        checked_pose(position, quat)


def test_a_quaternion_is_normalised() -> None:
    pose = checked_pose((0.4, 0.0, 0.4), (0.0, 2.0, 0.0, 0.0))
    assert pose.tolist() == [0.4, 0.0, 0.4, 0.0, 1.0, 0.0, 0.0]


def test_steps_move_the_arm_only_within_its_limits_until_cancelled(
    franka: tuple[SimAttachedHAL, EeTargetFollower],
) -> None:
    hal, follower = franka
    hold = np.array(hal.hold_action())
    assert follower.next_action(hold, 0.0, hal.control_period_s) is None  # no target yet
    follower.submit(checked_pose((0.45, 0.2, 0.4), DOWN))
    period = hal.control_period_s
    step = follower.next_action(hold, 1.0, period)
    assert step is not None
    action, point = step
    arm = list(follower.ee.ee.arm)
    others = [i for i in range(len(hold)) if i not in arm]
    assert action[others].tolist() == hold[others].tolist()  # the gripper keeps its command
    assert np.abs(action[arm] - hold[arm]).max() > 1e-3
    assert point.names == follower.names and point.time_s == pytest.approx(1.0 + period)
    joints = hal.description.joints
    for index in arm:
        low, high = joints[index].position_limits
        assert low <= action[index] <= high
    assert np.abs(point.velocities).max() > 0.0
    assert follower.cancel("test") is True and follower.cancel("again") is False
    assert follower.next_action(hold, 1.0, period) is None
