"""Write RGB frames and depth images as PNG files with the standard library (no imaging
dependency)."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import numpy.typing as npt


def encode_png(image: npt.NDArray[np.uint8]) -> bytes:
    """PNG bytes of an HxWx3 uint8 RGB image."""
    if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8:
        raise ValueError(f"expected an HxWx3 uint8 image, got {image.shape} {image.dtype}")
    return _png(image.reshape(image.shape[0], -1), image.shape[1], 8, 2)


def encode_depth_png(depth_m: npt.NDArray[np.floating]) -> bytes:
    """16-bit greyscale PNG bytes of an HxW depth image [m], in millimetres (the usual depth
    PNG convention): NaN and anything at or past 65.535 m is 0, "no reading"."""
    if depth_m.ndim != 2:
        raise ValueError(f"expected an HxW depth image, got shape {depth_m.shape}")
    millimetres = np.rint(np.nan_to_num(np.asarray(depth_m, np.float64), nan=0.0) * 1000.0)
    millimetres[(millimetres < 0) | (millimetres >= 65535)] = 0
    big_endian = millimetres.astype(">u2")
    return _png(big_endian.view(np.uint8).reshape(depth_m.shape[0], -1), depth_m.shape[1], 16, 0)


def _png(rows: npt.NDArray[np.uint8], width: int, bit_depth: int, colour_type: int) -> bytes:
    """A PNG of ``rows`` (H x row-bytes, unfiltered) of ``width`` pixels."""
    height = rows.shape[0]
    filtered = np.concatenate([np.zeros((height, 1), np.uint8), rows], axis=1)

    def chunk(kind: bytes, payload: bytes) -> bytes:
        body = kind + payload
        return struct.pack(">I", len(payload)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, bit_depth, colour_type, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(filtered.tobytes(), 6))
        + chunk(b"IEND", b"")
    )


def write_png(path: Path, image: npt.NDArray[np.uint8]) -> None:
    """Write ``image`` to ``path`` as PNG."""
    path.write_bytes(encode_png(image))
