"""The robot pictures of the docs are real renders of the current manifests and scenes."""

from __future__ import annotations

import json
import shutil
import struct
import zlib
from pathlib import Path

import numpy as np
import numpy.typing as npt
from openral_codegen.docs_images import (
    HEIGHT,
    IMAGE_DIR,
    RECORD_NAME,
    WIDTH,
    render_robot,
    stale_images,
)

from tests.conftest import REPO

MAX_MEAN_DIFFERENCE = 3.0
"""Largest mean absolute difference [0-255 levels] between the committed franka picture and
a fresh render; covers small rasteriser differences between Mesa versions, not a changed
scene, pose or viewpoint."""


def read_png(path: Path) -> npt.NDArray[np.uint8]:
    """Decode an 8-bit RGB PNG with filter type 0 rows (what openral_mujoco.png writes)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    offset, idat, size = 8, b"", (0, 0)
    while offset < len(data):
        (length,) = struct.unpack(">I", data[offset : offset + 4])
        kind = data[offset + 4 : offset + 8]
        payload = data[offset + 8 : offset + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", payload[:10])
            assert (depth, colour) == (8, 2), f"{path}: not 8-bit RGB"
            size = (height, width)
        elif kind == b"IDAT":
            idat += payload
        offset += 12 + length
    rows = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(size[0], size[1] * 3 + 1)
    assert not rows[:, 0].any(), f"{path}: only unfiltered rows are supported"
    return rows[:, 1:].reshape(size[0], size[1], 3)


def test_every_robot_picture_is_current() -> None:
    problems = stale_images(REPO)
    assert not problems, "run `just docs-images`:\n" + "\n".join(problems)


def test_franka_picture_matches_a_fresh_render() -> None:
    committed = read_png(REPO / IMAGE_DIR / "franka_panda.png")
    fresh = render_robot(REPO, "franka_panda")
    record = json.loads((REPO / IMAGE_DIR / RECORD_NAME).read_text())["franka_panda"]
    assert committed.shape == fresh.image.shape == (HEIGHT, WIDTH, 3)
    assert (fresh.azimuth, fresh.elevation) == (record["azimuth_deg"], record["elevation_deg"])
    difference = np.abs(committed.astype(np.int16) - fresh.image.astype(np.int16)).mean()
    assert difference <= MAX_MEAN_DIFFERENCE, (
        f"franka_panda.png differs from a fresh render by {difference:.2f} levels on average; "
        "run `just docs-images franka_panda`"
    )
    assert fresh.image.std() > 20, "the render is (nearly) blank"


def test_editing_a_scene_makes_its_picture_stale(tmp_path: Path) -> None:
    shutil.copytree(REPO / "robots", tmp_path / "robots")
    shutil.copytree(REPO / IMAGE_DIR, tmp_path / IMAGE_DIR)
    scene = tmp_path / "robots" / "ur5e" / "scenes" / "tabletop.yaml"
    text = scene.read_text()
    assert "control_freq_hz: 20.0" in text
    scene.write_text(text.replace("control_freq_hz: 20.0", "control_freq_hz: 25.0"))
    (tmp_path / IMAGE_DIR / "so101.png").unlink()
    assert stale_images(tmp_path) == [
        "so101: no picture",
        "ur5e: manifest, scene, model or settings changed",
    ]
