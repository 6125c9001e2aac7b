"""Render the JSON Schemas as Markdown reference pages for the docs site.

One page per schema file: the schema's description, one table per object (top level and
each ``$defs`` entry) listing every property with its type, constraints, default and
description, and the cross-field rules from ``$comment``.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from openral_core.schemas import SchemaName

Schemas = Mapping[SchemaName, dict[str, Any]]

HEADER = "<!-- GENERATED from schema/ by `just schema-export` -- do not edit. -->\n"

_CONSTRAINTS = (
    ("minimum", "≥ {}"),
    ("exclusiveMinimum", "> {}"),
    ("maximum", "≤ {}"),
    ("exclusiveMaximum", "< {}"),
    ("minLength", "length ≥ {}"),
    ("maxLength", "length ≤ {}"),
    ("minItems", "items ≥ {}"),
    ("maxItems", "items ≤ {}"),
    ("pattern", "matches `{}`"),
)


def page_name(name: SchemaName) -> str:
    """File name of the reference page of ``name`` (inside docs/reference/)."""
    return f"{name.value}.md"


def read_schemas(schema_dir: Path) -> dict[SchemaName, dict[str, Any]]:
    """Parse every schema file in ``schema_dir``."""
    return {n: json.loads((schema_dir / n.file_name).read_text("utf-8")) for n in SchemaName}


def render_schema_page(name: SchemaName, schemas: Schemas) -> str:
    """The Markdown reference page of schema ``name``."""
    schema = schemas[name]
    parts = [
        HEADER,
        f"# {schema['title']}\n",
        f"{schema['description']}\n",
        f"Source: `schema/{name.file_name}` (JSON Schema draft 2020-12, `$id` "
        f"`{schema['$id']}`).\n",
        _object_section(schema["title"], schema, schemas, with_description=False),
    ]
    for def_name, definition in schema.get("$defs", {}).items():
        if definition.get("type") == "object":
            parts.append(_object_section(def_name, definition, schemas))
        else:
            parts.append(_value_section(def_name, definition, schemas))
    if "$comment" in schema:
        parts.append("## Rules checked after the schema\n\n" + _rules(schema["$comment"]))
    return "\n".join(parts)


def property_names(schema: dict[str, Any]) -> set[str]:
    """Every property name declared anywhere in ``schema`` (for coverage tests)."""
    names: set[str] = set()

    def walk(node: Any) -> None:
        if isinstance(node, dict):
            names.update(node.get("properties", {}))
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for item in node:
                walk(item)

    walk(schema)
    return names


def _object_section(
    title: str, schema: dict[str, Any], schemas: Schemas, *, with_description: bool = True
) -> str:
    lines = [f"## {title}\n"]
    if with_description and schema.get("description"):
        lines.append(f"{schema['description']}\n")
    required = set(schema.get("required", []))
    lines.append("| Field | Type | Required | Default | Constraints | Description |")
    lines.append("|---|---|---|---|---|---|")
    for prop, spec in schema.get("properties", {}).items():
        default = f"`{json.dumps(spec['default'])}`" if "default" in spec else ""
        lines.append(
            "| "
            + " | ".join(
                [
                    f"`{prop}`",
                    _type_text(spec, schemas),
                    "yes" if prop in required else "no",
                    default,
                    _constraint_text(spec),
                    _cell(spec.get("description", "")),
                ]
            )
            + " |"
        )
    conditions = _conditions(schema)
    if conditions:
        lines.append("\n" + conditions)
    return "\n".join(lines) + "\n"


def _value_section(title: str, schema: dict[str, Any], schemas: Schemas) -> str:
    text = f"## {title}\n\n{schema.get('description', '')}\n\n"
    if "enum" in schema:
        text += "Allowed values: " + ", ".join(f"`{v}`" for v in schema["enum"]) + ".\n"
    if "oneOf" in schema:
        options = [_type_text(option, schemas) for option in schema["oneOf"]]
        text += "Exactly one of: " + ", ".join(options) + ".\n"
    return text


def _type_text(spec: dict[str, Any], schemas: Schemas) -> str:
    if "$ref" in spec:
        ref = str(spec["$ref"])
        if ref.startswith("#/$defs/"):
            target = ref.removeprefix("#/$defs/")
            return f"[{target}](#{target.lower()})"
        other = SchemaName(ref.removesuffix(".schema.json"))
        return f"[{schemas[other]['title']}]({page_name(other)})"
    if "const" in spec:
        return f"`{json.dumps(spec['const'])}`"
    if "enum" in spec:
        return " \\| ".join(f"`{v}`" for v in spec["enum"])
    if "oneOf" in spec:
        return " or ".join(_type_text(option, schemas) for option in spec["oneOf"])
    kind = spec.get("type", "any")
    if kind == "array":
        return f"list of {_type_text(spec.get('items', {}), schemas)}"
    if kind == "object" and isinstance(spec.get("additionalProperties"), dict):
        return f"map of name → {_type_text(spec['additionalProperties'], schemas)}"
    return str(kind)


def _constraint_text(spec: dict[str, Any]) -> str:
    found = [fmt.format(spec[key]) for key, fmt in _CONSTRAINTS if key in spec]
    items = spec.get("items")
    if isinstance(items, dict):
        found += [f"each {fmt.format(items[key])}" for key, fmt in _CONSTRAINTS if key in items]
    if spec.get("uniqueItems"):
        found.append("unique items")
    return _cell(", ".join(found))


def _conditions(schema: dict[str, Any]) -> str:
    blocks = [schema, *schema.get("allOf", [])]
    notes = []
    for block in blocks:
        condition = block.get("if", {}).get("properties", {})
        if not condition:
            continue
        ((key, test),) = condition.items()
        when = f"When `{key}` is `{test['const']}`"
        for branch, prefix in (("then", when), ("else", "Otherwise")):
            rule = block.get(branch)
            if rule:
                notes.append(f"- {prefix}: {_rule_text(rule)}.")
    return "Conditional rules:\n\n" + "\n".join(notes) + "\n" if notes else ""


def _rule_text(rule: dict[str, Any]) -> str:
    parts = []
    if "required" in rule:
        parts.append("requires " + ", ".join(f"`{k}`" for k in rule["required"]))
    forbidden = rule.get("not", {})
    keys = list(forbidden.get("required", []))
    for option in forbidden.get("anyOf", []):
        keys += option.get("required", [])
    if keys:
        parts.append("does not allow " + ", ".join(f"`{k}`" for k in keys))
    return "; ".join(parts)


def _rules(comment: str) -> str:
    head, _, rest = comment.partition(": (1)")
    if not rest:
        return comment + "\n"
    items = ("(1)" + rest).split("; (")
    lines = [f"{head}:\n"]
    for item in items:
        text = item if item.startswith("(") else "(" + item
        lines.append(f"- {text.rstrip('.')}.")
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def reference_index(schemas: Schemas) -> str:
    """The landing page of the reference section."""
    lines = [HEADER, "# Schema reference\n", "Generated from the JSON Schemas in `schema/`.\n"]
    for name in SchemaName:
        schema = schemas[name]
        lines.append(f"- [{schema['title']}]({page_name(name)}) — {schema['description']}")
    return "\n".join(lines) + "\n"
