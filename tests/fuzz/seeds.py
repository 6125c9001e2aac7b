"""The seeds: every manifest and scene under robots/, and how a mutated copy is laid out.

A manifest copy is written as ``<folder>/<robot>/robot.yaml`` next to copies of the robot
folder's other files (``mjcf/`` of rizon4, ...), so the folder-name rule and relative
``file:`` URIs behave as in robots/. A scene copy is written as ``<folder>/<scene>.yaml``;
its ``robot_id`` still names a robot under robots/.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Literal

from openral_core.paths import repo_root
from openral_core.registry import MANIFEST_NAME
from ruamel.yaml import YAML

Kind = Literal["manifest", "scene"]


@dataclass(frozen=True)
class Seed:
    """One real file that cases start from.

    Attributes:
        name: Path below robots/, e.g. ``rizon4/robot.yaml``; what a case records.
        kind: ``manifest`` or ``scene``.
        robot: The robot folder it belongs to (a scene is built with this robot).
        path: The file in robots/.
        slow: A robosuite scene (about 2 s to build; drawn less often).
    """

    name: str
    kind: Kind
    robot: str
    path: Path
    slow: bool

    @property
    def weight(self) -> float:
        """How often a campaign draws this seed relative to a fast one."""
        return 0.2 if self.slow else 1.0

    def read(self) -> bytes:
        """The seed's bytes."""
        return self.path.read_bytes()


@cache
def seeds() -> tuple[Seed, ...]:
    """Every manifest and scene under robots/, sorted by name."""
    robots = repo_root() / "robots"
    found: list[Seed] = []
    for manifest in sorted(robots.glob(f"*/{MANIFEST_NAME}")):
        robot = manifest.parent.name
        found.append(Seed(f"{robot}/{MANIFEST_NAME}", "manifest", robot, manifest, slow=False))
        for scene in sorted((manifest.parent / "scenes").glob("*.yaml")):
            name = f"{robot}/scenes/{scene.name}"
            found.append(Seed(name, "scene", robot, scene, slow=_is_robosuite(scene)))
    return tuple(found)


def seed_named(name: str) -> Seed:
    """The seed called ``name``.

    Raises:
        KeyError: No such seed.
    """
    for seed in seeds():
        if seed.name == name:
            return seed
    raise KeyError(name)


def donors() -> tuple[bytes, ...]:
    """The bytes of every seed (the lines splice mutations borrow)."""
    return tuple(seed.read() for seed in seeds())


def _is_robosuite(scene: Path) -> bool:
    data = YAML(typ="safe", pure=True).load(scene.read_text(encoding="utf-8"))
    return bool(data["scene"]["backend"] == "robosuite")


def lay_out(seed: Seed, content: bytes, folder: Path) -> Path:
    """Write ``content`` as the mutated copy of ``seed`` under ``folder``; return its path.

    The path is absolute and resolved, as errors will print it.
    """
    folder = folder.resolve()
    if seed.kind == "scene":
        folder.mkdir(parents=True, exist_ok=True)
        target = folder / seed.path.name
    else:
        home = folder / seed.robot
        home.mkdir(parents=True, exist_ok=True)
        for entry in seed.path.parent.iterdir():
            if entry.name in (MANIFEST_NAME, "scenes"):
                continue
            if entry.is_dir():
                shutil.copytree(entry, home / entry.name, dirs_exist_ok=True)
            else:
                shutil.copy2(entry, home / entry.name)
        target = home / MANIFEST_NAME
    target.write_bytes(content)
    return target
