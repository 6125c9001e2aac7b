"""Sensor-name → VLA-slot realignment: the pure rule the runner applies to camera frames."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from openral_core import VlaSlot, load_robot_by_id, robot_ids, vla_slots
from openral_core.models import RgbSensor
from openral_nodes.rskill_runner import realign_frames


def test_franka_frames_land_on_the_slots_of_its_table() -> None:
    table = vla_slots(load_robot_by_id("franka_panda"))
    frames = {"wrist": "wrist-frame", "agentview": "agentview-frame"}
    assert realign_frames(frames, table) == {
        "camera1": "agentview-frame",
        "camera2": "wrist-frame",
    }


def test_sensors_outside_the_table_and_absent_frames_are_dropped() -> None:
    table = (VlaSlot("front", "camera1"), VlaSlot("wrist", "camera2"))
    assert realign_frames({"wrist": 2, "depth": 9}, table) == {"camera2": 2}
    assert realign_frames({}, table) == {}


def test_a_sensor_without_a_feature_key_keeps_its_name_as_slot() -> None:
    table = (VlaSlot("robot0_eye_in_hand", "robot0_eye_in_hand"),)
    assert realign_frames({"robot0_eye_in_hand": 1}, table) == {"robot0_eye_in_hand": 1}


@pytest.mark.parametrize("robot_id", robot_ids())
@settings(max_examples=20, deadline=None, derandomize=True)
@given(data=st.data())
def test_every_manifests_rgb_sensors_map_to_distinct_slots(
    robot_id: str, data: st.DataObject
) -> None:
    robot = load_robot_by_id(robot_id)
    rgb = [s.name for s in robot.sensors if isinstance(s, RgbSensor)]
    table = vla_slots(robot)
    assert [entry.sensor for entry in table] == rgb
    assert len({entry.slot for entry in table}) == len(rgb), f"{robot_id}: slots collide"
    present = data.draw(st.lists(st.sampled_from(rgb), unique=True) if rgb else st.just([]))
    frames = {sensor: f"frame of {sensor}" for sensor in present}
    by_slot = realign_frames(frames, table)
    assert len(by_slot) == len(present)  # no two frames share a slot
    slot_of = {entry.sensor: entry.slot for entry in table}
    assert all(by_slot[slot_of[sensor]] == f"frame of {sensor}" for sensor in present)
