"""One contract on every path: the robot alone (MujocoArmHAL) and the robot inside its
native scene (build_hal → SimAttachedHAL → NativeScene) follow the same joint trajectory
for the same actions, and no path moves a set point faster than the manifest allows.

The comparison runs while nothing touches the scene's props (table, pedestal, floor,
objects: geoms named ``scene_*``); the first robot-prop contact ends it. The scenes render
no cameras here (pictures do not touch physics).

Excluded: the floating-base robots (g1, h1). Their own models have no floor and nothing
holds their base, so alone they fall freely from the first step, while in their scene they
are welded in place (or, unwelded, stand on the scene's floor — a prop): the two physics
differ by design before any action is sent. And the OpenArm, whose arms hang beside the
scene's pedestal: a random walk touches it within 2 to 5 actions, so an example would
compare next to nothing. And panda_mobile, whose arm stands on its mobile base in the scene:
the base's joints give a little under the arm's reactions (velocity servos against dry
friction; 4 µrad at the start pose already), so the arm on the base and the arm bolted to the
world differ by design. Their scene path is covered by the set-point test below (every
robot), by tests/sim and, for the OpenArm's grippers, by tests/hal.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from openral_core import robot_ids
from openral_core.loaded import LoadedRobot, open_robot_by_id
from openral_core.loader import load_scene
from openral_core.models import DeployScene, LimitedJoint
from openral_core.paths import robots_dir
from openral_hal.factory import build_hal
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.command_limits import CommandLimits
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.model_check import compile_robot_model
from openral_sim.native_scene import NativeScene

ACTIONS = 200
TOLERANCE_RAD = 1e-6
WALK_RAD = 0.1
"""Largest random change of an arm target from one action to the next."""
PULL = 0.1
"""Share of its distance from the start pose a target walks back each action (the walk
stays near the start, where the arm rarely reaches the table)."""
HOLD_STEPS = 25
"""Physics steps each action is held for; the scene runs one physics step per control
period, so a contact with a prop is seen at the step it happens."""
MIN_COMPARED = 5
"""Actions (of HOLD_STEPS physics steps each) that must be compared before a prop contact,
or the example says nothing (the OpenArm's hanging arms reach its pedestal soonest)."""


EXCLUDED = {
    "g1": "floating base",
    "h1": "floating base",
    "openarm": "arms hang at the pedestal",
    "panda_mobile": "arm on a mobile base",
}
COMPARED = [r for r in robot_ids() if r not in EXCLUDED]


def _scene(robot: LoadedRobot) -> DeployScene:
    scene = load_scene(robots_dir() / robot.name / "scenes" / "tabletop.yaml")
    model_file = robot_model_file(robot.description, robot.folder)
    timestep = compile_robot_model(robot.description, model_file).opt.timestep
    options = scene.scene.options
    assert options is not None
    per_step = options.model_copy(update={"control_freq_hz": 1.0 / timestep, "horizon": None})
    spec = scene.scene.model_copy(update={"cameras": [], "options": per_step})
    return scene.model_copy(update={"scene": spec})


def _touches_a_prop(model: mujoco.MjModel, data: mujoco.MjData) -> bool:
    def prop(geom: int) -> bool:
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom) or ""
        return name.startswith("scene_")

    contacts = data.contact[: data.ncon]
    return any(prop(g1) != prop(g2) for g1, g2 in zip(contacts.geom1, contacts.geom2, strict=True))


def _walk(robot: LoadedRobot, start: np.ndarray, seed: int) -> list[np.ndarray]:
    """ACTIONS valid actions: arm targets walk inside their limits, grippers jump anywhere
    inside their command range."""
    assert robot.tables.hal_wiring is not None
    limits = CommandLimits(robot.description, robot.tables.hal_wiring.grippers)
    grippers = {g.joint for g in robot.tables.hal_wiring.grippers}
    is_gripper = np.array([j.name in grippers for j in robot.description.joints])
    low = np.where(np.isfinite(limits.low), limits.low, start - np.pi)
    high = np.where(np.isfinite(limits.high), limits.high, start + np.pi)
    rng = np.random.default_rng(seed)
    action, actions = start.copy(), []
    for _ in range(ACTIONS):
        pull = PULL * (start - action)
        step = np.clip(action + pull + rng.uniform(-WALK_RAD, WALK_RAD, action.size), low, high)
        action = np.where(is_gripper, rng.uniform(low, high), step)
        actions.append(action)
    return actions


def _paths(robot_id: str) -> tuple[MujocoArmHAL, SimAttachedHAL, NativeScene]:
    robot = open_robot_by_id(robot_id)
    alone = MujocoArmHAL.from_robot(robot)
    attached = build_hal(robot, mode="sim", scene=_scene(robot))
    assert isinstance(attached, SimAttachedHAL) and isinstance(attached.env, NativeScene)
    alone.connect()
    attached.connect()
    return alone, attached, attached.env


def _hold_in_both(alone: MujocoArmHAL, attached: SimAttachedHAL, action: np.ndarray) -> bool:
    """Send ``action`` for HOLD_STEPS physics steps on both paths; True as soon as the
    robot touches a prop in the scene."""
    assert isinstance(attached.env, NativeScene)
    scene = attached.env
    for _ in range(HOLD_STEPS):
        alone.send_action(action)
        alone.step(1)
        attached.send_action(action)
        if _touches_a_prop(scene.model, scene.data):
            return True
    return False


@pytest.mark.parametrize("robot_id", COMPARED)
@settings(max_examples=2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1))
def test_alone_and_in_its_scene_the_robot_follows_one_trajectory(robot_id: str, seed: int) -> None:
    alone, attached, _ = _paths(robot_id)
    try:
        start = alone.read_state()
        np.testing.assert_allclose(
            attached.read_state().positions, start.positions, atol=TOLERANCE_RAD
        )
        np.testing.assert_array_equal(attached.hold_action(), alone.hold_action())
        compared = 0
        for action in _walk(alone.robot, alone.hold_action(), seed):
            if _hold_in_both(alone, attached, action):
                break
            gap = np.abs(attached.read_state().positions - alone.read_state().positions)
            assert gap.max() <= TOLERANCE_RAD, (compared, alone.joint_names[gap.argmax()], gap)
            compared += 1
        assert compared >= MIN_COMPARED, f"a prop was touched after {compared} actions"
    finally:
        alone.disconnect()
        attached.disconnect()


@pytest.mark.parametrize("robot_id", robot_ids())
@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), chunk=st.integers(1, 40))
def test_no_path_moves_a_set_point_faster_than_its_velocity_limit(
    robot_id: str, seed: int, chunk: int
) -> None:
    """Each arm joint's set point moves at most velocity_limit * dt per step, alone and in
    the scene; an out-of-range target is clamped onto the joint's limits."""
    alone, attached, scene = _paths(robot_id)
    robot = alone.robot
    joints = {j.name: j for j in robot.description.joints}
    arm = [n for n in alone.joint_names if n not in alone.grippers]
    vmax = np.array([joints[n].velocity_limit for n in arm])
    try:
        rng = np.random.default_rng(seed)
        for _ in range(3):
            wild = alone.hold_action() + rng.uniform(-10.0, 10.0, len(alone.joint_names))
            paths = ((alone, chunk, alone.driver), (attached, scene.substeps, scene.driver))
            for hal, steps, driver in paths:
                before = driver.setpoint
                hal.send_action(wild)
                if isinstance(hal, MujocoArmHAL):
                    hal.step(steps)
                dt = steps * scene.model.opt.timestep
                moved = np.abs(driver.setpoint - before)
                assert (moved <= vmax * dt * (1 + 1e-9) + 1e-12).all(), (arm, moved / dt, vmax)
                limited = [joints[n] for n in arm if isinstance(joints[n], LimitedJoint)]
                for joint in limited:  # inside, or on its way in from a start outside
                    slot = arm.index(joint.name)
                    value, was = driver.setpoint[slot], before[slot]
                    low, high = joint.position_limits
                    assert min(low, was) - 1e-9 <= value <= max(high, was) + 1e-9, joint.name
    finally:
        alone.disconnect()
        attached.disconnect()
