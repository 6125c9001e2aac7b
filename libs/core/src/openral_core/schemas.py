"""The JSON Schemas of the contract, loaded once and ready to validate with.

Schemas live in ``schema/`` at the repository root; this module wires their cross-file
``$ref`` s into one registry and builds draft 2020-12 validators. JSON Schema's
``integer`` normally admits ``1.0``; here it does not, so the schema and the generated
pydantic models (validated strictly) agree on every document.
"""

from __future__ import annotations

import json
from enum import StrEnum
from functools import cache
from typing import Any

import jsonschema
from jsonschema.protocols import Validator
from referencing import Registry, Resource

from openral_core.paths import schema_dir


class SchemaName(StrEnum):
    """The top-level schemas, named by file stem."""

    ROBOT = "robot"
    SIM = "sim"
    REAL = "real"
    SCENE = "scene"

    @property
    def file_name(self) -> str:
        """File name inside ``schema/``."""
        return f"{self.value}.schema.json"


def _is_strict_integer(_checker: Any, instance: object) -> bool:
    return isinstance(instance, int) and not isinstance(instance, bool)


_TYPE_CHECKER = jsonschema.Draft202012Validator.TYPE_CHECKER.redefine("integer", _is_strict_integer)
_StrictValidator = jsonschema.validators.extend(  # type: ignore[no-untyped-call]
    jsonschema.Draft202012Validator, type_checker=_TYPE_CHECKER
)


@cache
def load_schema(name: SchemaName) -> dict[str, Any]:
    """The parsed JSON Schema document ``name``."""
    document: dict[str, Any] = json.loads((schema_dir() / name.file_name).read_text("utf-8"))
    return document


@cache
def _registry() -> Registry[Any]:
    resources = []
    for name in SchemaName:
        resource = Resource.from_contents(load_schema(name))
        resources.append((name.file_name, resource))
        resources.append((load_schema(name)["$id"], resource))
    return Registry().with_resources(resources)


def validator(name: SchemaName) -> Validator:
    """A draft 2020-12 validator for schema ``name`` with cross-file refs resolved."""
    validator_class: Any = _StrictValidator
    result: Validator = validator_class(load_schema(name), registry=_registry())
    return result
