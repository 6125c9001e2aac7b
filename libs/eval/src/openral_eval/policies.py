"""The built-in policies by name, and the ones installed packages register.

Built-in policies are registered by name with a config type (a dataclass or a pydantic
model) whose fields double as ``key=value`` parameters on the command line
(:mod:`openral_eval.policy_config`).

Example::

    policy = make_policy("wave", {"amplitude": "0.2", "action_slots": "panda_joint1"})
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

from openral_eval.osc_lift import OscLift
from openral_eval.policy import Observation, PolicyAdapter, PolicyConfigError
from openral_eval.policy_config import config_fields, parse_config, parse_params
from openral_eval.policy_source import build, is_reference, load_class
from openral_eval.remote_policy import RemoteConfig, RemotePolicy, is_address
from openral_eval.scripted_lift import ScriptedLift
from openral_eval.wave import WaveConfig, WavePolicy

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

__all__ = [
    "ENTRY_POINT_GROUP",
    "POLICIES",
    "Observation",
    "PolicyAdapter",
    "PolicyConfigError",
    "PolicyEntry",
    "PolicyListing",
    "WaveConfig",
    "WavePolicy",
    "available_policies",
    "make_policy",
    "parse_params",
]


@dataclass(frozen=True)
class PolicyEntry:
    """A registered policy: its config type and how to build it from one."""

    config_type: type[Any]
    build: Callable[[Any], PolicyAdapter]


POLICIES: dict[str, PolicyEntry] = {
    name: PolicyEntry(cls.config_type, cls)
    for name, cls in (("wave", WavePolicy), ("scripted_lift", ScriptedLift), ("osc_lift", OscLift))
}
"""Built-in policies by name (each class declares its config, as a class named by
``file.py:Class`` does)."""


ENTRY_POINT_GROUP = "openral.policies"
"""Installed packages register policies here: an entry point named after the policy that
loads a :class:`PolicyEntry`."""


def make_policy(name: str, params: Mapping[str, str] | None = None) -> PolicyAdapter:
    """Build policy ``name`` from string parameters (its config's fields): a policy server's
    address (``ws://HOST:PORT``, :mod:`openral_eval.remote_policy`), a built-in one, a class
    named by ``file.py:Class`` or ``package.module:Class``
    (:mod:`openral_eval.policy_source`), else one an installed package registers under
    :data:`ENTRY_POINT_GROUP`.

    Raises:
        PolicyConfigError: An unknown name (the message lists what there is), a registered
            entry point that does not load a PolicyEntry, a bad parameter, or a policy that
            does not declare what it needs (``required_slots``, ``needs_privileged``).
    """
    if is_address(name):  # a policy server (openral_eval.remote_policy)
        return RemotePolicy(name, parse_config(RemoteConfig, params or {}, name))
    entry = POLICIES.get(name) or (_referenced(name) if is_reference(name) else _registered(name))
    policy: object = entry.build(parse_config(entry.config_type, params or {}, name))
    if not isinstance(policy, PolicyAdapter):
        wanted = ("required_slots", "needs_privileged", "act")
        lacking = [attribute for attribute in wanted if not hasattr(policy, attribute)]
        raise PolicyConfigError(
            f"policy {name!r} ({type(policy).__name__}) lacks {', '.join(lacking)}; a policy "
            "declares the camera slots and the privileged state it needs"
        )
    return policy


def _referenced(reference: str) -> PolicyEntry:
    """The entry of a class named by ``file.py:Class`` or ``module:Class``."""
    cls, config_type = load_class(reference)
    return PolicyEntry(config_type, partial(build, cls))


def _registered(name: str) -> PolicyEntry:
    """The PolicyEntry an installed package registers as ``name``."""
    from importlib.metadata import entry_points

    found = {point.name: point for point in entry_points(group=ENTRY_POINT_GROUP)}
    point = found.get(name)
    if point is None:
        names = ", ".join([*POLICIES, *sorted(found)])
        raise PolicyConfigError(f"unknown policy {name!r}; available: {names}")
    return _load(point)


def _load(point: EntryPoint) -> PolicyEntry:
    """The PolicyEntry entry point ``point`` loads (a plug-in's failure in one line)."""
    where = f"entry point {point.value!r} of {point.dist.name if point.dist else '?'}"
    try:
        entry = point.load()
    except Exception as error:  # a broken plug-in is its package's fault, said in one line
        raise PolicyConfigError(
            f"policy {point.name!r}: {where} does not load ({type(error).__name__}: {error})"
        ) from None
    if not isinstance(entry, PolicyEntry):
        raise PolicyConfigError(
            f"policy {point.name!r}: {where} is a {type(entry).__name__}, not a PolicyEntry"
        )
    return entry


@dataclass(frozen=True)
class PolicyListing:
    """One policy that can be built by name: where it comes from and its parameters."""

    name: str
    source: str
    """``built-in``, or the distribution and entry point that registers it."""
    parameters: tuple[tuple[str, str], ...]
    """(name, default as typed on the command line) of each ``-p`` parameter."""
    problem: str = ""
    """Why a registered policy cannot be built (its entry point does not load), else ''."""


def available_policies() -> list[PolicyListing]:
    """Every policy buildable by name: the built-in ones, then those installed packages
    register under :data:`ENTRY_POINT_GROUP`, by name."""
    from importlib.metadata import entry_points

    listings = [PolicyListing(name, "built-in", _defaults(e)) for name, e in POLICIES.items()]
    for point in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda p: p.name):
        source = f"{point.dist.name if point.dist else '?'} ({point.value})"
        try:
            listings.append(PolicyListing(point.name, source, _defaults(_load(point))))
        except PolicyConfigError as error:
            listings.append(PolicyListing(point.name, source, (), str(error)))
    return listings


def _defaults(entry: PolicyEntry) -> tuple[tuple[str, str], ...]:
    """Each config field and its default, written as ``-p`` would take it."""

    def text(value: object) -> str:
        if isinstance(value, tuple | list) and all(isinstance(v, str) for v in value):
            return ",".join(value)
        if isinstance(value, str):
            return value
        return _json_text(value)

    fields = config_fields(entry.config_type)
    return tuple((name, text(default)) for name, (_, default) in fields.items())


def _json_text(value: object) -> str:
    """A default as JSON (how ``-p`` reads it back); its ``repr`` when JSON cannot hold it."""
    import pydantic

    try:
        return pydantic.TypeAdapter(type(value)).dump_json(value).decode()
    except (pydantic.PydanticSchemaGenerationError, ValueError):
        return repr(value)
