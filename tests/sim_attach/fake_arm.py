"""The two-joint fake arm the attach tests load: its manifest, written into a robot folder."""

from __future__ import annotations

from pathlib import Path

JOINTS = """\
schema_version: "0.1"
name: fake_arm
display_name: Fake arm
base: fixed
joints:
  - {name: joint1, type: revolute, position_limits: [-3.0, 3.0],
     velocity_limit: 5.0, effort_limit: 10.0}
  - {name: joint2, type: revolute, position_limits: [-3.0, 3.0],
     velocity_limit: 5.0, effort_limit: 10.0}
"""
CAMERAS = """\
sensors:
  - {name: agentview, kind: rgb, width: 32, height: 32, rate_hz: 10.0, frame_id: agentview_optical}
  - {name: wrist, kind: rgb, width: 32, height: 32, rate_hz: 10.0, frame_id: wrist_optical}
"""
NO_SENSORS = "sensors: []\n"


def write_fake_arm(folder: Path, sensors: str = CAMERAS) -> Path:
    """``folder/fake_arm/robot.yaml`` with the fake arm's joints and ``sensors``."""
    path = folder / "fake_arm" / "robot.yaml"
    path.parent.mkdir()
    path.write_text(JOINTS + sensors)
    return path
