"""Property tests: valid actions keep the simulation finite; rejected ones change nothing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from openral_core import load_robot_by_id
from openral_core.tables import hal_wiring
from openral_hal.errors import ActionRejected
from openral_hal.mujoco_arm import MujocoArmHAL

ROBOTS = ["franka_panda", "aloha", "h1", "so101"]
"""One per wiring family: tendon gripper, mirrored bimanual, torque PD, affine jaw."""

_HALS: dict[tuple[str, int], MujocoArmHAL] = {}


def _connected(robot_id: str, copy: int = 0) -> MujocoArmHAL:
    """A HAL reconnected (fresh model and data) for every example; ``copy`` picks a twin."""
    key = (robot_id, copy)
    if key not in _HALS:
        _HALS[key] = MujocoArmHAL.from_description(load_robot_by_id(robot_id))
    hal = _HALS[key]
    hal.connect()
    return hal


def _snapshot(hal: MujocoArmHAL) -> tuple[np.ndarray, ...]:
    _, data = hal.mujoco_handles()
    return (data.qpos.copy(), data.qvel.copy(), data.ctrl.copy(), np.array([data.time]))


def _within_limits(robot_id: str) -> st.SearchStrategy[list[float]]:
    """One value per joint: inside its limits (gripper commands inside 0..1 or ctrl_range)."""
    description = load_robot_by_id(robot_id)
    assert description.sim is not None
    grippers = {g.joint: g for g in description.sim.grippers or []}
    per_joint = []
    for joint in description.joints:
        if joint.name in grippers:
            g = grippers[joint.name]
            low, high = (0.0, 1.0) if g.write_mode.value == "normalised" else g.ctrl_range
        else:
            low, high = getattr(joint, "position_limits", (-np.pi, np.pi))
        per_joint.append(st.floats(min_value=low, max_value=high, allow_nan=False))
    return st.tuples(*per_joint).map(list)


@pytest.mark.parametrize("robot_id", ROBOTS)
@settings(
    max_examples=15,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(data=st.data())
def test_random_valid_actions_keep_state_finite(robot_id: str, data: st.DataObject) -> None:
    hal = _connected(robot_id)
    for _ in range(3):
        hal.send_action(data.draw(_within_limits(robot_id)))
        hal.step(20)
        state = hal.read_state()
        assert np.isfinite(state.positions).all()
        assert np.isfinite(state.velocities).all()
        assert np.isfinite(state.efforts).all()


def _bad_actions(width: int) -> st.SearchStrategy[object]:
    finite = st.floats(-3, 3, allow_nan=False)
    good = st.lists(finite, min_size=width, max_size=width)
    non_finite = st.tuples(
        good, st.integers(0, width - 1), st.sampled_from([np.nan, np.inf, -np.inf])
    ).map(lambda t: [*t[0][: t[1]], t[2], *t[0][t[1] + 1 :]])
    return st.one_of(
        # a non-finite value somewhere, as a list and as the float64 array of a control loop
        non_finite,
        non_finite.map(lambda v: np.array(v, dtype=np.float64)),
        # the wrong width
        st.lists(finite, max_size=width + 3).filter(lambda v: len(v) != width),
        # the wrong element or container type
        good.map(lambda v: [*v[:-1], "0.1"]),
        good.map(lambda v: [*v[:-1], True]),
        good.map(lambda v: dict(enumerate(v))),
        good.map(lambda v: np.array(v).reshape(1, -1)),
        good.map(lambda v: np.array([str(x) for x in v])),
        st.none(),
    )


@pytest.mark.parametrize("robot_id", ROBOTS)
@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_rejected_actions_change_nothing(robot_id: str, data: st.DataObject) -> None:
    hal, twin = _connected(robot_id), _connected(robot_id, copy=1)
    action = hal.read_state().positions + 0.01
    for each in (hal, twin):
        each.send_action(action)
    before = _snapshot(hal)
    bad = data.draw(_bad_actions(len(hal.joint_names)))
    with pytest.raises(ActionRejected):
        hal.send_action(bad)
    for old, new in zip(before, _snapshot(hal), strict=True):
        np.testing.assert_array_equal(old, new)
    # The held targets were not touched either: it evolves exactly like its twin.
    for each in (hal, twin):
        each.step(10)
    np.testing.assert_array_equal(hal.read_state().positions, twin.read_state().positions)


@pytest.mark.parametrize("robot_id", ["franka_panda", "h1"])
@settings(max_examples=10, deadline=None)
@given(steps=st.integers(1, 50))
def test_estop_freezes_the_simulation_for_any_number_of_steps(robot_id: str, steps: int) -> None:
    hal = _connected(robot_id)
    hal.step(5)
    hal.estop()
    before = _snapshot(hal)
    for _ in range(steps):
        assert hal.step() is False
    for old, new in zip(before, _snapshot(hal), strict=True):
        np.testing.assert_array_equal(old, new)


@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_targets_are_approached_no_faster_than_the_velocity_limits(data: st.DataObject) -> None:
    """The position set point (ctrl) moves at most ``velocity_limit * dt`` per step."""
    hal = _connected("franka_panda")
    model, data_ = hal.mujoco_handles()
    description = load_robot_by_id("franka_panda")
    arm = [i for i, j in enumerate(description.joints) if j.name not in hal.grippers]
    vmax = np.array([description.joints[i].velocity_limit for i in arm])
    wiring = hal_wiring(description)
    assert wiring is not None
    actuators = [wiring.actuator_index[description.joints[i].name] for i in arm]
    target = np.array(data.draw(_within_limits("franka_panda")))
    hal.send_action(target)
    for _ in range(3):
        before = data_.ctrl[actuators].copy()
        steps = data.draw(st.integers(1, 400))
        hal.step(steps)
        moved = np.abs(data_.ctrl[actuators] - before)
        assert (moved <= vmax * steps * model.opt.timestep + 1e-9).all()
    hal.step(3000)  # six seconds: every joint has arrived
    np.testing.assert_allclose(data_.ctrl[actuators], target[arm], atol=1e-9)
