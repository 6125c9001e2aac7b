"""SimAttachedHAL (ADR-0034 scene attach; a control loop ticks it, see
``tests/bridge/test_control_loop.py``); build_hal is tested in ``test_build_hal.py``.

Two honest fakes stand in for scene backends: a tiny MuJoCo arm whose joints carry
robosuite's ``robot0_`` prefix and whose fixed camera really renders, and a non-MuJoCo
backend that only reports ``obs.joints``.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from openral_core.loaded import loaded_robot, open_robot_by_id

os.environ.setdefault("MUJOCO_GL", "egl")

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_core.errors import ManifestError
from openral_core.loader import load_robot
from openral_core.models import RobotDescription
from openral_hal.errors import ActionRejected, ConfigurationError, EStopLatched
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.state import JointStateSample
from openral_sim.observation import Observation, Outcome, StepResult
from openral_sim.rollout import SimRollout

from tests.sim_attach.fake_arm import write_fake_arm

ARM_XML = """\
<mujoco>
  <option timestep="0.005" gravity="0 0 -9.81"/>
  <worldbody>
    <light pos="0 -1 3" dir="0 0.3 -1"/>
    <geom type="plane" size="3 3 0.1" rgba="0.2 0.2 0.25 1"/>
    <camera name="agentview" pos="0.3 -2.2 0.9" xyaxes="1 0 0 0 0 1"/>
    <body name="link1" pos="0 0 1">
      <joint name="robot0_joint1" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.06" rgba="0.9 0.1 0.1 1"/>
      <body name="link2" pos="0.5 0 0">
        <joint name="robot0_joint2" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.05" rgba="0.1 0.9 0.1 1"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="m1" joint="robot0_joint1"/>
    <motor name="m2" joint="robot0_joint2"/>
  </actuator>
</mujoco>
"""
"""Two links held out horizontally: under gravity and a zero torque they swing down."""


class MujocoArmRollout:
    """A real MuJoCo scene: two torque-driven hinges and one rendered fixed camera."""

    def __init__(self, horizon: int | None = None, substeps: int = 10) -> None:
        self.model = mujoco.MjModel.from_xml_string(ARM_XML)
        self.data = mujoco.MjData(self.model)
        self.renderer = mujoco.Renderer(self.model, 32, 32)
        self.horizon = horizon
        self.substeps = substeps
        self.resets: list[int | None] = []
        self.actions: list[npt.NDArray[Any]] = []
        self.closed = False
        self._steps = 0

    @property
    def action_dim(self) -> int | None:
        return int(self.model.nu)

    @property
    def camera_names(self) -> tuple[str, ...]:
        return ("agentview",)

    @property
    def camera_models(self) -> dict[str, str]:
        return {"agentview": "agentview"}

    @property
    def control_period_s(self) -> float:
        return self.substeps * float(self.model.opt.timestep)

    def reset(self, seed: int | None = None) -> Observation:
        self.resets.append(seed)
        mujoco.mj_resetData(self.model, self.data)
        mujoco.mj_forward(self.model, self.data)
        self._steps = 0
        return self._observe()

    def step(self, action: npt.NDArray[np.floating[Any]]) -> StepResult:
        self.actions.append(np.array(action))
        self.data.ctrl[:] = action
        mujoco.mj_step(self.model, self.data, nstep=self.substeps)
        self._steps += 1
        done = self.horizon is not None and self._steps >= self.horizon
        return StepResult(self._observe(), Outcome(terminated=done))

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        return self.model, self.data

    def close(self) -> None:
        self.renderer.close()
        self.closed = True

    def _observe(self) -> Observation:
        self.renderer.update_scene(self.data, camera="agentview")
        image = self.renderer.render().copy()
        return Observation(time_s=float(self.data.time), images={"agentview": image})


class NonMujocoRollout:
    """A backend without MuJoCo: reports joint positions (or not) and a counter image."""

    def __init__(self, n_positions: int | None = 2, action_dim: int | None = 3) -> None:
        self.n_positions = n_positions
        self._action_dim = action_dim
        self.resets = 0
        self.actions: list[npt.NDArray[Any]] = []

    @property
    def action_dim(self) -> int | None:
        return self._action_dim

    @property
    def camera_names(self) -> tuple[str, ...]:
        return ("agentview",)

    @property
    def camera_models(self) -> dict[str, str]:
        return {}  # nothing MuJoCo renders here

    @property
    def control_period_s(self) -> float:
        return 0.05

    def reset(self, seed: int | None = None) -> Observation:
        self.resets += 1
        return self._observe()

    def step(self, action: npt.NDArray[np.floating[Any]]) -> StepResult:
        self.actions.append(np.array(action))
        return StepResult(self._observe())

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        return None

    def close(self) -> None:
        pass

    def _observe(self) -> Observation:
        tick = len(self.actions)
        images = {"agentview": np.full((4, 4, 3), tick, dtype=np.uint8)}
        joints = None
        if self.n_positions is not None:
            positions = np.arange(1, self.n_positions + 1, dtype=np.float64) + tick
            names = tuple(f"j{i}" for i in range(self.n_positions))
            zeros = np.zeros(self.n_positions)
            joints = JointStateSample(names, positions, zeros, zeros, stamp_ns=0)
        return Observation(time_s=0.05 * tick, joints=joints, images=images)


@pytest.fixture
def fake_arm(tmp_path: Path) -> RobotDescription:
    return load_robot(write_fake_arm(tmp_path))


@pytest.fixture
def arm_env() -> Iterator[Callable[..., MujocoArmRollout]]:
    """Factory of MuJoCo fakes; every one is closed (its EGL context freed) afterwards."""
    made: list[MujocoArmRollout] = []

    def make(**kwargs: Any) -> MujocoArmRollout:
        made.append(MujocoArmRollout(**kwargs))
        return made[-1]

    yield make
    for env in made:
        if not env.closed:
            env.close()


def _attached(description: RobotDescription, env: SimRollout, **kwargs: Any) -> SimAttachedHAL:
    hal = SimAttachedHAL(env, loaded_robot(description), **kwargs)
    hal.connect()
    return hal


def _frame(hal: SimAttachedHAL) -> npt.NDArray[np.uint8]:
    return hal.read_images()["agentview"].copy()


# -- the MuJoCo path ---------------------------------------------------------------------


def test_fakes_satisfy_the_rollout_protocol(arm_env: Callable[..., MujocoArmRollout]) -> None:
    env = arm_env()
    assert isinstance(env, SimRollout) and isinstance(NonMujocoRollout(), SimRollout)
    env.close()


def test_read_state_finds_prefixed_joints_by_name(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env()
    hal = _attached(fake_arm, env, env_reset_seed=5)
    assert env.resets == [5] and hal.action_dim == 2
    hal.send_action([0.3, -0.2])
    state = hal.read_state()
    assert state.names == ("joint1", "joint2")
    np.testing.assert_array_equal(state.positions, env.data.qpos[:2])
    np.testing.assert_array_equal(state.velocities, env.data.qvel[:2])
    np.testing.assert_allclose(state.efforts, [0.3, -0.2])  # qfrc_actuator of the motors
    assert state.sim_time_s is not None and state.sim_time_s > 0
    assert state.sim_time_s == pytest.approx(env.data.time)
    hal.disconnect()
    assert env.closed


def test_read_images_gives_rendered_manifest_cameras_only(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    hal = _attached(fake_arm, arm_env())
    images = hal.read_images()
    assert set(images) == {"agentview"}  # the manifest's "wrist" is not rendered
    assert images["agentview"].shape == (32, 32, 3) and images["agentview"].dtype == np.uint8
    assert images["agentview"].std() > 1, "the camera frame is blank"


def test_a_joint_missing_from_the_scene_fails_at_connect(
    arm_env: Callable[..., MujocoArmRollout],
) -> None:
    env = arm_env()
    hal = SimAttachedHAL(env, open_robot_by_id("franka_panda"))
    with pytest.raises(ManifestError) as error:
        hal.connect()
    (issue,) = error.value.issues
    assert issue.field == "joints" and issue.file.name == "robot.yaml" and issue.line > 1
    message = issue.message
    for missing in ("joint3", "joint7", "finger_joint1"):
        assert missing in message
    assert "robot0_joint1" in message  # a few available names are listed
    assert not hal.connected


def test_a_tick_without_an_action_advances_the_rendered_frame(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env()
    hal = _attached(fake_arm, env)
    before, start = _frame(hal), hal.read_state()
    for _ in range(5):
        assert hal.tick(None)
    after, later = _frame(hal), hal.read_state()
    assert np.abs(after.astype(int) - before.astype(int)).mean() > 0.5, "the frame froze"
    assert not np.allclose(later.positions, start.positions)  # the arm swung under gravity
    assert later.sim_time_s is not None and start.sim_time_s is not None
    assert later.sim_time_s > start.sim_time_s
    assert all(not a.any() for a in env.actions)  # no hold of its own: zeros


def test_a_hold_tick_resets_a_finished_episode_then_steps_zero(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env(horizon=2)
    hal = _attached(fake_arm, env)
    hal.send_action([0.5, 0.5])
    assert hal.tick(None) and hal.episode_done and len(env.resets) == 1
    assert hal.tick(None)
    assert len(env.resets) == 2 and env.resets[-1] == 0
    assert not hal.episode_done  # one step into the new episode
    assert len(env.actions) == 3 and not env.actions[-1].any()
    assert env.data.time == pytest.approx(env.substeps * env.model.opt.timestep)


def test_send_action_resets_a_finished_episode_first(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env(horizon=1)
    hal = _attached(fake_arm, env, env_reset_seed=3)
    hal.send_action([0.1, 0.1])
    assert hal.episode_done
    hal.send_action([0.2, 0.2])
    assert env.resets == [3, 3] and hal.episode_done
    np.testing.assert_allclose(env.actions[-1], [0.2, 0.2])


def test_estop_stops_ticks_and_actions(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env()
    hal = _attached(fake_arm, env)
    hal.tick(None)
    frame = _frame(hal)
    hal.estop()
    assert hal.estopped
    assert not hal.tick(None)
    with pytest.raises(EStopLatched):
        hal.send_action([0.0, 0.0])
    np.testing.assert_array_equal(_frame(hal), frame)
    assert len(env.actions) == 1
    hal.release_estop()
    assert hal.tick(None) and len(env.actions) == 2


def test_a_tick_with_an_action_steps_it_and_keeps_it_commanded(
    fake_arm: RobotDescription, arm_env: Callable[..., MujocoArmRollout]
) -> None:
    env = arm_env()
    hal = _attached(fake_arm, env)
    assert hal.control_period_s == pytest.approx(10 * 0.005)
    assert hal.tick([0.4, -0.1])
    with pytest.raises(ActionRejected, match="expected 2"):
        hal.tick([0.1, 0.2, 0.3])
    assert len(env.actions) == 1  # the refused tick did not step
    for _ in range(3):
        hal.tick(None)
    np.testing.assert_allclose(hal.last_env_action, [0.4, -0.1])
    assert len(env.actions) == 4


# -- the non-MuJoCo path -----------------------------------------------------------------


@pytest.mark.parametrize(
    ("reported", "expected"),
    [(2, [1.0, 2.0]), (1, [1.0, 0.0]), (4, [1.0, 2.0]), (None, [0.0, 0.0])],
)
def test_non_mujoco_positions_come_from_the_observation(
    fake_arm: RobotDescription,
    caplog: pytest.LogCaptureFixture,
    reported: int | None,
    expected: list[float],
) -> None:
    hal = _attached(fake_arm, NonMujocoRollout(n_positions=reported))
    with caplog.at_level(logging.WARNING, logger="openral_hal.sim_attached"):
        states = [hal.read_state(), hal.read_state()]
    for state in states:
        assert state.names == ("joint1", "joint2") and state.sim_time_s is None
        np.testing.assert_array_equal(state.positions, expected)
        assert not state.velocities.any() and not state.efforts.any()
    warnings = [r for r in caplog.records if "joint positions" in r.getMessage()]
    assert len(warnings) == (1 if reported in (1, 4) else 0)


def test_non_mujoco_hold_tick_advances_the_scene(fake_arm: RobotDescription) -> None:
    env = NonMujocoRollout()
    hal = _attached(fake_arm, env)
    assert hal.mujoco_handles() is None
    assert hal.tick(None)
    assert env.actions[-1].shape == (3,) and not env.actions[-1].any()
    assert _frame(hal)[0, 0, 0] == 1
    np.testing.assert_array_equal(hal.read_state().positions, [2.0, 3.0])


def test_connect_without_an_action_width_names_the_backend(fake_arm: RobotDescription) -> None:
    hal = SimAttachedHAL(NonMujocoRollout(action_dim=None), loaded_robot(fake_arm))
    with pytest.raises(ConfigurationError, match="NonMujocoRollout"):
        hal.connect()
    override = _attached(fake_arm, NonMujocoRollout(action_dim=None), env_action_dim=4)
    assert override.action_dim == 4
    override.send_action([0.0, 1.0, 2.0, 3.0])
