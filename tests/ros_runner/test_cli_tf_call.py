"""``openral ros call`` and ``openral ros tf`` against small real-rclpy peers, and the TF
buffer's composition against numpy (no graph needed)."""

from __future__ import annotations

import math
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from openral_bridge.ros_messages import LATCHED
from openral_cli.main import app
from openral_core.errors import OpenralError
from openral_nodes.runtime import Spinner, ros_session
from openral_nodes.tf_listener import FrameNotFound, TfBuffer, Transform
from rclpy.context import Context
from rclpy.node import Node
from std_srvs.srv import SetBool, Trigger
from tf2_msgs.msg import TFMessage
from typer.testing import CliRunner

from tests.ros_runner.conftest import DOMAIN_ID, run_cli

runner = CliRunner()
ENV = {"COLUMNS": "200", "ROS_DOMAIN_ID": str(DOMAIN_ID)}
TF_HZ = 20.0


def matrix(t: Transform) -> np.ndarray:
    """4x4 homogeneous matrix of ``t`` (the textbook quaternion formula)."""
    x, y, z, w = t.rotation
    rotation = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation, t.translation
    return out


def rpy_matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """``Rz(yaw) Ry(pitch) Rx(roll)``."""
    cr, sr, cp, sp, cy, sy = (f(a) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    rotation: np.ndarray = rz @ ry @ rx
    return rotation


def random_transform(rng: np.random.Generator) -> Transform:
    x, y, z = (float(v) for v in rng.uniform(-2, 2, 3))
    q = rng.normal(size=4)
    qx, qy, qz, qw = (float(v) for v in q / np.linalg.norm(q))
    return Transform((x, y, z), (qx, qy, qz, qw))


def about_z(angle: float, translation: tuple[float, float, float]) -> Transform:
    return Transform(translation, (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2)))


# The tree both the unit tests and the live peer hold: world → base → {camera, hand}.
BASE = about_z(math.pi / 2, (0.1, 0.2, 0.3))
CAMERA = Transform((0.0, -0.05, 0.4), (0.5, -0.5, 0.5, -0.5))
HAND = about_z(-0.3, (0.5, 0.0, 0.25))
HAND_STAMP = 12.5


def test_lookup_composes_through_the_common_ancestor_like_numpy() -> None:
    rng = np.random.default_rng(7)
    links = {"a": ("world", None), "b": ("a", None), "c": ("b", None), "d": ("a", None)}
    buffer, mats = TfBuffer(), {"world": np.eye(4)}
    for child, (parent, _) in links.items():
        t = random_transform(rng)
        buffer.set_transform(parent, child, t, 1.0, static=True)
        mats[child] = mats[parent] @ matrix(t)
    for target, source in [("world", "c"), ("d", "c"), ("c", "d"), ("b", "world"), ("c", "c")]:
        got = buffer.lookup(target, source).transform
        expected = np.linalg.inv(mats[target]) @ mats[source]
        assert np.allclose(matrix(got), expected, atol=1e-12, rtol=0), (target, source)
        assert np.allclose(rpy_matrix(*got.rpy()), expected[:3, :3], atol=1e-12, rtol=0)


def test_inverse_undoes_and_rpy_reads_a_known_rotation() -> None:
    t = random_transform(np.random.default_rng(3))
    assert np.allclose(matrix(t * t.inverse()), np.eye(4), atol=1e-12, rtol=0)
    assert BASE.rpy() == pytest.approx((0.0, 0.0, math.pi / 2), abs=1e-12)


def test_stamps_tree_roots_and_bad_transforms() -> None:
    buffer = TfBuffer()
    buffer.set_transform("world", "base", BASE, 1.0, static=True)
    for seen in (0.0, 0.1, 0.2):
        buffer.set_transform("/base", "hand", HAND, 7.0 + seen, static=False, seen_s=seen)
    buffer.set_transform("loop_a", "loop_b", BASE, 0.0, static=True)
    buffer.set_transform("loop_b", "loop_a", BASE, 0.0, static=True)
    for bad in (Transform((math.nan, 0.0, 0.0)), Transform(rotation=(0.0, 0.0, 0.0, 0.0))):
        buffer.set_transform("world", "bad", bad, 0.0, static=True)
    buffer.set_transform("same", "same", BASE, 0.0, static=True)
    assert buffer.rejected == 3
    assert buffer.lookup("world", "hand").stamp_s == pytest.approx(7.2)  # the dynamic link
    assert buffer.lookup("world", "base").stamp_s == 1.0
    rows, unrooted = buffer.tree()
    assert [(row.depth, row.frame) for row in rows] == [(0, "world"), (1, "base"), (2, "hand")]
    assert rows[2].link is not None and rows[2].link.rate_hz == pytest.approx(10.0)
    assert unrooted == ["loop_a", "loop_b"]
    with pytest.raises(FrameNotFound, match=r"^unknown frame hnad \(did you mean hand\?\)"):
        buffer.lookup("world", "hnad")
    with pytest.raises(FrameNotFound, match=r"^unknown frame panda_hand \(did you mean hand\?\)"):
        buffer.lookup("panda_hand", "world")  # the frame without its prefix
    with pytest.raises(OpenralError, match="no transform path from world to loop_a"):
        buffer.lookup("world", "loop_a")


def test_an_empty_buffer_reports_that_nothing_arrived() -> None:
    from openral_cli.commands.ros_tf import report

    buffer = TfBuffer()
    buffer.set_transform("a", "a", BASE, 0.0, static=True)
    with pytest.raises(OpenralError) as error:
        report(buffer, None, None, 3.0, 7)
    assert str(error.value) == (
        "no transforms on /tf or /tf_static (1 dropped as invalid) within 6 s on ROS_DOMAIN_ID=7"
    )


def stamped(parent: str, child: str, t: Transform, stamp_s: float = 0.0) -> TransformStamped:
    msg = TransformStamped()
    msg.header.frame_id, msg.child_frame_id = parent, child
    msg.header.stamp.sec = int(stamp_s)
    msg.header.stamp.nanosec = round((stamp_s % 1) * 1e9)
    msg.transform.translation.x, msg.transform.translation.y, msg.transform.translation.z = (
        t.translation
    )
    rotation = msg.transform.rotation
    rotation.x, rotation.y, rotation.z, rotation.w = t.rotation
    return msg


class Peer(Node):
    """The graph the commands look at. Services: a Trigger E-stop that succeeds, a Trigger
    reset that fails, a SetBool switch. TF: world → base, base → camera on /tf_static
    (latched), base → hand on /tf at 20 Hz."""

    def __init__(self, context: Context) -> None:
        super().__init__("test_peer", context=context)
        self.switched: list[bool] = []
        self.create_service(Trigger, "/openral/estop", self._estop)
        self.create_service(Trigger, "/openral/reset", self._reset)
        self.create_service(SetBool, "/test/switch", self._switch)
        static = self.create_publisher(TFMessage, "/tf_static", LATCHED)
        static.publish(
            TFMessage(
                transforms=[stamped("world", "base", BASE), stamped("base", "camera", CAMERA)]
            )
        )
        dynamic = self.create_publisher(TFMessage, "/tf", 100)
        hand = TFMessage(transforms=[stamped("base", "hand", HAND, HAND_STAMP)])
        self.create_timer(1.0 / TF_HZ, lambda: dynamic.publish(hand))

    def _estop(self, _: Any, response: Any) -> Any:
        response.success, response.message = True, "E-stop engaged"
        return response

    def _reset(self, _: Any, response: Any) -> Any:
        response.success, response.message = False, "no scene [to reset]"
        return response

    def _switch(self, request: Any, response: Any) -> Any:
        self.switched.append(request.data)
        response.success, response.message = request.data, f"switch {request.data}"
        return response


@pytest.fixture(scope="module")
def running_peer() -> Iterator[Peer]:
    """One peer for the whole module (a graph per test would cost its start and stop)."""
    with ros_session(DOMAIN_ID) as context:
        spinner = Spinner(context)
        node = Peer(context)
        spinner.add_node(node)
        spinner.start()
        try:
            yield node
        finally:
            spinner.stop()
            node.destroy_node()  # type: ignore[no-untyped-call]


@pytest.fixture
def peer(running_peer: Peer) -> Peer:
    """The module's peer, its record of switch requests emptied."""
    running_peer.switched.clear()
    return running_peer


def test_tf_prints_the_tree_with_static_frames_and_rates(peer: Peer) -> None:
    result = runner.invoke(app, ["ros", "tf", "--timeout", "1.5"], env=ENV)
    assert result.exit_code == 0, result.output
    lines = [line.split() for line in result.output.splitlines()]
    assert lines[0] == ["world", "root"]
    assert lines[1] == ["base", "static", "parent", "world"]
    assert lines[2] == ["camera", "static", "parent", "base"]
    assert lines[3][0] == "hand" and lines[3][2:] == ["Hz", "parent", "base"]
    assert 0.5 * TF_HZ < float(lines[3][1]) < 1.5 * TF_HZ, result.output
    assert result.output.splitlines()[3].startswith("    hand")  # two levels below world
    assert len(lines) == 4


def printed_pose(output: str) -> tuple[np.ndarray, tuple[float, ...], float]:
    """The 4x4 matrix, roll/pitch/yaw and stamp that ``ros tf FRAME`` printed."""
    values = {
        key: [float(v) for v in rest.split()]
        for key, _, rest in (line.partition(": ") for line in output.splitlines()[1:])
    }
    pose = Transform(
        tuple(values["translation [m]"]),  # type: ignore[arg-type]
        tuple(values["rotation (x y z w)"]),  # type: ignore[arg-type]
    )
    return matrix(pose), tuple(values["roll pitch yaw [rad]"]), values["stamp [s]"][0]


def test_tf_frame_prints_its_pose_in_the_root(peer: Peer) -> None:
    result = runner.invoke(app, ["ros", "tf", "hand", "--timeout", "1"], env=ENV)
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[0] == "world -> hand"
    pose, rpy, stamp = printed_pose(result.output)
    expected = matrix(BASE) @ matrix(HAND)
    assert np.allclose(pose, expected, atol=1e-8), result.output
    assert np.allclose(rpy_matrix(*rpy), expected[:3, :3], atol=1e-8)
    assert rpy == pytest.approx((0.0, 0.0, math.pi / 2 - 0.3), abs=1e-8)
    assert stamp == HAND_STAMP


def test_tf_frame_in_a_target_frame_returns_once_it_resolves(peer: Peer) -> None:
    result = runner.invoke(
        app, ["ros", "tf", "hand", "--target", "camera", "--timeout", "20"], env=ENV
    )
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[0] == "camera -> hand"
    pose, _, _ = printed_pose(result.output)
    assert np.allclose(pose, np.linalg.inv(matrix(CAMERA)) @ matrix(HAND), atol=1e-8)


def test_tf_of_an_unknown_frame_is_one_line_naming_the_closest(
    peer: Peer, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run_cli(monkeypatch, capsys, "ros", "tf", "hnad", "--timeout", "1")
    assert (code, out) == (1, "")
    assert err == "error: unknown frame hnad (did you mean hand?); 4 frames known\n"


def test_call_finds_the_type_and_prints_the_response(peer: Peer) -> None:
    result = runner.invoke(app, ["ros", "call", "/openral/estop"], env=ENV)
    assert result.exit_code == 0, result.output
    assert result.output == (
        "# /openral/estop: std_srvs/srv/Trigger\nsuccess: true\nmessage: E-stop engaged\n"
    )


def test_call_with_a_type_and_values_sends_them(peer: Peer) -> None:
    args = ["ros", "call", "test/switch", "std_srvs/srv/SetBool", "{data: true}"]
    result = runner.invoke(app, args, env=ENV)
    assert result.exit_code == 0, result.output
    assert "success: true\nmessage: switch True" in result.output
    assert peer.switched == [True]


def test_success_false_is_printed_and_exits_1(
    peer: Peer, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run_cli(monkeypatch, capsys, "ros", "call", "/test/switch", "{data: false}")
    assert code == 1
    assert out == "# /test/switch: std_srvs/srv/SetBool\nsuccess: false\nmessage: switch False\n"
    assert err == "error: /test/switch answered success: false\n"
    code, out, err = run_cli(monkeypatch, capsys, "ros", "reset", "--timeout", "5")
    assert (code, out, err) == (1, "", "error: /openral/reset: no scene [to reset]\n")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["/test/switch", "std_srvs/srv/SetBool", "{data: maybe}"],
            "data: expected true or false, got 'maybe'",
        ),
        (
            ["/s", "std_srvs/srv/SetBool", "{dta: true}"],
            "dta: not a field of std_srvs/srv/SetBool request; its fields: data",
        ),
        (["/test/switch", "{data: [}"], "values: "),
        (["/x", "os/srv/System"], "service /x has type os/srv/System, which openral does not"),
        (["/x", "std_srvs/msg/Trigger"], "which is not a service type (expected pkg/srv/Name)"),
        (["/a//b"], "/a//b is not a valid ROS service name: service name must not contain"),
    ],
)
def test_bad_arguments_are_one_line_and_exit_1_at_once(
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    message: str,
) -> None:
    start = time.monotonic()
    code, out, err = run_cli(monkeypatch, capsys, "ros", "call", *args)
    assert (code, out) == (1, ""), err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert message in err, err
    assert time.monotonic() - start < 0.3  # no ROS context was made


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["/test/switch", "{dta: true}"], "dta: not a field of std_srvs/srv/SetBool request"),
        (
            ["/openral/estop", "std_srvs/srv/SetBool"],
            "/openral/estop is a std_srvs/srv/Trigger service, not std_srvs/srv/SetBool",
        ),
        (  # 4 s: a peer whose first announcement was missed shows up within FastDDS's 3 s
            ["/openral/estp", "--timeout", "4"],
            f"nobody offers /openral/estp within 4 s on ROS_DOMAIN_ID={DOMAIN_ID} "
            "(did you mean /openral/estop?)",
        ),
    ],
    ids=["unknown-field", "wrong-type", "misspelt-service"],  # the same in every process
)
def test_calls_the_graph_refuses_are_one_line_and_exit_1(
    peer: Peer,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    args: list[str],
    message: str,
) -> None:
    code, out, err = run_cli(monkeypatch, capsys, "ros", "call", *args)
    assert (code, out) == (1, ""), err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert message in err, err
    assert peer.switched == []
