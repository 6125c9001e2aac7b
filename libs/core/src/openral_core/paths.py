"""Where the project's data lives: the schema folder and the robots folder.

openral is a monorepo: ``schema/`` and ``robots/`` sit at the repository root, next to
``pyproject.toml``. They are found relative to this package, so commands work from any
working directory.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

from openral_core.errors import OpenralError


@cache
def repo_root() -> Path:
    """The repository root: the nearest ancestor holding ``schema/robot.schema.json``."""
    for folder in Path(__file__).resolve().parents:
        if (folder / "schema" / "robot.schema.json").is_file():
            return folder
    raise OpenralError(
        "cannot find the openral repository (a folder with schema/robot.schema.json) above "
        f"{Path(__file__).resolve().parent}; install openral from its checkout (./bootstrap)"
    )


def schema_dir() -> Path:
    """The folder holding the hand-written JSON Schemas."""
    return repo_root() / "schema"


def robots_dir() -> Path:
    """The folder holding one ``<id>/robot.yaml`` per robot."""
    return repo_root() / "robots"


def generated_dir() -> Path:
    """The folder holding code and tables derived by ``just schema-export``."""
    return repo_root() / "generated"
