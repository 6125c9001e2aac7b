"""Tests for gravity.py: ``sim.gravity_compensation`` cancels gravity on the robot, inside
MuJoCo, through its joints' actuators, and nowhere else."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import open_robot
from openral_core.loaded import LoadedRobot
from openral_hal.errors import HalError
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_mujoco.joint_driver import JointDriver
from openral_mujoco.mjcf_uri import robot_model_file
from openral_mujoco.robot_addresses import locate_robot

TWO_LINK = """
<mujoco>
  <compiler angle="radian"/>
  <option timestep="0.002" integrator="implicitfast"/>
  <worldbody>
    <body name="link1" pos="0 0 0.5">
      <joint name="shoulder" axis="0 1 0" range="-2 2"/>
      <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="2"/>
      <body name="link2" pos="0.4 0 0">
        <joint name="elbow" axis="0 1 0" range="-2 2"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="1"/>
      </body>
    </body>
    <body name="door" pos="1 1 0.5">
      <joint name="door_hinge" axis="0 1 0"/>
      <geom type="box" size="0.1 0.01 0.1" pos="0.1 0 0" mass="1"/>
    </body>
    <body name="ball" pos="0 1 1">
      <freejoint/>
      <geom type="sphere" size="0.05" mass="0.5"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" ctrlrange="-50 50"/>
    <motor joint="elbow" ctrlrange="-20 20"/>
  </actuator>
</mujoco>
"""
"""A horizontal two-link arm on motors (gravity pulls its shoulder with about 9.3 N·m), a
door on a hinge no manifest joint names, and a loose ball."""

MANIFEST = """\
schema_version: "0.1"
name: two_link
display_name: Two link
base: fixed
joints:
  - {name: shoulder, type: revolute, position_limits: [-2.0, 2.0], velocity_limit: 2.0,
     effort_limit: 50.0}
  - {name: elbow, type: revolute, position_limits: [-2.0, 2.0], velocity_limit: 2.0,
     effort_limit: 20.0}
sensors: []
sim:
  mjcf_uri: file:arm.xml
  gravity_compensation: COMPENSATED
  control: {mode: torque_pd, kp: 100.0, kd: 5.0}
"""
KP = 100.0
SHOULDER_GRAVITY_NM = 9.81 * (2.0 * 0.2 + 1.0 * 0.55)
"""Gravity torque on the horizontal arm's shoulder [N·m] (link masses at their middles)."""


def _two_link(tmp_path: Path, *, compensated: bool) -> LoadedRobot:
    folder = tmp_path / "two_link"
    folder.mkdir(exist_ok=True)
    (folder / "arm.xml").write_text(TWO_LINK)
    manifest = folder / "robot.yaml"
    manifest.write_text(MANIFEST.replace("COMPENSATED", str(compensated).lower()))
    return open_robot(manifest)


def _held(robot: LoadedRobot, seconds: float) -> tuple[MujocoArmHAL, float]:
    """The connected HAL, and the largest distance from the start pose while holding."""
    hal = MujocoArmHAL.from_robot(robot)
    hal.connect()
    start = hal.read_state().positions.copy()
    worst = 0.0
    for _ in range(round(seconds / hal.control_period_s)):
        hal.tick(None)
        worst = max(worst, float(np.abs(hal.read_state().positions - start).max()))
    return hal, worst


def test_a_compensated_arm_holds_its_pose_and_an_uncompensated_one_sags(
    tmp_path: Path,
) -> None:
    _, compensated = _held(_two_link(tmp_path, compensated=True), 2.0)
    _, sagging = _held(_two_link(tmp_path, compensated=False), 2.0)
    assert compensated < 1e-6
    assert sagging == pytest.approx(SHOULDER_GRAVITY_NM / KP, rel=0.3)


def test_only_the_robots_bodies_are_compensated_through_its_actuators(tmp_path: Path) -> None:
    hal, _ = _held(_two_link(tmp_path, compensated=True), 0.1)
    model, data = hal.mujoco_handles()

    def body(name: str) -> float:
        return float(model.body_gravcomp[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)])

    def joint(name: str) -> int:
        return int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name))

    assert (body("link1"), body("link2"), body("door"), body("ball")) == (1.0, 1.0, 0.0, 0.0)
    assert model.jnt_actgravcomp[[joint("shoulder"), joint("elbow")]].all()
    assert not model.jnt_actgravcomp[joint("door_hinge")]
    shoulder = model.jnt_dofadr[joint("shoulder")]
    # Delivered as actuator force (at rest it balances the bias force, gravity here); the
    # motor's own PD share is nearly nothing.
    assert data.qfrc_actuator[shoulder] == pytest.approx(data.qfrc_bias[shoulder], abs=1e-3)
    assert abs(data.qfrc_actuator[shoulder]) == pytest.approx(SHOULDER_GRAVITY_NM, rel=0.02)
    assert abs(data.actuator_force[0]) < 1e-3
    assert data.qvel[model.jnt_dofadr[joint("door_hinge")]] != 0.0  # the door still swings


def test_a_driver_refuses_a_model_compiled_without_the_compensation(tmp_path: Path) -> None:
    robot = _two_link(tmp_path, compensated=True)
    plain = mujoco.MjModel.from_xml_path(str(robot_model_file(robot.description, robot.folder)))
    wiring = robot.tables.hal_wiring
    assert wiring is not None and wiring.gravity_compensation
    with pytest.raises(HalError) as info:
        JointDriver(robot.description, wiring, plain, locate_robot(wiring, plain, plain))
    assert str(info.value) == (
        "sim.gravity_compensation is true, but the model does not compensate gravity at "
        "shoulder, elbow; compile the robot's spec through "
        "openral_mujoco.gravity.apply_gravity_compensation"
    )
