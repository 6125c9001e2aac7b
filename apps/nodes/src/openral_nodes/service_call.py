"""Call a service of the graph from a spun client node, with timeouts.

:func:`call_service` calls any service whose type belongs to one of
:data:`~openral_nodes.topic_graph.SERVICE_PACKAGES`; without a type named, it takes the one
the graph advertises. The request is filled like ``openral ros pub`` fills a message
(:mod:`openral_nodes.message_fill`), and checked before anything is sent.
:func:`call_trigger` is the ``std_srvs/srv/Trigger`` shortcut.

Each call waits up to ``timeout_s`` [s] for the service to appear (and its server to
match), then up to ``timeout_s`` more for the answer.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from openral_core.errors import OpenralError, did_you_mean, escaped
from rclpy.node import Node

from openral_nodes.message_fill import MessageValueError, build_message
from openral_nodes.topic_graph import POLL_S, service_class, topic_name

TRIGGER = "std_srvs/srv/Trigger"


class ServiceNotAnswered(OpenralError):
    """The service is not offered, or did not answer in time."""


@dataclass(frozen=True)
class ServiceAnswer:
    """A service's response and the type it was called as."""

    service: str
    type_name: str
    response: Any

    @property
    def failed(self) -> bool:
        """True when the response has a boolean ``success`` field that is false."""
        return getattr(self.response, "success", None) is False


def call_service(
    node: Node,
    service: str,
    type_name: str | None,
    values: Mapping[str, Any],
    timeout_s: float,
) -> ServiceAnswer:
    """Call ``service`` (``node`` is spun by the caller) with a request holding ``values``.

    Args:
        node: A node spun on another thread.
        service: Service name; relative names are made absolute.
        type_name: ``pkg/srv/Name``, or None to take the type the graph advertises.
        values: Request fields (see :func:`~openral_nodes.message_fill.build_message`).
        timeout_s: Wait for the service, then for its answer, each at most this long [s].

    Raises:
        TopicNameError: Not a valid service name.
        MessageTypeError: A type outside the allow-list, or not installed.
        MessageValueError: ``values`` do not fit the request.
        ServiceNotAnswered: Nobody offers ``service`` in time, or no answer came in time.
        OpenralError: The graph offers ``service`` with another type than ``type_name``.
    """
    name, request = checked_request(service, type_name, values)
    deadline = time.monotonic() + timeout_s
    advertised = _advertised_type(node, name, timeout_s, deadline)
    if type_name is not None and advertised != type_name:
        raise OpenralError(f"{name} is a {escaped(advertised)} service, not {escaped(type_name)}")
    cls = service_class(advertised, name)
    if request is None:
        request = _request(cls, advertised, values)
    response = _call(node, cls, name, request, timeout_s, deadline)
    return ServiceAnswer(name, advertised, response)


def checked_request(
    service: str, type_name: str | None, values: Mapping[str, Any]
) -> tuple[str, Any | None]:
    """``service``'s absolute name and, when ``type_name`` is given, the request holding
    ``values``: everything :func:`call_service` checks before it looks at the graph.

    Raises:
        TopicNameError, MessageTypeError, MessageValueError: as :func:`call_service`.
    """
    name = topic_name(service, service=True)
    if type_name is None:
        return name, None
    return name, _request(service_class(type_name, name), type_name, values)


def call_trigger(node: Node, service: str, timeout_s: float) -> Any:
    """The ``Trigger`` response of ``service`` (``node`` is spun by the caller).

    Raises:
        ServiceNotAnswered: Nobody offers ``service`` within ``timeout_s``, or no answer came
            within ``timeout_s`` more.
    """
    return call_service(node, service, TRIGGER, {}, timeout_s).response


def _request(cls: type[Any], type_name: str, values: Mapping[str, Any]) -> Any:
    """``cls``'s request holding ``values``; an error names the request as
    ``pkg/srv/Name request`` (message_fill calls every class ``pkg/msg/...``)."""
    try:
        return build_message(cls.Request, values)
    except MessageValueError as error:
        package, _, name = type_name.split("/")
        wrong = f"{package}/msg/{name}_Request"
        raise MessageValueError(str(error).replace(wrong, f"{type_name} request")) from None


def _advertised_type(node: Node, service: str, timeout_s: float, deadline: float) -> str:
    """The one type the graph advertises for ``service``, once it appears (by ``deadline``)."""
    while True:
        offered = dict(node.get_service_names_and_types())
        types = offered.get(service)
        if types and len(types) == 1:
            return str(types[0])
        if types:
            shown = ", ".join(map(escaped, types))
            raise OpenralError(f"{service} is offered with several types ({shown}); name one")
        if time.monotonic() >= deadline:
            hint = did_you_mean(service, offered)
            domain = node.context.get_domain_id()
            raise ServiceNotAnswered(
                f"nobody offers {service} within {timeout_s:g} s on ROS_DOMAIN_ID={domain}"
                f"{escaped(hint)} (is deploy sim running on this ROS domain?)"
            )
        time.sleep(POLL_S)


def _call(
    node: Node, cls: type[Any], service: str, request: Any, timeout_s: float, deadline: float
) -> Any:
    """``cls``'s response of ``service`` to ``request``: its server matched by ``deadline``,
    the answer within ``timeout_s`` after sending."""
    client = node.create_client(cls, service)
    try:
        if not client.wait_for_service(timeout_sec=max(deadline - time.monotonic(), 0.0)):
            raise ServiceNotAnswered(
                f"{service} is in the graph, but its server did not match within {timeout_s:g} s"
            )
        future = client.call_async(request)
        answer_by = time.monotonic() + timeout_s
        while not future.done():  # type: ignore[no-untyped-call]
            if time.monotonic() > answer_by:
                raise ServiceNotAnswered(f"{service} did not answer within {timeout_s:g} s")
            time.sleep(0.01)
        return future.result()  # type: ignore[no-untyped-call]
    finally:
        node.destroy_client(client)
