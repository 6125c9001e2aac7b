"""Serve a robot policy to openral from any Python environment: ``serve(PolicyClass)``
(:mod:`openral_policy_server.server`) over the protocol of :mod:`openral_policy_server.wire`
(WebSocket, msgpack, numpy arrays). Needs numpy, msgpack and websockets, not openral."""

from openral_policy_server.server import PolicyServer, ServedPolicy, serve, start
from openral_policy_server.wire import PROTOCOL, WireError, pack, unpack

__all__ = [
    "PROTOCOL",
    "PolicyServer",
    "ServedPolicy",
    "WireError",
    "pack",
    "serve",
    "start",
    "unpack",
]
