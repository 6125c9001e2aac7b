"""The rskill runner node: camera frames realigned to VLA slots in, policy actions out.

Frames arrive on ``/openral/cameras/<sensor>/image`` keyed by the manifest sensor name;
policies look them up by VLA slot (``camera1`` …). The two are joined through the
derived slot table of the loaded robot (``LoadedRobot.tables.vla_slots``: the table
``openral robot show`` prints and ``just schema-export`` writes under ``generated/``), so
the rule lives in one place.

Each tick (``rate_hz``) the node builds an :class:`~openral_eval.policies.Observation` from
the latest frames, ``/joint_states`` and the latched ``/openral/action_spec``, calls the
policy and publishes its action on ``/openral/safe_action`` (an ``ee_delta_pose`` or
``ee_pose`` policy's action first becomes joint targets:
:mod:`openral_nodes.graph_ee_actions`). With a namespace, every name lands under it, as
deploy's do. Until ``frame_timeout_s`` after start it waits for missing inputs; after that a
missing input (or a camera slot whose frames stopped for ``frame_timeout_s``) aborts the
runner: ``abort_error`` is set, the timer stops, and nothing more is published."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt
from geometry_msgs.msg import PoseStamped
from openral_bridge import topics
from openral_bridge.ros_messages import LATCHED
from openral_core import VlaSlot, open_robot_by_id
from openral_core.errors import OpenralError
from openral_eval import observation_keys as keys
from openral_eval.policies import Observation, PolicyAdapter, make_policy, parse_params
from openral_eval.policy import action_mode
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (
    qos_profile_sensor_data,
)
from sensor_msgs.msg import Image, JointState
from std_msgs.msg import Float64MultiArray

from openral_nodes.graph_ee_actions import GraphEeActions
from openral_nodes.graph_names import NamespacedEntities
from openral_nodes.topic_codec import image_to_rgb

T = TypeVar("T")


def realign_frames(frames: Mapping[str, T], slots: Sequence[VlaSlot]) -> dict[str, T]:
    """Re-key frames from sensor name to VLA slot; sensors outside the table are dropped."""
    return {entry.slot: frames[entry.sensor] for entry in slots if entry.sensor in frames}


def _slot_list(slots: Sequence[str]) -> str:
    return ", ".join(slots) if slots else "none"


class MissingSlots(OpenralError):
    """A policy's required camera slots are not provided (by the manifest or the graph)."""

    def __init__(
        self,
        policy: str,
        robot: str,
        expected: Sequence[str],
        seen: Sequence[str],
        table: Sequence[VlaSlot],
        where: str,
        hint: str = "",
    ) -> None:
        self.expected = tuple(expected)
        self.seen = tuple(seen)
        routes = ", ".join(f"{e.slot} <- {topics.camera_image(e.sensor)}" for e in table)
        super().__init__(
            f"policy {policy} needs camera slots ({_slot_list(expected)}) but {where} "
            f"({_slot_list(seen)}); {robot}: {routes or 'no RGB sensors'}{hint}"
        )


class RunnerAborted(OpenralError):
    """The runner stopped: an input never arrived or the policy misbehaved."""


@dataclass(frozen=True)
class RunnerStatus:
    """Snapshot of the runner for status displays."""

    state: str
    """``waiting``, ``running`` or ``aborted``."""
    seen_slots: tuple[str, ...]
    actions: int
    """Actions published so far."""


def runner_parameters(
    robot_id: str,
    *,
    policy: str = "wave",
    policy_params: Sequence[str] = (),
    rate_hz: float = 10.0,
    frame_timeout_s: float = 5.0,
) -> list[Parameter]:
    """Typed ``parameter_overrides`` for :class:`RskillRunnerNode`.

    An empty ``policy_params`` is left out: rclpy reads ``[]`` as a byte array.
    """
    values: list[tuple[str, Parameter.Type, object]] = [
        ("robot_id", Parameter.Type.STRING, robot_id),
        ("policy", Parameter.Type.STRING, policy),
        ("rate_hz", Parameter.Type.DOUBLE, float(rate_hz)),
        ("frame_timeout_s", Parameter.Type.DOUBLE, float(frame_timeout_s)),
    ]
    if policy_params:
        values.append(("policy_params", Parameter.Type.STRING_ARRAY, list(policy_params)))
    return [Parameter(n, t, v) for n, t, v in values]  # type: ignore[no-untyped-call]


def _refuse_off_graph(policy: PolicyAdapter, name: str) -> None:
    """Refuse, in one line, a policy a ROS graph cannot serve: one that reads the
    simulation itself, or one whose actions are not joint targets.

    Raises:
        RunnerAborted: Such a policy.
    """
    if policy.needs_privileged:
        raise RunnerAborted(
            f"policy {name} reads the simulation itself (privileged state); "
            "it runs in `openral sim sweep`, not on a ROS graph"
        )
    if action_mode(policy) not in ("joint_position", "ee_delta_pose", "ee_pose"):
        raise RunnerAborted(
            f"policy {name} acts in {action_mode(policy)}; on a ROS graph a policy acts in "
            "joint_position, ee_delta_pose or ee_pose; run it with `openral sim sweep`"
        )


class RskillRunnerNode(NamespacedEntities, Node):
    """Runs one policy against the openral topic contract (see the module docstring).

    ROS parameters: ``robot_id`` (str), ``policy`` (built-in policy name, default
    ``wave``), ``policy_params`` (``key=value`` strings), ``rate_hz`` (float, default 10.0),
    ``frame_timeout_s`` (float, default 5.0: covers DDS discovery, 0.02-3.5 s here).
    A ``policy`` object passed to the constructor replaces the ``policy`` and
    ``policy_params`` parameters (tests, embedding).
    """

    def __init__(
        self,
        *,
        context: Context | None = None,
        parameter_overrides: list[Parameter] | None = None,
        policy: PolicyAdapter | None = None,
        namespace: str = "",
    ) -> None:
        super().__init__(
            "rskill_runner",
            context=context,
            parameter_overrides=parameter_overrides,
            namespace=namespace,
        )
        robot_id = str(self.declare_parameter("robot_id", "").value)
        policy_name = str(self.declare_parameter("policy", "wave").value)
        params = self.declare_parameter("policy_params", Parameter.Type.STRING_ARRAY).value
        rate_hz = float(self.declare_parameter("rate_hz", 10.0).value)
        self.frame_timeout_s = float(self.declare_parameter("frame_timeout_s", 5.0).value)
        if rate_hz <= 0:
            raise RunnerAborted(f"rate_hz must be > 0, got {rate_hz:g}")
        robot = open_robot_by_id(robot_id)
        self.robot = robot.name
        self.slot_table = robot.tables.vla_slots
        self.policy = policy or make_policy(policy_name, parse_params(params or []))
        self.policy_name = policy_name if policy is None else type(policy).__name__
        _refuse_off_graph(self.policy, self.policy_name)
        provided = [entry.slot for entry in self.slot_table]
        if any(slot not in provided for slot in self.policy.required_slots):
            raise MissingSlots(
                self.policy_name,
                self.robot,
                self.policy.required_slots,
                provided,
                self.slot_table,
                "the manifest provides",
                "; pick another policy or set its required_slots parameter",
            )
        self._joint_names = [joint.name for joint in robot.description.joints]
        self._ee = None
        mode = action_mode(self.policy)
        if mode != "joint_position":  # the runner's own IK: module doc
            self._ee = GraphEeActions(robot, 1.0 / rate_hz, mode=mode)
        self._frames: dict[str, tuple[float, Any]] = {}
        self._joints: dict[str, float] = {}
        self._speeds: dict[str, float] = {}
        self._tcp: npt.NDArray[np.float64] | None = None
        """The latest ``/openral/tcp_pose`` (x, y, z, qw, qx, qy, qz in the base frame)."""
        self._spec: tuple[tuple[str, ...], npt.NDArray[np.float64]] | None = None
        self._started = time.monotonic()
        self._first_act: float | None = None
        self.abort_error: OpenralError | None = None
        self.status = RunnerStatus("waiting", (), 0)
        self._connect(rate_hz)

    def _connect(self, rate_hz: float) -> None:
        """Subscribe to the frames, joint states and action spec; publish actions each
        ``1 / rate_hz`` seconds."""
        for entry in self.slot_table:
            self.create_subscription(
                Image,
                topics.camera_image(entry.sensor),
                self._frame_callback(entry.sensor),
                qos_profile_sensor_data,
            )
        self.create_subscription(
            JointState, topics.JOINT_STATES, self._on_joint_state, qos_profile_sensor_data
        )
        self.create_subscription(JointState, topics.ACTION_SPEC, self._on_action_spec, LATCHED)
        self.create_subscription(PoseStamped, topics.TCP_POSE, self._on_tcp_pose, 10)
        self._publisher = self.create_publisher(Float64MultiArray, topics.SAFE_ACTION, 10)
        self._timer = self.create_timer(1.0 / rate_hz, self._tick)

    def _frame_callback(self, sensor: str) -> Callable[[Any], None]:
        def on_frame(msg: Any) -> None:
            self._frames[sensor] = (time.monotonic(), msg)

        return on_frame

    def _on_tcp_pose(self, msg: Any) -> None:
        p, q = msg.pose.position, msg.pose.orientation
        self._tcp = np.array([p.x, p.y, p.z, q.w, q.x, q.y, q.z])

    def _on_joint_state(self, msg: Any) -> None:
        self._joints.update(zip(msg.name, msg.position, strict=False))
        self._speeds.update(zip(msg.name, msg.velocity, strict=False))

    def _observation(self, by_slot: Mapping[str, Any], time_s: float) -> Observation:
        """The one observation (:mod:`openral_eval.observation_keys`) of the latest
        messages: joints in manifest order (NaN where not reported), frames by slot, and
        the TCP's pose once ``/openral/tcp_pose`` has said it (a robot with a ``sim.tcp``)."""
        assert self._spec is not None
        names = self._joint_names
        obs: Observation = {
            keys.STATE: np.array([self._joints.get(name, np.nan) for name in names]),
            keys.VELOCITY: np.array([self._speeds.get(name, np.nan) for name in names]),
            **{keys.image_key(slot): image_to_rgb(msg) for slot, msg in by_slot.items()},
        }
        if self._tcp is not None:
            obs[keys.TCP_POSE] = self._tcp.copy()
        obs[keys.ACTION_SPEC], obs[keys.TIME_S] = self._spec, time_s
        return obs

    def _on_action_spec(self, msg: Any) -> None:
        names, hold = tuple(msg.name), np.asarray(msg.position, dtype=np.float64)
        if len(names) != hold.size:
            self._abort(
                RunnerAborted(f"{topics.ACTION_SPEC}: {len(names)} names, {hold.size} holds")
            )
            return
        self._spec = (names, hold)

    def _tick(self) -> None:
        if self.abort_error is not None:
            return
        now = time.monotonic()
        fresh = {s: msg for s, (t, msg) in self._frames.items() if now - t <= self.frame_timeout_s}
        by_slot = realign_frames(fresh, self.slot_table)
        seen = tuple(by_slot)
        missing_slots = [s for s in self.policy.required_slots if s not in by_slot]
        if missing_slots or self._spec is None or not self._joints:
            self.status = RunnerStatus("waiting", seen, self.status.actions)
            if now - self._started > self.frame_timeout_s:
                self._abort(self._missing_input_error(missing_slots, seen))
            return
        if self._first_act is None:
            self._first_act = now
        try:
            obs = self._observation(by_slot, now - self._first_act)
            action = np.asarray(self.policy.act(obs), dtype=np.float64)
            if self._ee is not None:
                if not self._ee.started:
                    self._ee.start(self._spec[1], self._joints)
                action = self._ee.joint_action(action, self._joints)
        except OpenralError as error:
            self._abort(error)
            return
        except Exception as error:  # a policy bug must stop the runner, not the executor
            self._abort(RunnerAborted(f"policy raised {type(error).__name__}: {error}"))
            return
        width = len(self._spec[0])
        if action.shape != (width,) or not np.all(np.isfinite(action)):
            self._abort(
                RunnerAborted(
                    f"policy returned an action of shape {action.shape} (finite: "
                    f"{bool(np.all(np.isfinite(action)))}); the HAL expects {width} finite values"
                )
            )
            return
        self._publisher.publish(Float64MultiArray(data=action.tolist()))
        self.status = RunnerStatus("running", seen, self.status.actions + 1)

    def _missing_input_error(self, missing_slots: list[str], seen: tuple[str, ...]) -> OpenralError:
        domain = self.context.get_domain_id()
        graph_hint = f"; is `openral deploy sim` running on ROS_DOMAIN_ID={domain}?"
        nothing = not self._frames and self._spec is None and not self._joints
        if missing_slots:
            where = f"got frames within {self.frame_timeout_s:g} s only for"
            return MissingSlots(
                self.policy_name,
                self.robot,
                self.policy.required_slots,
                seen,
                self.slot_table,
                where,
                graph_hint if nothing else "",
            )
        absent = [
            topic
            for topic, ok in ((topics.ACTION_SPEC, self._spec), (topics.JOINT_STATES, self._joints))
            if not ok
        ]
        return RunnerAborted(
            f"no message on {' or '.join(absent)} within {self.frame_timeout_s:g} s{graph_hint}"
        )

    def _abort(self, error: OpenralError) -> None:
        self.abort_error = error
        self.status = RunnerStatus("aborted", self.status.seen_slots, self.status.actions)
        self._timer.cancel()  # type: ignore[no-untyped-call]
        self.get_logger().error(str(error))  # type: ignore[no-untyped-call]
