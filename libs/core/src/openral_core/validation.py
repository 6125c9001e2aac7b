"""JSON Schema validation of a located document, with messages a user can act on.

jsonschema reports *what* failed; this module says it in plain words (what was expected,
what was found) and points at the line and column of the offending key or value.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from jsonschema.exceptions import ValidationError

from openral_core.errors import Issue
from openral_core.schemas import SchemaName, validator
from openral_core.yaml_source import LocatedDocument, PathKey

_DISCRIMINATORS = ("kind", "type", "mode", "backend", "read_mode")
_JSON_TYPE_NAMES = {
    "object": "a mapping",
    "array": "a list",
    "string": "a string",
    "number": "a number",
    "integer": "an integer",
    "boolean": "true or false",
    "null": "null",
}


def schema_issues(document: LocatedDocument, name: SchemaName) -> list[Issue]:
    """Every violation of schema ``name`` in ``document``, sorted by position, deduplicated."""
    issues: dict[tuple[int, int, str, str], Issue] = {}
    for error in validator(name).iter_errors(document.data):
        for path, message in _explain(error):
            issue = document.issue(path, message)
            issues.setdefault((issue.line, issue.column, issue.field, issue.message), issue)
    return [issues[key] for key in sorted(issues)]


def describe_value(value: Any) -> str:
    """Short description of a YAML value for messages (type and a clipped repr)."""
    kind = {dict: "a mapping", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), "a number" if isinstance(value, int | float) else type(value).__name__
    )
    if value is None:
        return "null"
    text = repr(value)
    return kind if len(text) > 40 or isinstance(value, dict | list) else f"{kind} {text}"


def _explain(error: ValidationError) -> Iterable[tuple[PathKey, str]]:
    path: PathKey = tuple(error.absolute_path)
    instance: Any = error.instance
    value: Any = error.validator_value
    schema: Any = error.schema
    kind = error.validator
    because = _because(error)
    if kind == "additionalProperties" and isinstance(instance, dict):
        known = sorted(schema.get("properties", {}))
        for key in instance:
            if key not in known:
                expected = f"; expected one of: {', '.join(known)}" if known else ""
                yield (*path, key), f"unknown field {key!r}{expected}"
        return
    if kind == "required" and isinstance(instance, dict):
        for key in value:
            if key not in instance:
                yield path, f"missing required field {key!r}{because}"
        return
    if kind == "not" and isinstance(instance, dict):
        for key in _required_keys(value):
            if key in instance:
                yield (*path, key), f"field {key!r} is not allowed here{because}"
        return
    yield path, _message(error) + because


def _message(error: ValidationError) -> str:
    instance: Any = error.instance
    value: Any = error.validator_value
    kind = error.validator
    got = describe_value(instance)
    if kind == "type":
        names = [value] if isinstance(value, str) else list(value)
        return f"expected {' or '.join(_JSON_TYPE_NAMES.get(n, n) for n in names)}, got {got}"
    if kind == "enum":
        return f"expected one of {', '.join(map(str, value))}, got {got}"
    if kind == "const":
        return f"expected {value!r}, got {got}"
    if kind == "pattern":
        return f"{instance!r} does not match the required form {value}"
    bounds = {
        "minimum": ">=",
        "maximum": "<=",
        "exclusiveMinimum": ">",
        "exclusiveMaximum": "<",
    }
    if kind in bounds:
        return f"expected a value {bounds[str(kind)]} {value}, got {instance}"
    if kind in ("minItems", "maxItems"):
        word = "at least" if kind == "minItems" else "at most"
        return f"expected {word} {value} item(s), got {len(instance)}"
    if kind in ("minLength", "maxLength"):
        word = "at least" if kind == "minLength" else "at most"
        return f"expected text of {word} {value} character(s), got {len(instance)}"
    if kind == "uniqueItems":
        return "items must be unique"
    if kind in ("oneOf", "anyOf"):
        options = [_JSON_TYPE_NAMES.get(str(s.get("type")), "a value") for s in value]
        return f"expected {' or '.join(options)} matching the schema, got {got}"
    if kind == "propertyNames":
        return f"key {instance!r} is not a valid name"
    return str(error.message)


def _because(error: ValidationError) -> str:
    """Explain conditional requirements, e.g. ' (because kind is 'lidar')'."""
    schema_path = list(error.relative_schema_path)
    if not any(step in ("then", "else") for step in schema_path):
        return ""
    parent = error.parent.instance if error.parent is not None else None
    instance = parent if isinstance(parent, dict) else error.instance
    if not isinstance(instance, dict):
        return ""
    for key in _DISCRIMINATORS:
        if key in instance:
            return f" (because {key} is {instance[key]!r})"
    return ""


def _required_keys(schema: Any) -> list[str]:
    """Keys named by ``required`` anywhere inside a (``not``) subschema."""
    if isinstance(schema, dict):
        keys = list(schema.get("required", []))
        for sub in schema.get("anyOf", []) + schema.get("allOf", []):
            keys += _required_keys(sub)
        return keys
    return []
