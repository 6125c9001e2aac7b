"""Ray for a sweep: a local instance, or a running cluster joined by address.

- ``local`` starts a Ray instance on this machine with the sweep's CPUs and shuts it down
  after the sweep.
- ``auto`` or ``[ray://]HOST:PORT`` joins a running cluster (whose nodes must have openral
  installed) and leaves it running. The head must accept a TCP connection within
  :data:`JOIN_TIMEOUT_S`, checked before anything else: Ray's own join retries for many
  minutes when nothing listens there.
- Token authentication: from Ray 2.59 on, ``ray start`` and a local ``ray.init()`` ask
  joining drivers for a token, but a driver in Ray's default mode never sends one (it
  fails after 20 s). When ``RAY_AUTH_MODE`` is unset and a token is at hand, a join uses
  token mode; a cluster that asks for no token ignores it. Ray reads the mode when it is
  imported, so this is settled before ``import ray``.
- Ray's usage report is off (nothing leaves the machine) and its start-up lines are
  silenced (they would interleave with the sweep's own report).
"""

from __future__ import annotations

import logging
import os
import socket
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType

from openral_core.errors import OpenralError

JOIN_TIMEOUT_S = 5.0
"""How long a cluster's head has to accept a TCP connection before ``--ray ADDRESS`` fails."""
TOKEN_HINT = (
    " (a cluster started by `ray start` asks for a token from Ray 2.59 on: put the "
    "cluster's token in ~/.ray/auth_token or RAY_AUTH_TOKEN)"
)


class SweepError(OpenralError):
    """A sweep could not start (Ray missing or unreachable)."""


@contextmanager
def ray_session(address: str, workers: int) -> Iterator[ModuleType]:
    """Ray for the block: a new local instance with ``workers`` CPUs (``address``
    ``local``) or the cluster at ``address``; shut down (or left) after the block.

    Raises:
        SweepError: Ray is not installed, or the cluster at ``address`` cannot be joined.
    """
    token = False
    if address != "local":
        check_ray_address(address)
        token = _token_mode()
    try:
        import ray
    except ImportError:
        raise SweepError(
            "--ray needs Ray: install openral with the 'ray' extra (pip install 'openral[ray]')"
        ) from None
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    try:
        if address == "local":
            ray.init(
                num_cpus=workers,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.ERROR,
            )
        else:
            ray.init(address=address, log_to_driver=False, logging_level=logging.ERROR)
    except (ConnectionError, RuntimeError, ValueError, ray.exceptions.RayError) as error:
        hint = "" if address == "local" or token else TOKEN_HINT
        raise SweepError(f"cannot start or join Ray at {address!r}: {error}{hint}") from None
    try:
        yield ray
    finally:
        ray.shutdown()


def _token_mode() -> bool:
    """Set ``RAY_AUTH_MODE=token`` when it is unset and a token is at hand
    (``RAY_AUTH_TOKEN``, ``RAY_AUTH_TOKEN_PATH`` or ``~/.ray/auth_token``). Returns
    whether the join will send a token."""
    if os.environ.get("RAY_AUTH_MODE"):
        return os.environ["RAY_AUTH_MODE"] == "token"
    at_hand = bool(os.environ.get("RAY_AUTH_TOKEN") or os.environ.get("RAY_AUTH_TOKEN_PATH"))
    if at_hand or (Path.home() / ".ray" / "auth_token").is_file():
        os.environ["RAY_AUTH_MODE"] = "token"
        return True
    return False


def check_ray_address(address: str) -> None:
    """Fail fast unless something accepts a connection at ``address`` (``[ray://]HOST:PORT``;
    ``auto`` is left to Ray, which finds a local cluster or fails at once).

    Raises:
        SweepError: the address is malformed, or nothing answers within :data:`JOIN_TIMEOUT_S`.
    """
    if address == "auto":
        return
    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise SweepError(
            f"--ray {address!r}: expected 'local', 'auto' or a cluster's HOST:PORT "
            "(e.g. 10.0.0.5:6379)"
        )
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=JOIN_TIMEOUT_S).close()
    except TimeoutError:
        raise SweepError(
            f"cannot join Ray at {address!r}: nothing answers within {JOIN_TIMEOUT_S:g} s"
        ) from None
    except OSError as error:
        reason = error.strerror or type(error).__name__
        raise SweepError(f"cannot join Ray at {address!r}: nothing answers ({reason})") from None
