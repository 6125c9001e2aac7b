"""Serve a policy over the policy server protocol (:mod:`openral_policy_server.wire`).

Example::

    from openral_policy_server import serve

    class Sway:
        required_slots = ()
        needs_privileged = False

        def act(self, obs):
            names, hold = obs["action_spec"]
            return hold + 0.1 * np.sin(obs["time_s"])

    serve(Sway, port=8765)  # each connection (one episode) gets Sway()

A policy sees the observation as openral's policies do (``observation.state``,
``observation.images.<slot>`` and the other ``observation.*`` keys, ``action_spec`` as
``(names, hold)``, ``time_s``, and ``task_state`` where offered), so one policy class runs
in-process (``--policy file.py:Sway``) and served (``--policy ws://HOST:PORT``) unchanged.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np
from websockets.exceptions import ConnectionClosed
from websockets.sync.server import Server, ServerConnection
from websockets.sync.server import serve as websocket_server

from openral_policy_server.wire import MAX_MESSAGE_BYTES, PROTOCOL, WireError, pack, unpack

OBSERVATION = "observation."
"""The prefix of the observation's own keys (openral's one observation)."""


class ServedPolicy(Protocol):
    """What a served policy offers (openral's policy seam, without openral)."""

    required_slots: tuple[str, ...]
    needs_privileged: bool

    def act(self, obs: dict[str, Any]) -> Any:
        """One action: a value per action slot."""
        ...


PolicyFactory = Callable[[], ServedPolicy]
"""Makes the policy of one connection (one episode)."""


def hello(policy: ServedPolicy) -> dict[str, Any]:
    """The hello message that declares ``policy``'s needs."""
    return {
        "type": "hello",
        "protocol": PROTOCOL,
        "required_slots": [str(slot) for slot in policy.required_slots],
        "needs_privileged": bool(policy.needs_privileged),
        "action_mode": str(getattr(policy, "action_mode", "joint_position")),
    }


def observation(message: dict[str, Any]) -> dict[str, Any]:
    """An ``act`` message's observation as a policy sees it.

    Raises:
        WireError: A field missing or of the wrong kind.
    """
    raw = message.get("observation")
    if not isinstance(raw, dict):
        raise WireError("an act message without an observation map")
    try:
        obs: dict[str, Any] = {
            str(k): np.asarray(v) for k, v in raw.items() if str(k).startswith(OBSERVATION)
        }
        obs |= {
            "action_spec": (
                tuple(str(name) for name in raw["action_names"]),
                np.asarray(raw["hold"], dtype=np.float64),
            ),
            "time_s": float(raw["time_s"]),
        }
    except (KeyError, TypeError, ValueError) as error:
        raise WireError(f"an observation without a valid {error}") from None
    if "observation.state" not in obs:
        raise WireError("an observation without observation.state")
    if "task_state" in raw:
        obs["task_state"] = {str(k): np.asarray(v) for k, v in dict(raw["task_state"]).items()}
    return obs


def _answer(policy: ServedPolicy, frame: bytes | str) -> dict[str, Any]:
    """The answer to one frame: the action, or an error line."""
    try:
        obs = observation(unpack(frame, ("act",)))
    except WireError as error:
        return {"type": "error", "message": f"bad request: {error}"}
    try:
        action = np.asarray(policy.act(obs), dtype=np.float64).reshape(-1)
    except Exception as error:  # the policy's failure, told to the client in one line
        return {"type": "error", "message": f"the policy raised {type(error).__name__}: {error}"}
    return {"type": "action", "action": action}


def _episode(factory: PolicyFactory, connection: ServerConnection) -> None:
    """One connection: a fresh policy, its hello, then an answer per request."""
    try:
        policy = factory()
        connection.send(pack(hello(policy)))
        for frame in connection:
            connection.send(pack(_answer(policy, frame)))
    except ConnectionClosed:
        pass  # the episode ended


class PolicyServer:
    """A running server (see :func:`start`)."""

    def __init__(self, server: Server) -> None:
        self._server = server
        self._thread = threading.Thread(target=server.serve_forever, daemon=True)

    @property
    def port(self) -> int:
        """The port it listens on (the one the system chose for port 0)."""
        return int(self._server.socket.getsockname()[1])

    def close(self) -> None:
        """Stop listening and end every connection."""
        self._server.shutdown()
        self._thread.join(5.0)


def start(factory: PolicyFactory, host: str = "127.0.0.1", port: int = 0) -> PolicyServer:
    """Serve ``factory``'s policies on a thread; returns once it listens."""
    server = websocket_server(
        lambda connection: _episode(factory, connection),
        host,
        port,
        max_size=MAX_MESSAGE_BYTES,
        compression=None,
    )
    running = PolicyServer(server)
    running._thread.start()
    return running


def serve(factory: PolicyFactory, host: str = "127.0.0.1", port: int = 8765) -> None:
    """Serve ``factory``'s policies until interrupted (Ctrl-C)."""
    running = start(factory, host, port)
    print(
        f"serving {getattr(factory, '__name__', 'a policy')} on ws://{host}:{running.port}",
        flush=True,
    )
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        running.close()
