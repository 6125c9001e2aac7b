"""Tests for start_pose.py and JointDriver's reset: the keyframe, then ``sim.start_pose``."""

from __future__ import annotations

import mujoco
import numpy as np
from openral_core import open_robot
from openral_core.loaded import open_robot_by_id
from openral_core.loader import load_scene
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_mujoco.start_pose import set_start_pose
from openral_sim.native_scene import NativeScene

from tests.conftest import FRANKA, ROBOTS, ManifestWriter

SETTLED = 1e-3
"""rad a position servo may sit off its start pose after connect's settle steps."""


def _start_pose(robot_id: str) -> dict[str, float]:
    robot = open_robot_by_id(robot_id)
    assert robot.description.sim is not None and robot.description.sim.start_pose
    return robot.description.sim.start_pose


def test_the_ur10e_connects_and_resets_into_its_start_pose() -> None:
    pose = _start_pose("ur10e")
    hal = MujocoArmHAL.from_robot(open_robot_by_id("ur10e"))
    hal.connect()
    expected = np.array([pose[name] for name in hal.joint_names])
    np.testing.assert_allclose(hal.read_state().positions, expected, atol=SETTLED)
    np.testing.assert_array_equal(hal.hold_action(), expected)  # held there exactly
    moved = expected.copy()
    moved[0] -= 0.3
    hal.send_action(moved)
    hal.step(1000)
    assert hal.read_state().positions[0] < expected[0] - 0.25  # it left the start pose
    hal.reset()
    np.testing.assert_allclose(hal.read_state().positions, expected, atol=SETTLED)


FRANKA_START = (
    "  start_pose: {panda_joint1: 0.0, panda_joint2: -0.785398, panda_joint3: 0.0, "
    "panda_joint4: -2.356194, panda_joint5: 0.0, panda_joint6: 1.570796, panda_joint7: 0.785398}\n"
)
"""franka_panda's own start pose line (Franka's ready pose), replaced by one of one joint."""


def test_joints_left_out_of_the_start_pose_keep_the_keyframe(
    write_manifest: ManifestWriter,
) -> None:
    path = write_manifest(
        (FRANKA_START, "  start_pose: {panda_joint1: 0.5}\n"),
        base=FRANKA,
        folder="franka_panda",
    )
    hal = MujocoArmHAL.from_robot(open_robot(path))
    hal.connect()
    model, _ = hal.mujoco_handles()
    positions = hal.read_state().positions
    assert abs(positions[0] - 0.5) < SETTLED
    keyframe = model.key_qpos[0]
    others = [i for i, name in enumerate(hal.joint_names) if name.startswith("panda_joint")][1:]
    qpos = [hal.wiring.joint_qpos_addr[hal.joint_names[i]] for i in others]
    np.testing.assert_allclose(positions[others], keyframe[qpos], atol=SETTLED)
    assert keyframe[hal.wiring.joint_qpos_addr["panda_joint1"]] != 0.5


def test_set_start_pose_by_name_puts_the_joints_where_the_driver_does() -> None:
    """The model-only path (a scene framing its cameras) and the driver's reset agree."""
    hal = MujocoArmHAL.from_robot(open_robot_by_id("ur10e"))
    hal.connect()
    model, _ = hal.mujoco_handles()
    by_driver, by_name = mujoco.MjData(model), mujoco.MjData(model)
    hal.driver.reset_to_keyframe(model, by_driver)
    mujoco.mj_resetDataKeyframe(model, by_name, 0)
    set_start_pose(model, by_name, hal.description)
    np.testing.assert_array_equal(by_driver.qpos, by_name.qpos)
    assert not np.array_equal(by_name.qpos, model.key_qpos[0])


def test_a_native_scene_resets_into_the_start_pose() -> None:
    pose = _start_pose("ur10e")
    scene = load_scene(ROBOTS / "ur10e" / "scenes" / "tabletop.yaml")
    env = NativeScene(scene, open_robot(ROBOTS / "ur10e" / "robot.yaml"), render_observations=False)
    try:
        env.reset(0)
        state = env.joint_state()
        expected = np.array([pose[name] for name in state.names])
        np.testing.assert_allclose(state.positions, expected, atol=SETTLED)
    finally:
        env.close()
