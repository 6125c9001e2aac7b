"""One docs page per robot, generated from its manifest, its tables, README and scenes.

``docs/robots/<id>.md`` shows the picture ``just docs-images`` rendered, where the model
comes from and its licence, the joints with their MJCF names and HAL wiring, the grippers,
the sensors with their policy slots, the simulation settings, the scenes and the manifest.
``docs/robots/index.md`` lists every robot, and the robots section of ``mkdocs.yml``'s nav
(between ``BEGIN/END GENERATED robots-nav`` markers) is rewritten to match.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from openral_core.models import (
    DeployScene,
    DepthSensor,
    LimitedJoint,
    RgbSensor,
    RobotDescription,
    Sensor,
    SiteSensor,
    StateSensor,
)
from openral_core.tables import RobotTables

from openral_codegen.models import CodegenError
from openral_codegen.robot_real_docs import real_section

HEADER = "<!-- GENERATED from robots/ by `just schema-export` -- do not edit. -->\n"
IMAGE_DIR = "docs/images/robots"
DEFAULT_SCENE = "scenes/tabletop.yaml"
NAV_BEGIN = "# BEGIN GENERATED robots-nav"
NAV_END = "# END GENERATED robots-nav"
LICENCES = re.compile(
    r"\b(Apache-2\.0|BSD-[23]-Clause|MIT|MPL-2\.0|GPL-[23]\.0(?:-only|-or-later)?"
    r"|LGPL-[23]\.[01](?:-only|-or-later)?|CC-BY(?:-SA)?-4\.0)\b"
)


@dataclass(frozen=True)
class RobotSource:
    """Everything a robot page is generated from.

    Attributes:
        robot: The validated manifest.
        tables: Its derived tables (``openral_core.tables``).
        manifest_text: The manifest file as written.
        readme: The robot's README.md text ('' when missing).
        scenes: Scene files of the robot, repo-relative path → loaded scene, default first.
    """

    robot: RobotDescription
    tables: RobotTables
    manifest_text: str
    readme: str
    scenes: dict[str, DeployScene]


def robot_pages(sources: list[RobotSource]) -> dict[str, str]:
    """Every robot page and the index, keyed by file name inside ``docs/robots/``."""
    pages = {f"{s.robot.name}.md": robot_page(s) for s in sources}
    pages["index.md"] = robots_index(sources)
    return pages


def robot_page(source: RobotSource) -> str:
    """The Markdown page of one robot."""
    robot = source.robot
    sections = [
        HEADER,
        f"# {robot.display_name}\n",
        _summary(robot) + "\n",
        f"![{robot.display_name} in its default scene](../images/robots/{robot.name}.png)"
        '{ width="480" }\n',
        f"*{robot.display_name} in `robots/{robot.name}/{DEFAULT_SCENE}`, rendered offscreen "
        "by `just docs-images`.*\n",
        '!!! note "Generated page"\n'
        f"    Generated from `robots/{robot.name}/` by `just schema-export`. To change it, edit "
        "the manifest or README there and regenerate.\n",
        _model_section(source),
        _joints_section(source),
        _grippers_section(source),
        _sensors_section(source),
        _sim_section(source),
        real_section(robot.name, source.tables.real),
        _scenes_section(source),
        _readme_section(source.readme, "Known limitations"),
        _manifest_section(source),
    ]
    return "\n".join(s for s in sections if s)


def robots_index(sources: list[RobotSource]) -> str:
    """The robots landing page: one row per robot, with its picture."""
    lines = [
        HEADER,
        "# Robots\n",
        "Every robot in `robots/`, each described by one `robot.yaml`. A page per robot shows "
        "its joints, wiring, grippers, sensors and a picture in its default scene. To add one, "
        "follow [Add a robot](../tutorials/add-a-robot.md).\n",
        "| | Robot | Joints | Grippers | Cameras | Base | Model licence |",
        "|---|---|---|---|---|---|---|",
    ]
    for source in sources:
        robot = source.robot
        grippers = len(robot.sim.grippers) if robot.sim else 0
        cameras = sum(isinstance(s, RgbSensor | DepthSensor) for s in robot.sensors)
        base = "floating" if robot.sim and robot.sim.floating_base else robot.base.value
        lines.append(
            f'| ![{robot.name}](../images/robots/{robot.name}.png){{ width="160" }} '
            f"| [{robot.display_name}]({robot.name}.md)<br>`{robot.name}` | {len(robot.joints)} "
            f"| {grippers} | {cameras} | {base} | {_licence_text(source.readme)} |"
        )
    return "\n".join(lines) + "\n"


def robots_nav(sources: list[RobotSource], indent: str) -> str:
    """The nav entries of the robot pages (what goes between the mkdocs.yml markers)."""
    return "".join(
        f"{indent}- {_yaml_key(s.robot.display_name)}: robots/{s.robot.name}.md\n" for s in sources
    )


def with_robots_nav(mkdocs_yml: str, sources: list[RobotSource]) -> str:
    """``mkdocs_yml`` with the lines between the robots-nav markers regenerated.

    Raises:
        CodegenError: The markers are missing or out of order.
    """
    lines = mkdocs_yml.splitlines(keepends=True)
    begin = [i for i, line in enumerate(lines) if line.strip().startswith(NAV_BEGIN)]
    end = [i for i, line in enumerate(lines) if line.strip().startswith(NAV_END)]
    if len(begin) != 1 or len(end) != 1 or end[0] < begin[0]:
        raise CodegenError(f"mkdocs.yml needs one '{NAV_BEGIN}' line followed by '{NAV_END}'")
    marker = lines[begin[0]]
    indent = marker[: len(marker) - len(marker.lstrip())]
    body = robots_nav(sources, indent)
    return "".join([*lines[: begin[0] + 1], body, *lines[end[0] :]])


# -- sections ------------------------------------------------------------------------------


def _summary(robot: RobotDescription) -> str:
    sim = robot.sim
    grippers = len(sim.grippers) if sim else 0
    cameras = sum(isinstance(s, RgbSensor | DepthSensor) for s in robot.sensors)
    base = "floating base" if sim and sim.floating_base else f"{robot.base.value} base"
    return (
        f"`{robot.name}` · {len(robot.joints)} joints · {grippers} gripper(s) · "
        f"{cameras} camera(s) · {base}"
    )


def _model_section(source: RobotSource) -> str:
    robot = source.robot
    lines = ["## Model and licence\n"]
    if robot.sim is not None:
        lines.append(f"- MJCF: `{robot.sim.mjcf_uri}` (resolved offline; nothing is downloaded)")
    lines.append(f"- Model licence: {_licence_text(source.readme)}")
    lines.append(f"- Manifest: `robots/{robot.name}/robot.yaml`\n")
    readme = _readme_body(source.readme, "Model")
    if readme:
        lines.append(f"From `robots/{robot.name}/README.md`:\n\n{readme}\n")
    return "\n".join(lines)


def _joints_section(source: RobotSource) -> str:
    robot, tables = source.robot, source.tables
    wiring = tables.hal_wiring
    pd = wiring is not None and bool(wiring.kp)
    lines = [
        "## Joints\n",
        "Canonical order (the order of joint states and joint-space actions). Limits are in "
        "rad and rad/s for revolute joints, m and m/s for prismatic ones; effort in N·m or N. "
        "qpos, qvel and actuator are the MuJoCo indices the HAL reads and writes.\n",
        "| # | Joint | Type | Position limits | Velocity limit | Effort limit | MJCF joint "
        "| qpos | qvel | Actuator |" + (" kp | kd |" if pd else ""),
        "|---|---|---|---|---|---|---|---|---|---|" + ("---|---|" if pd else ""),
    ]
    for index, joint in enumerate(robot.joints):
        limits = (
            f"[{_num(joint.position_limits[0])}, {_num(joint.position_limits[1])}]"
            if isinstance(joint, LimitedJoint)
            else "none"
        )
        cells = [
            str(index),
            f"`{joint.name}`",
            str(getattr(joint.type, "value", joint.type)),
            limits,
            _num(joint.velocity_limit),
            _num(joint.effort_limit),
            f"`{tables.joint_name_map[joint.name]}`",
            str(wiring.joint_qpos_addr[joint.name]) if wiring else "-",
            str(wiring.joint_qvel_addr[joint.name]) if wiring else "-",
            str(wiring.actuator_index[joint.name]) if wiring else "-",
        ]
        if pd and wiring is not None:
            for gains in (wiring.kp, wiring.kd):
                cells.append(_num(gains[joint.name]) if joint.name in gains else "-")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _grippers_section(source: RobotSource) -> str:
    wiring = source.tables.hal_wiring
    if wiring is None or not wiring.grippers:
        return "## Grippers\n\nNone.\n"
    lines = [
        "## Grippers\n",
        "How each gripper is read from qpos and written to its actuator; the modes are "
        "explained in the [gripper reference](../reference/grippers.md).\n",
        "| Joint | Actuator | Mirror actuator | ctrl range | qpos addresses | qpos scale "
        "| Read mode | Write mode |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for g in wiring.grippers:
        mirror = "-" if g.mirror_actuator_index is None else str(g.mirror_actuator_index)
        cells = [
            f"`{g.joint}`",
            str(g.actuator_index),
            mirror,
            f"[{_num(g.ctrl_range[0])}, {_num(g.ctrl_range[1])}]",
            ", ".join(map(str, g.qpos_addrs)),
            _num(g.qpos_scale),
            f"[`{g.read_mode}`](../reference/grippers.md#gripperreadmode)",
            f"[`{g.write_mode}`](../reference/grippers.md#gripperwritemode)",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _sensors_section(source: RobotSource) -> str:
    robot = source.robot
    if not robot.sensors:
        return "## Sensors\n\nNone.\n"
    slots = {slot.sensor: slot.slot for slot in source.tables.vla_slots}
    lines = [
        "## Sensors\n",
        "The VLA slot is the name a policy receives an RGB camera's frames under "
        "(`camera1`, `camera2`, …: the suffix of `vla_feature_key`, else the sensor name).\n",
        "| Sensor | Kind | Size [px] | Rate [Hz] | Where | Frame id | VLA slot |",
        "|---|---|---|---|---|---|---|",
    ]
    for sensor in robot.sensors:
        cells = [
            f"`{sensor.name}`",
            sensor.kind,
            "-" if isinstance(sensor, StateSensor) else f"{sensor.width}x{sensor.height}",
            _num(sensor.rate_hz),
            _where(sensor),
            f"`{sensor.frame_id}`",
            f"`{slots[sensor.name]}`" if sensor.name in slots else "-",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def _sim_section(source: RobotSource) -> str:
    wiring = source.tables.hal_wiring
    if wiring is None:
        return "## Simulation\n\nNo `sim` block: this robot has no simulation model.\n"
    rows = [
        ("Floating base", "yes (free joint first)" if wiring.floating_base else "no"),
        (
            "Reset keyframe",
            "none (qpos0)" if wiring.keyframe_index is None else str(wiring.keyframe_index),
        ),
        ("Start pose (over the keyframe)", _start_pose(wiring.start_pose)),
        ("Seed ctrl from qpos", "yes" if wiring.seed_ctrl_from_qpos else "no"),
        ("Gravity compensation", "yes" if wiring.gravity_compensation else "no"),
        ("Settle steps per action", str(wiring.settle_steps_default)),
        ("Control law", f"`{wiring.control_mode}`"),
    ]
    if wiring.kp:
        rows.append(("PD gains", "per joint, in the [joints table](#joints)"))
    lines = ["## Simulation\n", "| Setting | Value |", "|---|---|"]
    lines += [f"| {name} | {value} |" for name, value in rows]
    return "\n".join(lines) + "\n"


def _start_pose(pose: dict[str, float]) -> str:
    """``joint = value`` per start-pose joint, or "none"."""
    return ", ".join(f"`{joint}` = {_num(value)}" for joint, value in pose.items()) or "none"


def _scenes_section(source: RobotSource) -> str:
    name = source.robot.name
    lines = ["## Scenes\n", "| Scene file | Backend | Assets | Cameras | Image size [px] |"]
    lines.append("|---|---|---|---|---|")
    for path, scene in source.scenes.items():
        spec = scene.scene
        cameras = ", ".join(f"`{c}`" for c in spec.cameras) or "-"
        size = f"{spec.observation.width}x{spec.observation.height}"
        backend = spec.backend.value
        lines.append(f"| `{path}` | `{backend}` | `{spec.assets}` | {cameras} | {size} |")
    lines.append(
        "\nRun the default scene headless and write its camera frames as PNG files:\n\n"
        "```console\n"
        f"$ openral sim run --config robots/{name}/{DEFAULT_SCENE} --steps 20 --out out/{name}\n"
        "```\n\nand print the wiring tables of this page in a terminal:\n\n"
        f"```console\n$ openral robot show {name}\n```\n"
    )
    return "\n".join(lines)


def _manifest_section(source: RobotSource) -> str:
    name = source.robot.name
    body = "\n".join(f"    {line}" if line else "" for line in source.manifest_text.splitlines())
    return (
        f'## Manifest\n\n??? example "robots/{name}/robot.yaml"\n\n    ```yaml\n{body}\n    ```\n'
    )


# -- helpers -------------------------------------------------------------------------------


def _where(sensor: Sensor) -> str:
    if isinstance(sensor, SiteSensor):
        made = f" (created on body `{sensor.mount_body}`)" if sensor.mount_body else ""
        return f"site `{sensor.site}`{made}{_mjcf_sensors(sensor)}"
    if sensor.camera is not None:
        return f"model camera `{sensor.camera}`"
    if sensor.mount_body is not None:
        return f"mounted on body `{sensor.mount_body}`"
    return "fixed camera placed by the scene"


def _mjcf_sensors(sensor: SiteSensor) -> str:
    """``; reads MJCF gyro `x`, …; adds …`` for a state sensor: which quantities come from
    the model's own sensors and which the native scene adds."""
    if not isinstance(sensor, StateSensor):
        return ""
    quantities = {
        "imu": ("accelerometer", "gyro", "orientation"),
        "force_torque": ("force", "torque"),
        "pose": ("position", "orientation"),
    }[sensor.kind]
    named = [f"{q} `{getattr(sensor, q)}`" for q in quantities if getattr(sensor, q)]
    added = [q for q in quantities if not getattr(sensor, q)]
    parts = [f"reads MJCF {', '.join(named)}"] if named else []
    parts += [f"the scene adds {', '.join(added)}"] if added else []
    return "; " + "; ".join(parts)


def _readme_body(readme: str, heading: str) -> str:
    """The text under ``## <heading>`` of a README, up to the next heading of that level."""
    match = re.search(rf"^## {re.escape(heading)}\s*\n(.*?)(?=^## |\Z)", readme, re.M | re.S)
    return match.group(1).strip() if match else ""


def _readme_section(readme: str, heading: str) -> str:
    body = _readme_body(readme, heading)
    return f"## {heading}\n\n{body}\n" if body else ""


def _licence_text(readme: str) -> str:
    found = list(dict.fromkeys(LICENCES.findall(_readme_body(readme, "Model"))))
    return ", ".join(found) if found else "not named in the README"


def _num(value: float) -> str:
    return f"{value:g}"


def _yaml_key(text: str) -> str:
    return f'"{text}"' if re.search(r"[:#\[\]{},&*!|>'\"%@`]", text) else text
