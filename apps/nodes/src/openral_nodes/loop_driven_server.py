"""An rclpy action server whose goals are ended by a control loop, not by a coroutine.

rclpy runs an action's execute callback as a coroutine that its executor polls on every
spin while it waits (a busy loop on the only executor thread). Here no callback waits: a
goal is started by its accept callback (``goal_handle.execute()`` only marks it executing)
and ended from any thread by :meth:`LoopDrivenServer.finish`, which schedules the ending on
the executor.
"""

from __future__ import annotations

from typing import Any

from rclpy.action.server import ActionServer


class LoopDrivenServer(ActionServer):
    """An ActionServer whose goals end when the control loop says so (see the module doc):
    ``goal_handle.execute()`` only marks the goal executing; :meth:`finish` ends it."""

    def notify_execute(self, goal_handle: Any, execute_callback: Any) -> None:
        if execute_callback is not None:
            super().notify_execute(goal_handle, execute_callback)  # type: ignore[no-untyped-call]

    def finish(self, goal_handle: Any, status: str, result: Any) -> None:
        """End ``goal_handle`` (any thread): on the executor, move it to ``status``
        (``succeed``, ``abort`` or ``canceled``) and hand ``result`` to its client."""

        def end(handle: Any) -> Any:
            try:
                if handle.is_active:
                    getattr(handle, status)()
            except Exception:  # a transition the goal's state no longer allows: abort it
                if handle.is_active:
                    handle.abort()
            return result

        super().notify_execute(goal_handle, end)  # type: ignore[no-untyped-call]
