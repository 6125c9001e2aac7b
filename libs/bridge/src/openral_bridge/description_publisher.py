"""DescriptionPublisher: the robot's URDF on ``/robot_description`` (or its SRDF on
``/robot_description_semantic``), latched.

``std_msgs/String`` with transient-local durability, as robot_state_publisher offers it, so
rviz2's RobotModel display, MoveIt and Foxglove get it whenever they join. The URDF is made
on a thread of its own (the first run exports the meshes into the cache), so the graph's
start-up never waits for it; a failure is logged once and the graph runs on without it.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from std_msgs.msg import String

from openral_bridge.ros_messages import LATCHED
from openral_bridge.topics import ROBOT_DESCRIPTION, TopicInfo

if TYPE_CHECKING:
    from rclpy.node import Node


STOP_WAIT_S = 10.0
"""Longest a stop waits for a URDF still being made [s] (the first run exports meshes)."""


class DescriptionPublisher:
    """Makes the URDF on a thread and publishes it once, latched."""

    def __init__(self, node: Node, make: Callable[[], str], topic: str = ROBOT_DESCRIPTION) -> None:
        """Nothing runs until :meth:`start`.

        Args:
            node: The node that owns the publisher and logs.
            make: Returns the text (may take a while the first time).
            topic: Where it is published.
        """
        self.node, self.make, self.topic = node, make, topic
        self.text: str | None = None
        """The URDF once published."""
        self.error: str | None = None
        """Why it could not be made, if it could not."""
        self._publisher: Any = None
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()

    def start(self) -> None:
        """Create the publisher and start making the URDF."""
        self._publisher = self.node.create_publisher(String, self.topic, LATCHED)
        self._thread = threading.Thread(target=self._run, name="openral-urdf", daemon=True)
        self._thread.start()

    def wait(self, timeout_s: float) -> bool:
        """Wait for the URDF to be published (or to fail); True when it was published."""
        thread = self._thread
        if thread is not None:
            thread.join(timeout_s)
        return self.text is not None

    def stop(self) -> None:
        """Destroy the publisher, then wait up to ``STOP_WAIT_S`` for the thread to end (it
        publishes nothing once the publisher is gone), so a stopped graph leaves no thread."""
        with self._lock:
            publisher, self._publisher = self._publisher, None
        if publisher is not None:
            self.node.destroy_publisher(publisher)
        thread, self._thread = self._thread, None
        if thread is not None and thread is not threading.current_thread():
            thread.join(STOP_WAIT_S)

    def topics(self) -> list[TopicInfo]:
        """Its topic (latched)."""
        return [TopicInfo(self.topic, "std_msgs/msg/String", None)]

    def _run(self) -> None:
        try:
            text = self.make()
        except Exception as error:  # reported once; the graph runs on without it
            self.error = str(error) or type(error).__name__
            self.node.get_logger().warning(  # type: ignore[no-untyped-call]
                f"{self.topic} is not published: {self.error}"
            )
            return
        with self._lock:
            if self._publisher is not None:
                self._publisher.publish(String(data=text))
                self.text = text
