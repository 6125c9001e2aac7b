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
# never reading or filling the user's cache (openral_mujoco.model_cache). pytest-xdist's
# workers inherit the folder the controlling process made (the cache is safe to share
# between processes), so a model is compiled once per run, not once per worker; `just test`
# makes one folder for both of its runs.
_MODEL_CACHE = os.environ.get("OPENRAL_TEST_MODEL_CACHE", "")
if not _MODEL_CACHE:
    _MODEL_CACHE = tempfile.mkdtemp(prefix="openral-test-models-")
    os.environ["OPENRAL_TEST_MODEL_CACHE"] = _MODEL_CACHE
    atexit.register(shutil.rmtree, _MODEL_CACHE, ignore_errors=True)
os.environ["OPENRAL_MODEL_CACHE"] = _MODEL_CACHE

# execnet gives pytest-xdist's workers COLUMNS=80 and LINES=24; a serial run has neither, and
# the CLI's tables (and the tutorials' expected output) follow $COLUMNS when it is set.
if os.environ.get("PYTEST_XDIST_WORKER"):
    for _name in ("COLUMNS", "LINES"):
        os.environ.pop(_name, None)

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


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "exclusive: measures real time; `just test` runs these after the others, in one "
        "process of their own, never beside another test",
    )


LONGEST_FIRST = (
    "tests/docs/test_tutorials.py",
    "tests/eval/test_sweep.py",
    "tests/fuzz/test_fuzz.py",
    "tests/eval/test_osc_lift.py",
    "tests/properties/test_one_contract.py",
    "tests/ros/test_deploy_hostile.py",
    "tests/hal/test_action_properties.py",
    "tests/codegen/test_generated_up_to_date.py",
)
"""The modules that take longest (120-290 s of a 2-core run's test time for the first two,
45-95 s for the others), started first: ``just test`` hands whole modules to its workers
in collection order, and a long module collected last left one core idle for minutes."""


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Put the tests of :data:`LONGEST_FIRST` first, in that order; the rest keep theirs."""
    rank = {module: index for index, module in enumerate(LONGEST_FIRST)}

    def order(item: pytest.Item) -> int:
        module = item.nodeid.split("::", 1)[0]
        return rank.get(module, len(rank))

    items.sort(key=order)  # stable: each module's own order is kept
