"""The policy server protocol and the client in-process: what travels, a policy per
connection, and each failure as one line (a server down, slow, off protocol, a policy that
raises)."""

from __future__ import annotations

import socket
from collections.abc import Iterator

import msgpack
import numpy as np
import pytest
from openral_eval.policies import make_policy
from openral_eval.policy import Observation, action_mode
from openral_eval.remote_policy import PolicyServerError, RemotePolicy
from openral_policy_server import PolicyServer, WireError, pack, start, unpack
from openral_policy_server.wire import ARRAY_EXT

from tests.policy_server import served_policies as served


def _obs(time_s: float = 0.5) -> Observation:
    hold = np.array([0.1, -0.2, 0.3])
    return {
        "observation.images.camera1": np.full((4, 5, 3), 2, dtype=np.uint8),
        "observation.state": np.array([0.1, -0.2, 0.3]),
        "action_spec": (("a", "b", "c"), hold),
        "time_s": time_s,
        "observation.tcp_pose": np.array([0.4, 0.0, 0.3, 1.0, 0.0, 0.0, 0.0]),
    }


@pytest.fixture
def serving() -> Iterator[list[PolicyServer]]:
    running: list[PolicyServer] = []
    yield running
    for server in running:
        server.close()


def _address(server: PolicyServer) -> str:
    return f"ws://127.0.0.1:{server.port}"


@pytest.mark.parametrize(
    "array",
    [
        np.arange(6, dtype=np.float64).reshape(2, 3),
        np.array([np.nan, -np.inf, 1e-300]),
        np.zeros((2, 3, 3), dtype=np.uint8),
        np.array([True, False]),
        np.arange(4, dtype=">i4"),  # big-endian in: the same values out
        np.zeros((0, 3)),
    ],
)
def test_arrays_travel_with_their_values_dtype_kind_and_shape(array: np.ndarray) -> None:
    back = unpack(pack({"type": "action", "action": array}), ("action",))["action"]
    assert back.shape == array.shape and back.dtype.kind == array.dtype.kind
    np.testing.assert_array_equal(back, array)


def test_what_is_not_of_the_protocol_is_refused_in_one_line() -> None:
    with pytest.raises(WireError, match="dtype object does not travel"):
        pack({"type": "action", "action": np.array([object()])})
    with pytest.raises(WireError, match="a text frame"):
        unpack("{}", ("act",))
    with pytest.raises(WireError, match="not msgpack"):
        unpack(b"\xc1", ("act",))
    with pytest.raises(WireError, match="a 'hello' message; expected act"):
        unpack(msgpack.packb({"type": "hello"}), ("act",))
    with pytest.raises(WireError, match="a 'list' message"):
        unpack(msgpack.packb([1, 2]), ("act",))
    with pytest.raises(WireError, match="unknown msgpack extension type 7"):
        unpack(msgpack.packb({"type": "act", "x": msgpack.ExtType(7, b"")}), ("act",))
    with pytest.raises(WireError, match="a malformed array"):
        unpack(msgpack.packb({"type": "act", "x": msgpack.ExtType(ARRAY_EXT, b"\x93")}), ("act",))


def test_a_served_policy_declares_its_needs_and_each_connection_gets_a_policy_of_its_own(
    serving: list[PolicyServer],
) -> None:
    serving.append(server := start(served.Counter))
    first, second = (make_policy(_address(server)) for _ in range(2))
    assert isinstance(first, RemotePolicy)
    assert first.required_slots == ("camera1",) and first.needs_privileged
    assert action_mode(first) == "ee_delta_pose"
    one, two = first.act(_obs(0.25)), second.act(_obs(0.75))
    assert one[0] != two[0]  # two policies, one per connection
    np.testing.assert_array_equal(one[1:], [0.25, 4 * 5 * 3 * 2])
    np.testing.assert_array_equal(two[1:], [0.75, 4 * 5 * 3 * 2])
    assert first.act(_obs())[0] == one[0]  # the same connection keeps its policy
    first.close()
    second.close()


def test_the_served_action_equals_the_in_process_one(serving: list[PolicyServer]) -> None:
    serving.append(server := start(served.Sway))
    remote = make_policy(_address(server))
    for time_s in (0.0, 0.013, 1.7):
        np.testing.assert_array_equal(remote.act(_obs(time_s)), served.Sway().act(_obs(time_s)))
    assert isinstance(remote, RemotePolicy)
    remote.close()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def test_a_server_that_is_down_slow_or_whose_policy_raises_is_one_line_each(
    serving: list[PolicyServer],
) -> None:
    down = make_policy(f"ws://127.0.0.1:{_free_port()}", {"timeout_s": "2"})
    with pytest.raises(PolicyServerError, match=r"is not reachable \(ConnectionRefusedError"):
        down.act(_obs())
    serving.append(slow := start(served.Slow))
    late = make_policy(_address(slow), {"timeout_s": "0.2"})
    with pytest.raises(PolicyServerError, match=r"did not answer within 0\.2 s"):
        late.act(_obs())
    serving.append(raising := start(served.Raises))
    with pytest.raises(
        PolicyServerError, match="the policy raised RuntimeError: weights not found"
    ):
        make_policy(_address(raising)).act(_obs())


def test_a_server_off_protocol_is_refused_at_its_hello(serving: list[PolicyServer]) -> None:
    import openral_policy_server.server as serving_module

    class Future(served.Sway):
        action_mode = "ee_fly"

    serving.append(server := start(Future))
    with pytest.raises(PolicyServerError, match="declares action_mode 'ee_fly'; valid: "):
        assert make_policy(_address(server)).required_slots is None  # never reached
    original = serving_module.PROTOCOL
    serving_module.PROTOCOL = 99  # type: ignore[misc]
    try:
        serving.append(newer := start(served.Sway))
        with pytest.raises(PolicyServerError, match="speaks protocol 99; this openral speaks 2"):
            make_policy(_address(newer)).act(_obs())
    finally:
        serving_module.PROTOCOL = original  # type: ignore[misc]
