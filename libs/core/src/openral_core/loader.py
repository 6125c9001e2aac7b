"""The one load path for manifests and scene files.

YAML (safe, with positions) → JSON Schema → generated pydantic model (strict) →
cross-field rules. Every problem of a file is collected and raised together as a
:class:`ManifestError` whose lines read ``file:line:col: field.path: message``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import TypeVar

from openral_base import OpenralModel
from pydantic import ValidationError

from openral_core.errors import Issue, ManifestError
from openral_core.located import remember_source
from openral_core.models import DeployScene, RobotDescription
from openral_core.rules import robot_findings, scene_findings
from openral_core.schemas import SchemaName
from openral_core.validation import schema_issues
from openral_core.yaml_source import LocatedDocument, load_located

ModelT = TypeVar("ModelT", bound=OpenralModel)


def load_robot(file: Path, *, check_folder_name: bool = True) -> RobotDescription:
    """Load and fully validate a ``robot.yaml``.

    Args:
        file: Path of the manifest.
        check_folder_name: Require ``name`` to equal the name of the containing folder.

    Raises:
        ManifestError: With every problem found in the file.
    """
    document = load_located(file)
    robot = _build(document, SchemaName.ROBOT, RobotDescription)
    folder = file.resolve().parent.name if check_folder_name else None
    findings = robot_findings(robot, folder)
    if findings:
        raise ManifestError(file, [document.issue(path, msg) for path, msg in findings])
    return robot


def load_scene(file: Path) -> DeployScene:
    """Load and validate a deploy-scene file (the ``--config`` of sim run / deploy sim).

    A file under ``robots/<id>/scenes/`` belongs to robot ``<id>``: its ``robot_id`` may be
    left out (it is then ``<id>``) and any other value is refused at its line and column.

    Raises:
        ManifestError: With every problem found in the file.
    """
    document = load_located(file)
    scene = _build(document, SchemaName.SCENE, DeployScene)
    folder_robot = scene_folder_robot(file)
    findings = scene_findings(scene, folder_robot)
    if findings:
        raise ManifestError(file, [document.issue(path, msg) for path, msg in findings])
    if scene.robot_id is None and folder_robot is not None:
        scene.robot_id = folder_robot
    return scene


def scene_folder_robot(file: Path) -> str | None:
    """``<id>`` when ``file`` (resolved: links and ``..`` followed) is
    ``robots/<id>/scenes/<name>``, else None."""
    parts = file.resolve().parts
    if len(parts) >= 4 and parts[-2] == "scenes" and parts[-4] == "robots":
        return parts[-3]
    return None


def validate_robot_file(file: Path, *, check_folder_name: bool = True) -> list[Issue]:
    """Every problem in a manifest, or an empty list when it is valid."""
    try:
        load_robot(file, check_folder_name=check_folder_name)
    except ManifestError as error:
        return list(error.issues)
    return []


def _build(document: LocatedDocument, name: SchemaName, model: type[ModelT]) -> ModelT:
    issues = schema_issues(document, name)
    if issues:
        raise ManifestError(document.file, issues)
    try:
        built = model.model_validate_json(json.dumps(document.data), strict=True)
    except ValidationError as error:
        # The schema and the models are generated to agree (a property test guards it);
        # should they ever disagree, report the model's verdict the same way.
        raise ManifestError(
            document.file,
            [document.issue(tuple(e["loc"]), e["msg"]) for e in error.errors()],
        ) from None
    remember_source(built, document)
    return built
