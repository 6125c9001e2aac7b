"""The control loop a HAL gets under the manifest node: ticked on the pacer, or driven.

- A simulated HAL (:func:`~openral_hal.factory.can_tick`) is stepped by a
  :class:`~openral_bridge.control_loop.ControlLoop` on the node's pacer, once per control
  period, publishing ``/clock`` after each step.
- A real HAL with a loop of its own (:class:`~openral_hal.protocol.CycledHal`) is never
  ticked: the control loop rides on its driver's cycle
  (:class:`~openral_bridge.real_cadence.RealCadence`), one tick per reading, and there is no
  ``/clock`` (a real robot's time is the system clock's). Its faults are logged as errors.
- Any other HAL has no loop; actions go straight to it.

Either loop follows joint trajectories when the HAL's action slots are the manifest's
joints.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING

from openral_bridge.control_loop import ControlLoop
from openral_bridge.pacer import Pacer
from openral_bridge.real_cadence import RealCadence
from openral_bridge.trajectory_follower import follower_for
from openral_core import LoadedRobot
from openral_hal.factory import can_tick
from openral_hal.protocol import CycledHal, PathScreen, RobotHal

if TYPE_CHECKING:
    from rclpy.node import Node


def start_control_loop(
    node: Node,
    hal: RobotHal,
    lock: threading.Lock,
    robot: LoadedRobot | None,
    pacer: Pacer,
    *,
    on_tick: Callable[[float | None], None],
    on_reset: Callable[[], None],
) -> ControlLoop | None:
    """The running control loop of ``hal`` (see the module doc), or None."""
    joints = robot is not None and hal.action_names == hal.joint_names
    follower = follower_for(robot) if robot is not None and joints else None
    if follower is not None and isinstance(hal, PathScreen):
        follower.screen = hal.path_contact  # a twin scene refuses a goal into its table
    if can_tick(hal):
        loop = ControlLoop(
            node, hal, on_tick=on_tick, lock=lock, follower=follower, on_reset=on_reset
        )
        loop.start(pacer)
        return loop
    if isinstance(hal, CycledHal):
        log = node.get_logger()  # type: ignore[no-untyped-call]
        hal.on_fault = lambda line: log.error(line)
        cadence = RealCadence(hal)
        loop = ControlLoop(node, cadence, lock=lock, follower=follower)
        loop.start_driven(cadence.drive)
        return loop
    return None
