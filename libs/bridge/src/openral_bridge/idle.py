"""When the sensor bridge may advance an attached scene on its own.

A simulated scene only moves when something calls ``env.step``. While a skill streams
actions, ``send_action`` does that; between skills nobody does, so physics freezes and
the cameras keep publishing the same frame. The bridge therefore ticks the scene itself
(``SimAttachedHAL.idle_step``), but only in the quiet gaps: once no action has arrived for
a hold window. A skill that is commanding always owns the scene.
"""

from __future__ import annotations


def should_idle_step(now_ns: int, last_action_ns: int, hold_ns: int) -> bool:
    """True when the scene may be idle-stepped: no action for at least ``hold_ns``.

    Args:
        now_ns: Current ``time.monotonic_ns()``.
        last_action_ns: ``time.monotonic_ns()`` of the last action sent to the HAL, or 0
            when none has ever been sent (the scene idles from the start).
        hold_ns: Quiet window after an action during which the skill keeps the scene.
    """
    if last_action_ns == 0:
        return True
    return now_ns - last_action_ns >= hold_ns
