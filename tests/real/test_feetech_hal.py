"""Tests for feetech_hal.py against the bus emulator: a real HAL's contract and safety rules.

Every line here ran on the emulator (an emulated STS3215 bus on a pseudo-terminal, its
shafts moved by the simulation), not on hardware.
"""

from __future__ import annotations

import gc
import json
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from openral_core import LoadedRobot
from openral_hal.errors import ActionRejected, ConfigurationError, EStopLatched
from openral_hal.factory import RealOptions, build_hal, can_tick
from openral_hal.protocol import CameraHal, FramesHal, RobotHal, Tickable
from openral_real.feetech_hal import FeetechHal

from tests.real.conftest import Rig


def wait_for(condition: Callable[[], bool], timeout_s: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.005)
    return condition()


def _goals(line: str) -> list[int]:
    """The values of a ``SYNC_WRITE Goal_Position 1=.. 2=..`` log line."""
    return [int(item.split("=")[1]) for item in line.split()[3:]]


def test_build_hal_gives_the_feetech_hal_which_has_no_tick(rig: Rig) -> None:
    hal = build_hal(
        rig.robot,
        mode="real",
        transport=rig.path,
        real_options=RealOptions(calibration_file=rig.calibration),
    )
    assert isinstance(hal, FeetechHal) and isinstance(hal, RobotHal)
    assert hal.is_real and not can_tick(hal) and not isinstance(hal, Tickable)
    assert not hasattr(hal, "tick") and not hasattr(hal, "idle_step")
    assert isinstance(hal, FramesHal) and isinstance(hal, CameraHal)


def test_a_real_robot_refuses_a_scene(so101: LoadedRobot) -> None:
    from openral_core.loader import load_scene
    from openral_core.paths import repo_root

    scene = load_scene(repo_root() / "robots" / "so101" / "scenes" / "tabletop.yaml")
    with pytest.raises(ConfigurationError, match="real robot cannot attach to a simulated scene"):
        build_hal(so101, mode="real", transport="/dev/null", scene=scene)


def test_connecting_far_from_zero_holds_the_arm_where_it_is(rig: Rig) -> None:
    rig.bus.arm.place("shoulder_pan", 1.2)
    rig.bus.arm.place("elbow_flex", -1.0)
    started = time.time()
    hal = rig.hal()
    hal.connect()
    try:
        present = [s.get("Present_Position") for s in rig.bus.emulator.servos.values()]
        first = _goals(rig.bus.written("Goal_Position", after=started)[0])
        assert all(abs(g - p) <= 1 for g, p in zip(first, present, strict=True))
        assert hal.read_state().positions[0] == pytest.approx(1.2, abs=0.003)
        assert hal.hold_action()[0] == pytest.approx(1.2, abs=0.003)  # hold: measured, not 0
        torque = [s.get("Torque_Enable") for s in rig.bus.emulator.servos.values()]
        assert torque == [1] * 6
    finally:
        hal.disconnect()


def test_a_zero_action_is_refused_and_changes_nothing(rig: Rig) -> None:
    rig.bus.arm.place("shoulder_pan", 1.0)
    hal = rig.hal()
    hal.connect()
    try:
        with pytest.raises(ActionRejected, match="zero is not hold on a real robot"):
            hal.send_action(np.zeros(6))
        time.sleep(0.3)
        assert hal.read_state().positions[0] == pytest.approx(1.0, abs=0.003)
        for line in rig.bus.written("Goal_Position"):
            assert abs(_goals(line)[0] - _goals(rig.bus.written("Goal_Position")[0])[0]) <= 1
    finally:
        hal.disconnect()


def test_commands_move_the_arm_within_its_velocity_envelope(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    try:
        started = time.time()
        target = hal.hold_action()
        target[:4] += [0.6, -0.4, 0.5, 0.3]
        target[5] = 1.0  # the gripper open, in its write mode (normalised)
        hal.send_action(target)
        assert wait_for(lambda: np.allclose(hal.read_state().positions, target, atol=0.01), 10)
        goals = np.array([_goals(line) for line in rig.bus.written("Goal_Position", started)])
        per_step = np.abs(np.diff(goals, axis=0)).max(axis=0)
        period = hal.control_period_s
        limit_steps = 10.0 * period * 4096 / (2 * np.pi)  # velocity_limit x period, in steps
        assert per_step.max() <= limit_steps + 1
    finally:
        hal.disconnect()


def test_the_gripper_reads_and_writes_in_the_manifests_units(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    try:
        action = hal.hold_action()
        action[5] = 0.0  # shut: ctrl_range's low end, -0.1745 rad
        hal.send_action(action)
        assert wait_for(lambda: abs(hal.read_state().positions[5]) < 0.01, 10)
        goal = _goals(rig.bus.written("Goal_Position")[-1])[5]  # the goal as written
        servo = rig.bus.emulator.servos[6]
        raw = goal + servo.get("Homing_Offset")
        assert rig.bus.arm.angle_of(5, raw) == pytest.approx(-0.17453, abs=0.0016)  # one step
        jaw = rig.bus.arm.angle_of(5, rig.bus.arm.shafts()[5].raw)
        assert jaw == pytest.approx(-0.17453, abs=0.015)  # the model's soft joint limit
    finally:
        hal.disconnect()


def test_an_estop_holds_within_a_period_and_release_resumes_slowly(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    try:
        target = hal.hold_action()
        target[0] += 1.0
        hal.send_action(target)
        time.sleep(0.3)
        latched = time.time()
        hal.estop()
        time.sleep(0.2)
        writes = rig.bus.written("Goal_Position", latched)
        assert 1 <= len(writes) <= 2  # the hold, after the one write already under way if any
        assert float(writes[-1].split()[0]) - latched < hal.control_period_s  # one period
        time.sleep(0.2)
        assert rig.bus.written("Goal_Position", latched) == writes  # then nothing
        with pytest.raises(EStopLatched):
            hal.send_action(target)
        measured = hal.read_state().positions[0]
        assert abs(measured - target[0]) > 0.1  # stopped short, where it was
        hal.release_estop()
        hal.send_action(target)
        assert wait_for(lambda: abs(hal.read_state().positions[0] - target[0]) < 0.01, 10)
    finally:
        hal.disconnect()


def test_disconnect_holds_then_turns_torque_off(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    stopped = time.time()
    hal.disconnect()

    def kinds() -> list[list[str]]:
        lines = [line for line in rig.bus.lines if float(line.split()[0]) > stopped]
        return [line.split()[1:3] for line in lines if "SYNC_WRITE" in line]

    assert wait_for(lambda: ["SYNC_WRITE", "Torque_Enable"] in kinds(), 1.0)
    assert kinds()[-2:] == [["SYNC_WRITE", "Goal_Position"], ["SYNC_WRITE", "Torque_Enable"]]
    assert [s.get("Torque_Enable") for s in rig.bus.emulator.servos.values()] == [0] * 6


def test_a_stale_reading_latches_the_estop(rig: Rig) -> None:
    hal = rig.hal()
    hal.connect()
    try:
        hal._running().cycle.stop()  # the driver falls behind: nothing reads the bus
        time.sleep(2.5 * hal.control_period_s)  # the latch comes at two periods
        assert hal.read_state().stale and hal.estopped
        assert "ms old" in (hal.estop_reason or "") and len(rig.faults) == 1
    finally:
        hal.disconnect()


def test_the_servos_holding_another_calibration_are_refused_untouched(
    rig: Rig, tmp_path: Path
) -> None:
    other = tmp_path / "other.json"
    document = json.loads(rig.calibration.read_text())
    for motor in document.values():
        motor["homing_offset"] += 5  # another arm's (or a recalibration's) offsets
    other.write_text(json.dumps(document))
    written = len([line for line in rig.bus.lines if "WRITE" in line])
    hal = FeetechHal(rig.robot, rig.path, RealOptions(calibration_file=other))
    with pytest.raises(ConfigurationError, match="the servos hold another calibration"):
        hal.connect()
    assert len([line for line in rig.bus.lines if "WRITE" in line]) == written
    assert gc.get_freeze_count() == 0  # the heap frozen for the loop is given back


@pytest.mark.exclusive  # torque off within one 10 ms period: a real-time measurement
def test_an_estop_that_cuts_torque_and_a_release_that_holds_again(
    so101: LoadedRobot, tmp_path: Path
) -> None:
    """`estop: torque_off`: torque off within one period; the release turns it on again at
    the measured pose (goals first), nothing jumping."""
    from openral_core.tables import robot_tables
    from openral_real.emulator.emulated_bus import EmulatedBus

    from tests.real.conftest import calibrate

    real = so101.description.real
    assert real is not None
    cutting = so101.description.model_copy(
        update={"real": real.model_copy(update={"estop": type(real.estop)("torque_off")})}
    )
    robot = LoadedRobot(cutting, so101.folder, robot_tables(cutting))
    with EmulatedBus(robot, seed=4) as bus:
        file = tmp_path / "arm.json"
        calibrate(robot, bus.path, file)
        hal = FeetechHal(robot, bus.path, RealOptions(calibration_file=file))
        hal.connect()
        try:
            servos = list(bus.emulator.servos.values())
            latched = time.time()
            hal.estop()
            assert wait_for(lambda: all(s.get("Torque_Enable") == 0 for s in servos), 1.0)
            cut = [line for line in bus.lines if "SYNC_WRITE Torque_Enable" in line]
            assert float(cut[-1].split()[0]) - latched < hal.control_period_s
            released = time.time()
            hal.release_estop()
            assert wait_for(lambda: all(s.get("Torque_Enable") == 1 for s in servos), 1.0)
            after = [line.split()[1:3] for line in bus.lines if float(line.split()[0]) > released]
            first_torque = after.index(["SYNC_WRITE", "Torque_Enable"])
            assert ["SYNC_WRITE", "Goal_Position"] in after[:first_torque]  # goals first
        finally:
            hal.disconnect()


def test_a_deferred_connect_holds_until_its_loop_starts(rig: Rig) -> None:
    """The graph builds before the driver's loop starts: until then the arm holds at the
    goals written at connect, the reading is the connect's and is not stale."""
    hal = rig.hal()
    hal.defer_cycle = True
    hal.connect()
    try:
        connected = time.time()
        first = hal.read_state()
        time.sleep(3 * hal.control_period_s)
        waited = hal.read_state()
        assert not waited.stale and not hal.estopped
        assert waited.stamp_ns == first.stamp_ns  # no loop: no new reading
        assert rig.bus.written("Goal_Position", connected) == []
        hal.start_cycle()
        hal.start_cycle()  # idempotent
        assert wait_for(lambda: hal.read_state().stamp_ns > first.stamp_ns, 2.0)
        assert not hal.estopped, hal.estop_reason
    finally:
        hal.disconnect()
