"""The index of every shipped scene (``generated/.../tables/scenes.json``).

``just schema-export`` writes one entry per ``robots/<id>/scenes/<name>.yaml``: the
gymnasium id it is registered under (``openral/<robot>-<scene>-v0``), its file, its task,
its horizon (the id's ``max_episode_steps``) and whether it declares success and a dense
reward. The runtime reads the index instead of loading every scene file.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass
from pathlib import Path

from openral_core.models import DeployScene
from openral_core.paths import generated_dir

SCENE_INDEX = "openral_generated/tables/scenes.json"
"""The index, under ``generated/``."""


@dataclass(frozen=True)
class SceneEntry:
    """One shipped scene."""

    env_id: str
    """Its gymnasium id, ``openral/<robot>-<scene file's stem>-v0``."""
    file: str
    """The scene file, relative to the repository root."""
    robot_id: str
    task: str | None
    """What the robot is asked to do (None: no task text)."""
    horizon: int | None
    """Control steps per episode (None: no limit)."""
    success: bool
    """The scene declares success predicates."""
    dense_reward: bool
    """The scene declares a dense reward."""


def scene_entry(file: str, scene: DeployScene) -> SceneEntry:
    """The index entry of ``scene``, loaded from ``file`` (``robots/<id>/scenes/...``)."""
    options = scene.scene.options
    robot_id = Path(file).parts[1]
    return SceneEntry(
        env_id=f"openral/{robot_id}-{Path(file).stem}-v0",
        file=file,
        robot_id=robot_id,
        task=scene.task,
        horizon=options.horizon if options is not None else None,
        success=bool(scene.success),
        dense_reward=scene.reward is not None,
    )


def index_text(entries: list[SceneEntry]) -> str:
    """The index file's text (sorted by id, stable bytes)."""
    rows = [asdict(entry) for entry in sorted(entries, key=lambda e: e.env_id)]
    return json.dumps({"scenes": rows}, indent=2, sort_keys=True) + "\n"


def read_scene_index(root: Path | None = None) -> list[SceneEntry]:
    """The index as committed (``root``: the ``generated/`` folder; default the repo's)."""
    path = (root or generated_dir()) / SCENE_INDEX
    rows = json.loads(path.read_text("utf-8"))["scenes"]
    return [SceneEntry(**row) for row in rows]
