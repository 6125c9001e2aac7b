"""Tests for link_names.py, extra_links.py, self_collision.py and srdf.py: the Panda takes
franka_description's link and joint names, and its SRDF matches its URDF."""

from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import LoadedRobot, open_robot_by_id
from openral_core.tables import robot_tables
from openral_mujoco.errors import TreeUnsupported
from openral_mujoco.robot_tree import RobotTree, robot_tree
from openral_mujoco.self_collision import link_pairs
from openral_mujoco.srdf import srdf_text
from openral_sim.frame_tree import scene_frame_tree
from openral_sim.robot_description import robot_description
from openral_sim.scene_base import robot_alone

from tests.conftest import ROBOTS

PANDA_LINKS = [f"panda_link{i}" for i in range(9)] + [
    "panda_hand",
    "panda_leftfinger",
    "panda_rightfinger",
]
PANDA_JOINTS = [f"panda_joint{i}" for i in range(1, 8)] + [
    "panda_finger_joint1",
    "panda_finger_joint2",
]


@pytest.fixture(scope="module")
def panda() -> LoadedRobot:
    return open_robot_by_id("franka_panda")


@pytest.fixture(scope="module")
def tree_and_model(panda: LoadedRobot) -> tuple[RobotTree, mujoco.MjModel]:
    alone = robot_alone(panda)
    return robot_tree(alone.model, panda.description, panda.tables, alone.addresses), alone.model


def test_the_urdf_has_franka_descriptions_names(panda: LoadedRobot) -> None:
    urdf = ET.fromstring(robot_description(panda))
    links = [link.get("name") for link in urdf.iter("link")]
    joints = {joint.get("name"): joint for joint in urdf.iter("joint")}
    assert set(PANDA_LINKS) <= set(links)
    assert set(PANDA_JOINTS) <= set(joints)
    assert not {"link0", "hand", "left_finger", "finger_joint2"} & (set(links) | set(joints))
    flange = joints["panda_joint8"]
    assert flange.get("type") == "fixed"
    assert flange.find("parent").get("link") == "panda_link7"  # type: ignore[union-attr]
    assert flange.find("origin").get("xyz") == "0 0 0.107"  # type: ignore[union-attr]
    hand = joints["panda_hand_joint"]
    assert hand.find("parent").get("link") == "panda_link8"  # type: ignore[union-attr]
    mimic = joints["panda_finger_joint2"].find("mimic")
    assert mimic is not None and mimic.get("joint") == "panda_finger_joint1"


def test_the_flange_and_the_hand_sit_where_mujoco_puts_them(panda: LoadedRobot) -> None:
    alone = robot_alone(panda)
    frames = scene_frame_tree(alone.model, panda, alone.addresses, {}, None)
    data = mujoco.MjData(alone.model)
    data.qpos[:7] = [0.3, -0.5, 0.2, -2.0, 0.1, 1.5, 0.7]
    mujoco.mj_kinematics(alone.model, data)
    sample = frames.sample(data)
    row = {name: i for i, name in enumerate(frames.names_of_frames)}
    hand = mujoco.mj_name2id(alone.model, mujoco.mjtObj.mjOBJ_BODY, "hand")
    link7 = mujoco.mj_name2id(alone.model, mujoco.mjtObj.mjOBJ_BODY, "link7")
    np.testing.assert_allclose(sample.positions[row["panda_hand"]], data.xpos[hand], atol=1e-9)
    flange = data.xpos[link7] + data.xmat[link7].reshape(3, 3) @ [0.0, 0.0, 0.107]
    np.testing.assert_allclose(sample.positions[row["panda_link8"]], flange, atol=1e-9)


def test_the_srdf_names_the_urdfs_links_and_the_arm_in_order(
    panda: LoadedRobot, tree_and_model: tuple[RobotTree, mujoco.MjModel]
) -> None:
    tree, model = tree_and_model
    srdf = ET.fromstring(srdf_text(tree, model, panda.description, panda.tables))
    groups = {g.get("name"): g for g in srdf.iter("group")}
    assert [j.get("name") for j in groups["arm"].iter("joint")] == PANDA_JOINTS[:7]
    assert [li.get("name") for li in groups["gripper"].iter("link")] == [
        "panda_hand",
        "panda_leftfinger",
        "panda_rightfinger",
    ]
    effector = srdf.find("end_effector")
    assert effector is not None and effector.get("parent_link") == "panda_link8"
    virtual = srdf.find("virtual_joint")
    assert virtual is not None and virtual.get("child_link") == tree.base
    links = {link.name for link in tree.links}
    for pair in srdf.iter("disable_collisions"):
        assert {pair.get("link1"), pair.get("link2")} <= links
    states = {s.get("name"): s for s in srdf.iter("group_state")}
    assert set(states) == {"ready", "open", "closed"}
    ready = [float(j.get("value") or "nan") for j in states["ready"].iter("joint")]
    for value, joint in zip(ready, panda.description.joints, strict=False):
        low, high = joint.position_limits  # type: ignore[union-attr]
        assert low <= value <= high


def test_no_pair_marked_never_touches_in_an_independent_sample(
    tree_and_model: tuple[RobotTree, mujoco.MjModel],
) -> None:
    """MuJoCo's contacts, no margin and no pair filter, over 1500 poses of another seed."""
    tree, model = tree_and_model
    pairs = link_pairs(tree, model)
    assert pairs.never and pairs.adjacent and pairs.touching
    link_of = {}
    for link in tree.links:
        if link.body >= 0:
            first = int(model.body_geomadr[link.body])
            for geom in range(first, first + int(model.body_geomnum[link.body])):
                if model.geom_contype[geom] or model.geom_conaffinity[geom]:
                    link_of[geom] = link.name
    probe = model.__copy__()
    listed = np.isin(np.arange(probe.ngeom), list(link_of))
    probe.geom_contype[:] = probe.geom_conaffinity[:] = listed.astype(np.int32)
    probe.geom_margin[:] = 0.0
    probe.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_FILTERPARENT)
    joints = [link.joint for link in tree.links if link.joint is not None]
    data, rng, never = mujoco.MjData(probe), np.random.default_rng(12345), set(pairs.never)
    for _ in range(1500):
        for joint in joints:
            data.qpos[joint.qpos] = rng.uniform(joint.lower, joint.upper)
        mujoco.mj_kinematics(probe, data)
        mujoco.mj_collision(probe, data)
        for contact in data.contact[: data.ncon]:
            a, b = sorted((link_of[int(contact.geom1)], link_of[int(contact.geom2)]))
            assert (a, b) not in never, (a, b, contact.dist)


@pytest.mark.parametrize(
    ("frames", "expected"),
    [
        ({"links": {"no_such_body": "x"}}, "frames.links: 'no_such_body' is no body"),
        ({"joints": {"panda_joint1": "x"}}, "frames.joints: 'panda_joint1' is neither"),
        (
            {"extra_links": [{"name": "tip", "parent": "nowhere", "joint": "tip_joint"}]},
            "frames.extra_links: 'tip' hangs from 'nowhere', which is no link",
        ),
        (
            {
                "extra_links": [
                    {"name": "tip", "parent": "link7", "joint": "j", "children": ["link3"]}
                ]
            },
            "takes over 'link3', which is no child link of 'link7'",
        ),
    ],
)
def test_a_name_that_names_nothing_is_one_line(frames: dict[str, object], expected: str) -> None:
    panda = open_robot_by_id("franka_panda")
    description = panda.description.model_copy(
        update={"frames": panda.description.frames.model_validate(frames)}  # type: ignore[union-attr]
    )
    robot = LoadedRobot(description, panda.folder, robot_tables(description))
    alone = robot_alone(robot)
    with pytest.raises(TreeUnsupported, match=expected) as caught:
        robot_tree(alone.model, robot.description, robot.tables, alone.addresses)
    assert "\n" not in str(caught.value)


def test_openral_robot_srdf_prints_it_and_a_robot_without_a_tree_is_one_line(
    tmp_path: Path,
) -> None:
    openral = Path(sys.executable).parent / "openral"
    done = subprocess.run(
        [openral, "robot", "srdf", "franka_panda"], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    arm = ET.fromstring(done.stdout).find("group")
    assert arm is not None and [j.get("name") for j in arm] == PANDA_JOINTS[:7]
    broken = tmp_path / "franka_panda" / "robot.yaml"
    broken.parent.mkdir()
    text = (ROBOTS / "franka_panda" / "robot.yaml").read_text()
    broken.write_text(text.replace("hand: panda_hand,", "hand: panda_hand, nope: x,"))
    done = subprocess.run([openral, "robot", "srdf", str(broken)], capture_output=True, text=True)
    assert done.returncode == 1 and "frames.links: 'nope' is no body" in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
