"""Every robot's URDF states limits a planner can use: each revolute and prismatic joint has
a positive velocity and effort limit, and the start pose lies inside the joint limits
(MoveIt refuses to plan from a start state out of bounds, and reads a zero velocity limit as
a joint that cannot move). A ``frames.joint_limits`` key that names no unlisted joint is
refused with one line naming it."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
import yourdfpy
from openral_core import open_robot_by_id
from openral_core.loaded import open_robot
from openral_mujoco.errors import TreeUnsupported
from openral_sim.robot_description import robot_description

from tests.conftest import ROBOTS

IDS = sorted(p.parent.name for p in ROBOTS.glob("*/robot.yaml"))


@pytest.mark.parametrize("robot_id", IDS)
def test_every_moving_joint_has_positive_limits_and_the_start_pose_fits(robot_id: str) -> None:
    robot = open_robot_by_id(robot_id)
    urdf = yourdfpy.URDF.load(
        io.StringIO(robot_description(robot)), load_meshes=False, build_scene_graph=False
    )
    start = (robot.description.sim.start_pose if robot.description.sim else None) or {}
    moving = [j for j in urdf.robot.joints if j.type in ("revolute", "prismatic")]
    assert moving
    for joint in moving:
        limit = joint.limit
        assert limit is not None, joint.name
        assert limit.velocity > 0 and limit.effort > 0, (joint.name, limit)
        assert limit.lower < limit.upper, (joint.name, limit)
        if joint.name in start:
            assert limit.lower <= start[joint.name] <= limit.upper, (joint.name, limit)


def test_an_unknown_joint_limits_key_is_refused(tmp_path: Path) -> None:
    text = (ROBOTS / "panda_mobile" / "robot.yaml").read_text()
    folder = tmp_path / "panda_mobile"
    folder.mkdir()
    typo = text.replace("joint_limits: {joint_torso_height:", "joint_limits: {joint_torso_heigth:")
    assert typo != text
    (folder / "robot.yaml").write_text(typo)
    robot = open_robot(folder / "robot.yaml")
    with pytest.raises(TreeUnsupported, match=r"frames\.joint_limits: 'joint_torso_heigth' is no"):
        robot_description(robot)


def test_relative_mesh_paths_compile_in_mujoco(tmp_path: Path) -> None:
    """``--mesh-uri relative``'s form: meshes beside the URDF, named by relative path, which
    MuJoCo's own URDF compiler loads (it cannot open ``file://`` URIs)."""
    import mujoco

    text = robot_description(open_robot_by_id("franka_panda"), beside=tmp_path)
    assert "file://" not in text and 'filename="meshes/' in text
    (tmp_path / "panda.urdf").write_text(text)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "panda.urdf"))
    assert model.nmesh > 0 and model.njnt == 9
