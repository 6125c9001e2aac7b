"""JSON Schema validation of a located document, with messages a user can act on.

jsonschema reports *what* failed; this module says it in plain words (what was expected,
what was found) and points at the line and column of the offending key or value.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from jsonschema.exceptions import ValidationError

from openral_core.errors import Issue, did_you_mean
from openral_core.schemas import SchemaName, validator
from openral_core.yaml_source import LocatedDocument, PathKey

_DISCRIMINATORS = ("kind", "type", "mode", "backend", "read_mode")
_DESCENDING = ("properties", "items", "prefixItems", "additionalProperties", "patternProperties")
"""Schema keywords whose sub-schemas apply one level down the instance."""
_VAGUE = "does not match any allowed form of this field"
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
    """Every violation of schema ``name`` in ``document``, sorted by position, deduplicated.

    A field with a precise message (such as a backend's conditional rule) does not also get
    the vague "does not match any allowed form" one.
    """
    issues: dict[tuple[int, int, str, str], Issue] = {}
    for error in validator(name).iter_errors(document.data):
        for path, message in _explain(error, _condition(error, document.data)):
            issue = document.issue(path, message)
            issues.setdefault((issue.line, issue.column, issue.field, issue.message), issue)
    precise = {key[:3] for key, issue in issues.items() if _VAGUE not in issue.message}
    return [
        issues[key]
        for key in sorted(issues)
        if not (_VAGUE in issues[key].message and key[:3] in precise)
    ]


def _condition(error: ValidationError, data: Any) -> str:
    """`` (because backend is 'native')`` for an error of an ``if``/``then`` rule whose object
    has a discriminator; empty otherwise."""
    schema_path = list(error.schema_path)
    if "then" not in schema_path:
        return ""
    rest = schema_path[len(schema_path) - schema_path[::-1].index("then") :]
    depth = sum(1 for step in rest if step in _DESCENDING)
    instance_path = list(error.absolute_path)
    owner: Any = data
    for step in instance_path[: len(instance_path) - depth]:
        owner = owner[step]
    key = next((k for k in _DISCRIMINATORS if isinstance(owner, dict) and k in owner), None)
    return f" (because {key} is {owner[key]!r})" if key else ""


def describe_value(value: Any) -> str:
    """Short description of a YAML value for messages (type and a clipped repr)."""
    kind = {dict: "a mapping", list: "a list", str: "a string", bool: "a boolean"}.get(
        type(value), "a number" if isinstance(value, int | float) else type(value).__name__
    )
    if value is None:
        return "null"
    text = repr(value)
    return kind if len(text) > 40 or isinstance(value, dict | list) else f"{kind} {text}"


def _explain(error: ValidationError, because: str = "") -> Iterable[tuple[PathKey, str]]:
    path: PathKey = tuple(error.absolute_path)
    instance: Any = error.instance
    value: Any = error.validator_value
    schema: Any = error.schema
    kind = error.validator
    if kind == "additionalProperties" and isinstance(instance, dict):
        known = sorted(schema.get("properties", {}))
        for key in instance:
            if key not in known:
                expected = f"; expected one of: {', '.join(known)}" if known else ""
                hint = did_you_mean(key, known)
                yield (*path, key), f"unknown field {key!r}{hint}{expected}{because}"
        return
    if kind == "required" and isinstance(instance, dict):
        for key in value:
            if key not in instance:
                yield path, f"missing required field {key!r}{because}"
        return
    if kind == "oneOf" and error.context:
        yield from _explain_variant(error)
        return
    yield path, _message(error) + because


def _explain_variant(error: ValidationError) -> Iterable[tuple[PathKey, str]]:
    """Explain a failed ``oneOf`` by the variant its discriminator (kind/type/mode) selects."""
    path: PathKey = tuple(error.absolute_path)
    instance: Any = error.instance
    branches: dict[int, list[ValidationError]] = {}
    for sub in error.context or []:
        branches.setdefault(int(sub.relative_schema_path[0]), []).append(sub)
    key = next((k for k in _DISCRIMINATORS if isinstance(instance, dict) and k in instance), None)
    selected = [
        errors
        for errors in branches.values()
        if not any(_rejects_discriminator(sub, error, key) for sub in errors)
    ]
    if len(selected) == 1:
        because = f" (because {key} is {instance[key]!r})" if key else ""
        for sub in selected[0]:
            yield from _explain(sub, because)
        return
    if key is not None and not selected:
        allowed = sorted(
            {str(v) for errors in branches.values() for sub in errors for v in _allowed(sub, key)}
        )
        yield (
            (*path, key),
            f"expected one of {', '.join(allowed)}, got {describe_value(instance[key])}",
        )
        return
    yield path, _message(error)


def _rejects_discriminator(sub: ValidationError, parent: ValidationError, key: str | None) -> bool:
    """True when ``sub`` says its variant does not apply (wrong type or wrong discriminator)."""
    relative = list(sub.absolute_path)[len(parent.absolute_path) :]
    if sub.validator == "type" and not relative:
        return True
    return key is not None and relative == [key] and sub.validator in ("const", "enum")


def _allowed(sub: ValidationError, key: str) -> list[Any]:
    relative = list(sub.absolute_path)[-1:]
    if relative != [key]:
        return []
    value: Any = sub.validator_value
    return [value] if sub.validator == "const" else list(value) if sub.validator == "enum" else []


_BOUNDS = {"minimum": ">=", "exclusiveMinimum": ">", "maximum": "<=", "exclusiveMaximum": "<"}


def _range(schema: Any) -> str:
    """Every bound ``schema`` sets on a number, e.g. ``>= 1 and <= 2000``."""
    return " and ".join(f"{op} {schema[key]}" for key, op in _BOUNDS.items() if key in schema)


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
    if kind in _BOUNDS:
        return f"expected a value {_range(error.schema)}, got {instance}"
    if kind in ("minItems", "maxItems"):
        word = "at least" if kind == "minItems" else "at most"
        return f"expected {word} {value} item(s), got {len(instance)}"
    if kind in ("minLength", "maxLength"):
        word = "at least" if kind == "minLength" else "at most"
        return f"expected text of {word} {value} character(s), got {len(instance)}"
    if kind == "uniqueItems":
        return "items must be unique"
    if kind in ("oneOf", "anyOf"):
        return f"{got} {_VAGUE}"
    if kind == "propertyNames":
        return f"key {instance!r} is not a valid name"
    return str(error.message)
