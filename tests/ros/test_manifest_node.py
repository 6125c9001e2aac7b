"""Tests for manifest_node.py + sim_sensor_bridge.py: the franka default scene as a live graph."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from openral_bridge.topics import ACTION_SPEC, ESTOP, RELEASE_ESTOP, SAFE_ACTION
from openral_core.models import RgbSensor
from openral_mujoco.png import encode_png
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64MultiArray
from std_srvs.srv import Trigger

from tests.ros.ros_helpers import (
    CAMERAS,
    FRANKA_SCENE,
    PROBE_TOPICS,
    WAIT_S,
    Deployed,
    image_topic,
    info_topic,
    wait_until,
)

pytestmark = pytest.mark.exclusive  # real-time rates and latencies: run alone

CONTROL_PERIOD_S = 0.05
"""One scene step of the franka tabletop scene (control_freq_hz 20) [s]."""
CAMERA_HZ = 10.0
RATE_WINDOW_S = 3.0
STATE_HZ = 100.0
"""The scene's state rate: one tick every 0.01 s of simulated time."""
"""The franka tabletop's control rate [Hz]."""


def stamp_s(msg: Any) -> float:
    stamp = msg.clock if isinstance(msg, Clock) else msg.header.stamp
    return float(stamp.sec + stamp.nanosec * 1e-9)


def frame(msg: Any) -> np.ndarray:
    return np.frombuffer(bytes(msg.data), dtype=np.uint8).reshape(msg.height, msg.width, 3)


def call_trigger(deployed: Deployed, service: str) -> Any:
    client = deployed.probe.node.create_client(Trigger, service)
    try:
        assert client.wait_for_service(timeout_sec=WAIT_S), f"{service} is not offered"
        done = threading.Event()
        future = client.call_async(Trigger.Request())
        future.add_done_callback(lambda _: done.set())
        assert done.wait(WAIT_S), f"no answer from {service}"
        return future.result()
    finally:
        deployed.probe.node.destroy_client(client)


MANIFEST_STATES = "/openral/manifest_joint_states"


def test_deploy_publishes_joint_states_cameras_and_action_spec(deployed: Deployed) -> None:
    probe, description = deployed.probe, deployed.description
    for topic in [
        "/joint_states",
        ACTION_SPEC,
        *map(image_topic, CAMERAS),
        *map(info_topic, CAMERAS),
    ]:
        probe.wait_count(topic, 1)

    manifest_joints = [j.name for j in description.joints]
    probe.wait_count("/openral/manifest_joint_states", 1)

    def same_tick() -> bool:
        stamps = [probe.latest(t).header.stamp for t in ("/joint_states", MANIFEST_STATES)]
        return stamps[0] == stamps[1]

    probe.wait(same_tick, WAIT_S, "both joint-state views of one tick")
    joints = probe.latest("/joint_states")  # the URDF's joints, SI: the mimic finger too
    assert list(joints.name) == [*manifest_joints, "panda_finger_joint2"]
    assert all(math.isfinite(v) for v in joints.position)
    finger, mimic = joints.position[7], joints.position[8]
    # metres, both fingers; MuJoCo's limits are soft, so a finger rests up to a few nm past
    assert -1e-6 <= finger <= 0.04 + 1e-6 and abs(finger - mimic) < 1e-3
    manifest = probe.latest(MANIFEST_STATES)  # what a policy sees
    assert list(manifest.name) == manifest_joints
    assert list(manifest.position[:7]) == list(joints.position[:7])
    assert manifest.position[7] == pytest.approx((finger + mimic) / 0.08, abs=1e-9)  # read mode

    sensors = {s.name: s for s in description.sensors if isinstance(s, RgbSensor)}
    for camera in CAMERAS:
        image = probe.latest(image_topic(camera))
        assert (image.encoding, image.height, image.width) == ("rgb8", 128, 128)
        assert image.step == 128 * 3 and len(image.data) == 128 * 128 * 3
        assert image.header.frame_id == sensors[camera].frame_id
        info = probe.latest(info_topic(camera))
        assert info.header.frame_id == sensors[camera].frame_id
        assert (info.width, info.height) == (128, 128)
    wrist = probe.latest(info_topic("wrist"))  # mounted camera: the manifest's fovy_deg, 75
    assert wrist.k[0] == wrist.k[4] == 64.0 / math.tan(math.radians(75.0) / 2)

    spec = probe.latest(ACTION_SPEC)
    names, hold = deployed.spinner.call(deployed.node.action_layout)
    assert tuple(spec.name) == names and len(names) == 8
    assert list(spec.position) == hold


def test_camera_frames_come_at_most_at_10_hz_of_scene_time(deployed: Deployed) -> None:
    """Each camera's frames are stamped on ticks (0.01 s of simulated time at 100 Hz), in
    order, one per tick at most, and never more than 10 in any second of simulated time: a
    frame that comes due while the camera is still rendering waits for a later tick
    (:class:`~openral_sim.sensor_schedule.SensorSchedule`). How many frames a second
    this machine renders is a benchmark's question (``just bench-camera``), not this
    test's: the wall rate depends on the machine's load."""
    probe = deployed.probe
    start = time.monotonic()
    for camera in CAMERAS:
        probe.wait(
            lambda c=camera: any(
                r.at >= start + RATE_WINDOW_S for r in probe.messages[image_topic(c)]
            ),
            what=f"{RATE_WINDOW_S} s of {camera} frames",
        )
    tick = 1.0 / STATE_HZ
    for camera in CAMERAS:
        frames = [
            r for r in probe.since(image_topic(camera), start) if r.at <= start + RATE_WINDOW_S
        ]
        stamps = np.array([stamp_s(r.msg) for r in frames])
        ticks = np.diff(stamps) / tick
        wall = (len(frames) - 1) / (frames[-1].at - frames[0].at)
        print(f"{camera}: {len(frames)} frames, {wall:.2f} Hz of wall time")
        assert len(frames) >= RATE_WINDOW_S * CAMERA_HZ / 4, f"{camera}: {len(frames)} frames"
        assert np.allclose(ticks, np.round(ticks), atol=1e-3), f"{camera}: off the ticks {stamps}"
        assert np.all(ticks >= 1.0 - 1e-3), f"{camera}: a tick sent two frames: {stamps}"
        within_1_s = [np.sum((stamps >= t) & (stamps < t + 1.0 - 1e-6)) for t in stamps]
        assert max(within_1_s) <= CAMERA_HZ + 1, f"{camera}: over 10 Hz of scene time: {stamps}"


def test_idle_scene_advances_and_estop_freezes_it(deployed: Deployed) -> None:
    probe, topic = deployed.probe, image_topic("agentview")
    # Idle (no action ever sent): the control loop advances the scene, one control period a
    # tick, and the settling scene looks different from one frame to the next.
    probe.wait(
        lambda: any(stamp_s(r.msg) >= 1.0 for r in probe.messages[topic]),
        what="agentview frames up to 1 s of simulated time",
    )
    early = [r.msg for r in probe.since(topic, 0.0) if stamp_s(r.msg) <= 1.0]
    stamps = [stamp_s(m) for m in early]
    assert stamps == sorted(stamps) and stamps[-1] - stamps[0] >= 0.3, stamps
    assert len({frame(m).tobytes() for m in early}) >= 2, "idle frames never changed"
    assert deployed.node_stats()["ticks"] > 0

    answer = call_trigger(deployed, ESTOP)
    assert answer.success and "latched" in answer.message
    frozen = probe.wait_count(topic, 6, start=time.monotonic())[1:]  # the first may predate it
    assert len({stamp_s(r.msg) for r in frozen}) == 1, "simulated time advanced while E-stopped"
    assert len({frame(r.msg).tobytes() for r in frozen}) == 1

    assert call_trigger(deployed, RELEASE_ESTOP).success
    held = stamp_s(frozen[-1].msg)
    probe.wait(
        lambda: stamp_s(probe.messages[topic][-1].msg) > held,
        what="the scene to advance again after release",
    )


def test_actions_move_the_arm_and_the_loop_keeps_its_pace(deployed: Deployed) -> None:
    probe = deployed.probe
    probe.wait_count(ACTION_SPEC, 1)
    spec = probe.latest(ACTION_SPEC)
    hold = np.array(spec.position)
    publisher = probe.node.create_publisher(Float64MultiArray, SAFE_ACTION, 10)
    wait_until(
        lambda: publisher.get_subscription_count() > 0, what="the node's action subscription"
    )

    # Malformed actions are refused and change nothing.
    before = deployed.node_stats()
    publisher.publish(Float64MultiArray(data=[0.0, 0.0, 0.0]))
    publisher.publish(Float64MultiArray(data=[*hold[:-1], math.nan]))
    wait_until(lambda: deployed.node_stats()["refused"] >= before["refused"] + 2, what="refusals")
    assert deployed.node_stats()["accepted"] == before["accepted"]

    # A stream at 20 Hz (the scene's control rate) moves joint 1, one action per tick.
    start_q1 = probe.latest("/joint_states").position[0]
    target = hold.copy()
    target[0] += 0.4
    timer = deployed.spinner.call(
        lambda: probe.node.create_timer(
            0.05, lambda: publisher.publish(Float64MultiArray(data=target.tolist()))
        )
    )
    try:
        wait_until(
            lambda: deployed.node_stats()["applied"] >= before["applied"] + 3,
            what="actions applied",
        )
        streaming = deployed.node_stats()
        probe.wait(
            lambda: probe.latest("/joint_states").position[0] > start_q1 + 0.2,
            what="panda_joint1 to follow the commanded +0.4 rad",
        )
        wait_until(
            lambda: deployed.node_stats()["applied"] >= streaming["applied"] + 20,
            what="20 more actions",
        )
        during = deployed.node_stats()
        applied = during["applied"] - streaming["applied"]
        ticks = during["ticks"] - streaming["ticks"]
        assert applied <= ticks, "more actions applied than ticks"
        late = during["superseded"] - streaming["superseded"]
        pending = during["accepted"] - streaming["accepted"] - applied - late
        assert pending in (-1, 0, 1), "an accepted action was neither applied nor superseded"
    finally:
        deployed.spinner.call(probe.node.destroy_timer, timer)
    stopped = deployed.node_stats()
    wait_until(lambda: deployed.node_stats()["ticks"] > stopped["ticks"] + 5, what="hold ticks")
    assert deployed.node_stats()["applied"] <= stopped["applied"] + 1  # one may be pending
    probe.node.destroy_publisher(publisher)


def test_sim_run_and_deploy_show_the_same_frames_for_the_same_seed(
    deployed: Deployed, tmp_path: Path
) -> None:
    steps = 60
    openral = Path(sys.executable).parent / "openral"
    command = [
        str(openral),
        "sim",
        "run",
        "--config",
        str(FRANKA_SCENE),
        "--steps",
        str(steps),
        "--motion",
        "hold",
        "--out",
        str(tmp_path),
    ]
    subprocess.run(
        command,
        check=True,
        capture_output=True,
        env={**os.environ, "MUJOCO_GL": "egl"},
        timeout=120,
    )
    for camera in CAMERAS:
        # The first stepped frame the probe caught at the end of a control period (a frame
        # shows the newest state, which may be a part of a period: 100 Hz state, 20 Hz
        # control); its simulated-time stamp says which step (connect settles the scene for a
        # few physics steps, far less than a control period).
        periods = [
            stamp_s(r.msg) / CONTROL_PERIOD_S
            for r in deployed.probe.since(image_topic(camera), 0.0)
        ]
        stepped = [
            r.msg
            for r, at in zip(deployed.probe.since(image_topic(camera), 0.0), periods, strict=True)
            if at > 0.5 and abs(at - round(at)) < 0.1
        ]
        assert stepped, f"no {camera} frame after the first step was received"
        first = min(stepped, key=stamp_s)
        step = round(stamp_s(first) / CONTROL_PERIOD_S) - 1
        assert step < steps, (
            f"{camera}: first frame received is from step {step}; discovery too slow"
        )
        expected = (tmp_path / f"{camera}_{step:04d}.png").read_bytes()
        assert encode_png(frame(first)) == expected, f"{camera} frame of step {step} differs"


def test_no_message_carries_a_zero_stamp(deployed: Deployed) -> None:
    """The loop steps before anything is published: the first 100 messages of every topic
    (action_spec and /clock too) are stamped in simulated time above zero."""
    probe = deployed.probe
    for topic in PROBE_TOPICS:
        probe.wait_count(topic, 1)
    for topic, received in probe.messages.items():
        stamps = [stamp_s(r.msg) for r in received[:100]]
        assert stamps and min(stamps) > 0.0, f"{topic}: a zero stamp among {stamps[:5]}"


def test_a_use_sim_time_node_reads_the_time_of_the_stamps(deployed: Deployed) -> None:
    reader = Node(
        "sim_time_reader",
        context=deployed.probe.node.context,
        parameter_overrides=[Parameter("use_sim_time", value=True)],  # type: ignore[no-untyped-call]
    )
    deployed.spinner.add_node(reader)
    try:
        wait_until(lambda: reader.get_clock().now().nanoseconds > 0, what="/clock to arrive")
        deployed.probe.wait_count("/joint_states", 2, start=time.monotonic())
        now_s = reader.get_clock().now().nanoseconds / 1e9
        latest_s = stamp_s(deployed.probe.latest("/joint_states"))
        assert abs(now_s - latest_s) < 0.25, (now_s, latest_s)  # a few 50 ms control periods
    finally:
        deployed.spinner.remove_node(reader)
        reader.destroy_node()
