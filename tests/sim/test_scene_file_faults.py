"""Valid-looking files that used to crash a scene build: each is refused at its field.

Each case writes a copy of a real manifest or scene with one fault, builds what the user
would build (a native scene, a bare-robot HAL) and checks the one located line it gets.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import pytest
from openral_core import open_robot
from openral_core.errors import ManifestError
from openral_core.loader import load_scene
from openral_hal.factory import build_hal
from openral_sim.native_scene import NativeScene
from openral_sim.scene_checks import (
    MAX_PHYSICS_STEPS_PER_CONTROL,
    check_object_names,
    physics_steps_per_control,
)

from tests.conftest import ROBOTS

FRANKA_SCENE = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


def _copy(tmp_path: Path, source: Path, old: str, new: str, folder: str = "") -> Path:
    """``source`` copied into ``tmp_path/folder`` with ``old`` replaced by ``new`` once."""
    text = source.read_text()
    assert old in text, f"{old!r} not in {source}"
    target = tmp_path / folder / source.name
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(text.replace(old, new, 1))
    return target


def _line_of(file: Path, fragment: str) -> int:
    return next(i for i, line in enumerate(file.read_text().splitlines(), 1) if fragment in line)


def _only_issue(error: pytest.ExceptionInfo[ManifestError]) -> tuple[Path, int, str, str]:
    (issue,) = error.value.issues
    assert issue.column >= 1
    return issue.file, issue.line, issue.field, issue.message


def test_two_objects_with_one_name_are_refused_by_the_loader(tmp_path: Path) -> None:
    scene = _copy(tmp_path, FRANKA_SCENE, "name: green_cube", "name: red_cube")
    with pytest.raises(ManifestError) as error:
        load_scene(scene)
    file, line, field, message = _only_issue(error)
    second = [i for i, text in enumerate(scene.read_text().splitlines(), 1) if "red_cube" in text]
    assert (file, line) == (scene, second[1])
    assert field == "scene.options.objects[1].name"
    assert "duplicate object name 'red_cube' (also at scene.options.objects[0].name)" in message


def _ur5e_scene(tmp_path: Path) -> Path:
    """The franka tabletop for the ur5e, with the two cameras both robots have."""
    scene = _copy(tmp_path, FRANKA_SCENE, "robot_id: franka_panda", "robot_id: ur5e")
    text = scene.read_text()
    assert text.count("cameras: [agentview, wrist, front_depth]") == 1
    scene.write_text(text.replace("agentview, wrist, front_depth]", "agentview, wrist]"))
    return scene


def test_floating_base_on_a_fixed_robot_is_refused_at_the_field(tmp_path: Path) -> None:
    manifest = _copy(
        tmp_path,
        ROBOTS / "ur5e" / "robot.yaml",
        "  keyframe_index: 0\n",
        "  keyframe_index: 0\n  floating_base: true\n",
        folder="ur5e",
    )
    robot = open_robot(manifest)
    hal = build_hal(robot, mode="sim")
    with pytest.raises(ManifestError) as error:
        hal.connect()
    fields = {issue.field: issue for issue in error.value.issues}
    base = fields["sim.floating_base"]
    assert (base.file, base.line) == (manifest, _line_of(manifest, "floating_base"))
    assert "the manifest says true, the model has no free joint at qpos 0" in base.message
    assert not hal.connected
    scene = _ur5e_scene(tmp_path)
    with pytest.raises(ManifestError, match=r"robot\.yaml:\d+:\d+: sim\.floating_base: "):
        NativeScene(load_scene(scene), robot)


def test_a_manifest_camera_the_model_lacks_is_refused_at_the_field(tmp_path: Path) -> None:
    manifest = _copy(
        tmp_path,
        ROBOTS / "ur5e" / "robot.yaml",
        "    kind: rgb\n    mount_body: wrist_3_link",
        "    kind: rgb\n    camera: no_such_camera",
        folder="ur5e",
    )
    scene = _ur5e_scene(tmp_path)
    with pytest.raises(ManifestError) as error:
        NativeScene(load_scene(scene), open_robot(manifest))
    file, line, field, message = _only_issue(error)
    assert (file, line, field) == (
        manifest,
        _line_of(manifest, "no_such_camera"),
        "sensors[1].camera",
    )
    assert "no_such_camera" in message and "not in the model" in message


def test_a_control_rate_faster_than_physics_is_refused(tmp_path: Path) -> None:
    scene = _copy(tmp_path, FRANKA_SCENE, "control_freq_hz: 20.0", "control_freq_hz: 2000.0")
    robot = open_robot(ROBOTS / "franka_panda" / "robot.yaml")
    with pytest.raises(ManifestError) as error:
        NativeScene(load_scene(scene), robot)
    file, line, field, message = _only_issue(error)
    assert (file, line) == (scene, _line_of(scene, "control_freq_hz"))
    assert field == "scene.options.control_freq_hz"
    assert "2000 Hz is faster than the model's physics (500 Hz" in message


def test_a_control_period_of_too_many_physics_steps_is_refused(tmp_path: Path) -> None:
    scene = load_scene(
        _copy(tmp_path, FRANKA_SCENE, "control_freq_hz: 20.0", "control_freq_hz: 1.0")
    )
    assert physics_steps_per_control(scene, 0.002) == 500
    with pytest.raises(ManifestError, match=f"at most {MAX_PHYSICS_STEPS_PER_CONTROL} are allowed"):
        physics_steps_per_control(scene, 1e-5)


def test_an_object_named_like_a_model_element_is_refused(tmp_path: Path) -> None:
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body name="scene_red_cube"><geom size="0.1"/></body>'
        "</worldbody></mujoco>"
    )
    scene = load_scene(FRANKA_SCENE)
    with pytest.raises(ManifestError) as error:
        check_object_names(scene, model)
    file, line, field, message = _only_issue(error)
    assert (file, field) == (FRANKA_SCENE, "scene.options.objects[0].name")
    assert line == _line_of(FRANKA_SCENE, "red_cube")
    assert "already has an element named 'scene_red_cube'" in message


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "control_freq_hz: 20.0",
            "control_freq_hz: 0.002",
            "expected a value >= 1 and <= 2000, got 0.002",
        ),
        (
            "control_freq_hz: 20.0",
            "control_freq_hz: 5000",
            "expected a value >= 1 and <= 2000, got 5000",
        ),
        (
            "{width: 128, height: 128}",
            "{width: 8, height: 128}",
            "expected a value >= 16 and <= 4096, got 8",
        ),
    ],
    ids=["rate-too-low", "rate-too-high", "image-too-small"],
)
def test_rates_and_sizes_outside_their_range_are_refused_with_it(
    tmp_path: Path, old: str, new: str, expected: str
) -> None:
    scene = _copy(tmp_path, FRANKA_SCENE, old, new)
    with pytest.raises(ManifestError) as error:
        load_scene(scene)
    file, line, _, message = _only_issue(error)
    assert (file, line) == (scene, _line_of(scene, new.split(":")[0].strip("{ ")))
    assert expected in message
