"""The policy server protocol's messages: msgpack maps, numpy arrays inside them.

Every message is one binary WebSocket frame holding one msgpack map with a ``type`` key:

==========  =========  ===========================================================
type        from       fields
==========  =========  ===========================================================
``hello``   server     ``protocol`` (:data:`PROTOCOL`), ``required_slots`` (list of
                       str), ``needs_privileged`` (bool), ``action_mode`` (str)
``act``     client     ``observation`` (map, below)
``action``  server     ``action`` (1-D float64 array, one value per action slot)
``error``   server     ``message`` (str, one line: the policy raised)
==========  =========  ===========================================================

The server sends ``hello`` first, once per connection; each connection is one episode and
gets a policy of its own. An observation holds every ``observation.*`` key of openral's one
observation (arrays: ``observation.state`` and ``observation.velocity`` float64, each
``observation.images.<slot>`` HxWx3 uint8, ``observation.tcp_pose`` x, y, z [m] and the
quaternion w, x, y, z where the robot has a TCP, the state sensors' fields …),
``action_names`` (list of str) and ``hold`` (float64 array: the action that keeps the robot
still), ``time_s`` (float), and for a policy that needs privileged state ``task_state``
(name → float64 array).

A numpy array travels as msgpack extension type :data:`ARRAY_EXT`: a msgpack list
``[dtype, shape, bytes]`` (dtype as numpy spells it, little-endian; C order). Only bool,
integer, unsigned and float arrays travel; anything else is refused when packed.
"""

from __future__ import annotations

from typing import Any

import msgpack
import numpy as np
import numpy.typing as npt

PROTOCOL = 2
"""The protocol version a hello carries (2: the observation by openral's one observation's
keys; 1 had ``joint_positions`` and ``images``)."""
ARRAY_EXT = 42
"""msgpack extension type code of a numpy array."""
KINDS = "biuf"
"""numpy dtype kinds that travel: bool, signed and unsigned integers, floats."""
MAX_MESSAGE_BYTES = 64 * 2**20
"""Largest frame either side takes [bytes] (a few camera images fit)."""


class WireError(ValueError):
    """A message that is not of the protocol (one line saying what was expected)."""


def _default(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in KINDS:
            raise WireError(f"an array of dtype {value.dtype} does not travel (only {KINDS})")
        array = np.ascontiguousarray(value, dtype=value.dtype.newbyteorder("<"))
        body = msgpack.packb([array.dtype.str, list(array.shape), array.tobytes()])
        return msgpack.ExtType(ARRAY_EXT, body)
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple):
        return list(value)
    raise WireError(f"a {type(value).__name__} does not travel")


def _ext_hook(code: int, data: bytes) -> Any:
    if code != ARRAY_EXT:
        raise WireError(f"unknown msgpack extension type {code} (arrays are {ARRAY_EXT})")
    try:
        dtype, shape, body = msgpack.unpackb(data)
        array: npt.NDArray[Any] = np.frombuffer(body, dtype=np.dtype(dtype))
        if array.dtype.kind not in KINDS:
            raise WireError(f"an array of dtype {dtype} does not travel")
        return array.reshape(shape)
    except WireError:
        raise
    except Exception as error:
        raise WireError(f"a malformed array ({type(error).__name__}: {error})") from None


def pack(message: dict[str, Any]) -> bytes:
    """One message as the bytes of its frame.

    Raises:
        WireError: A value that does not travel.
    """
    return bytes(msgpack.packb(message, default=_default, use_bin_type=True))


def unpack(frame: bytes | str, expected: tuple[str, ...]) -> dict[str, Any]:
    """The message in ``frame``, whose ``type`` must be one of ``expected``.

    Raises:
        WireError: Not a msgpack map of one of those types (said in one line).
    """
    if not isinstance(frame, bytes):
        raise WireError(f"a text frame; expected a binary msgpack {' or '.join(expected)}")
    try:
        message = msgpack.unpackb(frame, ext_hook=_ext_hook, raw=False, strict_map_key=True)
    except WireError:
        raise
    except Exception as error:
        raise WireError(f"not msgpack ({type(error).__name__}: {error})") from None
    if not isinstance(message, dict) or message.get("type") not in expected:
        kind = message.get("type") if isinstance(message, dict) else type(message).__name__
        raise WireError(f"a {kind!r} message; expected {' or '.join(expected)}")
    return message
