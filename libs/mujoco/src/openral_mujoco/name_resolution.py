"""Find a manifest's joints in a scene model whose joint names may carry a robosuite prefix.

The manifest names each joint as the robot's own MJCF does (``sim_joint_name``, else the
canonical name). A native scene keeps those names; robosuite prefixes them per robot
(``robot0_joint1``, and ``gripper0_right_finger_joint1`` for a gripper mounted on it).
Resolution takes an exact name first and falls back to the name with that prefix removed,
but only where that fallback is unambiguous: a stripped name that two models' joints share
(a bimanual ``robot0_``/``robot1_`` pair) or that equals another joint's exact name
resolves to nothing, so a joint is never silently mis-wired.
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Sequence

from openral_mujoco.errors import HalError

ROBOSUITE_PREFIX = re.compile(r"^(?:robot\d+|gripper\d+(?:_(?:right|left))?)_")
"""The prefixes robosuite gives the joints of robot ``k`` and of its grippers."""
SHOWN_AVAILABLE = 8
"""How many model joint names an error message lists."""


def strip_robot_prefix(name: str) -> str:
    """``robot0_joint1`` → ``joint1``, ``gripper0_right_finger_joint1`` → ``finger_joint1``;
    names without such a prefix are returned unchanged."""
    return ROBOSUITE_PREFIX.sub("", name, count=1)


def resolve_joint_names(wanted: Sequence[str], available: Sequence[str]) -> dict[str, str]:
    """Map each wanted MJCF joint name to the model joint that carries it.

    Args:
        wanted: Joint names as the manifest gives them (``sim_joint_name`` or canonical).
        available: Joint names of the scene's model.

    Raises:
        HalError: Naming every wanted joint that resolves to no model joint, or to more
            than one.
    """
    exact = set(available)
    stripped = Counter(strip_robot_prefix(n) for n in available if ROBOSUITE_PREFIX.match(n))
    fallback = {
        strip_robot_prefix(n): n
        for n in available
        if ROBOSUITE_PREFIX.match(n)
        and stripped[strip_robot_prefix(n)] == 1
        and strip_robot_prefix(n) not in exact
    }
    resolved: dict[str, str] = {}
    missing: list[str] = []
    for name in wanted:
        if name in exact:
            resolved[name] = name
        elif name in fallback:
            resolved[name] = fallback[name]
        else:
            missing.append(name)
    if missing:
        shown = ", ".join(list(available)[:SHOWN_AVAILABLE])
        more = len(available) - SHOWN_AVAILABLE
        raise HalError(
            f"joints not found in the scene model: {', '.join(missing)} (the model has "
            f"{len(available)} joints: {shown or '<none>'}{f', … {more} more' if more > 0 else ''}"
            "); a prefixed name shared by several robots needs an explicit sim_joint_name"
        )
    return resolved
