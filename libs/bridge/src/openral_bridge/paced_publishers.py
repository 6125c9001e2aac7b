"""PacedPublishers: a node's publishers and the pacer job that feeds them, made and torn
down together.

A stream such as ``/joint_states`` or ``/tf`` owns a few publishers and one periodic job on
the node's :class:`~openral_bridge.pacer.Pacer`. Stopping it must unschedule the job first
(so no callback runs on a destroyed publisher), then destroy the publishers; doing so twice
does nothing.

Example::

    out = PacedPublishers(node)
    out.open(node.create_publisher(JointState, "/joint_states", 10))
    out.schedule(pacer, 0.02, publish, "joint_states")
    ...
    out.close()
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from openral_bridge.pacer import PacedJob, Pacer

if TYPE_CHECKING:
    from rclpy.node import Node


class PacedPublishers:
    """Publishers of one stream and its pacer job (see the module doc)."""

    def __init__(self, node: Node) -> None:
        """Nothing is open until :meth:`open`."""
        self.node = node
        self.publishers: tuple[Any, ...] = ()
        """The open publishers, in the order given; empty when closed."""
        self._job: tuple[Pacer, PacedJob] | None = None

    def open(self, *publishers: Any) -> None:
        """Take ``publishers`` (closing what was open before)."""
        self.close()
        self.publishers = publishers

    def schedule(
        self, pacer: Pacer, period_s: float, callback: Callable[[], None], name: str
    ) -> None:
        """Run ``callback`` every ``period_s`` [s] on ``pacer`` until :meth:`close`."""
        self._unschedule()
        self._job = (pacer, pacer.every(period_s, callback, name))

    def close(self) -> None:
        """Unschedule the job, then destroy the publishers (idempotent)."""
        self._unschedule()
        publishers, self.publishers = self.publishers, ()
        for publisher in publishers:
            self.node.destroy_publisher(publisher)

    def _unschedule(self) -> None:
        if self._job is not None:
            pacer, job = self._job
            self._job = None
            pacer.cancel(job)
