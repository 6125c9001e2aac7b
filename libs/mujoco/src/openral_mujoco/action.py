"""Validation of actions, shared by every HAL: the one place an action is checked.

An action is one target per action slot (on every native path: per manifest joint, in
manifest order): a joint position for arm joints, a gripper command (per the gripper's
write mode) for gripper joints. It comes as a 1-D numpy array of real numbers, a
list/tuple of ints and floats, or a typed :class:`Action`: slots by name (the others keep
the hold action's value), the gripper's command, and a mobile base's twist.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from numbers import Real

import numpy as np

from openral_mujoco.errors import ActionRejected
from openral_mujoco.state import FloatArray

_FLOAT64 = np.dtype(np.float64)


def validated_action(
    action: object, names: Sequence[str], *, finite_checked_by_caller: bool = False
) -> FloatArray:
    """``action`` as a float64 array of len(names), or :class:`ActionRejected`.

    A float64 array of the right width is returned as it is (callers only read it); with
    ``finite_checked_by_caller`` its values are not scanned for NaN/Inf here, because the
    caller's own pass over them finds those (see ``JointDriver.command``)."""
    width = len(names)
    if (
        type(action) is np.ndarray
        and action.dtype is _FLOAT64
        and action.shape == (width,)
        and (finite_checked_by_caller or math.isfinite(action.sum()))
    ):
        return action  # the fast path of a control loop
    if isinstance(action, np.ndarray):
        if action.dtype.kind not in "fiu":
            raise ActionRejected(f"action array has dtype {action.dtype}; expected real numbers")
        if action.ndim != 1:
            raise ActionRejected(f"action array has shape {action.shape}; expected ({width},)")
        values = action.astype(np.float64)
    elif isinstance(action, list | tuple):
        bad = [i for i, v in enumerate(action) if isinstance(v, bool) or not isinstance(v, Real)]
        if bad:
            got = type(action[bad[0]]).__name__
            raise ActionRejected(f"action[{bad[0]}] is a {got}; expected a real number")
        values = np.asarray(action, dtype=np.float64)
    else:
        raise ActionRejected(
            f"action is a {type(action).__name__}; expected a 1-D numpy array or a list of "
            f"{width} numbers"
        )
    if values.shape != (width,):
        raise ActionRejected(
            f"action has {values.shape[0]} values; expected {width} (one per joint: "
            f"{', '.join(names)})"
        )
    bad_index = np.flatnonzero(~np.isfinite(values))
    if bad_index.size:
        i = int(bad_index[0])
        raise ActionRejected(f"action[{i}] ({names[i]}) is {values[i]}; expected a finite number")
    return values


@dataclass(frozen=True)
class BaseTwist:
    """A mobile base's velocity command in its base frame [m/s, m/s, rad/s]."""

    vx_m_s: float = 0.0
    vy_m_s: float = 0.0
    wz_rad_s: float = 0.0

    def __post_init__(self) -> None:
        for name in ("vx_m_s", "vy_m_s", "wz_rad_s"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
                raise ActionRejected(f"base twist {name} is {value!r}; expected a finite number")


@dataclass(frozen=True)
class Action:
    """A typed action: some slots by name, the gripper, the base; the rest held.

    Attributes:
        slots: Action slot name → value (manifest units); slots not named keep the hold
            action's value (the targets in force).
        gripper: The first gripper's command, in its write mode (``normalised``: 1 open,
            0 closed); None: as ``slots`` or the hold say.
        base: A mobile base's twist, applied with the joints (None: no base command).
    """

    slots: Mapping[str, float] = field(default_factory=dict)
    gripper: float | None = None
    base: BaseTwist | None = None

    def values(
        self, names: Sequence[str], hold: FloatArray, gripper_slot: str | None
    ) -> FloatArray:
        """The whole action (one value per slot of ``names``), validated like any other.

        Raises:
            ActionRejected: An unknown slot, a gripper command for a robot without one, a
                slot named twice (by name and as the gripper), or a non-finite value.
        """
        unknown = sorted(set(self.slots) - set(names))
        if unknown:
            raise ActionRejected(
                f"action names slots {', '.join(unknown)}, which are not action slots; the "
                f"slots are: {', '.join(names)}"
            )
        values = np.array(hold, dtype=np.float64)
        for name, value in self.slots.items():
            values[names.index(name)] = _real(value, name)
        if self.gripper is not None:
            if gripper_slot is None or gripper_slot not in names:
                raise ActionRejected("action sets a gripper, and this robot's actions have none")
            if gripper_slot in self.slots:
                raise ActionRejected(f"action sets {gripper_slot} both by name and as the gripper")
            values[names.index(gripper_slot)] = _real(self.gripper, "gripper")
        return validated_action(values, names)


def split_action(
    action: object,
    names: Sequence[str],
    hold: Callable[[], FloatArray],
    gripper_slot: str | None,
) -> tuple[object, BaseTwist | None]:
    """(the joint part, the base twist) of any action a HAL is sent: an :class:`Action`
    resolved against ``names`` and the ``hold`` action in force (validated), anything
    else unchanged for :func:`validated_action`, with no base twist."""
    if isinstance(action, Action):
        return action.values(names, hold(), gripper_slot), action.base
    return action, None


def _real(value: object, what: str) -> float:
    """``value`` as a float, or :class:`ActionRejected` naming ``what``."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise ActionRejected(f"action {what} is a {type(value).__name__}; expected a real number")
    return float(value)
