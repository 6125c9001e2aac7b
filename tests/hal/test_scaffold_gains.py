"""Tests for scaffold_gains.py: gains from a model's inertia, and a drafted motor-driven arm
(robosuite's xArm7) that holds and tracks without a hand edit."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import open_robot
from openral_core.models import TorquePdControl
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.scaffold import scaffold_manifest
from openral_hal.scaffold_gains import (
    BANDWIDTH_RAD_S,
    EXPLICIT_STEP_FRACTION,
    SATURATION_ERROR_RAD,
    STATIC_ERROR_RAD,
    inertia_diagonal,
    joint_gains,
)

XARM7 = "pkg:robosuite/robosuite/models/assets/robots/xarm7/robot.xml"
"""robosuite's xArm7: seven motors (±80 N·m), friction loss 1 N·m per joint, no keyframe."""
HOLD_S = 10.0
HOLD_TOLERANCE_RAD = 0.005
STEP_RAD = 0.5
STEP_WINDOW_S = 3.0
"""Time after a step command within which the joint has settled: the set point needs about
0.75 s at the draft's 1 rad/s velocity limit."""
STEADY_S = 1.0
"""The end of the window over which the steady-state error is taken."""
STEADY_TOLERANCE_RAD = 0.01


def _hinge(
    *, integrator: str = "implicitfast", timestep: float = 0.002, joint: str = "", motor: str = ""
) -> mujoco.MjModel:
    """One hinge about z through the centre of a body of inertia 0.5 kg·m² about it."""
    return mujoco.MjModel.from_xml_string(f"""
        <mujoco><option timestep="{timestep}" integrator="{integrator}"/>
          <worldbody><body><joint name="j" axis="0 0 1" {joint}/>
            <inertial pos="0 0 0" mass="1" diaginertia="0.5 0.5 0.5"/></body></worldbody>
          <actuator><motor joint="j" {motor}/></actuator>
        </mujoco>""")


def test_inertia_diagonal_is_the_mass_matrix_diagonal_with_armature() -> None:
    assert inertia_diagonal(_hinge()) == pytest.approx([0.5])
    assert inertia_diagonal(_hinge(joint='armature="0.1"')) == pytest.approx([0.6])


def test_a_frictionless_joint_gets_the_bandwidth_law() -> None:
    gains = joint_gains(_hinge(), 0, 0.5, None)
    assert gains.kp == pytest.approx(0.5 * BANDWIDTH_RAD_S**2, rel=1e-3)
    assert gains.kd == pytest.approx(2 * 0.5 * BANDWIDTH_RAD_S, rel=1e-3)  # critically damped
    assert gains.note == ""


def test_friction_loss_raises_kp_and_a_light_joint_gets_kd_of_at_least_kp_dt() -> None:
    heavy = joint_gains(_hinge(joint='frictionloss="10"'), 0, 0.5, None)
    assert heavy.kp == pytest.approx(10 / STATIC_ERROR_RAD)
    assert heavy.kd == pytest.approx(2 * np.sqrt(heavy.kp * 0.5), rel=1e-3)
    assert heavy.note == "raised for its friction loss 10"
    light = joint_gains(_hinge(joint='frictionloss="1"'), 0, 1e-4, None)
    assert light.kp == pytest.approx(1 / STATIC_ERROR_RAD)
    assert light.kd == pytest.approx(light.kp * 0.002)  # above 2·sqrt(kp·M) = 0.45


def test_kp_is_capped_where_the_motor_would_saturate() -> None:
    gains = joint_gains(_hinge(joint='frictionloss="10"'), 0, 0.5, 2.0)
    assert gains.kp == pytest.approx(2.0 / SATURATION_ERROR_RAD)
    assert gains.note == "raised for its friction loss 10; capped by its effort 2"


def test_an_explicit_integrator_bounds_the_servo_by_the_time_step() -> None:
    model = _hinge(integrator="Euler", timestep=0.01, joint='frictionloss="10"')
    gains = joint_gains(model, 0, 0.5, None)
    omega = EXPLICIT_STEP_FRACTION / 0.01  # 20 rad/s, below the 31 rad/s bandwidth
    assert gains.kp == pytest.approx(0.5 * omega**2)
    assert gains.kd == pytest.approx(2 * 0.5 * omega)
    assert gains.note == "friction loss 10 may stop it 0.05 short"


@pytest.fixture(scope="module")
def xarm7(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The unedited draft of robosuite's xArm7."""
    folder = tmp_path_factory.mktemp("drafts") / "xarm7"
    folder.mkdir()
    manifest = folder / "robot.yaml"
    manifest.write_text(scaffold_manifest(XARM7, "xarm7", folder), encoding="utf-8")
    return manifest


def test_a_motor_driven_draft_compensates_gravity_with_gains_from_inertia(xarm7: Path) -> None:
    robot = open_robot(xarm7).description
    assert robot.sim is not None and robot.sim.gravity_compensation
    control = robot.sim.control
    assert isinstance(control, TorquePdControl)
    assert isinstance(control.kp, dict) and isinstance(control.kd, dict)
    names = [j.name for j in robot.joints]
    assert list(control.kp) == list(control.kd) == names
    assert all(control.kp[n] > 0 and control.kd[n] > 0 for n in names)
    assert len(set(control.kd.values())) > 1  # per joint, not one placeholder


def _connected(manifest: Path) -> MujocoArmHAL:
    hal = MujocoArmHAL.from_robot(open_robot(manifest))
    hal.connect()
    return hal


def _hold_error(hal: MujocoArmHAL, seconds: float) -> float:
    """Largest distance of any joint from where it was, holding for ``seconds``."""
    start = hal.read_state().positions.copy()
    worst = 0.0
    for _ in range(round(seconds / hal.control_period_s)):
        hal.tick(None)
        worst = max(worst, float(np.abs(hal.read_state().positions - start).max()))
    return worst


def test_the_xarm7_draft_holds_its_start_pose_for_ten_seconds(xarm7: Path) -> None:
    assert _hold_error(_connected(xarm7), HOLD_S) < HOLD_TOLERANCE_RAD


def test_the_xarm7_draft_sags_without_gravity_compensation(xarm7: Path, tmp_path: Path) -> None:
    """The compensation, not the gains alone, holds the arm."""
    folder = tmp_path / "xarm7"
    folder.mkdir()
    text = xarm7.read_text(encoding="utf-8")
    assert text.count("gravity_compensation: true") == 1
    (folder / "robot.yaml").write_text(text.replace("gravity_compensation: true", "# off"))
    assert _hold_error(_connected(folder / "robot.yaml"), HOLD_S) > HOLD_TOLERANCE_RAD


@pytest.mark.parametrize("joint", range(7), ids=lambda j: f"joint{j + 1}")
def test_the_xarm7_draft_tracks_a_half_radian_step(xarm7: Path, joint: int) -> None:
    hal = _connected(xarm7)
    target = hal.read_state().positions.copy()
    target[joint] += STEP_RAD
    hal.send_action(target)
    errors = []
    for _ in range(round(STEP_WINDOW_S / hal.control_period_s)):
        hal.tick(None)
        errors.append(float(np.abs(hal.read_state().positions - target).max()))
    steady = max(errors[-round(STEADY_S / hal.control_period_s) :])
    assert steady < STEADY_TOLERANCE_RAD
