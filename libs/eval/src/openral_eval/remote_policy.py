"""A policy served from its own process: ``--policy ws://HOST:PORT``.

:class:`RemotePolicy` is a :class:`~openral_eval.policy.PolicyAdapter` whose ``act`` sends
the observation to a policy server and returns its answer, over the protocol of
:mod:`openral_policy_server.wire` (WebSocket, msgpack, numpy arrays; as openpi's and
LeRobot's async inference servers serve theirs). The server runs in any Python environment
(torch, a GPU box) with ``openral-policy-server`` installed, not openral.

One :class:`RemotePolicy` is one connection and one episode: it connects on first use,
reads the server's hello (the camera slots, privileged state and action mode the policy
declares) and then asks for one action per step. The MuJoCo simulation itself
(``privileged``) does not travel; ``task_state`` and ``tcp_pose`` do.

Failures are one line each (:class:`PolicyServerError`): a server that is not reachable,
one that does not answer within ``timeout_s``, one that answers off protocol or reports
that its policy raised. In a sweep each ends its episode with that line, and the sweep goes
on.
"""

from __future__ import annotations

import contextlib
import weakref
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError
from openral_policy_server.wire import MAX_MESSAGE_BYTES, PROTOCOL, WireError, pack, unpack

from openral_eval import observation_keys as keys
from openral_eval.policy import (
    ACTION_MODES,
    Observation,
    PolicyConfigError,
    action_spec_of,
    task_state_of,
    time_of,
)

SCHEMES = ("ws://", "wss://")
"""How a policy name says it is an address."""
TIMEOUT_S = 10.0
"""Default longest wait for the server's answer to one request [s]."""


class PolicyServerError(OpenralError):
    """The policy server is unreachable, slow, off protocol, or its policy raised."""


def is_address(name: str) -> bool:
    """Whether policy ``name`` is a policy server's address."""
    return name.startswith(SCHEMES)


@dataclass(frozen=True)
class RemoteConfig:
    """Parameters of a served policy (``-p timeout_s=...``)."""

    timeout_s: float = TIMEOUT_S
    """Longest wait for one answer [s]."""


class RemotePolicy:
    """The policy served at an address (see the module doc)."""

    def __init__(self, address: str, config: RemoteConfig | None = None) -> None:
        """Nothing is opened until the policy is first used."""
        self.address = address
        self.timeout_s = (config or RemoteConfig()).timeout_s
        if not self.timeout_s > 0:
            raise PolicyConfigError(f"policy {address}: timeout_s must be > 0 s")
        self._connection: Any = None
        self._opened = contextlib.ExitStack()
        self._hello: dict[str, Any] | None = None

    @property
    def required_slots(self) -> tuple[str, ...]:
        """The camera slots the served policy declares."""
        return tuple(self._declared()["required_slots"])

    @property
    def needs_privileged(self) -> bool:
        """Whether the served policy reads ``task_state``."""
        return bool(self._declared()["needs_privileged"])

    @property
    def action_mode(self) -> str:
        """The action mode the served policy declares."""
        return str(self._declared()["action_mode"])

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        """The served policy's action for ``obs``.

        Raises:
            PolicyServerError: See the module doc.
        """
        self._declared()
        self._send({"type": "act", "observation": _travelling(obs)})
        answer = self._receive(("action", "error"))
        if answer["type"] == "error":
            raise PolicyServerError(f"policy server {self.address}: {answer.get('message')}")
        action = answer.get("action")
        if not isinstance(action, np.ndarray) or action.ndim != 1:
            raise PolicyServerError(
                f"policy server {self.address} answered an action that is no 1-D array"
            )
        return action.astype(np.float64)

    def close(self) -> None:
        """End the connection (idempotent)."""
        self._connection = None
        self._opened.close()

    # -- the connection ----------------------------------------------------------------------

    def _declared(self) -> dict[str, Any]:
        """The server's hello (connecting first)."""
        if self._hello is None:
            self._connect()
            hello = self._receive(("hello",))
            self._hello = _checked_hello(hello, self.address)
        return self._hello

    def _connect(self) -> None:
        from websockets.sync.client import connect

        try:
            opening = connect(
                self.address,
                open_timeout=self.timeout_s,
                close_timeout=1.0,
                max_size=MAX_MESSAGE_BYTES,
                compression=None,
            )
        except Exception as error:  # refused, unresolvable, no WebSocket there, too slow
            raise PolicyServerError(
                f"policy server {self.address} is not reachable ({type(error).__name__}: {error})"
            ) from None
        self._connection = self._opened.enter_context(opening)
        weakref.finalize(self, self._opened.close)

    def _send(self, message: dict[str, Any]) -> None:
        try:
            self._connection.send(pack(message))
        except Exception as error:
            raise PolicyServerError(
                f"policy server {self.address}: the request did not go out "
                f"({type(error).__name__}: {error})"
            ) from None

    def _receive(self, expected: tuple[str, ...]) -> dict[str, Any]:
        try:
            frame = self._connection.recv(timeout=self.timeout_s)
        except TimeoutError:
            raise PolicyServerError(
                f"policy server {self.address} did not answer within {self.timeout_s:g} s"
            ) from None
        except Exception as error:  # the connection closed under it
            raise PolicyServerError(
                f"policy server {self.address} closed the connection ({type(error).__name__})"
            ) from None
        try:
            return unpack(frame, expected)
        except WireError as error:
            raise PolicyServerError(f"policy server {self.address}: {error}") from None


def _checked_hello(hello: dict[str, Any], address: str) -> dict[str, Any]:
    """``hello`` when it is of this protocol and declares a known action mode."""
    if hello.get("protocol") != PROTOCOL:
        raise PolicyServerError(
            f"policy server {address} speaks protocol {hello.get('protocol')!r}; "
            f"this openral speaks {PROTOCOL}"
        )
    slots = hello.get("required_slots")
    if not isinstance(slots, list) or not all(isinstance(slot, str) for slot in slots):
        raise PolicyServerError(f"policy server {address}: required_slots is no list of names")
    if hello.get("action_mode") not in ACTION_MODES:
        raise PolicyServerError(
            f"policy server {address} declares action_mode {hello.get('action_mode')!r}; "
            f"valid: {', '.join(ACTION_MODES)}"
        )
    return hello


def _travelling(obs: Observation) -> dict[str, Any]:
    """``obs`` as the wire carries it (the simulation itself stays here)."""
    names, hold = action_spec_of(obs)
    out: dict[str, Any] = {
        key: np.asarray(value) for key, value in obs.items() if key.startswith(keys.PREFIX)
    }
    out |= {"action_names": list(names), "hold": hold, "time_s": time_of(obs)}
    state = task_state_of(obs)
    if state is not None:
        out[keys.TASK_STATE] = state
    return out
