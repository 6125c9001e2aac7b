"""ManifestLifecycleNode: one ROS 2 lifecycle node that runs any robot from its manifest.

Parameters (all read at configure):

- ``robot_id`` (str) or ``manifest_path`` (str): which robot; with neither, the robot the
  ``sim_env_yaml`` scene names. A ``manifest_path`` runs that file as it reads (not the
  repository's manifest of the same id); a scene naming another robot is refused;
- ``hal_mode`` (``sim`` | ``real``), ``sim_env_yaml`` (a deploy-scene file, ``""`` for none);
- ``viewer_enabled``; ``joint_state_rate_hz`` and ``camera_publish_rate_hz`` (0: each
  sensor's own) within :data:`RATE_RANGE_HZ`; ``view_port`` (0: no browser view).

Transitions:

- configure → load the robot and the scene file once, then ``build_hal`` with both (a bad
  manifest, scene or mode fails here with one message);
- activate → connect the HAL; a simulated one gets its control loop
  (:class:`~openral_bridge.control_loop.ControlLoop`), which steps once before anything is
  published and then once per control period, publishing ``/clock`` after each step (a real
  one's loop rides on its driver's cycle instead: :mod:`openral_nodes.control_loops`); then
  publish the latched ``/openral/action_spec`` and ``/joint_states`` (stamped in simulated
  time), take commands (``/openral/safe_action``, ``/openral/joint_trajectory``, the E-stop
  and ``/openral/reset`` services: :mod:`openral_nodes.command_interfaces`) and start the
  :class:`~openral_nodes.scene_bridges.SceneBridges` (cameras, depth and lidar, a mobile
  base's ``/cmd_vel`` and ``/odom``, the TCP's ``/openral/ee_target`` and
  ``/openral/tcp_pose``);
- deactivate → stop all of that (the HAL stays connected and holds still);
- cleanup / shutdown / error → also disconnect and drop the HAL; shutdown also sets the
  ``shutdown_event`` the owner passed, so a process can end when told to over ROS.

A ChangeState request the current state does not allow is answered ``success=false``
(:mod:`openral_nodes.lifecycle_guard`). With a namespace, every name of the graph goes under
it (:mod:`openral_nodes.graph_names`).

The command on ``/openral/safe_action`` (``std_msgs/Float64MultiArray``) is ``data`` = one
value per HAL action slot, in the order and meaning ``/openral/action_spec`` announces
(``sensor_msgs/JointState``: ``name`` = slot names, ``position`` = the hold action when
activated). A joint trajectory names manifest joints instead and is followed by the control
loop. Refused commands change nothing and are reported with a throttled warning. Run it on
a single-threaded executor only.

Threads: the periodic work (control tick and ``/clock``, ``/joint_states``, camera frame
requests, the viewer's sync) runs on one :class:`~openral_bridge.pacer.Pacer` thread per
activation, so the executor wakes only for actions and services. Whatever touches the HAL
holds :attr:`hal_lock`; deactivate stops and joins that thread before it removes anything.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from openral_bridge import ros_messages
from openral_bridge.control_loop import ControlLoop
from openral_bridge.frame_renderer import renderers_opened
from openral_bridge.joint_state_publisher import sim_stamp
from openral_bridge.pacer import PacedJob, Pacer
from openral_bridge.ros_messages import LATCHED
from openral_bridge.topics import ACTION_SPEC, CLOCK, TopicInfo
from openral_core import LoadedRobot
from openral_core.errors import OpenralError
from openral_core.models import RobotDescription
from openral_hal.errors import NotConnected
from openral_hal.factory import can_tick
from openral_hal.protocol import CycledHal, RobotHal
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState

from openral_nodes.command_interfaces import CommandInterfaces
from openral_nodes.control_loops import start_control_loop
from openral_nodes.graph_names import NamespacedEntities, graph_name
from openral_nodes.heap_freeze import HeapFreeze
from openral_nodes.lifecycle_guard import guard_change_state
from openral_nodes.node_parameters import BOUNDS, PARAMETERS, check_rates, configured_hal
from openral_nodes.robot_state_streams import RobotStateStreams, descriptions_before_connect
from openral_nodes.scene_bridges import SceneBridges

NODE_NAME = "openral_manifest_node"
WARN_EVERY_S = 2.0
RENDERERS_OPEN_S = 30.0
"""Longest wait for the cameras' renderers before a real driver's loop starts [s]."""
"""At most one warning per this many seconds for a stream of refused actions or
lifecycle transitions [s]."""

Result = TransitionCallbackReturn
"""Transition outcome (a pybind enum, typed Any; hence the ``-> Any`` of the callbacks)."""


class ManifestLifecycleNode(NamespacedEntities, LifecycleNode):
    """Any robot of ``robots/`` as a lifecycle node, through its HAL (see the module doc)."""

    def __init__(
        self,
        *,
        node_name: str = NODE_NAME,
        parameter_overrides: dict[str, Any] | None = None,
        log_boot_errors: bool = True,
        shutdown_event: threading.Event | None = None,
        **kwargs: Any,
    ) -> None:
        """Declare the parameters; ``parameter_overrides`` replaces their defaults.

        Args:
            node_name: ROS node name.
            parameter_overrides: Parameter values by name (see :data:`PARAMETERS`).
            log_boot_errors: Log why configure failed; off when the caller reports
                :attr:`boot_error` itself (the CLI), so the reason is printed once.
            shutdown_event: Set by the shutdown transition (from any state, also one
                requested over ROS), for an owner that should then end its process.
            kwargs: Passed to :class:`rclpy.lifecycle.LifecycleNode` (e.g. ``context``).

        Raises:
            ValueError: An override names no parameter of this node.
        """
        unknown = sorted(set(parameter_overrides or {}) - set(PARAMETERS))
        if unknown:
            raise ValueError(f"unknown parameters {unknown}; known: {sorted(PARAMETERS)}")
        overrides = [
            Parameter(k, value=v)  # type: ignore[no-untyped-call]
            for k, v in (parameter_overrides or {}).items()
        ]
        super().__init__(node_name, parameter_overrides=overrides, **kwargs)
        self.heap = HeapFreeze()  # the owner enables it (deploy sim)
        for name, default in PARAMETERS.items():
            self.declare_parameter(name, default)
        self.description: RobotDescription | None = None
        self.hal: RobotHal | None = None
        self.bridge: SceneBridges | None = None
        self.loop: ControlLoop | None = None
        """The control loop of a simulated HAL while active (None for a real one)."""
        self.pacer: Pacer | None = None
        """The thread of the periodic work while active."""
        self.states: RobotStateStreams | None = None
        """``/joint_states``, ``/tf`` and ``/robot_description`` while active."""
        self.hal_lock = threading.Lock()
        """Held by whatever reads or changes the HAL (see the module doc)."""
        self.log_boot_errors = log_boot_errors
        self.boot_error: str | None = None
        """Why the last configure failed (None after a successful one)."""
        self.commands: CommandInterfaces | None = None
        """Actions, trajectories, E-stop and reset while active."""
        self._loaded: LoadedRobot | None = None
        self._entities: list[tuple[str, Any]] = []
        self._shutdown_event = shutdown_event
        self._texts: tuple[str, str] | None = None
        guard_change_state(self, WARN_EVERY_S)

    # -- transitions -----------------------------------------------------------------------

    def on_configure(self, state: LifecycleState) -> Any:
        """Load the robot and scene once and build the HAL; FAILURE (stay unconfigured) with
        the reason."""
        try:
            self._check_rates()
            robot, self.hal = configured_hal({name: self._param(name) for name in PARAMETERS})
            self.description, self._loaded = robot.description, robot
        except (OpenralError, ValueError) as error:
            return self._fail_configure(str(error))
        except Exception as error:  # anything else is a bug; report it the same way
            return self._fail_configure(f"{type(error).__name__}: {error}")
        self.boot_error = None
        self._log().info(f"configured {robot.name} ({type(self.hal).__name__})")
        return Result.SUCCESS

    def on_activate(self, state: LifecycleState) -> Any:
        """Connect the HAL and start publishing, subscribing and serving; FAILURE (stay
        inactive) with :attr:`boot_error` set when the HAL does not connect."""
        try:
            hal = self._hal()
            if hal.is_real:  # both stall threads for tens of ms: before the driver starts
                self._texts = descriptions_before_connect(hal, self._loaded)
                self.heap.freeze()
            # The graph is built before a real driver's loop runs (building it held Python's
            # lock up to 137 ms). is_real first: isinstance reads control_period_s, which a
            # simulated HAL that is not connected cannot tell.
            if hal.is_real and isinstance(hal, CycledHal):
                hal.defer_cycle = True
            if not hal.connected:
                hal.connect()
        except Exception as error:  # a HAL or renderer failure; report it, stay inactive
            name = "" if isinstance(error, OpenralError) else f"{type(error).__name__}: "
            self.boot_error = text = f"{name}{error}"
            if self.log_boot_errors:
                self._log().error(f"activate failed: {text}")
            return Result.FAILURE
        priority, warn = int(self._param("loop_priority")), self._log().warning
        self.pacer = pacer = Pacer(on_error=self._job_failed, priority=priority, on_refused=warn)
        self._start_loop(hal, pacer)
        self._create_entities(pacer)
        self.bridge = SceneBridges(
            self,
            hal,
            pacer,
            self.hal_lock,
            viewer_enabled=bool(self._param("viewer_enabled")),
            camera_rate_hz=float(self._param("camera_publish_rate_hz")) or None,
            odom_rate_hz=float(self._param("joint_state_rate_hz")),
            loop=self.loop,
            robot=self._loaded,
            view_port=int(self._param("view_port")),
        )
        self.bridge.setup()
        # Making a renderer and a full collection each hold Python's lock for 60-370 ms:
        # both happen before the first tick, so the loop keeps its period from the start.
        renderers_opened(RENDERERS_OPEN_S)
        self.heap.freeze()
        if self.loop is not None:  # the pace is judged from here on, not over the start-up
            self.loop.watch.restart()
        pacer.start()
        if hal.is_real and isinstance(hal, CycledHal):
            hal.start_cycle()
        super().on_activate(state)
        return Result.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> Any:
        """Stop the bridge and every publisher, subscription, service and timer."""
        self._stop()
        super().on_deactivate(state)
        return Result.SUCCESS

    def on_cleanup(self, state: LifecycleState) -> Any:
        """Disconnect and drop the HAL."""
        self._release()
        return Result.SUCCESS

    def on_shutdown(self, state: LifecycleState) -> Any:
        """Stop everything, disconnect and set the owner's ``shutdown_event``."""
        self._release()
        if self._shutdown_event is not None:
            self._shutdown_event.set()
        return Result.SUCCESS

    def on_error(self, state: LifecycleState) -> Any:
        """Stop everything and disconnect; the node returns to unconfigured."""
        self._release()
        return Result.SUCCESS

    # -- what the node offers --------------------------------------------------------------

    @property
    def lifecycle_state(self) -> str:
        """Label of the current lifecycle state (rclpy 7 has no public accessor)."""
        label: str = self._state_machine.current_state[1]
        return label

    def topics(self) -> list[TopicInfo]:
        """Every topic published now, with its nominal rate (None: latched or on change)."""
        if not self._entities:
            return []
        rows = [TopicInfo(ACTION_SPEC, "sensor_msgs/msg/JointState", None)]
        rows = (self.states.topics() if self.states else []) + rows
        if self.loop is not None and self.hal is not None and can_tick(self.hal):
            rows.insert(0, TopicInfo(CLOCK, "rosgraph_msgs/msg/Clock", 1 / self.loop.tick_period_s))
        rows += self.commands.topics() if self.commands is not None else []
        rows += self.bridge.topics() if self.bridge else []
        return [replace(row, name=graph_name(self, row.name)) for row in rows]

    def action_layout(self) -> tuple[tuple[str, ...], list[float]]:
        """Slot names and hold action of the connected HAL (what ``action_spec`` carries)."""
        hal = self._hal()
        with self.hal_lock:
            hold: list[float] = np.asarray(hal.hold_action(), dtype=np.float64).tolist()
        return tuple(hal.action_names), hold

    @property
    def actions_accepted(self) -> int:
        """Valid actions taken while active (handed to the control loop, or a real HAL)."""
        return self.commands.accepted if self.commands is not None else 0

    @property
    def actions_refused(self) -> int:
        """Actions refused while active."""
        return self.commands.refused if self.commands is not None else 0

    # -- internals -------------------------------------------------------------------------

    def _log(self) -> Any:
        return self.get_logger()  # type: ignore[no-untyped-call]

    def _param(self, name: str) -> Any:
        return self.get_parameter(name).value

    def _check_rates(self) -> None:
        check_rates({name: self._param(name) for name in BOUNDS})

    def _hal(self) -> RobotHal:
        if self.hal is None:
            raise NotConnected("the node has no HAL; configure it first")
        return self.hal

    def _fail_configure(self, message: str) -> Any:
        self.boot_error = message
        if self.log_boot_errors:
            self._log().error(f"configure failed: {message}")
        self.description = self.hal = self._loaded = None
        return Result.FAILURE

    def _start_loop(self, hal: RobotHal, pacer: Pacer) -> None:
        """The HAL's control loop (:mod:`openral_nodes.control_loops`); a simulated one steps
        once now, so every message after this carries a simulated time > 0, and has
        ``/clock``."""
        self._entities = []
        if can_tick(hal):
            self._clock_pub = self.create_publisher(Clock, CLOCK, 10)
            self._entities = [("publisher", self._clock_pub)]
        self.loop = start_control_loop(
            self,
            hal,
            self.hal_lock,
            self._loaded,
            pacer,
            on_tick=self._publish_clock,
            on_reset=self._publish_sensors_now,
        )

    def _create_entities(self, pacer: Pacer) -> None:
        """The latched action spec, ``/joint_states`` (published once now), the action
        subscription and the E-stop services."""
        hal = self._hal()
        spec = self.create_publisher(JointState, ACTION_SPEC, LATCHED)
        names, hold = self.action_layout()
        spec_msg = JointState(name=list(names), position=hold)
        with self.hal_lock:
            sim_time_s = hal.read_state().sim_time_s
        spec_msg.header.stamp = sim_stamp(self, sim_time_s)
        spec.publish(spec_msg)
        rate_hz = float(self._param("joint_state_rate_hz"))
        tf = (bool(self._param("publish_tf")), bool(self._param("publish_static_tf")))
        loop, loaded, texts = self.loop, self._loaded, self._texts
        self.states = RobotStateStreams(self, hal, self.hal_lock, loop, rate_hz, loaded, tf, texts)
        self.states.start(pacer)
        rules = self.description.trajectory if self.description is not None else None
        self.commands = CommandInterfaces(
            self,
            hal,
            self.hal_lock,
            self.loop,
            warn_every_s=WARN_EVERY_S,
            rules=rules,
            robot=self._loaded,
        )
        self._entities += [("publisher", spec), *self.commands.create(self.states.states)]

    def _job_failed(self, job: PacedJob, error: Exception) -> None:
        """A periodic job raised (the pacer's thread goes on)."""
        text = f"{job.name} failed ({type(error).__name__}: {error})"
        self._log().error(text, throttle_duration_sec=WARN_EVERY_S)

    def _publish_sensors_now(self) -> None:
        """After a reset: every camera and range sensor shows the start state at once, and
        the static transforms are sent again."""
        if self.states is not None:
            self.states.after_reset()
        if self.bridge is not None:
            self.bridge.publish_now()

    def _publish_clock(self, sim_time: float | None) -> None:
        if sim_time is not None:
            self._clock_pub.publish(Clock(clock=ros_messages.stamp(sim_time)))

    def _stop(self) -> None:
        """Stop the periodic work (its thread joined first), then remove every entity."""
        self.heap.thaw()
        if self.pacer is not None:
            pacer, self.pacer = self.pacer, None
            if not pacer.stop():
                self._log().warning("the periodic work did not stop within its timeout")
        if self.commands is not None:  # its goals end before the loop that follows them
            self.commands.destroy()
        if self.loop is not None:
            self.loop.stop()
            self.loop = None
        if self.states is not None:
            self.states.stop()
            self.states = None
        if self.bridge is not None:
            self.bridge.teardown()
            self.bridge = None
        destroy: dict[str, Callable[[Any], object]] = {
            "publisher": self.destroy_publisher,
            "subscription": self.destroy_subscription,
            "service": self.destroy_service,
        }
        for kind, entity in reversed(self._entities):
            destroy[kind](entity)
        self._entities = []

    def _release(self) -> None:
        self._stop()
        if self.hal is not None and self.hal.connected:
            self.hal.disconnect()
        self.hal = None
        self.description = self._loaded = None
