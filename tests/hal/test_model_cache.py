"""The compiled-model cache gives the model a fresh compile gives, and compiles again when
anything it is made of changes.

Each test copies robots/rizon4 (``file:mjcf/rizon4.xml``, primitives only) into a tmp
folder, adds a small OBJ mesh, and points ``OPENRAL_MODEL_CACHE`` at a tmp folder.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_core import open_robot
from openral_core.errors import ManifestError
from openral_core.loader import load_scene
from openral_mujoco import model_cache
from openral_mujoco.model_cache import CACHE_ENV, cache_key, cached_model, prune
from openral_mujoco.model_check import compile_robot_model
from openral_sim.native_scene import NativeScene

from tests.conftest import ROBOTS

RIZON = ROBOTS / "rizon4"
OBJ = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
MESH = ('<option integrator="implicitfast"/>', '<option integrator="implicitfast"/>'
        '<asset><mesh name="tip" file="tip.obj"/></asset>')  # fmt: skip


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "cache"
    monkeypatch.setenv(CACHE_ENV, str(folder))
    return folder


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    """A copy of robots/rizon4 whose model reads ``mjcf/tip.obj``; its manifest's path."""
    folder = tmp_path / "robots" / "rizon4"
    shutil.copytree(RIZON, folder)
    model = folder / "mjcf" / "rizon4.xml"
    text = model.read_text(encoding="utf-8")
    assert text.count(MESH[0]) == 1
    model.write_text(text.replace(*MESH), encoding="utf-8")
    (folder / "mjcf" / "tip.obj").write_text(OBJ, encoding="utf-8")
    return folder / "robot.yaml"


def _include(file: str) -> tuple[str, str]:
    return ("</mujoco>", f'<include file="{file}"/></mujoco>')


def _bytes(model: mujoco.MjModel) -> bytes:
    buffer = np.zeros(mujoco.mj_sizeModel(model), dtype=np.uint8)
    mujoco.mj_saveModel(model, None, buffer)
    return buffer.tobytes()


def _compile(manifest: Path) -> mujoco.MjModel:
    loaded = open_robot(manifest)
    return compile_robot_model(loaded.description, manifest.parent / "mjcf" / "rizon4.xml")


def _entries(cache: Path) -> list[Path]:
    return sorted(cache.glob("*.mjb")) if cache.exists() else []


def _later(path: Path) -> None:
    """Move the file's modification time on by a second (content and size unchanged)."""
    info = path.stat()
    os.utime(path, ns=(info.st_atime_ns, info.st_mtime_ns + 1_000_000_000))


def test_a_cached_model_is_the_model_a_fresh_compile_gives(cache: Path, robot: Path) -> None:
    fresh = mujoco.MjModel.from_xml_path(str(robot.parent / "mjcf" / "rizon4.xml"))
    first = _compile(robot)
    assert len(_entries(cache)) == 1
    second = _compile(robot)
    assert _bytes(first) == _bytes(fresh) == _bytes(second)
    assert second.nmesh == 1


def test_an_entry_is_read_instead_of_compiling(cache: Path) -> None:
    calls: list[int] = []

    def build() -> mujoco.MjModel:
        calls.append(1)
        return mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")

    for _ in range(3):
        cached_model(("same",), build)
    cached_model(("other",), build)
    cached_model(None, build)  # nothing to key it by: never cached
    assert len(calls) == 3 and len(_entries(cache)) == 2


@pytest.mark.parametrize("change", ["mesh", "model", "new file where MuJoCo looks"])
def test_a_changed_input_file_compiles_afresh(cache: Path, robot: Path, change: str) -> None:
    _compile(robot)
    mjcf = robot.parent / "mjcf"
    if change == "mesh":
        (mjcf / "tip.obj").write_text(OBJ.replace("0.1 0 0\n", "0.2 0 0\n", 1))
    elif change == "model":
        _later(mjcf / "rizon4.xml")
    else:  # an include found beside the including file, until one appears where MuJoCo
        # looks first (the main model's folder)
        (mjcf / "sub").mkdir()
        (mjcf / "sub" / "part.xml").write_text('<mujoco><include file="step.xml"/></mujoco>')
        (mjcf / "sub" / "step.xml").write_text('<mujoco><option timestep="0.002"/></mujoco>')
        text = (mjcf / "rizon4.xml").read_text()
        (mjcf / "rizon4.xml").write_text(text.replace(*_include("sub/part.xml")))
        assert _compile(robot).opt.timestep == 0.002
        (mjcf / "step.xml").write_text('<mujoco><option timestep="0.001"/></mujoco>')
    before = set(_entries(cache))
    model = _compile(robot)
    assert set(_entries(cache)) - before, "nothing was compiled"
    fresh = mujoco.MjModel.from_xml_path(str(mjcf / "rizon4.xml"))
    assert _bytes(model) == _bytes(fresh)


def test_a_damaged_entry_is_compiled_again_and_replaced(cache: Path, robot: Path) -> None:
    good = _bytes(_compile(robot))
    (entry,) = _entries(cache)
    entry.write_bytes(b"not a model" * 10)
    assert _bytes(_compile(robot)) == good
    assert entry.read_bytes()[:16] == good[:16] and entry.stat().st_size == len(good)


def test_errors_are_not_cached(cache: Path, robot: Path) -> None:
    (robot.parent / "mjcf" / "tip.obj").write_text("v 0 0 0\nf 1 1 1\n")
    for _ in range(2):
        with pytest.raises(ManifestError, match="does not load in MuJoCo"):
            _compile(robot)
    assert _entries(cache) == []


def test_an_unwritable_or_disabled_cache_still_compiles(
    tmp_path: Path, robot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "a file"
    blocker.write_text("")
    monkeypatch.setenv(CACHE_ENV, str(blocker / "models"))
    assert _compile(robot).nmesh == 1
    monkeypatch.setenv(CACHE_ENV, "off")
    assert model_cache.cache_folder() is None
    assert _compile(robot).nmesh == 1


def test_the_key_covers_mujoco_and_the_format(monkeypatch: pytest.MonkeyPatch) -> None:
    key = cache_key(("a", "b"))
    assert key != cache_key(("ab",)) and key != cache_key(("a", "b", ""))
    monkeypatch.setattr(model_cache, "FORMAT", "other")
    assert cache_key(("a", "b")) != key


def test_prune_removes_the_least_recently_used_first(tmp_path: Path) -> None:
    paths = []
    for index in range(4):
        path = tmp_path / f"{index}.mjb"
        path.write_bytes(b"x" * 100)
        os.utime(path, ns=(0, (index + 1) * 1_000_000_000))
        paths.append(path)
    removed = prune(tmp_path, 250, keep=paths[0])
    assert removed == paths[1:3]
    assert sorted(tmp_path.glob("*.mjb")) == [paths[0], paths[3]]


def test_a_scene_from_the_cache_moves_as_a_compiled_one(cache: Path) -> None:
    scene_file = ROBOTS / "so101" / "scenes" / "tabletop.yaml"
    scene = load_scene(scene_file)
    robot = open_robot(ROBOTS / "so101" / "robot.yaml")
    trajectories, models = [], []
    for _ in range(2):  # compiled, then read from the cache
        env = NativeScene(scene, robot, render_observations=False)
        env.reset(0)
        hold = env.hold_action()
        positions = []
        for i in range(5):
            env.step(hold + 0.1 * (i + 1) / 5)
            positions.append(env.data.qpos.copy())
        trajectories.append(np.array(positions))
        models.append(_bytes(env.model))
        env.close()
    assert len(_entries(cache)) == 2  # the robot alone, and the scene
    assert models[0] == models[1]
    np.testing.assert_array_equal(trajectories[0], trajectories[1])


def test_a_process_hands_out_copies_of_what_it_read_and_reads_a_replaced_entry_again(
    cache: Path, robot: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = _compile(robot)
    reads: list[str] = []
    with monkeypatch.context() as patch:
        patch.setattr(mujoco.MjModel, "from_binary_path", lambda path: reads.append(path))
        second = _compile(robot)  # from this process's memory: no read
        assert reads == [] and _bytes(second) == _bytes(first)
        second.opt.gravity[:] = 0.0  # a caller's edit stays in its copy
        assert _compile(robot).opt.gravity[2] == pytest.approx(-9.81)
    (entry,) = _entries(cache)
    entry.write_bytes(b"not a model" * 10)  # damaged in place: read, refused, compiled
    assert _bytes(_compile(robot)) == _bytes(first)
    assert entry.stat().st_size == len(_bytes(first))


def test_memory_holds_at_most_its_bound(cache: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(model_cache, "_MEMORY", type(model_cache._MEMORY)())
    monkeypatch.setattr(model_cache, "MEMORY_BYTES", 1)
    for name in ("a", "b", "c"):
        cached_model((name,), lambda: mujoco.MjModel.from_xml_string("<mujoco/>"))
    assert len(model_cache._MEMORY) == 1  # only the most recent: each is over the bound
