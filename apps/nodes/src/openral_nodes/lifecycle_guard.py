"""A ``change_state`` service that answers every request instead of crashing the executor.

rclpy 7.1's lifecycle node hands a ChangeState request's transition id straight to
``trigger_transition_by_id``; an id that is not valid in the current state (activate while
active, 42, 255) raises ``RCLError`` out of the service callback and ends the executor, and
with it the whole process. :func:`guard_change_state` puts a check in front of rclpy's own
callback: a request whose label (or, without a label, whose id) names a transition of the
current state runs as before; any other is answered ``success=false`` with a throttled
warning that names the request, the current state and the transitions it allows.

Example::

    node = MyLifecycleNode(...)
    guard_change_state(node, warn_every_s=2.0)  # once, right after construction
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.lifecycle import LifecycleNode

LABEL_SHOWN = 40
"""Characters of a requested label quoted in the warning (a hostile label can be long)."""

ServiceCallback = Callable[[Any, Any], Any]


def guard_change_state(node: LifecycleNode, warn_every_s: float) -> None:
    """Replace ``node``'s ChangeState service callback with a checked one (see module doc).

    Args:
        node: A lifecycle node created with its communication interface (the default).
        warn_every_s: Throttle of the refusal warning [s].
    """
    service = node._service_change_state
    original: ServiceCallback = service.callback
    service.callback = _checked(node, original, warn_every_s)


def _checked(
    node: LifecycleNode, original: ServiceCallback, warn_every_s: float
) -> ServiceCallback:
    machine = node._state_machine
    logger = node.get_logger()  # type: ignore[no-untyped-call]

    def refuse(response: Any, why: str) -> Any:
        logger.warning(f"change_state refused: {why}", throttle_duration_sec=warn_every_s)
        response.success = False
        return response

    def on_change_state(request: Any, response: Any) -> Any:
        state: str = machine.current_state[1]
        # (id, label, start id, start label, goal id, goal label) of each allowed transition
        allowed: dict[str, int] = {row[1]: row[0] for row in machine.available_transitions}
        label, transition_id = request.transition.label, request.transition.id
        shown = label if len(label) <= LABEL_SHOWN else f"{label[:LABEL_SHOWN]}…"
        asked = f"transition label {shown!r}" if label else f"transition id {transition_id}"
        valid = label in allowed if label else transition_id in allowed.values()
        if not valid:
            listed = ", ".join(f"{name} (id {tid})" for name, tid in allowed.items()) or "none"
            return refuse(response, f"{asked} is not valid in state {state}; valid: {listed}")
        try:
            return original(request, response)
        except Exception as error:  # RCLError from rcl, or a bug: answer, keep spinning
            return refuse(response, f"{asked} in state {state} failed: {error}")

    return on_change_state
