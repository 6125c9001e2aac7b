"""Tests for bag_view.py and ``openral ros view``: a recorded bag in the browser view.

A small bag written with rosbags (a static and a moving transform, joint states, a red
rgb8 and a blue bgr8 image, and a String topic) is drawn into a recording fake view: frames
land on entity paths along the tf tree, joints on the plot, images in RGB order under their
camera's name, the String topic is counted as left out. Then ``openral ros view`` serves
it to headless Chromium, whose screenshot shows the red camera frame; Ctrl-C ends it with
exit 0. A folder that is not a bag is one line and exit 1.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from openral_nodes.bag_view import show, survey
from openral_nodes.bag_writer import typestore
from PIL import Image
from rosbags.rosbag2 import StoragePlugin, Writer

from tests.docs.view_screenshot import REPO, free_port_pair, photograph, serve, view_url

TYPES = typestore()
T = TYPES.types


def _stamp(seconds: float) -> Any:
    return T["builtin_interfaces/msg/Time"](sec=int(seconds), nanosec=round(seconds % 1 * 1e9))


def _header(seconds: float, frame: str = "") -> Any:
    return T["std_msgs/msg/Header"](stamp=_stamp(seconds), frame_id=frame)


def _tf(seconds: float, parent: str, child: str, x: float) -> Any:
    vector = T["geometry_msgs/msg/Vector3"](x=x, y=0.0, z=0.0)
    rotation = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)
    transform = T["geometry_msgs/msg/Transform"](translation=vector, rotation=rotation)
    stamped = T["geometry_msgs/msg/TransformStamped"](
        header=_header(seconds, parent), child_frame_id=child, transform=transform
    )
    return T["tf2_msgs/msg/TFMessage"](transforms=[stamped])


def _image(seconds: float, encoding: str, first_channel: int) -> Any:
    pixels = np.zeros((48, 64, 3), dtype=np.uint8)
    pixels[..., 0] = first_channel
    return T["sensor_msgs/msg/Image"](
        header=_header(seconds, "cam"), height=48, width=64, encoding=encoding,
        is_bigendian=0, step=64 * 3, data=pixels.reshape(-1),
    )  # fmt: skip


def write_bag(folder: Path) -> None:
    """The bag of the module doc: 10 ticks of 0.1 s."""
    with Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        kinds = {
            "/tf_static": "tf2_msgs/msg/TFMessage",
            "/tf": "tf2_msgs/msg/TFMessage",
            "/joint_states": "sensor_msgs/msg/JointState",
            "/openral/cameras/wrist/image": "sensor_msgs/msg/Image",
            "/side/image_raw": "sensor_msgs/msg/Image",
            "/chatter": "std_msgs/msg/String",
            "/openral/cameras/wrist/depth": "sensor_msgs/msg/Image",
            "/odd/image": "sensor_msgs/msg/Image",
        }
        conn = {t: writer.add_connection(t, k, typestore=TYPES) for t, k in kinds.items()}

        def put(topic: str, seconds: float, msg: Any) -> None:
            data = TYPES.serialize_cdr(msg, kinds[topic])
            writer.write(conn[topic], int(seconds * 1e9), bytes(data))

        put("/tf_static", 0.0, _tf(0.0, "world", "base_link", 0.5))
        for tick in range(10):
            s = 0.1 * (tick + 1)
            put("/tf", s, _tf(s, "base_link", "hand", 0.1 * tick))
            joints = T["sensor_msgs/msg/JointState"](
                header=_header(s), name=["j1", "j2"], position=np.array([s, -s]),
                velocity=np.zeros(2), effort=np.zeros(0),
            )  # fmt: skip
            put("/joint_states", s, joints)
            put("/openral/cameras/wrist/image", s, _image(s, "rgb8", 255))
            put("/side/image_raw", s, _image(s, "bgr8", 255))
            put("/chatter", s, T["std_msgs/msg/String"](data="hi"))
        depth = np.full((48, 64), 1.25, dtype="<f4")
        put("/openral/cameras/wrist/depth", 0.5, T["sensor_msgs/msg/Image"](
            header=_header(0.5, "cam"), height=48, width=64, encoding="32FC1",
            is_bigendian=0, step=64 * 4, data=depth.view(np.uint8).reshape(-1),
        ))  # fmt: skip
        odd = _image(0.5, "rgb8", 0)
        odd.encoding = "yuv422"
        put("/odd/image", 0.5, odd)


class RecordingView:
    """The methods of BrowserView that bag_view calls, remembering each call."""

    def __init__(self) -> None:
        self.transforms: list[tuple[str, tuple[float, ...], float | None]] = []
        self.plots: list[tuple[str, dict[str, float], float]] = []
        self.images: list[tuple[str, np.ndarray, float]] = []
        self.depths: list[tuple[str, np.ndarray, float]] = []

    def transform(self, path: str, translation: Any, quaternion: Any, time_s: float | None) -> None:
        self.transforms.append((path, tuple(translation), time_s))

    def plot(self, group: str, values: dict[str, float], time_s: float) -> None:
        self.plots.append((group, values, time_s))

    def image(self, camera: str, rgb: np.ndarray, time_s: float) -> None:
        self.images.append((camera, rgb, time_s))

    def depth(self, camera: str, depth_m: np.ndarray, time_s: float) -> None:
        self.depths.append((camera, depth_m, time_s))


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("bags") / "run"
    write_bag(folder)
    return folder


def test_every_message_lands_where_the_view_draws_it(bag: Path) -> None:
    contents = survey(bag)
    assert contents.cameras == {
        "/openral/cameras/wrist/image": "wrist",
        "/side/image_raw": "side_image_raw",
        "/openral/cameras/wrist/depth": "wrist",
        "/odd/image": "odd_image",
    }
    assert contents.skipped == {"/chatter": 10}
    view = RecordingView()
    show(bag, view, contents)  # type: ignore[arg-type]
    assert view.transforms[0] == ("world/base_link", (0.5, 0.0, 0.0), None)
    moving = [t for t in view.transforms if t[2] is not None]
    assert [t[0] for t in moving] == ["world/base_link/hand"] * 10
    assert [round(t[1][0], 9) for t in moving] == [round(0.1 * k, 9) for k in range(10)]
    assert [round(t[2], 9) for t in moving] == [round(0.1 * (k + 1), 9) for k in range(10)]
    assert view.plots[3] == (
        "joints/joint_states",
        {"j1": pytest.approx(0.4), "j2": pytest.approx(-0.4)},
        pytest.approx(0.4),
    )
    wrist = [i for i in view.images if i[0] == "wrist"]
    side = [i for i in view.images if i[0] == "side_image_raw"]
    assert len(wrist) == len(side) == 10
    assert wrist[0][1].shape == (48, 64, 3) and (wrist[0][1][..., 0] == 255).all()
    assert (side[0][1][..., 2] == 255).all() and (side[0][1][..., 0] == 0).all()  # bgr8 → RGB
    [(camera, depth, stamp)] = view.depths
    assert camera == "wrist" and stamp == 0.5 and depth.shape == (48, 64)
    assert np.allclose(depth, 1.25)
    assert contents.skipped == {"/chatter": 10, "/odd/image": 1}  # an encoding not drawn
    assert (contents.frames, contents.joint_states, contents.images) == (11, 10, 21)


def _red_camera(png: Path) -> bool:
    pixels = np.asarray(Image.open(png).convert("RGB")).astype(int)
    height, width, _ = pixels.shape
    panel = pixels[60 : height // 3, int(0.62 * width) :]
    red = (panel[..., 0] > 200) & (panel[..., 1] < 60) & (panel[..., 2] < 60)
    return bool(red.mean() > 0.02)


def test_ros_view_serves_the_bag_to_a_browser(bag: Path, tmp_path: Path) -> None:
    port = free_port_pair()
    process, text = serve("ros", "view", str(bag), "--view-port", str(port))
    left = "left out /chatter (10), /odd/image (1)"
    assert f"drew 11 transforms, 10 joint states and 21 images; {left}" in text
    try:
        photograph(view_url(port), tmp_path / "bag.png", done=_red_camera)
        assert _red_camera(tmp_path / "bag.png")
    finally:
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=30)
    assert process.returncode == 0, err


def test_a_folder_that_is_not_a_bag_is_one_line(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "openral_cli.main", "ros", "view", str(tmp_path)]
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert done.stderr.strip().endswith("no metadata.yaml; expected a rosbag2 bag folder")
    assert len(done.stderr.strip().splitlines()) == 1


def test_a_broken_bag_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "metadata.yaml").write_text("garbage: [\n")
    command = [sys.executable, "-m", "openral_cli.main", "ros", "view", str(tmp_path)]
    done = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert len(done.stderr.strip().splitlines()) == 1, done.stderr
    assert f"{tmp_path}: not a readable bag (Could not load YAML" in done.stderr
