"""Tests for the mobile-base table of tables.py: MobileBaseWiring from panda_mobile's manifest."""

from __future__ import annotations

from openral_core import MobileBaseWiring, load_robot, robot_tables
from openral_core.loaded import open_robot_by_id
from openral_core.tables import RobotTables

from tests.conftest import MOCK_ARM, ROBOTS


def test_panda_mobile_base_is_wired_with_every_default_filled_in() -> None:
    wiring = robot_tables(load_robot(ROBOTS / "panda_mobile" / "robot.yaml")).mobile_base
    assert wiring == MobileBaseWiring(
        mjcf_uri="pkg:robosuite/robosuite/models/assets/bases/omron_mobile_base.xml",
        mount_body="support",
        mount_position_m=(0.0, 0.0, 0.0),
        mount_quat_wxyz=(1.0, 0.0, 0.0, 0.0),
        drive="holonomic",
        joints=("joint_mobile_forward", "joint_mobile_side", "joint_mobile_yaw"),
        actuators=("actuator_mobile_forward", "actuator_mobile_side", "actuator_mobile_yaw"),
        max_linear_velocity_m_s=0.5,
        max_angular_velocity_rad_s=1.0,
        max_linear_acceleration_m_s2=1.0,
        max_angular_acceleration_rad_s2=2.0,
        command_timeout_s=0.5,
        odom_frame="odom",
        base_frame="base_link",
    )


def test_the_runtime_reads_the_base_from_the_generated_table() -> None:
    robot = open_robot_by_id("panda_mobile")
    assert robot.tables.mobile_base == robot_tables(robot.description).mobile_base


def test_json_round_trip_keeps_the_base_and_a_fixed_robot_has_none() -> None:
    tables = robot_tables(load_robot(ROBOTS / "panda_mobile" / "robot.yaml"))
    assert RobotTables.from_json(tables.to_json()) == tables
    assert robot_tables(load_robot(MOCK_ARM)).mobile_base is None
