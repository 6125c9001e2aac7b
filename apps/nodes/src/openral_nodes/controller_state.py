"""``/joint_trajectory_controller/controller_state``: what the trajectory controller tracks.

A ``control_msgs/JointTrajectoryControllerState`` once per control period (the controller's
update: when a period's last part has stepped), stamped in simulated time, for the
controller's joints (manifest names, the URDF's): ``reference`` is the running trajectory's
point at that instant (the targets in force when none runs), ``feedback`` the measured
positions and velocities, ``error`` their difference, ``output`` what is commanded (the
reference: a position-controlled robot) and ``speed_scaling_factor`` 1.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

import numpy as np
from control_msgs.msg import JointTrajectoryControllerState
from openral_bridge.control_loop import ControlLoop
from openral_bridge.joint_state_publisher import sim_stamp
from openral_bridge.topics import JTC_STATE
from openral_bridge.trajectory_follower import TrajectoryFollower
from openral_hal.protocol import RobotHal
from openral_mujoco.state import JointStateSample
from trajectory_msgs.msg import JointTrajectoryPoint

if TYPE_CHECKING:
    from rclpy.node import Node


class ControllerStatePublisher:
    """Publishes the trajectory controller's state once per control period of ``loop``."""

    def __init__(
        self,
        node: Node,
        hal: RobotHal,
        lock: threading.Lock,
        loop: ControlLoop,
        follower: TrajectoryFollower,
        slots: tuple[int, ...],
    ) -> None:
        self.node, self.hal, self.lock, self.loop, self.follower = node, hal, lock, loop, follower
        self.slots = np.asarray(slots, dtype=np.intp)
        self.names = [hal.action_names[i] for i in slots]
        self.published = 0
        self._pub: Any = None

    def start(self) -> tuple[str, Any]:
        """Advertise and publish after every tick; returns the publisher as an entity."""
        self._pub = self.node.create_publisher(JointTrajectoryControllerState, JTC_STATE, 10)
        self.loop.watchers.append(self.publish)
        return ("publisher", self._pub)

    def stop(self) -> None:
        """Stop publishing (the node destroys the publisher)."""
        if self.publish in self.loop.watchers:
            self.loop.watchers.remove(self.publish)

    def publish(self, state: JointStateSample) -> None:
        """One message for the state after a tick (the control loop's thread)."""
        if state.sim_time_s is None or self._pub is None or self.loop.ticks_left:
            return
        with self.lock:
            reference = np.asarray(self.hal.hold_action(), dtype=np.float64)
        speeds = np.zeros(len(reference))
        sampled = self.follower.reference(state.sim_time_s)
        if sampled is not None:
            reference[sampled[0]], speeds[sampled[0]] = sampled[1], sampled[2]
        slots = self.slots
        ref_q, ref_v = reference[slots], speeds[slots]
        got_q, got_v = state.positions[slots], state.velocities[slots]
        msg = JointTrajectoryControllerState(joint_names=self.names, speed_scaling_factor=1.0)
        msg.header.stamp = sim_stamp(self.node, state.sim_time_s)
        msg.reference = _point(ref_q, ref_v)
        msg.feedback = _point(got_q, got_v)
        msg.error = _point(ref_q - got_q, ref_v - got_v)
        msg.output = _point(ref_q, ref_v)
        self._pub.publish(msg)
        self.published += 1


def _point(positions: Any, velocities: Any) -> Any:
    return JointTrajectoryPoint(
        positions=np.asarray(positions, np.float64).tolist(),
        velocities=np.asarray(velocities, np.float64).tolist(),
    )
