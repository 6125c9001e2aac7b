"""Break each cross-field rule on purpose and record the error the user would see.

The reference pages list the rules JSON Schema cannot state. For each one, a single text
edit of a real file (a robot's manifest, mostly franka_panda's, or a default scene) breaks
exactly that rule; the broken copy is run through the real validator at export time and the
error it produces is what the page shows. A rule whose edit no longer fails, or whose edit
no longer applies to the file, stops the export with a message saying which example to
update.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

from openral_core.errors import OpenralError
from openral_core.loader import validate_robot_file
from openral_core.schemas import SchemaName

from openral_codegen.models import CodegenError

ROBOT_FILE = "robots/franka_panda/robot.yaml"
MOBILE_FILE = "robots/panda_mobile/robot.yaml"
UR10E_FILE = "robots/ur10e/robot.yaml"
H1_FILE = "robots/h1/robot.yaml"
SCENE_FILE = "robots/franka_panda/scenes/tabletop.yaml"
SO101_FILE = "robots/so101/robot.yaml"
SO101_FEETECH_SECTION = """\
  feetech:
    servo_model: sts3215
    baud_rate: 1000000
    protocol: 0
    motors:
      - {joint: shoulder_pan, id: 1}
      - {joint: shoulder_lift, id: 2}
      - {joint: elbow_flex, id: 3}
      - {joint: wrist_flex, id: 4}
      - {joint: wrist_roll, id: 5}
      - {joint: gripper, id: 6}
    calibration: {lerobot_robot_type: so101_follower}
    settings:  # as LeRobot's follower configures its servos
      Return_Delay_Time: 0
      Acceleration: 254
      P_Coefficient: 16
      I_Coefficient: 0
      D_Coefficient: 32
    joint_settings:
      gripper: {Max_Torque_Limit: 500, Protection_Current: 250, Overload_Torque: 25}  # LeRobot's
"""
"""The so101's whole Feetech bus section (rule 20's example leaves it out)."""


@dataclass(frozen=True)
class RuleBreak:
    """One edit of a real file that breaks one rule.

    Attributes:
        schema: The schema whose ``$comment`` lists the rule.
        rule: The rule: its number in a ``(1) …; (2) …`` comment, else a short statement.
        file: Repo-relative path of the file the edit applies to.
        old: Text that occurs exactly once in the file.
        new: Its replacement.
        checked_in: The module (and function) that enforces the rule.
    """

    schema: SchemaName
    rule: int | str
    file: str
    old: str
    new: str
    checked_in: str = "openral_core.rules.robot_findings"


@dataclass(frozen=True)
class RuleExample:
    """A rule break and the error text the validator printed for it."""

    broken: RuleBreak
    error: str


RULE_BREAKS = (
    RuleBreak(SchemaName.ROBOT, 1, ROBOT_FILE, "name: franka_panda", "name: franka"),
    RuleBreak(SchemaName.ROBOT, 2, ROBOT_FILE, "{name: panda_joint2,", "{name: panda_joint1,"),
    RuleBreak(
        SchemaName.ROBOT, 3, ROBOT_FILE, "sim_joint_name: joint2,", "sim_joint_name: joint1,"
    ),
    RuleBreak(SchemaName.ROBOT, 4, ROBOT_FILE, "- name: wrist\n", "- name: agentview\n"),
    RuleBreak(
        SchemaName.ROBOT,
        5,
        ROBOT_FILE,
        "position_limits: [-1.7628, 1.7628]",
        "position_limits: [1.7628, -1.7628]",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        6,
        ROBOT_FILE,
        "- joint: panda_finger_joint1",
        "- joint: panda_finger_joint",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        7,
        ROBOT_FILE,
        "  keyframe_index: 0\n",
        "  keyframe_index: 0\n  joint_qpos_addr: {panda_joint8: 8}\n",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        8,
        ROBOT_FILE,
        "  keyframe_index: 0\n",
        "  keyframe_index: 0\n  control: {mode: torque_pd, kp: {panda_joint8: 100.0}, kd: 10.0}\n",
    ),
    RuleBreak(
        SchemaName.ROBOT, 9, ROBOT_FILE, "ctrl_range: [0.0, 255.0]", "ctrl_range: [255.0, 0.0]"
    ),
    RuleBreak(
        SchemaName.ROBOT,
        10,
        ROBOT_FILE,
        "observation.images.camera2",
        "observation.images.camera1",
    ),
    RuleBreak(SchemaName.ROBOT, 11, ROBOT_FILE, "base: fixed", "base: mobile"),
    RuleBreak(SchemaName.ROBOT, 12, MOBILE_FILE, "base: mobile", "base: fixed"),
    RuleBreak(
        SchemaName.ROBOT,
        13,
        ROBOT_FILE,
        "- name: agentview\n    kind: rgb\n",
        "- name: agentview\n    kind: rgb\n    mount_position_m: [1.0, 0.0, 1.0]\n",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        14,
        MOBILE_FILE,
        "base: mobile\n",
        "base: mobile\nframes: {base: base_footprint}\n",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        15,
        ROBOT_FILE,
        "frame_id: ft_sensor_link",
        "frame_id: wrist_optical_frame",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        16,
        UR10E_FILE,
        "    elbow_joint: 1.5708\n",
        "    elbow_joint: 3.5\n",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        17,
        H1_FILE,
        "  floating_base: true\n",
        "  floating_base: true\n  gravity_compensation: true\n",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        18,
        ROBOT_FILE,
        "offset_m: [0.0, 0.0, 0.1034]}",
        "offset_m: [0.0, 0.0, 0.1034], quat_wxyz: [0.0, 1.0, 1.0, 0.0]}",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        27,
        ROBOT_FILE,
        "position_m: [0.0, 0.0, 0.107],",
        "position_m: [0.0, 0.0, 0.107], quat_wxyz: [0.0, 0.0, 0.0, 0.0],",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        19,
        ROBOT_FILE,
        "tcp: {body: hand,",
        "tcp: {body: hand, site: hand_site,",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        20,
        SO101_FILE,
        SO101_FEETECH_SECTION,
        "",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        21,
        SO101_FILE,
        "      - {joint: wrist_roll, id: 5}\n",
        "",
    ),
    RuleBreak(
        SchemaName.ROBOT, 22, SO101_FILE, "{joint: gripper, id: 6}", "{joint: gripper, id: 5}"
    ),
    RuleBreak(
        SchemaName.ROBOT,
        23,
        SO101_FILE,
        "{name: wrist_roll, type: revolute, position_limits: [-2.743847, 2.841206]",
        "{name: wrist_roll, type: revolute, position_limits: [-3.5, 3.5]",
    ),
    RuleBreak(
        SchemaName.ROBOT,
        24,
        SO101_FILE,
        "      gripper: {Max_Torque_Limit: 500,",
        "      jaw: {Max_Torque_Limit: 500,",
    ),
    RuleBreak(SchemaName.ROBOT, 25, SO101_FILE, "    protocol: 0\n", "    protocol: 1\n"),
    RuleBreak(
        SchemaName.ROBOT, 26, SO101_FILE, "    baud_rate: 1000000\n", "    baud_rate: 230400\n"
    ),
    RuleBreak(SchemaName.ROBOT, 28, ROBOT_FILE, "  shutdown: hold  #", "  shutdown: torque_off  #"),
    RuleBreak(
        SchemaName.ROBOT,
        29,
        ROBOT_FILE,
        "    gripper_action: gripper_controller/gripper_cmd\n",
        "    gripper_action: gripper_controller/gripper_cmd\n"
        "    joint_names: {panda_joint2: panda_joint1}\n",
    ),
    RuleBreak(
        SchemaName.SCENE,
        1,
        SCENE_FILE,
        "{name: green_cube,",
        "{name: red_cube,",
        "openral_core.rules.scene_findings",
    ),
    RuleBreak(
        SchemaName.SCENE,
        2,
        SCENE_FILE,
        "size_m: [0.02, 0.02, 0.02]",
        "size_m: [0.02]",
        "openral_core.rules.scene_findings",
    ),
    RuleBreak(
        SchemaName.SCENE,
        3,
        SCENE_FILE,
        "robot_id: franka_panda",
        "robot_id: franka",
        "openral_core.rules.scene_findings",
    ),
    RuleBreak(
        SchemaName.SCENE,
        4,
        SCENE_FILE,
        "cameras: [agentview, wrist, front_depth]",
        "cameras: [agentview, wrist_cam, front_depth]",
        "openral_sim.scene_checks.check_scene_cameras",
    ),
    RuleBreak(
        SchemaName.SCENE,
        5,
        SCENE_FILE,
        "yaw_deg: 0.0}",
        "yaw_deg: 0.0, weld: true}",
        "openral_sim.scene_checks.check_weld",
    ),
    RuleBreak(
        SchemaName.SCENE,
        6,
        SCENE_FILE,
        "control_freq_hz: 20.0",
        "control_freq_hz: 1000.0",
        "openral_sim.scene_checks.physics_steps_per_control",
    ),
    RuleBreak(
        SchemaName.SCENE,
        7,
        SCENE_FILE,
        "control_freq_hz: 20.0",
        "control_freq_hz: 20.0\n    state_rate_hz: 10.0",
        "openral_sim.scene_checks.state_parts_per_control",
    ),
)
"""Every rule break the reference pages show, in page order."""


def numbered_rules(comment: str) -> tuple[str, dict[int, str]]:
    """Split a ``$comment`` of the form ``head: (1) rule; (2) rule.`` into head and rules."""
    head, colon, rest = comment.partition(": (1)")
    if not colon:
        return comment, {}
    rules = {}
    for match in re.finditer(r"\((\d+)\) (.*?)(?=; \(\d+\) |\.?$)", "(1)" + rest):
        rules[int(match.group(1))] = match.group(2)
    return head, rules


def rule_examples(root: Path) -> list[RuleExample]:
    """Apply every :data:`RULE_BREAKS` edit to a copy and validate it; returns the errors.

    Raises:
        CodegenError: An edit no longer applies, or the broken copy no longer fails.
    """
    examples = []
    with tempfile.TemporaryDirectory() as tmp:
        for broken in RULE_BREAKS:
            text = (root / broken.file).read_text("utf-8")
            if text.count(broken.old) != 1:
                raise CodegenError(
                    f"rule example {broken.rule!r}: {broken.old!r} must occur once in "
                    f"{broken.file}; update RULE_BREAKS in openral_codegen/rule_examples.py"
                )
            copy = Path(tmp) / broken.file
            copy.parent.mkdir(parents=True, exist_ok=True)
            copy.write_text(text.replace(broken.old, broken.new), "utf-8")
            error = _robot_error(copy) if broken.schema is SchemaName.ROBOT else _scene_error(copy)
            if not error:
                raise CodegenError(
                    f"rule example {broken.rule!r}: the edited {broken.file} passes; the rule "
                    "changed, so update RULE_BREAKS in openral_codegen/rule_examples.py"
                )
            examples.append(RuleExample(broken, error.replace(f"{tmp}/", "")))
    return examples


def _robot_error(file: Path) -> str:
    issues = validate_robot_file(file)
    return "\n".join(replace(issue, file=file).format() for issue in issues)


def _scene_error(file: Path) -> str:
    from openral_core.loader import load_scene
    from openral_sim.scene import build_scene, scene_robot

    try:
        scene = load_scene(file)
        env = build_scene(scene, scene_robot(scene))
    except OpenralError as error:
        return str(error)
    env.close()
    return ""
