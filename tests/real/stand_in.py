"""deploy sim standing in for a Panda's ros2_control driver (namespace /robot), as the
ros2_control tests drive it through deploy real (namespace /real).

The stand-in is a Python simulator on two shared cores: now and then (a program joining
the domain, a restart) its 100 Hz joint states pause past deploy real's two-period rule,
and deploy real latches its E-stop, as it must. A test that needs the arm to move releases
it once the stream is steady again, a bounded number of times, and each latch it meets
must be that rule's.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from sensor_msgs.msg import JointState

from tests.real.deploy_helpers import Remote
from tests.ros.action_client import PANDA_ARM, ended, goal
from tests.ros.ros_helpers import call_trigger, wait_until

ROBOT_STATES = "/robot/joint_states"
RELEASE = "/real/openral/release_estop"
RELEASES = 3
"""Releases a test may take before its goal runs through (see the module doc)."""


def arm_joints(message: JointState) -> list[float]:
    """The Panda's seven arm joints of a joint state message, in manifest order."""
    positions = dict(zip(message.name, message.position, strict=True))
    return [positions[name] for name in PANDA_ARM]


def steady(remote: Remote, seconds: float = 2.0) -> None:
    """Wait until the robot's joint states have come every period for ``seconds``."""

    def is_steady() -> bool:
        times = [r.at for r in remote.probe.since(ROBOT_STATES, time.monotonic() - seconds)]
        return len(times) > seconds * 80 and max(np.diff(times)) < 0.015

    wait_until(is_steady, 60.0, "a steady stream from the robot")


def released(remote: Remote, release: Any) -> None:
    """Release deploy real's E-stop; a release refused because the readings were stale at
    that instant (the same two-period rule) is asked again once the stream is steady, at
    most :data:`RELEASES` times."""
    for _ in range(RELEASES):
        answer = call_trigger(release, RELEASE)
        if answer.success:
            return
        assert "stale" in answer.message, answer
        steady(remote)
    raise AssertionError(f"the release was refused {RELEASES} times: the readings stayed stale")


def release_and_move(remote: Remote, release: Any, follow: Any, turn_rad: float) -> int:
    """Release deploy real's E-stop and send it a goal turning the robot's joint 1 by
    ``turn_rad`` in 2 s; assert the robot gets there (0.02 rad). Returns the releases it
    took (at most :data:`RELEASES`; see the module doc)."""
    from action_msgs.msg import GoalStatus

    for attempt in range(1, RELEASES + 1):
        released(remote, release)
        start = arm_joints(remote.probe.latest(ROBOT_STATES))
        target = [start[0] + turn_rad, *start[1:]]
        status, result = ended(follow, goal(PANDA_ARM, [(2.0, target)]))
        if status == GoalStatus.STATUS_SUCCEEDED:
            time.sleep(0.5)
            reached = arm_joints(remote.probe.latest(ROBOT_STATES))
            assert max(abs(a - b) for a, b in zip(reached, target, strict=True)) < 0.02
            return attempt
        assert "E-stop is latched" in result.error_string, result
        steady(remote)
    raise AssertionError(f"the goal stopped at the E-stop after each of {RELEASES} releases")
