"""The robot's SRDF (MoveIt's semantic description, srdfdom's format): what the ROS graph
publishes on ``/robot_description_semantic`` and ``openral robot srdf`` prints.

Read from the same tree as the URDF (:mod:`openral_mujoco.robot_tree`), so every name
matches it:

- a fixed ``virtual_joint`` from the world frame to the base frame;
- group ``arm``: the manifest's joints that are no gripper's, in manifest order;
- group ``gripper`` (a robot with a gripper): the link the first gripper joint hangs from
  and every link below it; an ``end_effector`` of that group on the link it hangs from,
  with ``arm`` as its parent group;
- named states: ``ready`` (the arm at its start pose: the keyframe, then ``sim.start_pose``)
  and, for the gripper, ``open`` and ``closed`` (its joint at its upper and lower limit);
- disabled collision pairs (:mod:`openral_mujoco.self_collision`): ``Adjacent`` and
  ``Never``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
from openral_core.models import RobotDescription
from openral_core.tables import RobotTables

from openral_mujoco.robot_tree import RobotTree, TreeLink
from openral_mujoco.self_collision import LinkPairs, cached_link_pairs
from openral_mujoco.start_pose import set_start_pose

ARM_GROUP = "arm"
GRIPPER_GROUP = "gripper"


def srdf_text(
    tree: RobotTree,
    model: mujoco.MjModel,
    robot: RobotDescription,
    tables: RobotTables,
    pairs: LinkPairs | None = None,
) -> str:
    """The SRDF of the robot whose ``tree`` was read from ``model`` (see the module doc);
    ``pairs`` default to the tree's (:func:`cached_link_pairs`)."""
    pairs = pairs if pairs is not None else cached_link_pairs(tree, model)
    root = ET.Element("robot", name=robot.name)
    gripper_joints = {g.joint for g in tables.hal_wiring.grippers} if tables.hal_wiring else set()
    arm = [j.name for j in robot.joints if j.name not in gripper_joints]
    group = ET.SubElement(root, "group", name=ARM_GROUP)
    for name in arm:
        ET.SubElement(group, "joint", name=name)
    hand = _gripper_links(tree, [j.name for j in robot.joints if j.name in gripper_joints])
    if hand:
        group = ET.SubElement(root, "group", name=GRIPPER_GROUP)
        for link in hand:
            ET.SubElement(group, "link", name=link.name)
    _states(root, tree, model, robot, arm, hand)
    if hand and hand[0].parent is not None:
        ET.SubElement(
            root,
            "end_effector",
            name=GRIPPER_GROUP,
            parent_link=hand[0].parent,
            group=GRIPPER_GROUP,
            parent_group=ARM_GROUP,
        )
    ET.SubElement(
        root,
        "virtual_joint",
        name="virtual_joint",
        type="fixed",
        parent_frame=tables.frames.world,
        child_link=tree.base,
    )
    for reason, found in (("Adjacent", pairs.adjacent), ("Never", pairs.never)):
        for a, b in found:
            ET.SubElement(root, "disable_collisions", link1=a, link2=b, reason=reason)
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _gripper_links(tree: RobotTree, gripper_joints: list[str]) -> list[TreeLink]:
    """The link the first gripper joint hangs from, then every link below it."""
    if not gripper_joints:
        return []
    moved = next(
        (link for link in tree.links if link.joint and link.joint.name == gripper_joints[0]), None
    )
    if moved is None or moved.parent is None:
        return []
    hand = [tree.link(moved.parent)]
    names = {hand[0].name}
    for link in tree.links:  # parents come first: one pass collects the subtree
        if link.parent in names and link.name not in names:
            hand.append(link)
            names.add(link.name)
    return hand


def _states(
    root: ET.Element,
    tree: RobotTree,
    model: mujoco.MjModel,
    robot: RobotDescription,
    arm: list[str],
    hand: list[TreeLink],
) -> None:
    """``ready`` for the arm; ``open`` and ``closed`` for the gripper."""
    data = mujoco.MjData(model)
    keyframe = robot.sim.keyframe_index if robot.sim is not None else None
    if keyframe is not None and keyframe < model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, keyframe)
    set_start_pose(model, data, robot)
    joints = {j.name: j for j in tree.joints}
    state = ET.SubElement(root, "group_state", name="ready", group=ARM_GROUP)
    for name in arm:
        ET.SubElement(state, "joint", name=name, value=_number(data.qpos[joints[name].qpos]))
    hand_joints = [
        link.joint for link in hand if link.joint is not None and link.joint.mimic is None
    ]
    if not hand_joints:
        return
    for name, pick in (("open", 1), ("closed", 0)):
        state = ET.SubElement(root, "group_state", name=name, group=GRIPPER_GROUP)
        for joint in hand_joints:
            value = (joint.lower, joint.upper)[pick]
            ET.SubElement(state, "joint", name=joint.name, value=_number(value))


def _number(value: float) -> str:
    return repr(round(float(value), 6))
