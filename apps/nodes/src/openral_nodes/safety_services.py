"""The E-stop, release and reset services on a thread of their own.

``/openral/estop``, ``/openral/release_estop`` and ``/openral/reset`` (``std_srvs/Trigger``)
are served by a node of their own (``<node>_safety``) spun by its own single-threaded
executor on its own thread, so that nothing the main node's executor is busy with (a flood
of actions, trajectories or goals, a huge message being read) delays an E-stop: it waits
only for the control tick in progress (the HAL's lock) and for Python's interpreter lock.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from openral_bridge.topics import ESTOP, RELEASE_ESTOP, RESET
from rclpy.context import Context
from rclpy.node import Node
from std_srvs.srv import Trigger

from openral_nodes.graph_names import graph_name
from openral_nodes.runtime import Spinner

Handler = Callable[[Any, Any], Any]
"""A Trigger service callback: (request, response) → response."""


class SafetyServices:
    """The safety services of one active manifest node (see the module doc)."""

    def __init__(self, context: Context, node_name: str, namespace: str = "/") -> None:
        """Nothing runs until :meth:`start`; the services go under ``namespace``
        (:mod:`openral_nodes.graph_names`)."""
        self.context = context
        self.node_name = f"{node_name}_safety"
        self.namespace = namespace
        self._node: Node | None = None
        self._spinner: Spinner | None = None

    def start(self, estop: Handler, release: Handler, reset: Handler) -> None:
        """Offer the three services, each answered by its handler on the safety thread."""
        node = Node(
            self.node_name,
            namespace=self.namespace,
            context=self.context,
            start_parameter_services=False,
        )
        for name, handler in ((ESTOP, estop), (RELEASE_ESTOP, release), (RESET, reset)):
            node.create_service(Trigger, graph_name(node, name), handler)
        spinner = Spinner(self.context)
        spinner.add_node(node)
        self._node, self._spinner = node, spinner.start()

    def stop(self) -> None:
        """Stop serving and join the thread (idempotent)."""
        spinner, self._spinner = self._spinner, None
        node, self._node = self._node, None
        if spinner is not None:
            spinner.stop()
        if node is not None:
            node.destroy_node()  # type: ignore[no-untyped-call]
