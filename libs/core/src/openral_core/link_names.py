"""The names a robot's links and joints take in ROS (the manifest's ``frames.links``,
``frames.joints`` and ``frames.extra_links``), as one table.

A MuJoCo model names its bodies as its author chose (``link0``, ``hand``); the robot's vendor
names the same parts in its URDF (``panda_link0``, ``panda_hand``), and MoveIt
configurations, SRDFs and controllers are written against the vendor's names. The tree
(``openral_mujoco.robot_tree``) reads this table once; TF, the URDF, the SRDF and every
frame_id take their names from the tree.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from openral_core.models import Frames, RobotDescription
from openral_core.tcp_wiring import unit_quaternion

Vector = tuple[float, float, float]
Quaternion = tuple[float, float, float, float]


@dataclass(frozen=True)
class ExtraLinkWiring:
    """A link fixed to another, with no body in the model (see ``ExtraLink``)."""

    name: str
    parent: str
    joint: str
    """The fixed joint's name."""
    position_m: Vector
    quat_wxyz: Quaternion
    """Unit quaternion (normalised here)."""
    children: tuple[str, ...]
    """Links of ``parent`` re-hung from this one (world poses unchanged)."""


@dataclass(frozen=True)
class LinkNaming:
    """Link and joint renames and extra links; empty: the MJCF's names, no extra link."""

    links: dict[str, str] = field(default_factory=dict)
    """MJCF body name → link name."""
    joints: dict[str, str] = field(default_factory=dict)
    """MJCF joint name, or a link's name for the fixed joint into it → joint name."""
    extra_links: tuple[ExtraLinkWiring, ...] = ()
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)
    """MJCF joint name → (velocity [rad/s or m/s], effort [N·m or N]) of an unlisted joint."""

    def link(self, body: str) -> str:
        """The link name of the MJCF body ``body``."""
        return self.links.get(body, body)

    def joint(self, mjcf: str) -> str:
        """The name of the MJCF joint ``mjcf`` (a joint the manifest does not list)."""
        return self.joints.get(mjcf, mjcf)

    def fixed_joint(self, link: str) -> str:
        """The name of the fixed joint into ``link``."""
        return self.joints.get(link, f"{link}_fixed")

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> LinkNaming:
        """Inverse of ``dataclasses.asdict``."""
        extras = tuple(
            ExtraLinkWiring(
                name=e["name"],
                parent=e["parent"],
                joint=e["joint"],
                position_m=_vector(e["position_m"]),
                quat_wxyz=_quaternion(e["quat_wxyz"]),  # stored normalised
                children=tuple(e["children"]),
            )
            for e in data.get("extra_links", ())
        )
        limits = {k: (float(v[0]), float(v[1])) for k, v in data.get("limits", {}).items()}
        return cls(dict(data.get("links", {})), dict(data.get("joints", {})), extras, limits)


def link_naming(robot: RobotDescription) -> LinkNaming:
    """The manifest's link naming, defaults filled in."""
    frames = robot.frames or Frames()
    extras = tuple(
        ExtraLinkWiring(
            name=extra.name,
            parent=extra.parent,
            joint=extra.joint,
            position_m=_vector(extra.position_m),
            quat_wxyz=_unit(extra.quat_wxyz),
            children=tuple(extra.children),
        )
        for extra in frames.extra_links
    )
    limits = {
        name: (float(limit.velocity_limit), float(limit.effort_limit))
        for name, limit in frames.joint_limits.items()
    }
    return LinkNaming(dict(frames.links), dict(frames.joints), extras, limits)


def _vector(values: Any) -> Vector:
    x, y, z = (float(v) for v in values)
    return x, y, z


def _quaternion(values: Any) -> Quaternion:
    w, x, y, z = (float(v) for v in values)
    return w, x, y, z


def _unit(values: Any) -> Quaternion:
    return unit_quaternion([float(v) for v in values])  # rule 27 refuses a zero one
