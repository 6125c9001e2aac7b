"""The robots of this repository: one folder per robot under ``robots/``."""

from __future__ import annotations

from pathlib import Path

from openral_core.errors import UnknownRobot
from openral_core.loader import load_robot
from openral_core.models import RobotDescription
from openral_core.paths import robots_dir

MANIFEST_NAME = "robot.yaml"


def robot_ids(root: Path | None = None) -> list[str]:
    """Ids of every folder under ``robots/`` that holds a ``robot.yaml``, sorted."""
    folder = root or robots_dir()
    return sorted(p.parent.name for p in folder.glob(f"*/{MANIFEST_NAME}"))


def manifest_path(robot_id: str, root: Path | None = None) -> Path:
    """Path of the manifest of ``robot_id``.

    Raises:
        UnknownRobot: No such folder.
    """
    folder = root or robots_dir()
    path = folder / robot_id / MANIFEST_NAME
    if not path.is_file():
        raise UnknownRobot(robot_id, robot_ids(folder))
    return path


def load_robot_by_id(robot_id: str, root: Path | None = None) -> RobotDescription:
    """Load and validate the manifest of ``robot_id``."""
    return load_robot(manifest_path(robot_id, root))
