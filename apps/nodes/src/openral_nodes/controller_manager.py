"""The controller manager's services, as ros2_control's ``controller_manager`` offers them.

The graph runs fixed controllers (:class:`Controller`): ``joint_state_broadcaster``
(``/joint_states``, ``/dynamic_joint_states``), ``joint_trajectory_controller`` (its action,
``joint_trajectory`` topic and ``controller_state``) on a scene whose action is the manifest's
joints, and ``gripper_controller`` (``gripper_cmd``) on a robot with a parallel gripper.
Under ``/controller_manager`` (controller_manager_msgs):

- ``list_controllers``: each controller's name, type, state (``active`` or ``inactive``),
  update rate, the command interfaces it claims while active, the ones it needs, and the
  state interfaces it reads (``<joint>/position`` etc., URDF joint names);
- ``list_hardware_interfaces``: every joint's ``position`` command interface (claimed or
  not) and its ``position``, ``velocity`` and ``effort`` state interfaces;
- ``switch_controller``: activate and deactivate by name. STRICT refuses the whole switch,
  changing nothing, when a name is unknown, a controller to activate is active already or
  one to deactivate is not active; BEST_EFFORT (and 0, unset) skips those and does the
  rest; AUTO and FORCE_AUTO are taken as STRICT (no controller here is chained). The
  answer's ``message`` says what was done or why not. A deactivated controller stops as
  its ros2_control namesake does (see each one's ``switch`` callback).

No controller is loaded, unloaded or configured over ROS: the services for that are not
offered (the graph's controllers are the manifest's).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from controller_manager_msgs.msg import ControllerState, HardwareInterface
from controller_manager_msgs.srv import ListControllers, ListHardwareInterfaces, SwitchController
from openral_bridge.topics import CONTROLLER_MANAGER

if TYPE_CHECKING:
    from rclpy.node import Node

STATE_INTERFACES = ("position", "velocity", "effort")
"""The state interfaces of every joint."""
MAX_NAMES = 64
"""Most controller names one switch request may carry (bounded work per request)."""


@dataclass
class Controller:
    """One controller of the graph."""

    name: str
    type: str
    command_joints: tuple[str, ...]
    """Joints whose ``position`` command interface it claims while active."""
    state_joints: tuple[str, ...]
    """Joints whose state interfaces it reads."""
    switch: Callable[[bool], None] = field(default=lambda active: None)
    """Called with the new state on activation (True) and deactivation (False)."""
    active: bool = True

    @property
    def command_interfaces(self) -> list[str]:
        return [f"{joint}/position" for joint in self.command_joints]

    @property
    def state_interfaces(self) -> list[str]:
        return [f"{j}/{kind}" for j in self.state_joints for kind in STATE_INTERFACES]


class ControllerManager:
    """The three services over the graph's controllers (see the module doc)."""

    def __init__(
        self, node: Node, controllers: Sequence[Controller], joints: Sequence[str], rate_hz: float
    ) -> None:
        """Nothing is served until :meth:`create`.

        Args:
            node: The node that owns the services.
            controllers: The graph's controllers.
            joints: Every joint with hardware interfaces (URDF names).
            rate_hz: The update rate reported for every controller [Hz].
        """
        self.node, self.joints, self.rate_hz = node, tuple(joints), rate_hz
        self.controllers = {c.name: c for c in controllers}
        self.switches = 0
        """Switch requests answered ``ok``."""

    def create(self) -> list[tuple[str, Any]]:
        """Serve the three services; returns them as the node's entities."""
        node, prefix = self.node, CONTROLLER_MANAGER
        return [
            ("service", node.create_service(kind, f"{prefix}/{name}", callback))
            for kind, name, callback in (
                (ListControllers, "list_controllers", self._list),
                (ListHardwareInterfaces, "list_hardware_interfaces", self._interfaces),
                (SwitchController, "switch_controller", self._switch),
            )
        ]

    def is_active(self, name: str) -> bool:
        """True while controller ``name`` is active (False when there is none)."""
        controller = self.controllers.get(name)
        return controller is not None and controller.active

    def _list(self, request: Any, response: Any) -> Any:
        rate = max(0, min(65535, round(self.rate_hz)))
        response.controller = [
            ControllerState(
                name=c.name,
                state="active" if c.active else "inactive",
                type=c.type,
                update_rate=rate,
                claimed_interfaces=c.command_interfaces if c.active else [],
                required_command_interfaces=c.command_interfaces,
                required_state_interfaces=c.state_interfaces,
            )
            for c in self.controllers.values()
        ]
        return response

    def _interfaces(self, request: Any, response: Any) -> Any:
        claimed = {i for c in self.controllers.values() if c.active for i in c.command_interfaces}
        response.command_interfaces = [
            HardwareInterface(
                name=f"{j}/position",
                data_type="double",
                is_available=True,
                is_claimed=f"{j}/position" in claimed,
            )
            for j in self.joints
        ]
        response.state_interfaces = [
            HardwareInterface(name=f"{j}/{k}", data_type="double", is_available=True)
            for j in self.joints
            for k in STATE_INTERFACES
        ]
        return response

    def _switch(self, request: Any, response: Any) -> Any:
        activate, deactivate = (
            list(request.activate_controllers),
            list(request.deactivate_controllers),
        )
        strict = int(request.strictness) not in (0, SwitchController.Request.BEST_EFFORT)
        problems, todo = self._plan(activate, deactivate)
        if len(activate) + len(deactivate) > MAX_NAMES:
            problems, todo = [f"at most {MAX_NAMES} controller names per request"], []
        if problems and strict:
            response.ok, response.message = (
                False,
                "; ".join(problems) + " (STRICT: nothing switched)",
            )
            self._log().warning(f"switch_controller refused: {response.message}")
            return response
        for controller, state in todo:
            controller.active = state
            controller.switch(state)
        done = ", ".join(f"{'activated' if s else 'deactivated'} {c.name}" for c, s in todo)
        skipped = f"; skipped: {'; '.join(problems)}" if problems else ""
        response.ok, response.message = True, (done or "nothing to switch") + skipped
        self.switches += 1
        self._log().info(f"switch_controller: {response.message}")
        return response

    def _plan(
        self, activate: list[str], deactivate: list[str]
    ) -> tuple[list[str], list[tuple[Controller, bool]]]:
        """(what is wrong, (controller, new state) to do) of a switch request."""
        problems: list[str] = []
        todo: list[tuple[Controller, bool]] = []
        known = ", ".join(self.controllers)
        for names, state in ((deactivate, False), (activate, True)):
            for name in dict.fromkeys(names):
                controller = self.controllers.get(name)
                if controller is None:
                    problems.append(f"no controller {name!r} (this graph has {known})")
                elif controller.active == state:
                    problems.append(f"{name} is {'active' if state else 'inactive'} already")
                else:
                    todo.append((controller, state))
        return problems, todo

    def _log(self) -> Any:
        return self.node.get_logger()  # type: ignore[no-untyped-call]
