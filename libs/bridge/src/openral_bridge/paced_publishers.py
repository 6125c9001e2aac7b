"""PacedPublishers: a node's publishers and the pacer job that feeds them, made and torn
down together.

A stream such as ``/joint_states`` or ``/tf`` owns a few publishers and one periodic job
(:class:`Cadence`): on the node's :class:`~openral_bridge.pacer.Pacer`, or, when its rate is
at least the control loop's tick rate, right after every tick of the loop, so each message
carries a new state (never the same one twice, none skipped; while the E-stop freezes the
scene, its frozen state at the tick rate). Stopping it must unschedule
the job first (so no callback runs on a destroyed publisher), then destroy the publishers;
doing so twice does nothing.

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

    from openral_bridge.control_loop import ControlLoop

_SLACK = 1e-9
"""Relative tolerance when a rate is compared with the loop's tick rate."""


class Cadence:
    """One periodic callback: every tick of a control loop, or every period on a pacer."""

    def __init__(self) -> None:
        self._job: tuple[Pacer, PacedJob] | None = None
        self._loop: ControlLoop | None = None
        self._report: Callable[[], None] | None = None

    def start(
        self,
        pacer: Pacer,
        rate_hz: float,
        callback: Callable[[], None],
        name: str,
        loop: ControlLoop | None = None,
    ) -> float:
        """Run ``callback`` after every tick of ``loop`` when ``rate_hz`` is at least its
        tick rate, else every ``1 / rate_hz`` s on ``pacer``; returns the rate it runs at
        [Hz] (stopping what ran before)."""
        self.stop()
        tick_hz = 1.0 / loop.tick_period_s if loop is not None else None
        if loop is not None and tick_hz is not None and rate_hz >= tick_hz * (1.0 - _SLACK):
            self._loop, self._report = loop, callback
            loop.reporters.append(callback)
            return tick_hz
        self._job = (pacer, pacer.every(1.0 / rate_hz, callback, name))
        return rate_hz

    def stop(self) -> None:
        """Unschedule (idempotent; a pacer job in progress has ended when this returns)."""
        if self._job is not None:
            pacer, job = self._job
            self._job = None
            pacer.cancel(job)
        loop, report = self._loop, self._report
        if loop is not None and report is not None and report in loop.reporters:
            loop.reporters.remove(report)
        self._loop = self._report = None


class PacedPublishers:
    """Publishers of one stream and its pacer job (see the module doc)."""

    def __init__(self, node: Node) -> None:
        """Nothing is open until :meth:`open`."""
        self.node = node
        self.publishers: tuple[Any, ...] = ()
        """The open publishers, in the order given; empty when closed."""
        self._cadence = Cadence()

    def open(self, *publishers: Any) -> None:
        """Take ``publishers`` (closing what was open before)."""
        self.close()
        self.publishers = publishers

    def schedule(
        self,
        pacer: Pacer,
        period_s: float,
        callback: Callable[[], None],
        name: str,
        loop: ControlLoop | None = None,
    ) -> float:
        """Run ``callback`` every ``period_s`` [s] until :meth:`close` (after every tick of
        ``loop`` when that is as often: see :class:`Cadence`); returns the rate [Hz]."""
        return self._cadence.start(pacer, 1.0 / period_s, callback, name, loop)

    def close(self) -> None:
        """Unschedule the job, then destroy the publishers (idempotent)."""
        self._cadence.stop()
        publishers, self.publishers = self.publishers, ()
        for publisher in publishers:
            self.node.destroy_publisher(publisher)
