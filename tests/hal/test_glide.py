"""Gliding along a sampled path, and reset, on the real franka models.

A joint trajectory reaches the HAL as one sample per control period; a glide moves the set
point to it at constant speed with that speed fed forward, so the joint tracks the path
instead of lagging it by kv/kp x speed. Reset puts the scene back where connect left it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import mujoco
import numpy as np
import pytest
from openral_core import load_robot_by_id, load_scene, open_robot_by_id
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.state import FloatArray
from openral_sim.native_scene import NativeScene
from openral_sim.scene import build_scene

from tests.conftest import ROBOTS

SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"
SPEED = 0.35
"""Speed of the ramp on panda_joint1 [rad/s]."""
VMAX = 2.175
"""panda_joint1's velocity_limit [rad/s]."""


def _native() -> NativeScene:
    scene = load_scene(SCENE)
    env = build_scene(scene, open_robot_by_id("franka_panda"), render_observations=False)
    assert isinstance(env, NativeScene)
    return env


@pytest.fixture
def env() -> Iterator[NativeScene]:
    built = _native()
    built.reset(0)
    yield built
    built.close()


def _ramp_errors(env: NativeScene, glide: bool, ticks: int = 40) -> FloatArray:
    """|joint1 - ramp| at the end of each period while joint1 follows a 0.35 rad/s ramp
    sampled once per period (every other joint holds)."""
    hold = env.hold_action()
    period = env.control_period_s
    errors = []
    for k in range(1, ticks + 1):
        action = hold.copy()
        action[0] = hold[0] + SPEED * period * k
        env.step(action, glide=glide)
        errors.append(abs(env.joint_state().positions[0] - action[0]))
    return np.array(errors)


def test_a_glide_tracks_a_ramp_that_plain_samples_lag(env: NativeScene) -> None:
    glided = _ramp_errors(env, glide=True)
    env.reset(0)
    plain = _ramp_errors(env, glide=False)
    assert glided.max() < 0.01, f"glide tracking error {glided.max():.4f} rad"
    assert plain[-20:].min() > 0.02, f"plain samples lag only {plain[-20:].min():.4f} rad"


def _chunk_speeds(env: NativeScene, action: FloatArray) -> FloatArray:
    """Command ``action`` gliding over one period and advance it chunk by chunk (as a step
    does); joint1's set-point speed in each chunk [rad/s]."""
    driver, chunk = env.driver, 5  # SLEW_CHUNK_STEPS
    dt = chunk * env.model.opt.timestep
    driver.command(action, env.data, glide_s=env.control_period_s)
    speeds = []
    for _ in range(round(env.control_period_s / dt)):
        before = driver.setpoint[0]
        driver.advance(env.model, env.data, chunk)
        speeds.append((driver.setpoint[0] - before) / dt)
    return np.array(speeds)


def _glide_then_too_fast(env: NativeScene) -> FloatArray:
    """Three samples glided at 2.0 rad/s (within the limit: exactly that speed), then one
    that needs 4 rad/s; joint1's set-point speed in each chunk of the four periods."""
    action, period = env.hold_action(), env.control_period_s
    speeds = []
    for _ in range(3):
        action[0] += 2.0 * period
        speeds += [*_chunk_speeds(env, action)]
        assert env.driver.setpoint[0] == action[0]
    action[0] += 4.0 * period
    speeds += [*_chunk_speeds(env, action)]
    assert env.driver.setpoint[0] < action[0]  # not there within the period: slewed
    return np.array(speeds)


def test_a_glide_faster_than_the_velocity_limit_is_slewed(env: NativeScene) -> None:
    speeds = _glide_then_too_fast(env)
    assert speeds[:15] == pytest.approx([2.0] * 15, rel=1e-9)
    target = env.driver.setpoint[0] + 1.0  # far on: the slew reaches its top speed
    action = env.hold_action()
    action[0] = target
    for _ in range(20):
        speeds = np.append(speeds, _chunk_speeds(env, action))
    assert env.driver.setpoint[0] == target  # slewed onto it in the end
    assert speeds.max() <= VMAX * (1 + 1e-9) and speeds.max() > 0.99 * VMAX


def test_a_slew_after_a_glide_keeps_the_speed_it_had(env: NativeScene) -> None:
    speeds = _glide_then_too_fast(env)
    ramp = VMAX / 0.25 * 5 * env.model.opt.timestep  # RAMP_S: the most a chunk may change
    assert np.abs(np.diff(speeds)).max() <= ramp * (1 + 1e-9)


def test_a_glide_sample_outside_the_limits_is_clamped_and_reported(env: NativeScene) -> None:
    action = env.hold_action()
    action[0] = 2.8973 + 0.05  # past panda_joint1's upper limit
    before = sum(env.driver.limits.clamped.values())
    env.step(action, glide=True)
    assert sum(env.driver.limits.clamped.values()) == before + 1
    assert env.hold_action()[0] == 2.8973  # the target is the limit, never past it


# -- reset -----------------------------------------------------------------------------------

Handles = tuple[mujoco.MjModel, mujoco.MjData]


def _assert_same_state(a: Handles, b: Handles) -> None:
    """Bit for bit: time, positions, velocities, controls and actuator states."""
    for field in ("time", "qpos", "qvel", "ctrl", "act", "qacc_warmstart"):
        np.testing.assert_array_equal(getattr(a[1], field), getattr(b[1], field), field)


def _wander(tick: Callable[..., bool], hold: FloatArray, ticks: int = 25) -> None:
    """Move every arm joint, gliding and not, then a plain jump, as a user would."""
    for k in range(ticks):
        action = hold.copy()
        action[:7] += 0.01 * k
        assert tick(action, glide=k % 2 == 0)
    action[:7] -= 0.3
    assert tick(action)


def _arm() -> MujocoArmHAL:
    hal = MujocoArmHAL.from_description(load_robot_by_id("franka_panda"))
    hal.connect()
    return hal


def test_the_arm_hal_resets_to_exactly_where_connect_left_it() -> None:
    hal, fresh = _arm(), _arm()
    _wander(hal.tick, hal.hold_action())
    assert np.abs(hal.read_state().positions - fresh.read_state().positions).max() > 0.1
    text = hal.reset()
    assert text.startswith("franka_panda: start pose restored at t=") and "latched" not in text
    _assert_same_state(hal.mujoco_handles(), fresh.mujoco_handles())
    np.testing.assert_array_equal(hal.hold_action(), fresh.hold_action())
    np.testing.assert_array_equal(hal.driver.setpoint, fresh.driver.setpoint)
    _wander(hal.tick, hal.hold_action())  # and from there both move alike: no state left
    _wander(fresh.tick, fresh.hold_action())
    _assert_same_state(hal.mujoco_handles(), fresh.mujoco_handles())


def test_an_arm_hal_reset_keeps_the_estop_latched() -> None:
    hal, fresh = _arm(), _arm()
    _wander(hal.tick, hal.hold_action())
    hal.estop()
    assert hal.reset().endswith("; the E-stop is still latched")
    assert hal.estopped and hal.tick(None) is False
    _assert_same_state(hal.mujoco_handles(), fresh.mujoco_handles())
    for each in (hal, fresh):  # released, each holds the pose it settled in
        each.estop()  # (a no-op for hal, latched all along)
        each.release_estop()
        assert each.tick(None)
    _assert_same_state(hal.mujoco_handles(), fresh.mujoco_handles())


def _attached() -> SimAttachedHAL:
    hal = SimAttachedHAL(_native(), open_robot_by_id("franka_panda"))
    hal.connect()
    return hal


def _handles(hal: SimAttachedHAL) -> Handles:
    handles = hal.mujoco_handles()
    assert handles is not None
    return handles


def test_the_attached_hal_resets_the_whole_scene_to_where_connect_left_it() -> None:
    hal, fresh = _attached(), _attached()
    try:
        _wander(hal.tick, hal.hold_action(), ticks=40)
        moved = np.abs(_handles(hal)[1].qpos - _handles(fresh)[1].qpos).max()
        assert moved > 0.1
        text = hal.reset()
        assert text.startswith("franka_panda: scene reset with seed 0") and "latched" not in text
        _assert_same_state(_handles(hal), _handles(fresh))  # every object too, not only the arm
        np.testing.assert_array_equal(hal.read_state().positions, fresh.read_state().positions)
        np.testing.assert_array_equal(hal.last_env_action, np.zeros(hal.action_dim))
        _wander(hal.tick, hal.hold_action())
        _wander(fresh.tick, fresh.hold_action())
        _assert_same_state(_handles(hal), _handles(fresh))
    finally:
        hal.disconnect()
        fresh.disconnect()


def test_both_hals_hand_glide_on_to_the_driver() -> None:
    arm, attached = _arm(), _attached()
    native = attached.env
    assert isinstance(native, NativeScene)
    try:
        for hal, driver in ((arm, arm.driver), (attached, native.driver)):
            step = 1.0 * hal.control_period_s  # 1 rad/s
            action = hal.hold_action()
            action[0] += step
            assert hal.tick(action, glide=True)
            assert driver.setpoint[0] == action[0]  # glided: there at the period's end
            action[0] += step
            assert hal.tick(action)  # a plain command: slewed from rest, still on its way
            assert action[0] - step < driver.setpoint[0] < action[0]
    finally:
        attached.disconnect()


def test_an_attached_hal_reset_keeps_the_estop_latched() -> None:
    hal, fresh = _attached(), _attached()
    try:
        _wander(hal.tick, hal.hold_action())
        hal.estop()
        assert hal.reset().endswith("; the E-stop is still latched")
        assert hal.estopped and hal.tick(None) is False
        _assert_same_state(_handles(hal), _handles(fresh))
        for each in (hal, fresh):  # released, each holds the pose it settled in
            each.estop()
            each.release_estop()
            assert each.tick(None)
        _assert_same_state(_handles(hal), _handles(fresh))
    finally:
        hal.disconnect()
        fresh.disconnect()
