"""The range of every action value a scene takes: one rule for every backend.

- A scene driven by the manifest's contract (:class:`~openral_sim.rollout.ManifestRollout`,
  the native scene) takes one value per manifest joint: an arm joint's target within its
  ``position_limits`` (a continuous joint: unbounded), a gripper's command within its write
  mode's range (:class:`~openral_mujoco.command_limits.CommandLimits`, the same envelope the
  driver clamps to).
- A scene whose controller states its own range (:class:`BoundedRollout`: robosuite's
  ``action_spec``, e.g. [-1, 1] for an operational-space delta) takes that range.
- Any other scene: unbounded, finite.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_mujoco.command_limits import CommandLimits

from openral_sim.rollout import ManifestRollout, SimRollout

Bounds = tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]
"""(low, high), one value per action slot."""


@runtime_checkable
class BoundedRollout(Protocol):
    """A scene whose controller states the range of each action value."""

    @property
    def action_limits(self) -> Bounds:
        """Lower and upper bound of every action value."""
        ...


def action_bounds(env: SimRollout, robot: LoadedRobot, width: int) -> Bounds:
    """(low, high) of each of the ``width`` action values ``env`` takes (see the module doc).

    Raises:
        ValueError: The backend's stated range is not ``width`` values wide.
    """
    if isinstance(env, ManifestRollout):
        wiring = robot.tables.hal_wiring
        limits = CommandLimits(robot.description, wiring.grippers if wiring is not None else ())
        low, high = limits.low, limits.high
    elif isinstance(env, BoundedRollout):
        low, high = (np.asarray(v, dtype=np.float64).ravel() for v in env.action_limits)
    else:
        low, high = np.full(width, -np.inf), np.full(width, np.inf)
    if low.shape != (width,) or high.shape != (width,):
        raise ValueError(
            f"{type(env).__name__} states {low.size} action bounds for an action of {width}"
        )
    return low.copy(), high.copy()
