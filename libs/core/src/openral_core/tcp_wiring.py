"""The robot's tool centre point (``sim.tcp``), resolved for the runtime tables."""

from __future__ import annotations

import math
from dataclasses import dataclass

from openral_core.models import ToolCentrePoint


@dataclass(frozen=True)
class TcpWiring:
    """The robot's tool centre point (see ToolCentrePoint for field meanings)."""

    frame: str
    """The MJCF body or site it is fixed to."""
    kind: str
    """``body`` or ``site``."""
    offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """The TCP in that frame [m]."""
    quat_wxyz: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    """The tool frame's orientation in that frame (z along the tool)."""


def tcp_wiring(tcp: ToolCentrePoint | None) -> TcpWiring | None:
    """The tool centre point of ``sim.tcp`` (rule 19 makes it one body or one site)."""
    if tcp is None:
        return None
    frame, kind = (tcp.body, "body") if tcp.body is not None else (tcp.site or "", "site")
    return TcpWiring(frame, kind, _triple(tcp.offset_m), unit_quaternion(tcp.quat_wxyz))


def unit_quaternion(values: list[float] | None) -> tuple[float, float, float, float]:
    """``values`` (w, x, y, z) normalised, else identity (None, or all zero): the manifest's
    rules bound how far from unit a stored quaternion may be (rules 18 and 27)."""
    norm = math.hypot(*values) if values is not None else 0.0
    if values is None or norm == 0.0:
        return (1.0, 0.0, 0.0, 0.0)
    w, x, y, z = (v / norm for v in values)
    return (w, x, y, z)


def _triple(values: list[float] | None) -> tuple[float, float, float]:
    """Three floats (zeros when absent)."""
    x, y, z = values if values is not None else (0.0, 0.0, 0.0)
    return (float(x), float(y), float(z))
