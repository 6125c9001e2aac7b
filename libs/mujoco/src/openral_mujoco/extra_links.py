"""Links with no body of their own (``frames.extra_links``): each fixed to a parent link at a
pose, taking over some of the parent's children with their world poses unchanged.

The Panda's MJCF hangs its hand straight from ``link7``; franka_description has a flange
``panda_link8`` between them, and MoveIt configurations name it. An extra link puts it back:
``panda_link8`` fixed to ``panda_link7`` 0.107 m along z, ``panda_hand`` re-hung from it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from openral_core.link_names import ExtraLinkWiring, LinkNaming

from openral_mujoco.errors import TreeUnsupported

if TYPE_CHECKING:
    from openral_mujoco.robot_tree import TreeLink


def hang_extra_links(links: list[TreeLink], extras: tuple[ExtraLinkWiring, ...]) -> list[TreeLink]:
    """``links`` (parents first) with each extra link after its parent and its children
    re-hung from it.

    Raises:
        TreeUnsupported: A parent is no link, a child is no child of that parent, or an
            extra link's name is taken.
    """
    out = list(links)
    for extra in extras:
        names = [link.name for link in out]
        if extra.parent not in names:
            raise TreeUnsupported(
                f"frames.extra_links: {extra.name!r} hangs from {extra.parent!r}, which is "
                f"no link of the robot (links: {', '.join(names)})"
            )
        if extra.name in names:
            raise TreeUnsupported(f"frames.extra_links: {extra.name!r} is already a link")
        parent_at = names.index(extra.parent)
        parent = out[parent_at]
        for child in extra.children:
            if child not in names or out[names.index(child)].parent != extra.parent:
                raise TreeUnsupported(
                    f"frames.extra_links: {extra.name!r} takes over {child!r}, which is no "
                    f"child link of {extra.parent!r}"
                )
        hung = replace(
            parent,
            name=extra.name,
            body=-1,
            parent=extra.parent,
            position=extra.position_m,
            quat=extra.quat_wxyz,
            joint=None,
            fixed_joint=extra.joint,
        )
        out = [_rehung(link, extra) if link.name in extra.children else link for link in out]
        out.insert(parent_at + 1, hung)
    return out


def _rehung(link: TreeLink, extra: ExtraLinkWiring) -> TreeLink:
    """``link`` (a child of the extra link's parent) as a child of the extra link."""
    inverse_position, inverse_quat = np.empty(3), np.empty(4)
    mujoco.mju_negPose(
        inverse_position,
        inverse_quat,
        np.array(extra.position_m),
        np.array(extra.quat_wxyz),
    )
    position, quat = np.empty(3), np.empty(4)
    mujoco.mju_mulPose(
        position,
        quat,
        inverse_position,
        inverse_quat,
        np.array(link.position),
        np.array(link.quat),
    )
    x, y, z = (float(v) for v in position)
    w, qx, qy, qz = (float(v) for v in quat / np.linalg.norm(quat))
    return replace(link, parent=extra.name, position=(x, y, z), quat=(w, qx, qy, qz))


def check_renames(naming: LinkNaming, bodies: set[str], links: list[TreeLink]) -> None:
    """Every key of ``frames.links`` is a body of the robot and every key of
    ``frames.joints`` one of its joints (by MJCF name) or links; never silently unused.

    Raises:
        TreeUnsupported: A key names nothing of the robot.
    """
    unknown = sorted(set(naming.links) - bodies)
    if unknown:
        raise TreeUnsupported(
            f"frames.links: {unknown[0]!r} is no body of the robot's model (bodies: "
            f"{', '.join(sorted(bodies))})"
        )
    joints = {link.joint.mjcf_name for link in links if link.joint and not link.joint.manifest}
    named = joints | {link.name for link in links}
    listing = f"joints: {', '.join(sorted(joints)) or 'none'}"
    for field, keys, allowed, what in (
        ("joint_limits", naming.limits, joints, "is no joint of the robot's model that the "
         f"manifest does not list (the manifest's own have its limits; {listing})"),
        ("joints", naming.joints, named, "is neither a joint of the robot's model that the "
         f"manifest does not list (those keep the manifest's names) nor a link ({listing})"),
    ):  # fmt: skip
        unknown = sorted(set(keys) - allowed)
        if unknown:
            raise TreeUnsupported(f"frames.{field}: {unknown[0]!r} {what}")
