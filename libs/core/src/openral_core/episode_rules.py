"""Rules of a scene's ``randomization`` and ``success`` that the schema cannot state.

Every object they name (and ``reward``'s terms name) must be one of
``scene.options.objects`` (with the closest names when it is not), a range's low end must
not exceed its high end, and a region's lowest corner must lie below its highest on every
axis. A ``reward`` needs ``success``: the dense reward is 1 where success holds.
"""

from __future__ import annotations

from collections.abc import Iterator

from openral_core.errors import did_you_mean
from openral_core.models import DeployScene, ObjectInRegion, PlaceReward
from openral_core.yaml_source import PathKey

Finding = tuple[PathKey, str]


def episode_findings(scene: DeployScene) -> list[Finding]:
    """Every violation of the module doc's rules in ``scene``."""
    options = scene.scene.options
    names = [o.name for o in options.objects] if options is not None and options.objects else []
    return [*_randomization(scene, names), *_success(scene, names), *_reward(scene, names)]


def _known(path: PathKey, name: str, names: list[str]) -> Iterator[Finding]:
    if name not in names:
        known = ", ".join(names) or "none"
        yield (
            path,
            f"no object {name!r} in scene.options.objects ({known}){did_you_mean(name, names)}",
        )


def _randomization(scene: DeployScene, names: list[str]) -> Iterator[Finding]:
    ranges = scene.randomization
    if ranges is None:
        return
    for index, obj in enumerate(ranges.objects or []):
        at: PathKey = ("randomization", "objects", index)
        yield from _known((*at, "object"), obj.object, names)
        low, high = obj.position_min_m, obj.position_max_m
        if (
            low is not None
            and high is not None
            and any(a > b for a, b in zip(low, high, strict=True))
        ):
            yield (*at, "position_max_m"), "each value must be at least position_min_m's"
        if (obj.position_min_m is None) != (obj.position_max_m is None):
            yield at, "position_min_m and position_max_m go together"
        if obj.yaw_deg is not None and obj.yaw_deg[0] > obj.yaw_deg[1]:
            yield (*at, "yaw_deg"), f"low {obj.yaw_deg[0]} is above high {obj.yaw_deg[1]}"
    scale = ranges.light_intensity_scale
    if scale is not None and scale[0] > scale[1]:
        yield ("randomization", "light_intensity_scale"), f"low {scale[0]} is above high {scale[1]}"


def _success(scene: DeployScene, names: list[str]) -> Iterator[Finding]:
    for index, predicate in enumerate(scene.success or []):
        at: PathKey = ("success", index)
        yield from _known((*at, "object"), predicate.object, names)
        if isinstance(predicate, ObjectInRegion) and any(
            lo > hi for lo, hi in zip(predicate.min_m, predicate.max_m, strict=True)
        ):
            yield (*at, "max_m"), "each value must be at least min_m's"


def _reward(scene: DeployScene, names: list[str]) -> Iterator[Finding]:
    if scene.reward is None:
        return
    if not scene.success:
        yield ("reward",), "a reward needs success: the dense reward is 1 where success holds"
    for index, term in enumerate(scene.reward.dense):
        at: PathKey = ("reward", "dense", index)
        yield from _known((*at, "object"), term.object, names)
        if isinstance(term, PlaceReward) and any(
            lo > hi for lo, hi in zip(term.min_m, term.max_m, strict=True)
        ):
            yield (*at, "max_m"), "each value must be at least min_m's"
