"""The services, actions and nodes of the ROS graph: what ``openral ros services``,
``actions`` and ``nodes`` list.

Read, like the topics of :mod:`openral_nodes.topic_graph`, from rmw's discovery cache. An
action is what ros2cli calls one: a ``<name>/_action/feedback`` topic of type
``<pkg>/action/<Name>_FeedbackMessage`` makes action ``<name>`` of type
``<pkg>/action/<Name>`` (its ``_action/`` services and topics are hidden names).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from rclpy.node import Node

from openral_nodes.topic_graph import ACTION_FEEDBACK, is_hidden, settled

FEEDBACK_SUFFIX = "/_action/feedback"
"""What an action's feedback topic adds to the action's name."""


@dataclass(frozen=True)
class Interface:
    """A service or an action: its name and the type(s) peers advertise for it."""

    name: str
    types: tuple[str, ...]


@dataclass(frozen=True, order=True)
class NodeName:
    """A node as the graph reports it."""

    namespace: str
    name: str

    @property
    def full_name(self) -> str:
        """Namespace and name, e.g. ``/demo/peer`` (``/peer`` in the root namespace)."""
        return f"{self.namespace.rstrip('/')}/{self.name}"


@dataclass(frozen=True)
class GraphListing:
    """Every node (but the reader's), service and action in the graph, hidden ones too,
    each sorted by name."""

    nodes: tuple[NodeName, ...]
    services: tuple[Interface, ...]
    actions: tuple[Interface, ...]

    def shown(self, include_hidden: bool) -> GraphListing:
        """This listing without hidden nodes and services unless ``include_hidden``."""
        if include_hidden:
            return self
        return GraphListing(
            tuple(node for node in self.nodes if not is_hidden(node.full_name)),
            tuple(service for service in self.services if not is_hidden(service.name)),
            self.actions,
        )


def actions_of(topics: Iterable[tuple[str, Sequence[str]]]) -> tuple[Interface, ...]:
    """The actions whose feedback topics are among ``topics`` (names and types), by name."""
    actions = []
    for name, types in topics:
        if not name.endswith(FEEDBACK_SUFFIX):
            continue
        action_types = []
        for type_name in types:
            package, _, message = type_name.rpartition("/action/")
            if package and (match := ACTION_FEEDBACK.fullmatch(message)):
                action_types.append(f"{package}/action/{match.group(1)}")
        if action_types:
            actions.append(Interface(name.removesuffix(FEEDBACK_SUFFIX), tuple(action_types)))
    return tuple(sorted(actions, key=lambda action: action.name))


def read_listing(node: Node) -> GraphListing:
    """What ``node`` sees of the graph now, hidden names included."""
    own = NodeName(node.get_namespace(), node.get_name())
    names = (NodeName(namespace, name) for name, namespace in node.get_node_names_and_namespaces())
    services = node.get_service_names_and_types()
    return GraphListing(
        tuple(sorted(name for name in names if name != own)),
        tuple(Interface(name, tuple(types)) for name, types in sorted(services)),
        actions_of(node.get_topic_names_and_types()),
    )


def settled_listing(node: Node, *, wait_s: float, longest_s: float) -> tuple[GraphListing, float]:
    """The listing after ``wait_s`` of discovery, once it has stayed the same for
    :data:`~openral_nodes.topic_graph.SETTLED_S` with another node in it (or ``longest_s``
    in all, whatever it is then); and the seconds waited."""
    return settled(
        lambda: read_listing(node),
        wait_s=wait_s,
        longest_s=longest_s,
        found=lambda listing: bool(listing.nodes),
    )
