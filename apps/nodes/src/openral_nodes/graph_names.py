"""Where the graph's names land under ``deploy sim --namespace``.

The graph's names are absolute (``/joint_states``, ``/openral/estop``, ...: see
:mod:`openral_bridge.topics`), and ROS leaves absolute names out of a node's namespace. A
node started in namespace ``/arm`` puts every one of them under it (``/arm/joint_states``,
``/arm/controller_manager/list_controllers``), as a robot's driver launched in a namespace
does; in the root namespace they stay as they are. The frames keep their names (a
``frame_prefix`` is robot_state_publisher's business, not ours).
"""

from __future__ import annotations

from typing import Any, Protocol, cast

from openral_hal.unlocked_publisher import UnlockedPublisher


class Namespaced(Protocol):
    """Anything with a ROS namespace (a node)."""

    def get_namespace(self) -> str: ...


def graph_name(node: Namespaced, name: str) -> str:
    """``name`` under ``node``'s namespace when it is absolute (else as given)."""
    namespace = node.get_namespace().rstrip("/")
    return f"{namespace}{name}" if namespace and name.startswith("/") else name


class NamespacedEntities:
    """Mixin for a node class (before rclpy's ``Node`` in its bases): every publisher,
    subscription and service it creates under an absolute name lands under the
    node's namespace (:func:`graph_name`); its publishers let go of Python's lock while
    they send (:class:`~openral_hal.unlocked_publisher.UnlockedPublisher`)."""

    def _graph_name(self, name: str) -> str:
        return graph_name(cast(Namespaced, self), name)

    def create_publisher(self, msg_type: Any, topic: str, *args: Any, **kwargs: Any) -> Any:
        kwargs.setdefault("publisher_class", UnlockedPublisher)  # no graph-wide freeze
        return super().create_publisher(msg_type, self._graph_name(topic), *args, **kwargs)  # type: ignore[misc]

    def create_subscription(self, msg_type: Any, topic: str, *args: Any, **kwargs: Any) -> Any:
        return super().create_subscription(msg_type, self._graph_name(topic), *args, **kwargs)  # type: ignore[misc]

    def create_service(self, srv_type: Any, srv_name: str, callback: Any, **kwargs: Any) -> Any:
        return super().create_service(srv_type, self._graph_name(srv_name), callback, **kwargs)  # type: ignore[misc]


def namespaced_node(name: str, namespace: str, **kwargs: Any) -> Any:
    """A plain rclpy node named ``name`` whose absolute names land under ``namespace``
    (a client of a namespaced graph: :class:`NamespacedEntities`).

    Raises:
        rclpy's InvalidNamespaceException (and kin): A namespace ROS refuses.
    """
    from rclpy.node import Node

    class ClientNode(NamespacedEntities, Node):
        pass

    return ClientNode(name, namespace=namespace, **kwargs)
