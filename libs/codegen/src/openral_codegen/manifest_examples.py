"""Collect real values of every schema field from the repository's manifests and scene files.

The reference pages show, next to each field, a value some robot actually uses. This
module walks each document alongside its schema (following ``$ref`` across files and
choosing the ``oneOf`` branch the value matches) and records, per object section, every
value seen for each property and every instance of the section itself.
"""

from __future__ import annotations

import json
import re
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from openral_core.schemas import SchemaName
from openral_core.yaml_source import load_located

Schemas = dict[SchemaName, dict[str, Any]]
Section = tuple[SchemaName, str]
"""A schema file and the title of one object in it (the top-level title or a ``$defs`` key)."""

_PLAIN_NON_STRING = re.compile(
    r"[-+]?(\d[\d_]*)?\.?\d*([eE][-+]?\d+)?|0x[0-9a-fA-F]+|\.(inf|Inf|nan|NaN)"
    r"|true|True|TRUE|false|False|FALSE|yes|Yes|no|No|on|On|off|Off|null|Null|~"
)
PREFERRED_ROBOT = "franka_panda"
"""The project's default robot: its values come first when several robots use a field."""
DEFAULT_SCENE = "tabletop"
"""Every robot's default scene file stem; its values come before other scenes'."""
MAX_EXAMPLE_CHARS = 60


@dataclass(frozen=True)
class Sample:
    """One value found in one document."""

    source: str
    """Short label of the document: ``<robot>`` or ``<robot>/<scene stem>``."""
    value: Any


@dataclass
class ManifestExamples:
    """Every value seen per (section, property), and every instance seen per section."""

    fields: dict[Section, dict[str, list[Sample]]] = field(
        default_factory=lambda: defaultdict(lambda: defaultdict(list))
    )
    instances: dict[Section, list[Sample]] = field(default_factory=lambda: defaultdict(list))

    def example(self, section: Section, prop: str) -> Sample | None:
        """The value to show for ``prop``: the preferred robot's unless it is too long."""
        samples = self.fields.get(section, {}).get(prop, [])
        if not samples:
            return None
        return min(samples, key=lambda s: len(flow(s.value)) > MAX_EXAMPLE_CHARS)


def collect_examples(root: Path, schemas: Schemas) -> ManifestExamples:
    """Walk every ``robots/*/robot.yaml`` and ``robots/*/scenes/*.yaml`` under ``root``."""
    found = ManifestExamples()
    for folder in _robot_folders(root / "robots"):
        manifest = folder / "robot.yaml"
        if manifest.is_file():
            _walk_document(manifest, folder.name, SchemaName.ROBOT, schemas, found)
        scenes = sorted((folder / "scenes").glob("*.yaml"), key=_default_scene_first)
        for scene in scenes:
            _walk_document(scene, f"{folder.name}/{scene.stem}", SchemaName.SCENE, schemas, found)
    return found


def flow(value: Any) -> str:
    """A compact YAML flow rendering of a plain value (``[0.0, 0.04]``, ``{a: 1}``)."""
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {flow(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        return "[" + ", ".join(flow(v) for v in value) + "]"
    if isinstance(value, str):
        return json.dumps(value) if _needs_quotes(value) else value
    return json.dumps(value)


def _needs_quotes(text: str) -> bool:
    """Whether plain YAML would read ``text`` as something other than this string."""
    special = not text or text[0] in "[]{}&*!|>'\"%@`#,?:- " or ": " in text or " #" in text
    return special or _PLAIN_NON_STRING.fullmatch(text) is not None


def short_flow(value: Any, limit: int = MAX_EXAMPLE_CHARS) -> str:
    """:func:`flow`, cut after whole items with ``…`` once it would pass ``limit`` characters."""
    text = flow(value)
    if len(text) <= limit or not isinstance(value, dict | list):
        return text
    items = (
        [f"{k}: {flow(v)}" for k, v in value.items()]
        if isinstance(value, dict)
        else [flow(v) for v in value]
    )
    kept: list[str] = []
    for item in items:
        if len(", ".join([*kept, item])) > limit - 5 and kept:
            break
        kept.append(item)
    opening, closing = ("{", "}") if isinstance(value, dict) else ("[", "]")
    return opening + ", ".join([*kept, "…"]) + closing


def _default_scene_first(path: Path) -> tuple[bool, str]:
    return (path.stem != DEFAULT_SCENE, path.stem)


def _robot_folders(robots: Path) -> list[Path]:
    folders = sorted(p for p in robots.iterdir() if p.is_dir()) if robots.is_dir() else []
    return sorted(folders, key=lambda p: p.name != PREFERRED_ROBOT)


def _walk_document(
    file: Path, source: str, name: SchemaName, schemas: Schemas, found: ManifestExamples
) -> None:
    data = load_located(file).data
    _walk(data, schemas[name], name, schemas[name]["title"], source, schemas, found)


def _walk(
    value: Any,
    node: dict[str, Any],
    schema: SchemaName,
    section: str | None,
    source: str,
    schemas: Schemas,
    found: ManifestExamples,
) -> None:
    """Record ``value`` against ``node``; ``section`` names the node when it is one."""
    if "$ref" in node:
        target_schema, target_section, target = _resolve(str(node["$ref"]), schema, schemas)
        _walk(value, target, target_schema, target_section, source, schemas, found)
        return
    if "oneOf" in node:
        for option in node["oneOf"]:
            option_schema, option_section, target = _follow(option, schema, schemas)
            if _matches(value, target):
                _walk(value, target, option_schema, option_section, source, schemas, found)
                return
        return
    if isinstance(value, list) and isinstance(node.get("items"), dict):
        for item in value:
            _walk(item, node["items"], schema, None, source, schemas, found)
        return
    properties = node.get("properties")
    if not isinstance(value, dict) or not properties or section is None:
        return
    found.instances[schema, section].append(Sample(source, value))
    for key, item in value.items():
        if key in properties:
            found.fields[schema, section][key].append(Sample(source, item))
            _walk(item, properties[key], schema, None, source, schemas, found)


def _follow(
    node: dict[str, Any], schema: SchemaName, schemas: Schemas
) -> tuple[SchemaName, str | None, dict[str, Any]]:
    if "$ref" in node:
        return _resolve(str(node["$ref"]), schema, schemas)
    return schema, None, node


def _resolve(
    ref: str, schema: SchemaName, schemas: Schemas
) -> tuple[SchemaName, str, dict[str, Any]]:
    if ref.startswith("#/$defs/"):
        target = ref.removeprefix("#/$defs/")
        return schema, target, schemas[schema]["$defs"][target]
    other = SchemaName(ref.removesuffix(".schema.json"))
    return other, schemas[other]["title"], schemas[other]


def _matches(value: Any, node: dict[str, Any]) -> bool:
    """Whether ``value`` fits ``node`` by type and by its const/enum discriminators."""
    kind = node.get("type")
    if kind == "number":
        return isinstance(value, int | float) and not isinstance(value, bool)
    if kind != "object" or not isinstance(value, dict):
        return False
    properties = node.get("properties", {})
    if node.get("additionalProperties") is False and not set(value) <= set(properties):
        return False
    for key, spec in properties.items():
        if key not in value:
            continue
        if "const" in spec and value[key] != spec["const"]:
            return False
        if "enum" in spec and value[key] not in spec["enum"]:
            return False
    return True
