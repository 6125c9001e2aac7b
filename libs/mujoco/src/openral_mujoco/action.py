"""Validation of joint-space actions, shared by every HAL.

An action is one target per manifest joint, in manifest order: a joint position for arm
joints, a gripper command (per the gripper's write mode) for gripper joints. It is a 1-D
numpy array of real numbers or a list/tuple of ints and floats.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
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
