"""The policy-adapter seam of the rskill runner and its built-in policies.

A policy is anything with ``required_slots`` (the VLA camera slots it needs frames for)
and ``act(observation) -> action``. The runner only calls a policy once every required
slot has a fresh frame, and publishes the returned vector (one value per HAL action slot)
on ``/openral/safe_action``. Built-in policies are registered by name with a config
dataclass whose fields double as ``key=value`` parameters on the command line.

Example::

    policy = make_policy("wave", {"amplitude": "0.2", "action_slots": "panda_joint1"})
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any, NotRequired, Protocol, TypedDict

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
    privileged: NotRequired[Privileged]
    """The simulation itself, for a policy with ``needs_privileged`` (episodes only)."""


class PolicyAdapter(Protocol):
    """What the rskill runner needs from a policy."""

    @property
    def required_slots(self) -> tuple[str, ...]:
        """VLA camera slots that must have frames before ``act`` is called."""
        ...

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        """One action: a value per action slot of ``obs["action_spec"]``."""
        ...


class PolicyConfigError(OpenralError):
    """An unknown policy, parameter or parameter value."""


@dataclass(frozen=True)
class WaveConfig:
    """A scripted joint-space wave around the hold action."""

    amplitude: float = 0.1
    """Peak offset added to the hold value (action units: rad for joint positions); small
    enough to stay well inside every manifest's joint limits around a resting pose."""
    period_s: float = 4.0
    """Seconds per full oscillation; slow enough for a 10 Hz camera to show the motion."""
    action_slots: tuple[str, ...] = ()
    """Action slots that wave; empty means every slot."""
    required_slots: tuple[str, ...] = ("camera1", "camera2")
    """Camera slots the policy insists on (the pair a typical two-camera VLA consumes)."""

    def __post_init__(self) -> None:
        if self.period_s <= 0:
            raise PolicyConfigError(f"wave period_s must be > 0, got {self.period_s:g}")


class WavePolicy:
    """``hold + amplitude * sin(2π t / period)`` on the configured action slots.

    It does not look at image content, but refuses to act without frames for its
    ``required_slots``, so a camera-less graph fails as a real VLA would.
    """

    def __init__(self, config: WaveConfig) -> None:
        self.config = config

    @property
    def required_slots(self) -> tuple[str, ...]:
        """Camera slots named by the config."""
        return self.config.required_slots

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        """The hold action with the sine added on the waving slots."""
        missing = [slot for slot in self.required_slots if slot not in obs["images"]]
        if missing:
            raise ValueError(f"wave policy called without frames for {missing}")
        names, hold = obs["action_spec"]
        unknown = sorted(set(self.config.action_slots) - set(names))
        if unknown:
            raise PolicyConfigError(
                f"wave action_slots {', '.join(unknown)} are not action slots; the HAL's are: "
                f"{', '.join(names)}"
            )
        waving = self.config.action_slots or names
        mask = np.array([name in waving for name in names], dtype=np.float64)
        offset = self.config.amplitude * math.sin(
            2 * math.pi * obs["time_s"] / self.config.period_s
        )
        return np.asarray(hold, dtype=np.float64) + offset * mask


@dataclass(frozen=True)
class PolicyEntry:
    """A registered policy: its config dataclass and how to build it from one."""

    config_type: type[Any]
    build: Callable[[Any], PolicyAdapter]


POLICIES: dict[str, PolicyEntry] = {
    "wave": PolicyEntry(WaveConfig, WavePolicy),
}
"""Built-in policies by name (``scripted_lift`` is added by its module, below)."""
"""Built-in policies by name."""


ENTRY_POINT_GROUP = "openral.policies"
"""Installed packages register policies here: an entry point named after the policy that
loads a :class:`PolicyEntry`."""


def make_policy(name: str, params: Mapping[str, str] | None = None) -> PolicyAdapter:
    """Build policy ``name`` from string parameters (its config's fields): a built-in one,
    else one an installed package registers under :data:`ENTRY_POINT_GROUP`.

    Raises:
        PolicyConfigError: An unknown name (the message lists what there is), a registered
            entry point that does not load a PolicyEntry, or a bad parameter.
    """
    entry = POLICIES.get(name) or _registered(name)
    return entry.build(parse_config(entry.config_type, params or {}, name))


def _registered(name: str) -> PolicyEntry:
    """The PolicyEntry an installed package registers as ``name``."""
    from importlib.metadata import entry_points

    found = {point.name: point for point in entry_points(group=ENTRY_POINT_GROUP)}
    point = found.get(name)
    if point is None:
        names = ", ".join([*POLICIES, *sorted(found)])
        raise PolicyConfigError(f"unknown policy {name!r}; available: {names}")
    where = f"entry point {point.value!r} of {point.dist.name if point.dist else '?'}"
    try:
        entry = point.load()
    except Exception as error:  # a broken plug-in is its package's fault, said in one line
        raise PolicyConfigError(
            f"policy {name!r}: {where} does not load ({type(error).__name__}: {error})"
        ) from None
    if not isinstance(entry, PolicyEntry):
        raise PolicyConfigError(
            f"policy {name!r}: {where} is a {type(entry).__name__}, not a PolicyEntry"
        )
    return entry


def parse_params(items: Iterable[str]) -> dict[str, str]:
    """``["k=v", …]`` → ``{"k": "v", …}``."""
    params: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise PolicyConfigError(f"policy parameter {item!r} is not key=value")
        params[key.strip()] = value.strip()
    return params


def parse_config(config_type: type[Any], params: Mapping[str, str], policy: str) -> Any:
    """An instance of the dataclass ``config_type`` with string ``params`` converted by field.

    Each value is converted to the type of the field's default: float, int, str, or a
    comma-separated tuple of strings.
    """
    fields = {f.name: f for f in dataclasses.fields(config_type)}
    values: dict[str, object] = {}
    for key, text in params.items():
        field = fields.get(key)
        if field is None:
            raise PolicyConfigError(
                f"unknown parameter {key!r} for policy {policy!r}; valid: {', '.join(fields)}"
            )
        default: object = field.default
        try:
            values[key] = _convert(text, default)
        except ValueError as error:
            raise PolicyConfigError(
                f"{policy} parameter {key}={text!r}: expected {type(default).__name__}"
            ) from error
    return config_type(**values)


def _convert(text: str, like: object) -> object:
    """``text`` as the type of ``like``: float, int, str or a comma-separated str tuple."""
    if isinstance(like, tuple):
        return tuple(part.strip() for part in text.split(",") if part.strip())
    if isinstance(like, float):
        return float(text)
    if isinstance(like, int):
        return int(text)
    return text


def _register_builtins() -> None:
    """Policies defined in modules of their own (imported here, after the registry)."""
    from openral_eval.scripted_lift import LiftConfig, ScriptedLift

    POLICIES["scripted_lift"] = PolicyEntry(LiftConfig, ScriptedLift)


_register_builtins()
