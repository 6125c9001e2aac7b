"""Every manifest in robots/ through MujocoArmHAL.from_description, on its real model.

Parametrised over the robots/ folder, so a new manifest is covered without editing a test.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import load_robot_by_id, robot_ids
from openral_core.loaded import open_robot_by_id
from openral_core.tables import robot_tables
from openral_hal.errors import EStopLatched, NotConnected, SimulationDiverged
from openral_hal.mujoco_arm import MujocoArmHAL

HOLD_STEPS = 200
HOLD_TOLERANCE = 0.05
"""rad or m a joint may move while holding its start pose for 200 steps (weak hobby servos
such as the SO-101's sag by ~0.03 rad under gravity; industrial arms stay below 0.01)."""
MOVE = 0.05
"""Size of the joint-space move each arm joint is asked to make (rad or m)."""
TRACK_STEPS = 1000
TRACK_TOLERANCE = 0.05


def _hal(robot_id: str) -> MujocoArmHAL:
    hal = MujocoArmHAL.from_description(load_robot_by_id(robot_id))
    hal.connect()
    return hal


def _arm_slots(hal: MujocoArmHAL) -> list[int]:
    return [i for i, name in enumerate(hal.joint_names) if name not in hal.grippers]


def _hold_action(hal: MujocoArmHAL) -> np.ndarray:
    """Current arm positions with each gripper's current reading as its command."""
    return hal.read_state().positions.copy()


@pytest.mark.parametrize("robot_id", robot_ids())
def test_connects_and_holds_its_start_pose(robot_id: str) -> None:
    hal = _hal(robot_id)
    start = hal.read_state()
    assert start.names == tuple(j.name for j in load_robot_by_id(robot_id).joints)
    hal.send_action(_hold_action(hal))
    assert hal.step(HOLD_STEPS)
    held = hal.read_state()
    for sample in (start, held):
        assert np.isfinite(sample.positions).all() and np.isfinite(sample.velocities).all()
        assert np.isfinite(sample.efforts).all()
    drift = np.abs(held.positions - start.positions)
    worst = int(drift.argmax())
    assert drift[worst] < HOLD_TOLERANCE, f"{held.names[worst]} drifted {drift[worst]:.4f}"
    assert held.sim_time_s is not None and start.sim_time_s is not None
    assert held.sim_time_s > start.sim_time_s


@pytest.mark.parametrize("robot_id", robot_ids())
def test_tracks_a_small_joint_space_move(robot_id: str) -> None:
    hal = _hal(robot_id)
    action = _hold_action(hal)
    arm = _arm_slots(hal)
    before = action[arm].copy()
    # Move each joint towards the middle of its range, so no target sits on a limit.
    description = load_robot_by_id(robot_id)
    for slot in arm:
        limits = getattr(description.joints[slot], "position_limits", None)
        middle = 0.0 if limits is None else (limits[0] + limits[1]) / 2
        action[slot] += MOVE if middle >= action[slot] else -MOVE
    hal.send_action(action)
    hal.step(TRACK_STEPS)
    reached = hal.read_state().positions[arm]
    error = np.abs(reached - action[arm])
    worst = int(error.argmax())
    assert error[worst] < TRACK_TOLERANCE, f"{hal.joint_names[arm[worst]]} off by {error[worst]}"
    assert np.abs(reached - before).mean() > MOVE / 2


GRIPPER_CASES = [
    (robot_id, joint)
    for robot_id in robot_ids()
    for joint in [g.joint for g in (load_robot_by_id(robot_id).sim.grippers or [])]  # type: ignore[union-attr]
]


@pytest.mark.parametrize(("robot_id", "joint"), GRIPPER_CASES)
def test_gripper_opens_and_closes_with_the_reading_following(robot_id: str, joint: str) -> None:
    hal = _hal(robot_id)
    gripper = hal.grippers[joint]
    slot = hal.joint_names.index(joint)
    closed, opened = (0.0, 1.0) if gripper.write_mode == "normalised" else gripper.ctrl_range
    readings = []
    for command in (closed, opened, closed):
        action = _hold_action(hal)
        action[slot] = command
        hal.send_action(action)
        hal.step(600)
        readings.append(float(hal.read_state().positions[slot]))
    span = abs(opened - closed)
    # Opening moves the reading the same way as the command, by at least half the range.
    assert (readings[1] - readings[0]) * np.sign(opened - closed) > 0.5 * span, readings
    # The reading lands near the command, whichever direction "open" is.
    for reading, command in zip(readings, (closed, opened, closed), strict=True):
        assert abs(reading - command) < 0.1 * span, (readings, command)
    if gripper.mirror_actuator_index is not None:
        _, data = hal.mujoco_handles()
        assert data.ctrl[gripper.mirror_actuator_index] == pytest.approx(
            -data.ctrl[gripper.actuator_index]
        )


def test_generated_table_wires_the_same_hal_as_the_manifest() -> None:
    from_table = open_robot_by_id("franka_panda")  # reads generated/…/franka_panda.json
    computed = replace(from_table, tables=robot_tables(from_table.description))
    hals = [MujocoArmHAL.from_robot(robot) for robot in (from_table, computed)]
    for hal in hals:
        hal.connect()
    action = hals[0].read_state().positions + 0.02
    for hal in hals:
        hal.send_action(action)
        hal.step(50)
    np.testing.assert_array_equal(hals[0].read_state().positions, hals[1].read_state().positions)


def test_estop_freezes_physics_and_refuses_actions_until_released() -> None:
    hal = _hal("franka_panda")
    _, data = hal.mujoco_handles()
    hal.estop()
    qpos, time_s = data.qpos.copy(), data.time
    assert hal.step(100) is False
    np.testing.assert_array_equal(data.qpos, qpos)
    assert data.time == time_s
    with pytest.raises(EStopLatched):
        hal.send_action(hal.read_state().positions)
    hal.release_estop()
    hal.send_action(hal.read_state().positions)
    assert hal.step(1) and data.time > time_s


def test_torque_pd_robot_is_driven_by_the_manifest_gains() -> None:
    hal = _hal("h1")
    assert hal.wiring.control_mode == "torque_pd"
    model, data = hal.mujoco_handles()
    wiring = hal.wiring
    knee = hal.joint_names.index("left_knee")
    actuator = wiring.actuator_index["left_knee"]
    qpos, dof = wiring.joint_qpos_addr["left_knee"], wiring.joint_qvel_addr["left_knee"]
    kp, kd = wiring.kp["left_knee"], wiring.kd["left_knee"]
    start = float(data.qpos[qpos])
    action = _hold_action(hal)
    action[knee] += 0.3
    hal.send_action(action)
    low, high = model.actuator_forcerange[actuator]
    motor = mujoco.MjModel.from_xml_path(str(hal.mjcf_path))
    assert (low, high) == tuple(motor.actuator_ctrlrange[actuator])  # its torque limits, kept
    for _ in range(40):  # MuJoCo applies kp * (set point - q) - kd * dq, clipped
        q, dq = float(data.qpos[qpos]), float(data.qvel[dof])
        hal.step(1)
        setpoint = float(data.ctrl[actuator])  # the set point this step used
        wanted = kp * (setpoint - q) - kd * dq
        assert data.actuator_force[actuator] == pytest.approx(min(max(wanted, low), high))
    assert start < setpoint <= action[knee]  # slewed towards the target
    assert data.qpos[qpos] > start  # and the torque moved the knee that way


def test_gravity_can_be_switched_off() -> None:
    hal = MujocoArmHAL.from_description(load_robot_by_id("ur5e"), gravity_enabled=False)
    hal.connect()
    model, _ = hal.mujoco_handles()
    assert not model.opt.gravity.any()


def test_calls_before_connect_are_refused() -> None:
    hal = MujocoArmHAL.from_description(load_robot_by_id("ur5e"))
    with pytest.raises(NotConnected):
        hal.read_state()
    with pytest.raises(NotConnected):
        hal.send_action([0.0] * 6)
    hal.connect()
    hal.disconnect()
    with pytest.raises(NotConnected):
        hal.step()


def test_state_is_flagged_stale_when_nobody_steps() -> None:
    hal = MujocoArmHAL.from_description(load_robot_by_id("ur5e"), staleness_limit_s=0.0)
    hal.connect()
    assert hal.read_state().stale
    hal = MujocoArmHAL.from_description(load_robot_by_id("ur5e"), staleness_limit_s=60.0)
    hal.connect()
    assert not hal.read_state().stale


def test_a_diverging_simulation_is_reported_not_silently_reset(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo appends its warning to ./MUJOCO_LOG.TXT
    hal = _hal("ur5e")
    _, data = hal.mujoco_handles()
    data.qvel[:] = 1e30  # what an exploding controller leaves behind
    with pytest.raises(SimulationDiverged, match="diverged"):
        hal.step(5)


def test_divergence_watch_covers_exactly_the_bad_state_warnings() -> None:
    from openral_mujoco.joint_driver import _BAD_STATE_WARNINGS

    watched = set(range(len(mujoco.mjtWarning.__members__))[_BAD_STATE_WARNINGS])
    expected = {
        int(mujoco.mjtWarning.mjWARN_BADQPOS),
        int(mujoco.mjtWarning.mjWARN_BADQVEL),
        int(mujoco.mjtWarning.mjWARN_BADQACC),
    }
    assert watched == expected
