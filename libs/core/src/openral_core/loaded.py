"""A robot loaded once: its validated manifest, its folder and its tables, passed down as one.

:func:`open_robot` and :func:`open_robot_by_id` load and validate a manifest and attach its
tables. A repository robot (``robots/<id>/robot.yaml``) reads them from
``generated/openral_generated/tables/<id>.json``, written by ``just schema-export``: the
generated tables are the runtime input. A file whose ``manifest_sha256`` is not the loaded
manifest's raises :class:`StaleTables`. A robot without such a file (just scaffolded, or
loaded from outside the repository) gets the same tables computed in memory by
:func:`openral_core.tables.robot_tables`.

Example::

    robot = open_robot_by_id("franka_panda")
    wiring = robot.tables.hal_wiring
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

from openral_core.errors import StaleTables
from openral_core.loader import load_robot
from openral_core.located import source_file
from openral_core.models import RobotDescription
from openral_core.paths import generated_dir, robots_dir
from openral_core.registry import MANIFEST_NAME, manifest_path
from openral_core.tables import RobotTables, manifest_sha256, robot_tables

TABLES_SUBDIR = Path("openral_generated", "tables")
"""Where ``just schema-export`` writes ``<id>.json``, under ``generated/``."""

_log = logging.getLogger(__name__)
_logged_in_memory: set[str] = set()


@dataclass(frozen=True)
class LoadedRobot:
    """One robot, loaded once and passed down (to the HAL, the scenes, the nodes)."""

    description: RobotDescription
    """The validated manifest; remembers its source file (:mod:`openral_core.located`)."""
    folder: Path
    """The folder holding the manifest: ``file:`` URIs resolve against it."""
    tables: RobotTables
    """Read from ``generated/`` when current, else computed in memory."""

    @property
    def name(self) -> str:
        """The robot's id (its ``name``)."""
        return self.description.name


def open_robot(file: Path, *, check_folder_name: bool = True) -> LoadedRobot:
    """Load and validate the manifest ``file`` and attach its tables.

    Args:
        file: Path of the manifest.
        check_folder_name: Require ``name`` to equal the name of the containing folder.

    Raises:
        ManifestError: With every problem found in the file.
        StaleTables: The robot's generated tables were made from another manifest.
    """
    return loaded_robot(load_robot(file, check_folder_name=check_folder_name))


def open_robot_by_id(robot_id: str, root: Path | None = None) -> LoadedRobot:
    """:func:`open_robot` of ``<root>/<robot_id>/robot.yaml`` (default root: ``robots/``).

    Raises:
        UnknownRobot: No such folder.
        ManifestError: With every problem found in the manifest.
        StaleTables: The robot's generated tables were made from another manifest.
    """
    return open_robot(manifest_path(robot_id, root))


def loaded_robot(description: RobotDescription, folder: Path | None = None) -> LoadedRobot:
    """Attach folder and tables to an already validated ``description``.

    Args:
        description: A validated manifest (from :func:`load_robot`, or built in code).
        folder: Its folder; defaults to the folder of the file it was loaded from, else
            ``robots/<name>``.

    Raises:
        StaleTables: The robot's generated tables were made from another manifest.
    """
    source = source_file(description)
    if folder is None:
        folder = source.parent if source is not None else robots_dir() / description.name
    return LoadedRobot(description, folder, tables_of(description))


def tables_of(description: RobotDescription) -> RobotTables:
    """The generated tables of ``description`` when it is a repository robot that has
    them, else the same tables computed in memory.

    Raises:
        StaleTables: The generated file was made from another manifest, or is unreadable.
    """
    source = source_file(description)
    table = None if source is None else generated_table(source, description.name)
    if source is not None and table is not None:
        return _read_current(table, source, description)
    key = str(source.resolve()) if source is not None else f"<{description.name} built in code>"
    if key not in _logged_in_memory:
        _logged_in_memory.add(key)
        _log.debug("%s: no generated tables; computed them in memory", key)
    return robot_tables(description)


def generated_table(manifest: Path, robot_id: str) -> Path | None:
    """``generated/openral_generated/tables/<id>.json`` when ``manifest`` is the
    repository's ``robots/<id>/robot.yaml`` and that file exists, else None."""
    file = manifest.resolve()
    is_repo_manifest = (
        file.name == MANIFEST_NAME
        and file.parent.name == robot_id
        and file.parent.parent == robots_dir().resolve()
    )
    table = generated_dir() / TABLES_SUBDIR / f"{robot_id}.json"
    return table if is_repo_manifest and table.is_file() else None


def _read_current(table: Path, manifest: Path, description: RobotDescription) -> RobotTables:
    shown_table = _shown(table, generated_dir().parent)
    shown_manifest = _shown(manifest, robots_dir().parent)
    try:
        tables = RobotTables.from_json(table.read_text("utf-8"))
    except (OSError, ValueError, KeyError, TypeError) as error:
        problem = f"unreadable ({type(error).__name__}: {error})"
        raise StaleTables(shown_table, shown_manifest, problem) from None
    if tables.manifest_sha256 != manifest_sha256(description):
        raise StaleTables(shown_table, shown_manifest)
    return tables


def _shown(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` when inside it (how a user reads repository paths)."""
    resolved, root = path.resolve(), base.resolve()
    return resolved.relative_to(root).as_posix() if resolved.is_relative_to(root) else str(path)
