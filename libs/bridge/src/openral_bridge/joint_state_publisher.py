"""JointStatePublisher: ``/joint_states`` and ``/openral/manifest_joint_states`` after every
control tick (or at a slower fixed rate, from a pacer job).

Two views of the same instant, both stamped in simulated time (the node clock for a HAL
without one):

- ``/joint_states`` is what ROS tools read (robot_state_publisher, rviz2, MoveIt): every joint
  of the robot's URDF (:class:`~openral_mujoco.robot_tree.RobotTree`) in SI units, a finger
  in metres (not a 0-1 opening), the mimic fingers too, under the names the URDF gives
  them; a mobile base adds its drive joints (MJCF names: x and y slides [m], yaw [rad]);
- ``/openral/manifest_joint_states`` is what a policy sees in an episode: the manifest's
  joints in manifest units, a gripper in its ``read_mode`` (the HAL's ``read_state``).

A HAL without a frame tree (a robosuite scene, a real robot) publishes its ``read_state`` on
both.

Where a reading comes from (a :class:`StateSource`):

- :class:`TickStates`: a simulated scene changes only when the control loop ticks (at the
  scene's state rate), so the loop copies both views right after each tick, holding the
  HAL's lock (:attr:`~openral_bridge.control_loop.ControlLoop.readers`), and the publisher
  sends them after that tick: every message a new state and a new stamp;
- :class:`HalStates`: a HAL without a control loop is read, holding its lock, at every
  publication.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

import mujoco
import numpy as np
from control_msgs.msg import DynamicJointState, InterfaceValue
from openral_hal.protocol import RobotHal
from openral_mujoco.robot_tree import RobotTree
from openral_mujoco.state import JointStateSample
from openral_sim.base_drive import BaseDrive
from sensor_msgs.msg import JointState

from openral_bridge import ros_messages
from openral_bridge.paced_publishers import PacedPublishers
from openral_bridge.pacer import Pacer
from openral_bridge.topics import DYNAMIC_JOINT_STATES, JOINT_STATES, MANIFEST_JOINT_STATES

if TYPE_CHECKING:
    from rclpy.node import Node

    from openral_bridge.control_loop import ControlLoop

QUEUE_DEPTH = 10
"""Queue of each publisher."""
INTERFACES = ("position", "velocity", "effort")
"""The state interfaces ``/dynamic_joint_states`` carries per joint."""


def sim_stamp(node: Node, sim_time_s: float | None) -> Any:
    """Simulated time [s] as a header stamp; the node clock's time for None."""
    if sim_time_s is None:
        return node.get_clock().now().to_msg()
    return ros_messages.stamp(sim_time_s)


@dataclass(frozen=True)
class StateReading:
    """Both views of one instant (see the module doc)."""

    joints: JointStateSample
    """``/joint_states``: the URDF's joints in SI units (and a mobile base's drive joints)."""
    manifest: JointStateSample
    """``/openral/manifest_joint_states``: the manifest's joints in manifest units."""


class StateSource(Protocol):
    """Where the publisher gets the newest reading."""

    def reading(self) -> StateReading:
        """The newest reading (the same object until the state changes)."""
        ...


class TickStates:
    """The readings a control loop copies after every tick (see the module doc)."""

    def __init__(
        self,
        loop: ControlLoop,
        tree: RobotTree | None = None,
        data: mujoco.MjData | None = None,
        base: BaseDrive | None = None,
    ) -> None:
        """Register with ``loop``, which captures the state it holds now at once.

        Args:
            loop: The control loop (its ``state`` is the manifest view).
            tree: The robot's tree in the scene's model, for the SI view (None: the
                manifest view on both topics).
            data: The scene's live data (with ``tree``).
            base: The mobile base, whose drive joints join the SI view.
        """
        self.loop, self.tree, self.data, self.base = loop, tree, data, base
        self._latest: StateReading | None = None
        loop.add_reader(self.capture)

    def capture(self) -> None:
        """Copy both views (the control loop calls it holding the HAL's lock)."""
        manifest = self.loop.state
        if manifest is None:
            return
        joints = manifest
        if self.tree is not None and self.data is not None:
            joints = self.tree.read_joints(self.data)
        if self.base is not None:
            joints = _joined(joints, self.base.joint_state())
        self._latest = StateReading(joints, manifest)

    def reading(self) -> StateReading:
        """The last tick's reading.

        Raises:
            RuntimeError: No tick has stepped the scene yet (the loop ticks at start).
        """
        if self._latest is None:
            raise RuntimeError("no control tick has stepped the scene yet")
        return self._latest


class HalStates:
    """A HAL read at every publication, holding its lock."""

    def __init__(self, hal: RobotHal, lock: threading.Lock) -> None:
        self.hal, self.lock = hal, lock

    def reading(self) -> StateReading:
        """The HAL's state now (both views alike)."""
        with self.lock:
            sample = self.hal.read_state()
        return StateReading(sample, sample)


class JointStatePublisher:
    """Publishes both views once at :meth:`start`, then at ``rate_hz`` on a pacer."""

    def __init__(self, node: Node, rate_hz: float, source: StateSource) -> None:
        """Nothing is created until :meth:`start`.

        Args:
            node: The node that owns the publishers.
            rate_hz: Publish rate [Hz].
            source: Where the readings come from.
        """
        self.node = node
        self.rate_hz = float(rate_hz)
        self.source = source
        self.published = 0
        """Readings published since :meth:`start`."""
        self.enabled = True
        """False while the joint state broadcaster is deactivated: nothing is published."""
        self._out = PacedPublishers(node)
        self._messages: tuple[StateReading, Any, Any] | None = None
        self._dynamic: Any = None

    def start(self, pacer: Pacer, loop: ControlLoop | None = None) -> None:
        """Create the publishers, publish once, then at :attr:`rate_hz` on ``pacer``, or after
        every tick of ``loop`` when that is as often (each a new state, freshly stamped:
        :class:`~openral_bridge.paced_publishers.Cadence`); :attr:`rate_hz` becomes the
        rate it runs at."""
        self.stop()
        node = self.node
        self._out.open(
            node.create_publisher(JointState, JOINT_STATES, QUEUE_DEPTH),
            node.create_publisher(JointState, MANIFEST_JOINT_STATES, QUEUE_DEPTH),
            node.create_publisher(DynamicJointState, DYNAMIC_JOINT_STATES, QUEUE_DEPTH),
        )
        self.published = 0
        self.publish()
        self.rate_hz = self._out.schedule(
            pacer, 1.0 / self.rate_hz, self.publish, "joint_states", loop
        )

    def stop(self) -> None:
        """Unschedule the job and destroy the publishers (idempotent)."""
        self._out.close()
        self._messages = None

    def publish(self) -> None:
        """Publish the newest reading."""
        publishers = self._out.publishers
        if not publishers or not self.enabled:
            return
        joints, manifest = self._messages_of(self.source.reading())
        publishers[0].publish(joints)
        publishers[1].publish(manifest)
        self._dynamic = dynamic_joint_state(joints, self._dynamic)
        publishers[2].publish(self._dynamic)
        self.published += 1

    def _messages_of(self, reading: StateReading) -> tuple[Any, Any]:
        """The two messages of ``reading``, built once per reading."""
        if self._messages is not None and self._messages[0] is reading:
            return self._messages[1], self._messages[2]
        joints = self._message(reading.joints)
        manifest = joints if reading.manifest is reading.joints else None
        manifest = manifest or self._message(reading.manifest)
        self._messages = (reading, joints, manifest)
        return joints, manifest

    def _message(self, sample: JointStateSample) -> Any:
        stamp = sim_stamp(self.node, sample.sim_time_s)
        return ros_messages.joint_state_msg(
            sample.names, sample.positions, sample.velocities, sample.efforts, stamp
        )


def dynamic_joint_state(joints: Any, reuse: Any = None) -> Any:
    """``control_msgs/DynamicJointState`` of a ``JointState``: each joint's position,
    velocity and effort interfaces (joint_state_broadcaster's ``/dynamic_joint_states``);
    ``reuse`` (the last one, same joints) is filled in place instead of building anew."""
    names = joints.name
    if reuse is None or list(reuse.joint_names) != list(names):
        reuse = DynamicJointState(
            joint_names=names,
            interface_values=[InterfaceValue(interface_names=list(INTERFACES)) for _ in names],
        )
    reuse.header = joints.header
    rows = zip(reuse.interface_values, joints.position, joints.velocity, joints.effort, strict=True)
    for value, q, v, e in rows:
        value.values = [q, v, e]
    return reuse


def _joined(first: JointStateSample, second: JointStateSample) -> JointStateSample:
    """``second``'s joints after ``first``'s (one instant)."""
    return first._replace(
        names=first.names + second.names,
        positions=np.concatenate([first.positions, second.positions]),
        velocities=np.concatenate([first.velocities, second.velocities]),
        efforts=np.concatenate([first.efforts, second.efforts]),
    )
