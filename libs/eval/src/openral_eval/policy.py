"""The policy seam: what a policy sees each step and what it declares it needs (its
parameters: :mod:`openral_eval.policy_config`).

A policy is anything with :attr:`PolicyAdapter.required_slots` (the VLA camera slots it
needs frames for), :attr:`PolicyAdapter.needs_privileged` (whether it reads the simulation
itself, which only an evaluation episode can give) and ``act(observation) -> action``; its
class may also declare ``action_mode`` (:func:`action_mode`: joint targets by default, or
end-effector deltas).
The rskill runner and the evaluator read those declarations; neither probes a policy for
anything else.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NotRequired, Protocol, TypedDict, runtime_checkable

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError

from openral_eval.privileged import Privileged


class Observation(TypedDict):
    """What a policy sees on each tick."""

    images: dict[str, npt.NDArray[np.uint8]]
    """VLA slot (``camera1`` …) → latest HxWx3 uint8 RGB frame."""
    joint_positions: npt.NDArray[np.float64]
    """Latest measured joint positions in manifest joint order (NaN where not reported)."""
    action_spec: tuple[tuple[str, ...], npt.NDArray[np.float64]]
    """HAL action slot names and the hold action that keeps the robot still."""
    time_s: float
    """Seconds since the runner's first tick with a complete observation."""
    tcp_pose: NotRequired[npt.NDArray[np.float64]]
    """The tool centre point in the robot's base frame: x, y, z [m], then the quaternion
    w, x, y, z (episodes, on a robot whose manifest declares ``sim.tcp``)."""
    task_state: NotRequired[Mapping[str, npt.NDArray[np.float64]]]
    """The scene's task state (object poses; robosuite's object observations), for a
    policy with ``needs_privileged`` (episodes only)."""
    privileged: NotRequired[Privileged]
    """The MuJoCo simulation itself, for a policy with ``needs_privileged`` on a native
    scene (episodes only)."""


@runtime_checkable
class PolicyAdapter(Protocol):
    """What the rskill runner needs from a policy."""

    @property
    def required_slots(self) -> tuple[str, ...]:
        """VLA camera slots that must have frames before ``act`` is called."""
        ...

    @property
    def needs_privileged(self) -> bool:
        """True when ``act`` reads ``task_state``/``privileged`` (the simulation itself):
        such a policy runs only in evaluation episodes, never on a ROS graph."""
        ...

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        """One action: a value per action slot of ``obs["action_spec"]``."""
        ...


class PolicyConfigError(OpenralError):
    """An unknown policy, parameter or parameter value."""


ACTION_MODES = ("joint_position", "ee_delta_pose", "ee_pose")
"""What a policy's actions may be: joint targets (every path), or end-effector deltas in
the robosuite preset (episodes on a native scene)."""


def action_mode(policy: object) -> str:
    """The action mode a policy's class declares in ``action_mode`` (default
    ``joint_position``: one value per action slot of ``obs["action_spec"]``).

    Raises:
        PolicyConfigError: A mode policies cannot use.
    """
    mode = getattr(policy, "action_mode", ACTION_MODES[0])  # a class's, or a served one's
    if mode not in ACTION_MODES:
        raise PolicyConfigError(
            f"policy {type(policy).__name__} declares action_mode {mode!r}; valid: "
            f"{', '.join(ACTION_MODES)}"
        )
    return str(mode)
