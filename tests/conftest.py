"""Shared fixtures: the repository paths and a writer for manifest variants."""

from __future__ import annotations

import atexit
import os
import shutil
import tempfile
from collections.abc import Callable
from pathlib import Path

import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # before any test module imports mujoco
from openral_core.paths import repo_root

# The suite (and every process it starts) keeps compiled models in a folder of its own,
# never reading or filling the user's cache (openral_mujoco.model_cache).
_MODEL_CACHE = tempfile.mkdtemp(prefix="openral-test-models-")
os.environ["OPENRAL_MODEL_CACHE"] = _MODEL_CACHE
atexit.register(shutil.rmtree, _MODEL_CACHE, ignore_errors=True)

REPO = repo_root()
ROBOTS = REPO / "robots"
FRANKA = ROBOTS / "franka_panda" / "robot.yaml"
MOCK_ARM = Path(__file__).parent / "fixtures" / "robots" / "mock_arm" / "robot.yaml"

ManifestWriter = Callable[..., Path]


@pytest.fixture
def write_manifest(tmp_path: Path) -> ManifestWriter:
    """Write manifest text to ``tmp_path/<folder>/robot.yaml`` and return its path.

    ``edits`` are (old, new) text replacements applied to ``base`` (default: mock_arm),
    each of which must match exactly once, so a test cannot silently test nothing.
    """

    def write(
        *edits: tuple[str, str],
        base: Path = MOCK_ARM,
        folder: str | None = None,
        text: str | None = None,
    ) -> Path:
        content = base.read_text() if text is None else text
        for old, new in edits:
            assert content.count(old) == 1, f"edit target {old!r} must occur exactly once"
            content = content.replace(old, new)
        target = tmp_path / (folder or base.parent.name) / "robot.yaml"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(content)
        return target

    return write
