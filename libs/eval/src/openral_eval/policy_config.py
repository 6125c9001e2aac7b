"""A policy's parameters: ``--param key=value`` items into the policy's own config type.

A policy class names its config in ``config_type``: a pydantic model or a dataclass, whose
fields (with defaults) are its parameters. pydantic validates either against the field types,
so a value is checked as the policy declared it, nested values included:

- a value is read as JSON when it is JSON (``gain=0.5``, ``offsets=[0.1, 0.2]``,
  ``target={"x": 0.4, "z": 0.2}``, ``verbose=true``); a field typed ``str`` always takes
  the text as it is (``name=123`` is the string ``"123"``);
- text that is not JSON stays text, and a tuple or list field takes comma-separated text
  as its items (``cameras=camera1,camera2``);
- a ``key`` may name a nested field with dots (``target.x=0.4``), merged into that field's
  default.

Every error is one line naming the policy, the parameter and what was expected.
"""

from __future__ import annotations

import dataclasses
import json
import typing
from collections.abc import Iterable, Mapping
from typing import Any

import pydantic

from openral_eval.policy import PolicyConfigError


def parse_params(items: Iterable[str]) -> dict[str, str]:
    """``["k=v", …]`` → ``{"k": "v", …}`` (a later value of the same key wins)."""
    params: dict[str, str] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise PolicyConfigError(f"policy parameter {item!r} is not key=value")
        params[key.strip()] = value.strip()
    return params


def is_config_type(config_type: object) -> bool:
    """Whether ``config_type`` can hold a policy's parameters (a dataclass or a pydantic
    model class)."""
    if not isinstance(config_type, type):
        return False
    return dataclasses.is_dataclass(config_type) or issubclass(config_type, pydantic.BaseModel)


def config_fields(config_type: type[Any]) -> dict[str, tuple[object, object]]:
    """Each parameter's (type annotation, default), in declaration order."""
    hints = typing.get_type_hints(config_type)
    if isinstance(config_type, type) and issubclass(config_type, pydantic.BaseModel):
        model_fields = config_type.model_fields
        return {name: (hints.get(name), f.get_default()) for name, f in model_fields.items()}
    defaults = {f.name: _dataclass_default(f) for f in dataclasses.fields(config_type)}
    return {name: (hints.get(name), default) for name, default in defaults.items()}


def parse_config(config_type: type[Any], params: Mapping[str, str], policy: str) -> Any:
    """An instance of ``config_type`` from text ``params`` (see the module doc).

    Raises:
        PolicyConfigError: An unknown parameter, or a value its field refuses (one line).
    """
    fields = config_fields(config_type)
    values: dict[str, Any] = {}
    for key, text in params.items():
        name, _, nested = key.partition(".")
        if name not in fields:
            valid = ", ".join(fields) or "none"
            raise PolicyConfigError(
                f"unknown parameter {name!r} for policy {policy!r}; valid: {valid}"
            )
        annotation, default = fields[name]
        if nested:
            base = values.get(name, _as_mapping(default))
            if not isinstance(base, dict):
                raise PolicyConfigError(f"{policy} parameter {key}: {name} holds no fields")
            values[name] = _merged(base, nested, _decoded(text, None), key, policy)
        else:
            values[name] = _decoded(text, annotation)
    try:
        return pydantic.TypeAdapter(config_type).validate_python(values)
    except pydantic.ValidationError as error:
        raise PolicyConfigError(_first_error(error, params, policy)) from None


def _decoded(text: str, annotation: object) -> object:
    """``text`` as JSON where it is JSON and its field is not a ``str``; comma-separated
    items for a sequence field given plain text; else the text."""
    if annotation is str:
        return text
    try:
        return json.loads(text)
    except ValueError:
        pass
    if typing.get_origin(annotation) in (tuple, list):
        return [part.strip() for part in text.split(",") if part.strip()]
    return text


def _as_mapping(default: object) -> dict[str, Any] | None:
    """A nested field's default as a dict to merge into (None: it holds no fields)."""
    if isinstance(default, pydantic.BaseModel):
        return default.model_dump()
    if dataclasses.is_dataclass(default) and not isinstance(default, type):
        return dataclasses.asdict(default)
    return dict(default) if isinstance(default, Mapping) else None


def _merged(
    base: dict[str, Any], path: str, value: object, key: str, policy: str
) -> dict[str, Any]:
    """``base`` with ``value`` at the dotted ``path``."""
    merged = dict(base)
    head, _, rest = path.partition(".")
    if rest:
        inner = merged.get(head, {})
        if not isinstance(inner, dict):
            raise PolicyConfigError(f"{policy} parameter {key}: {head} holds no fields")
        merged[head] = _merged(inner, rest, value, key, policy)
    else:
        merged[head] = value
    return merged


def _first_error(error: pydantic.ValidationError, params: Mapping[str, str], policy: str) -> str:
    """One line for pydantic's first complaint: the parameter, its text, what it expected."""
    first = error.errors()[0]
    where = ".".join(str(part) for part in first["loc"])
    top = where.partition(".")[0]
    given = params.get(where, params.get(top))
    shown = f"={given!r}" if given is not None else ""
    more = f" (and {error.error_count() - 1} more)" if error.error_count() > 1 else ""
    return f"{policy} parameter {where}{shown}: {first['msg']}{more}"


def _dataclass_default(field: dataclasses.Field[Any]) -> object:
    if field.default is not dataclasses.MISSING:
        return field.default
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return None
