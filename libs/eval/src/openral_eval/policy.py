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
from typing import Protocol, runtime_checkable

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError

from openral_eval import observation_keys as keys
from openral_eval.privileged import Privileged

Observation = dict[str, object]
"""What a policy sees on each tick: the one observation every path shares
(:mod:`openral_eval.observation_keys`: ``observation.state``, ``observation.velocity``,
``observation.images.<slot>`` for at least the slots it requires, ``observation.tcp_pose``
where the robot has a TCP, the state sensors), plus ``action_spec`` (the HAL's action slot
names and its hold action) and ``time_s`` (seconds since the first step with a complete
observation). A policy with ``needs_privileged`` (episodes only) also gets
``observation.environment_state``, ``task_state`` (the same by name) and, on a native
scene, ``privileged`` (:class:`~openral_eval.privileged.Privileged`). Read the policy's own
keys with :func:`action_spec_of`, :func:`time_of` and :func:`privileged_of`."""


def action_spec_of(obs: Observation) -> tuple[tuple[str, ...], npt.NDArray[np.float64]]:
    """``obs["action_spec"]``: the action slot names and the hold action.

    Raises:
        PolicyConfigError: ``obs`` has no action spec of that shape.
    """
    spec = obs.get(keys.ACTION_SPEC)
    if not isinstance(spec, tuple) or len(spec) != 2:
        raise PolicyConfigError("the observation has no action_spec (names, hold action)")
    names, hold = spec
    return tuple(str(name) for name in names), np.asarray(hold, dtype=np.float64)


def time_of(obs: Observation) -> float:
    """``obs["time_s"]`` [s].

    Raises:
        PolicyConfigError: ``obs`` has no time.
    """
    value = obs.get(keys.TIME_S)
    if not isinstance(value, int | float):
        raise PolicyConfigError("the observation has no time_s")
    return float(value)


def privileged_of(obs: Observation) -> Privileged | None:
    """``obs["privileged"]``, the simulation (None: not given)."""
    world = obs.get(keys.PRIVILEGED)
    return world if isinstance(world, Privileged) else None


def task_state_of(obs: Observation) -> Mapping[str, npt.NDArray[np.float64]] | None:
    """``obs["task_state"]``, the task state by name (None: not given)."""
    state = obs.get(keys.TASK_STATE)
    if not isinstance(state, Mapping):
        return None
    return {str(k): np.asarray(v, dtype=np.float64) for k, v in state.items()}


@runtime_checkable
class PolicyAdapter(Protocol):
    """What the rskill runner needs from a policy."""

    @property
    def required_slots(self) -> tuple[str, ...]:
        """VLA camera slots that must have frames before ``act`` is called."""
        ...

    @property
    def needs_privileged(self) -> bool:
        """True when ``act`` reads the environment state or ``privileged`` (the simulation):
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
