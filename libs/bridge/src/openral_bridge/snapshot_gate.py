"""When a paced sensor may take the live state: at the end of a control period.

``openral sim run`` observes a scene once per control period, after its last physics step,
so its frames, depth images and scans all show period-end states. Under ``deploy sim`` the
control loop steps a period in several ticks (the state rate) and each imaging sensor's job
runs on its own grid; without a gate the tick after which a job ran was fixed by start-up
order, and a camera could show only mid-period states for a whole run, never a state that
``sim run`` shows for the same seed. :func:`period_end_gate` holds a due snapshot back
until the tick that ends the period, so the same seed shows the same frames in both.

While no period is under way (the loop stopped, the E-stop latched: time is frozen) the
state may be taken at once, so sensors keep publishing the frozen scene.
"""

from __future__ import annotations

from openral_bridge.control_loop import ControlLoop
from openral_bridge.frame_renderer import SnapshotGate

__all__ = ["period_end_gate"]


def period_end_gate(loop: ControlLoop) -> SnapshotGate:
    """A gate (asked holding the HAL's lock) that opens right after a control period's last
    tick, and otherwise says to come back half a tick after that tick is due [s]."""

    def until_period_end_s() -> float:
        left = loop.ticks_left
        if left == 0 or not loop.running or loop.hal.estopped:
            return 0.0
        return (left + 0.5) * loop.tick_period_s

    return until_period_end_s
