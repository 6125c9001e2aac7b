"""RskillRunnerNode on real rclpy against a fake deploy-sim graph (see conftest)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pytest
from openral_core.errors import OpenralError
from openral_eval.policies import Observation
from openral_nodes.rskill_runner import (
    MissingSlots,
    RskillRunnerNode,
    RunnerAborted,
    runner_parameters,
)
from openral_nodes.runtime import ros_session

from tests.ros_runner.conftest import (
    COLOURS,
    DOMAIN_ID,
    FRAME_SHAPE,
    HOLD,
    JOINT_POSITIONS,
    RosHarness,
    wait_until,
)


class RecordingPolicy:
    """Keeps every observation and answers with the hold action."""

    required_slots = ("camera1", "camera2")
    needs_privileged = False

    def __init__(self) -> None:
        self.observations: list[Observation] = []

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        self.observations.append(obs)
        return obs["action_spec"][1]


def test_runner_keys_frames_by_vla_slot_and_passes_joints_and_spec(ros: RosHarness) -> None:
    ros.fake_graph()
    policy = RecordingPolicy()
    runner = RskillRunnerNode(
        context=ros.context, parameter_overrides=runner_parameters("franka_panda"), policy=policy
    )
    ros.add(runner)
    assert wait_until(lambda: len(policy.observations) >= 2), runner.status
    obs = policy.observations[-1]
    images = {key for key in obs if key.startswith("observation.images.")}
    assert images == {"observation.images.camera1", "observation.images.camera2"}
    for slot, sensor in (("camera1", "agentview"), ("camera2", "wrist")):
        frame = obs[f"observation.images.{slot}"]
        assert frame.shape == (*FRAME_SHAPE, 3) and frame.dtype == np.uint8
        assert (frame == COLOURS[sensor]).all(), f"{slot} does not show the {sensor} frame"
    assert np.allclose(obs["observation.state"], JOINT_POSITIONS)
    assert obs["observation.velocity"].shape == (len(JOINT_POSITIONS),)
    names, hold = obs["action_spec"]
    assert names[0] == "panda_joint1" and np.allclose(hold, HOLD)
    assert runner.status.state == "running" and runner.abort_error is None


def test_wave_runner_publishes_full_width_actions_waving_around_the_hold(
    ros: RosHarness,
) -> None:
    graph = ros.fake_graph()
    params = runner_parameters(
        "franka_panda",
        policy_params=["amplitude=0.25", "period_s=1.0", "action_slots=panda_joint2,panda_joint6"],
        rate_hz=20.0,
    )
    ros.add(RskillRunnerNode(context=ros.context, parameter_overrides=params))
    assert wait_until(lambda: len(graph.received()) >= 15)
    actions = np.array(graph.received())
    assert actions.shape[1] == len(HOLD)
    offsets = actions - HOLD
    waving = [1, 5]
    still = [i for i in range(len(HOLD)) if i not in waving]
    assert np.allclose(offsets[:, still], 0.0)
    assert np.allclose(offsets[:, 1], offsets[:, 5])  # one wave, two slots
    assert np.all(np.abs(offsets[:, waving]) <= 0.25 + 1e-9)
    assert offsets[:, 1].max() > 0.1 and offsets[:, 1].min() < -0.1  # it really swings


def test_runner_aborts_naming_expected_and_seen_slots_when_a_camera_is_silent(
    ros: RosHarness,
) -> None:
    graph = ros.fake_graph(cameras=("agentview",))
    params = runner_parameters("franka_panda", frame_timeout_s=4.0)
    runner = RskillRunnerNode(context=ros.context, parameter_overrides=params)
    ros.add(runner)
    assert wait_until(lambda: runner.abort_error is not None)
    error = runner.abort_error
    assert isinstance(error, MissingSlots)
    assert (error.expected, error.seen) == (("camera1", "camera2"), ("camera1",))
    assert str(error).startswith(
        "policy wave needs camera slots (camera1, camera2) but got frames within 4 s only for "
        "(camera1); franka_panda: camera1 <- /openral/cameras/agentview/image, "
    )
    assert "camera2 <- /openral/cameras/wrist/image" in str(error)
    assert runner.status.state == "aborted" and graph.received() == []


def test_runner_aborts_naming_the_silent_topic_when_the_action_spec_never_comes(
    ros: RosHarness,
) -> None:
    graph = ros.fake_graph(action_spec=False)
    params = runner_parameters("franka_panda", frame_timeout_s=4.0)
    runner = RskillRunnerNode(context=ros.context, parameter_overrides=params)
    ros.add(runner)
    assert wait_until(lambda: runner.abort_error is not None)
    assert isinstance(runner.abort_error, RunnerAborted)
    assert str(runner.abort_error) == (
        "no message on /openral/action_spec within 4 s; is `openral deploy sim` running on "
        f"ROS_DOMAIN_ID={DOMAIN_ID}?"
    )
    assert graph.received() == []


def test_runner_refuses_a_policy_whose_slots_the_manifest_lacks() -> None:
    with ros_session(DOMAIN_ID) as context, pytest.raises(MissingSlots) as caught:
        RskillRunnerNode(context=context, parameter_overrides=runner_parameters("g1"))
    assert str(caught.value) == (
        "policy wave needs camera slots (camera1, camera2) but the manifest provides (camera1); "
        "g1: camera1 <- /openral/cameras/head/image; "
        "pick another policy or set its required_slots parameter"
    )


class _EndEffectorPolicy:
    """A policy whose actions are end-effector deltas (7 values), not joint targets."""

    required_slots = ()
    needs_privileged = False
    action_mode = "ee_delta_pose"

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        return np.zeros(7)


def test_an_end_effector_policy_needs_a_robot_with_a_tool_centre_point() -> None:
    with ros_session(DOMAIN_ID) as context:
        node = RskillRunnerNode(
            context=context,
            parameter_overrides=runner_parameters("franka_panda"),
            policy=_EndEffectorPolicy(),
        )
        node.destroy_node()  # type: ignore[no-untyped-call]
        with pytest.raises(OpenralError) as caught:
            RskillRunnerNode(
                context=context,
                parameter_overrides=runner_parameters("ur5e"),
                policy=_EndEffectorPolicy(),
            )
    assert str(caught.value) == (
        "ur5e has no tool centre point (sim.tcp): ee_delta_pose actions need one"
    )
