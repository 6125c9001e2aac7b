"""What a scene is given when no new action arrives: the hold, one rule for every backend.

- A scene that can say how it holds (:class:`~openral_sim.rollout.HoldingRollout`: a native
  scene, whose arm targets and gripper commands stay where they were commanded, through
  :meth:`JointDriver.hold_action <openral_mujoco.joint_driver.JointDriver.hold_action>`) is
  given its own hold.
- Any other scene is given zeros: the hold of delta and velocity controllers (robosuite's
  operational-space deltas), never of position targets, which a position-controlled
  backend must therefore report.
- A mobile base is not part of the action: it holds by stopping when its last command is
  older than the manifest's ``command_timeout_s`` (:class:`~openral_sim.base_drive.BaseDrive`).

The control loop ticks a simulated HAL with no action when none arrived in a period, and
the HAL applies this hold; nothing else decides what holding means.
"""

from __future__ import annotations

import numpy as np
from openral_mujoco.state import FloatArray

from openral_sim.rollout import HoldingRollout, SimRollout


def hold_action(env: SimRollout, width: int) -> FloatArray:
    """The action that keeps ``env``'s robot where it is commanded to be (``width`` values)."""
    if isinstance(env, HoldingRollout):
        hold = np.asarray(env.hold_action(), dtype=np.float64).ravel()
        if hold.size == width:
            return hold
    return np.zeros(width)
