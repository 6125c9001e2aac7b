"""Call a ``std_srvs/Trigger`` service of the graph from a spun client node, with timeouts."""

from __future__ import annotations

import time
from typing import Any

from openral_core.errors import OpenralError
from rclpy.node import Node
from std_srvs.srv import Trigger


class ServiceNotAnswered(OpenralError):
    """The service is not offered, or did not answer in time."""


def call_trigger(node: Node, service: str, timeout_s: float) -> Any:
    """The ``Trigger`` response of ``service`` (``node`` is spun by the caller).

    Raises:
        ServiceNotAnswered: Nobody offers ``service`` within ``timeout_s``, or no answer came
            within ``timeout_s`` more.
    """
    client = node.create_client(Trigger, service)
    try:
        if not client.wait_for_service(timeout_sec=timeout_s):
            raise ServiceNotAnswered(
                f"nobody offers {service} within {timeout_s:g} s (is deploy sim running on "
                "this ROS domain?)"
            )
        future = client.call_async(Trigger.Request())
        deadline = time.monotonic() + timeout_s
        while not future.done():  # type: ignore[no-untyped-call]
            if time.monotonic() > deadline:
                raise ServiceNotAnswered(f"{service} did not answer within {timeout_s:g} s")
            time.sleep(0.01)
        return future.result()  # type: ignore[no-untyped-call]
    finally:
        node.destroy_client(client)
