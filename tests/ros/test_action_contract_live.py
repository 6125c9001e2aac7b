"""The action contract, checked from outside the graph: ``openral deploy sim`` on the franka
and aloha default scenes as a subprocess, commanded on ``/openral/safe_action`` and read on
``/openral/action_spec`` and ``/joint_states`` by a client on a domain of its own.

How the graph advances (what the numbers below depend on): every action received is one
control period of the scene (50 ms of physics at ``control_freq_hz: 20``); once no action
has arrived for the idle hold (200 ms), the idle stepper steps the scene with the last
command at ``--camera-rate`` (10 Hz by default). An action published once is therefore
approached at 10 x 50 ms = 0.5 s of physics per wall second. The camera rate is left at its
default on purpose: it is the idle-step rate, so lowering it would slow physics, not free
CPU for it (every step renders the cameras whatever the publish rate).

``/joint_states`` stamps are simulation time (MuJoCo ``data.time``): each distinct stamp is
one scene step, so speeds are finite differences over distinct stamps (dt = 50 ms of sim
time; samples repeated between steps, at 50 Hz against 10 Hz steps, are dropped).

One deploy per robot: class-scoped, so the franka graph is stopped before the aloha one
starts and the two never share the two cores.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from openral_bridge.topics import ACTION_SPEC, MANIFEST_JOINT_STATES, SAFE_ACTION
from openral_core.loaded import open_robot_by_id
from openral_core.loader import load_scene
from openral_core.models import LimitedJoint
from openral_hal.factory import build_hal
from openral_hal.protocol import MujocoBacked
from openral_nodes.runtime import Spinner, claim_domain_id, ros_session
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64MultiArray

from tests.conftest import ROBOTS
from tests.ros.lifecycle_client import deploy_output, deploy_sim
from tests.ros.ros_helpers import FRANKA_SCENE, Probe, wait_until

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

ALOHA_SCENE = ROBOTS / "aloha" / "scenes" / "tabletop.yaml"
PARTS = 5
"""Ticks per control period on the tabletops (100 Hz state, 20 Hz actions)."""
START_WAIT_S = 90.0
"""Longest wait for deploy sim to load its scene and publish on a loaded machine [s]."""
MOVE_WAIT_S = 20.0
"""Longest wait for a commanded motion to be seen (a failure, not a bound) [s]."""
REACH_BOUND_S = 3.0
"""Wall time from publishing a +0.3 rad target to /joint_states within tolerance [s]."""
TOLERANCE_RAD = 0.01
SETTLE_SIM_S = 0.25
"""Simulation time observed after a target is reached (overshoot, settled value) [s]."""

FRANKA_CLOSED_BELOW, FRANKA_OPEN_ABOVE = 0.1, 0.8
"""Franka gripper thresholds (read mode sum_over_scale). MujocoArmHAL, sent the hold action
with the gripper slot 0.0 then 1.0, reads 0.097 / 0.007 / 0.000 after 0.25 / 0.5 / 1 s of
physics (closing) and 0.903 / 0.993 / 1.000 (opening): settled 0 and 1, so < 0.1 and > 0.8
are met within about half a second of physics each way."""

ALOHA_CLOSED_CMD, ALOHA_OPEN_CMD = 0.021, 0.057
"""Aloha gripper commands (write mode passthrough, metres): ctrl_range closed, open."""
ALOHA_MET_MIN, ALOHA_CLOSED_MAX, ALOHA_OPEN_MIN = 0.0218, 0.0230, 0.056
"""Aloha gripper readings (read mode passthrough: the canonical finger, metres). Commanded
closed, the canonical finger stops at 0.0224 m, short of its 0.021 target, because the
mirrored finger closes symmetrically and the two touch (finger contact at a 0.0448 m
opening). Were the mirror to stay put at its start (-0.024), the canonical finger would
reach 0.0210 (measured in MujocoArmHAL with the mirror's ctrl pinned): a settled closed
reading in [0.0218, 0.0230] is the outside evidence that the mirrored finger moved. Open
settles at 0.0570 (0.0559 after 0.5 s of physics)."""
MIRRORS = {"left_gripper": "vx300s_left/right_finger", "right_gripper": "vx300s_right/right_finger"}
"""The mirrored finger of each aloha gripper (README: each jaw is two slide fingers, the
canonical joint is the left finger, the right finger's actuator gets the negated command)."""


@dataclass(frozen=True)
class Sample:
    """One /joint_states reading of one joint: arrival (monotonic), stamp [s], q, qdot."""

    at: float
    stamp_s: float
    position: float
    velocity: float


@dataclass
class Graph:
    """A running deploy sim, seen and commanded from outside."""

    probe: Probe
    publisher: Any
    names: tuple[str, ...]
    commanded: np.ndarray
    """The action in force: the spec's hold action, then the last one sent."""
    control_period_s: float

    def position(self, joint: str) -> float:
        msg = self.probe.latest(MANIFEST_JOINT_STATES)
        return float(msg.position[list(msg.name).index(joint)])

    def send(self, **values: float) -> float:
        """Publish the action in force with ``values`` replaced; when it left [monotonic s]."""
        action = self.commanded.copy()
        for joint, value in values.items():
            action[self.names.index(joint)] = value
        self.commanded = action
        sent = time.monotonic()
        self.publisher.publish(Float64MultiArray(data=action.tolist()))
        return sent

    def samples(self, joint: str, start: float) -> list[Sample]:
        """Readings of ``joint`` since ``start``, one per scene step (distinct stamps)."""
        out: list[Sample] = []
        for r in self.probe.since(MANIFEST_JOINT_STATES, start):
            i = list(r.msg.name).index(joint)
            stamp = r.msg.header.stamp.sec + r.msg.header.stamp.nanosec * 1e-9
            if not out or stamp != out[-1].stamp_s:
                out.append(Sample(r.at, stamp, r.msg.position[i], r.msg.velocity[i]))
        return out

    def first(self, joint: str, start: float, holds: Callable[[float], bool], what: str) -> Sample:
        """Wait until ``joint`` satisfies ``holds``; the first reading since ``start`` that does."""
        try:
            self.probe.wait(lambda: holds(self.position(joint)), MOVE_WAIT_S, what)
        except pytest.fail.Exception as timeout:
            pytest.fail(f"{timeout}; {joint} reads {self.position(joint):.5f}")
        hit = next((s for s in self.samples(joint, start) if holds(s.position)), None)
        if hit is None:  # it held already before ``start``: nothing was measured
            pytest.fail(f"{what}: already true before the command ({self.position(joint):.5f})")
        return hit

    def settle(self, joint: str, start: float, after: Sample) -> list[Sample]:
        """Wait :data:`SETTLE_SIM_S` of simulation past ``after``; every step since ``start``."""
        until = after.stamp_s + SETTLE_SIM_S
        self.probe.wait(
            lambda: self.samples(joint, after.at)[-1].stamp_s >= until, MOVE_WAIT_S, "settling"
        )
        return self.samples(joint, start)


def finite_difference_speeds(samples: list[Sample]) -> list[float]:
    """|dq/dt| between consecutive scene steps, dt from the (simulation time) stamps."""
    return [abs(b.position - a.position) / (b.stamp_s - a.stamp_s) for a, b in pairwise(samples)]


@contextmanager
def live_graph(scene: Path, logs: Path) -> Iterator[Graph]:
    """deploy sim on ``scene`` in a domain of its own, with a probe and an action publisher."""
    domain = claim_domain_id()
    topics = {MANIFEST_JOINT_STATES: JointState, ACTION_SPEC: JointState}
    with (
        deploy_sim(scene, domain, logs) as process,
        ros_session(domain_id=domain) as context,
        Spinner(context) as spinner,
    ):
        probe = Probe(context, topics, name="contract_probe")
        spinner.add_node(probe.node)
        publisher = probe.node.create_publisher(Float64MultiArray, SAFE_ACTION, 10)
        try:
            probe.wait_count(ACTION_SPEC, 1, timeout_s=START_WAIT_S)
            probe.wait_count(MANIFEST_JOINT_STATES, 1, timeout_s=START_WAIT_S)
            wait_until(lambda: publisher.get_subscription_count() > 0, what="safe_action match")
            spec = probe.latest(ACTION_SPEC)
            options = load_scene(scene).scene.options
            assert options is not None and options.control_freq_hz is not None
            yield Graph(
                probe,
                publisher,
                tuple(spec.name),
                np.array(spec.position, dtype=np.float64),
                1.0 / options.control_freq_hz,
            )
            assert process.poll() is None, deploy_output(logs)[1]
        finally:
            spinner.stop()
            probe.node.destroy_node()  # type: ignore[no-untyped-call]


def manifest_joints(robot_id: str) -> tuple[str, ...]:
    return tuple(j.name for j in open_robot_by_id(robot_id).description.joints)


def franka_joint1() -> LimitedJoint:
    joint = open_robot_by_id("franka_panda").description.joints[0]
    assert isinstance(joint, LimitedJoint) and joint.name == "panda_joint1"
    return joint


@dataclass(frozen=True)
class Move:
    """One arm joint commanded to a target and watched until settled."""

    target: float
    reached: Sample
    """The first reading within :data:`TOLERANCE_RAD` of the target."""
    steps: list[Sample]
    """Every scene step from publishing until :data:`SETTLE_SIM_S` after ``reached``."""
    took_s: float
    """Wall time from publishing to ``reached`` arriving [s]."""
    peak_speed: float
    """Peak finite-differenced speed over ``steps`` [rad/s]."""
    limit: float
    """The joint's manifest velocity limit [rad/s]."""

    @classmethod
    def of(cls, graph: Graph, joint: LimitedJoint, target: float) -> Move:
        sent = graph.send(**{joint.name: target})
        reached = graph.first(
            joint.name,
            sent,
            lambda q: abs(q - target) <= TOLERANCE_RAD,
            f"{joint.name} within {TOLERANCE_RAD} rad of {target:.4f}",
        )
        steps = graph.settle(joint.name, sent, reached)
        peak = max(finite_difference_speeds(steps))
        return cls(target, reached, steps, reached.at - sent, peak, joint.velocity_limit)

    @property
    def numbers(self) -> str:
        start, sim_s = self.steps[0], self.reached.stamp_s - self.steps[0].stamp_s
        reported = max(abs(s.velocity) for s in self.steps)
        return (
            f"{start.position:.4f} -> {self.target:.4f} rad: within {TOLERANCE_RAD} in "
            f"{self.took_s:.3f} s wall ({sim_s:.3f} s sim); peak finite-differenced speed "
            f"{self.peak_speed:.5f} rad/s (limit {self.limit}); peak reported velocity "
            f"{reported:.4f} rad/s; settled at {self.steps[-1].position:.5f}"
        )


@pytest.fixture(scope="class")
def franka(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Graph]:
    """The franka default scene, once for :class:`TestFrankaPanda`."""
    with live_graph(FRANKA_SCENE, tmp_path_factory.mktemp("franka_deploy")) as graph:
        yield graph


@pytest.fixture(scope="class")
def aloha(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Graph]:
    """The aloha default scene, once for :class:`TestAloha` (after franka's has stopped)."""
    with live_graph(ALOHA_SCENE, tmp_path_factory.mktemp("aloha_deploy")) as graph:
        yield graph


class TestFrankaPanda:
    """robots/franka_panda/scenes/tabletop.yaml under deploy sim."""

    def test_action_spec_names_the_eight_manifest_joints_in_order(self, franka: Graph) -> None:
        joints = manifest_joints("franka_panda")
        assert len(joints) == 8
        assert franka.names == joints
        assert len(franka.commanded) == 8

    def test_a_0_3_rad_target_is_reached_within_3_s_below_the_velocity_limit(
        self, franka: Graph
    ) -> None:
        joint = franka_joint1()
        move = Move.of(franka, joint, franka.position(joint.name) + 0.3)
        print(move.numbers)
        ticks = np.diff([s.stamp_s for s in move.steps]) / (franka.control_period_s / PARTS)
        assert np.allclose(ticks, np.round(ticks), atol=1e-6), f"not sim time: {ticks}"
        assert move.took_s <= REACH_BOUND_S, move.numbers
        assert move.peak_speed <= joint.velocity_limit, move.numbers
        assert abs(move.steps[-1].position - move.target) <= TOLERANCE_RAD, move.numbers

    def test_a_2_5_rad_step_never_exceeds_the_velocity_limit(self, franka: Graph) -> None:
        joint = franka_joint1()
        lower, upper = joint.position_limits
        start = franka.position(joint.name)
        target = start + 2.5 if start + 2.5 <= upper else start - 2.5
        assert lower <= target <= upper, f"{start} +- 2.5 leaves [{lower}, {upper}]"
        move = Move.of(franka, joint, target)
        print(move.numbers)
        # No allowance: the stamps are exact simulation times and physics is deterministic,
        # so the 50 ms differences carry no noise. They cruise at 2.17492 rad/s, just under
        # the limit, because the set point moves at exactly the limit (the joint's own speed
        # ripples 2.07-2.21 rad/s inside each 10 ms set-point chunk, which 50 ms averages).
        assert move.peak_speed <= joint.velocity_limit, move.numbers
        # The set point cruises at the limit: the speed is limited, not merely slow.
        assert move.peak_speed >= 0.95 * joint.velocity_limit, move.numbers
        assert abs(move.steps[-1].position - target) <= TOLERANCE_RAD, move.numbers

    def test_the_gripper_closes_then_opens_in_write_mode_units(self, franka: Graph) -> None:
        finger = "panda_finger_joint1"
        readings: list[str] = []
        phases: list[tuple[float, Callable[[float], bool], str]] = [
            (0.0, lambda g: g < FRANKA_CLOSED_BELOW, f"< {FRANKA_CLOSED_BELOW}"),
            (1.0, lambda g: g > FRANKA_OPEN_ABOVE, f"> {FRANKA_OPEN_ABOVE}"),
        ]
        for command, holds, what in phases:
            before = franka.position(finger)
            sent = franka.send(panda_finger_joint1=command)
            reached = franka.first(finger, sent, holds, f"{finger} {what} after {command}")
            settled = franka.settle(finger, sent, reached)[-1].position
            readings.append(
                f"command {command}: {before:.4f} -> {what} in {reached.at - sent:.3f} s wall "
                f"({reached.position:.4f}), settled {settled:.4f}"
            )
            assert holds(settled), "; ".join(readings)
        print("; ".join(readings))


class TestAloha:
    """robots/aloha/scenes/tabletop.yaml under deploy sim."""

    def test_action_spec_names_the_fourteen_manifest_joints_in_order(self, aloha: Graph) -> None:
        joints = manifest_joints("aloha")
        assert len(joints) == 14
        assert aloha.names == joints

    def test_each_gripper_closes_on_its_mirrored_finger_then_opens_alone(
        self, aloha: Graph
    ) -> None:
        closed = {"left_gripper": ALOHA_CLOSED_CMD, "right_gripper": ALOHA_CLOSED_CMD}
        settled = self._move(aloha, closed, lambda g: g <= ALOHA_CLOSED_MAX)
        for gripper, reading in settled.items():
            assert ALOHA_MET_MIN <= reading <= ALOHA_CLOSED_MAX, (
                f"{gripper} closed at {reading:.5f} m: the fingers did not meet in the middle"
            )
        # One gripper opens while the other stays closed: each slot drives its own jaw.
        for opening, other in (
            ("left_gripper", "right_gripper"),
            ("right_gripper", "left_gripper"),
        ):
            before = aloha.position(other)
            self._move(aloha, {opening: ALOHA_OPEN_CMD}, lambda g: g >= ALOHA_OPEN_MIN)
            assert abs(aloha.position(other) - before) < 5e-4, f"{other} moved with {opening}"

    @staticmethod
    def _move(
        graph: Graph, command: dict[str, float], holds: Callable[[float], bool]
    ) -> dict[str, float]:
        """Send ``command``; wait until every commanded gripper's reading ``holds``; the
        readings after settling."""
        sent = graph.send(**command)
        out = {}
        for gripper, value in command.items():
            reached = graph.first(gripper, sent, holds, f"{gripper} after {value}")
            out[gripper] = graph.settle(gripper, sent, reached)[-1].position
            print(
                f"{gripper} command {value}: reading {reached.position:.5f} after "
                f"{reached.at - sent:.3f} s wall, settled {out[gripper]:.5f}"
            )
        return out


def finger_qpos(hal: MujocoBacked, fingers: dict[str, tuple[str, str]]) -> dict[str, list[float]]:
    """qpos of each gripper's (canonical, mirrored) finger joints, read from the MuJoCo data."""
    handles = hal.mujoco_handles()
    assert handles is not None
    model, data = handles
    joint = mujoco.mjtObj.mjOBJ_JOINT
    return {
        g: [float(data.qpos[model.jnt_qposadr[mujoco.mj_name2id(model, joint, n)]]) for n in pair]
        for g, pair in fingers.items()
    }


def test_aloha_mirrored_fingers_move_opposite_the_canonical_ones_in_the_native_scene() -> None:
    """The mirrored fingers are no manifest joints and the graph publishes nothing of them:
    the same commands through the scene's HAL in-process, read from the MuJoCo data."""
    robot = open_robot_by_id("aloha")
    hal = build_hal(robot, mode="sim", scene=load_scene(ALOHA_SCENE))
    assert isinstance(hal, MujocoBacked)
    hal.connect()
    try:
        names = list(hal.action_names)
        joints = {j.name: j.sim_joint_name or j.name for j in robot.description.joints}
        fingers = {g: (joints[g], MIRRORS[g]) for g in MIRRORS}
        start = finger_qpos(hal, fingers)
        grippers = [names.index(g) for g in MIRRORS]

        def command_both(value: float) -> dict[str, list[float]]:
            action = np.asarray(hal.hold_action(), dtype=np.float64)
            action[grippers] = value
            for _ in range(20):  # 1 s of physics at 20 Hz
                hal.send_action(action)
            return finger_qpos(hal, fingers)

        closed, open_ = command_both(ALOHA_CLOSED_CMD), command_both(ALOHA_OPEN_CMD)
        seen = f"(canonical, mirrored) qpos: start {start}, closed {closed}, open {open_}"
        print(seen)
        for g in MIRRORS:
            (c_closed, m_closed), (c_open, m_open) = closed[g], open_[g]
            assert c_open - c_closed > 0.03 and m_open - m_closed < -0.03, seen
            assert abs(m_closed + c_closed) < 5e-4 and abs(m_open + c_open) < 5e-4, seen
            assert ALOHA_MET_MIN <= c_closed <= ALOHA_CLOSED_MAX and c_open >= ALOHA_OPEN_MIN, seen
    finally:
        hal.disconnect()
