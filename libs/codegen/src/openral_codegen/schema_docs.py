"""Render the JSON Schemas as Markdown reference pages for the docs site.

Each schema file gets a page (the gripper definitions of ``sim.schema.json`` get their own).
A page has one section per object, top level first, with a table giving every property's
type, whether it is required, its default, its allowed values, its description and a value
a real manifest uses; a YAML excerpt of a real instance follows the table. Rules that JSON
Schema cannot state come last, each with the error the validator prints when it is broken.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from openral_core.schemas import SchemaName

from openral_codegen.manifest_examples import (
    MAX_EXAMPLE_CHARS,
    ManifestExamples,
    flow,
    short_flow,
)
from openral_codegen.reference_text import (
    broken_text,
    cell,
    code,
    conditions_text,
    constraint_text,
    file_of,
    prose,
    yaml,
)
from openral_codegen.rule_examples import RuleExample, numbered_rules

Schemas = Mapping[SchemaName, dict[str, Any]]

HEADER = "<!-- GENERATED from schema/ by `just schema-export` -- do not edit. -->\n"
MAX_SNIPPET_LINES = 25


@dataclass(frozen=True)
class ReferencePage:
    """One reference page: a schema file, or the named ``$defs`` of one.

    Attributes:
        slug: File stem inside ``docs/reference/``.
        schema: The schema file the page documents.
        defs: The ``$defs`` on this page; None means the top level and every definition
            no other page claims.
        title: Page title; None means the schema's title.
        intro: Text under the title; None means the schema's description.
    """

    slug: str
    schema: SchemaName
    defs: tuple[str, ...] | None = None
    title: str | None = None
    intro: str | None = None


GRIPPER_INTRO = (
    "A gripper is one canonical joint of the robot (its driving finger or jaw) plus a "
    "`sim.grippers[]` entry that says how that joint is read from the model and written to "
    "its actuator. Readers and writers are chosen per gripper, so parallel fingers, tendon "
    "grippers and position-driven jaws share one HAL. The modes and the fields below are part "
    "of [SimDescription](sim.md); the last table shows what every robot in `robots/` uses."
)

PAGES = (
    ReferencePage("robot", SchemaName.ROBOT),
    ReferencePage("sim", SchemaName.SIM),
    ReferencePage(
        "grippers",
        SchemaName.SIM,
        defs=("SimGripperDescription", "GripperReadMode", "GripperWriteMode"),
        title="Grippers",
        intro=GRIPPER_INTRO,
    ),
    ReferencePage("real", SchemaName.REAL),
    ReferencePage("scene", SchemaName.SCENE),
)
"""Every reference page, in navigation order."""


def read_schemas(schema_dir: Path) -> dict[SchemaName, dict[str, Any]]:
    """Parse every schema file in ``schema_dir``."""
    return {n: json.loads((schema_dir / n.file_name).read_text("utf-8")) for n in SchemaName}


def render_reference(
    schemas: Schemas, examples: ManifestExamples, rules: list[RuleExample]
) -> dict[str, str]:
    """Every reference page and the index, keyed by file name inside docs/reference/."""
    renderer = _Renderer(schemas, examples, rules)
    pages = {f"{page.slug}.md": renderer.page(page) for page in PAGES}
    pages["index.md"] = renderer.index()
    return pages


class _Renderer:
    """Renders pages; knows which page holds each section, for cross-page links."""

    def __init__(
        self, schemas: Schemas, examples: ManifestExamples, rules: list[RuleExample]
    ) -> None:
        self.schemas = schemas
        self.examples = examples
        self.rules = rules
        self.home: dict[tuple[SchemaName, str], str] = {}
        for page in PAGES:
            for def_name in self._defs_of(page):
                self.home[page.schema, def_name] = page.slug
            if page.defs is None:
                self.home[page.schema, schemas[page.schema]["title"]] = page.slug

    def _defs_of(self, page: ReferencePage) -> list[str]:
        defs = list(self.schemas[page.schema].get("$defs", {}))
        if page.defs is not None:
            return [d for d in page.defs if d in defs]
        claimed = {d for p in PAGES if p.schema is page.schema and p.defs for d in p.defs}
        return [d for d in defs if d not in claimed]

    # -- pages -----------------------------------------------------------------------------

    def page(self, page: ReferencePage) -> str:
        schema = self.schemas[page.schema]
        source = f"schema/{page.schema.file_name}"
        parts = [
            HEADER,
            f"# {page.title or schema['title']}\n",
            f"{page.intro or prose(schema['description'])}\n",
            f'!!! note "Generated page"\n    Generated from `{source}` (JSON Schema draft '
            "2020-12) by `just schema-export`. To change it, edit the schema and regenerate.\n",
        ]
        if page.defs is None:
            parts.append(self._object_section(page, schema["title"], schema, top=True))
        for def_name in self._defs_of(page):
            definition = schema["$defs"][def_name]
            if definition.get("type") == "object":
                parts.append(self._object_section(page, def_name, definition))
            else:
                parts.append(self._value_section(page, def_name, definition))
        if page.slug == "grippers":
            parts.append(self._gripper_usage())
        if page.defs is None and "$comment" in schema:
            parts.append(self._rules_section(page.schema, schema["$comment"]))
        return "\n".join(parts)

    def index(self) -> str:
        lines = [
            HEADER,
            "# Schema reference\n",
            "Every field of every contract file, generated from the JSON Schemas in `schema/` "
            "(the single source of truth). Each field lists its type, whether it is required, "
            "its default, the values it allows, what it means and a value that a manifest in "
            "`robots/` really uses. Rules that a JSON Schema cannot express are listed at the "
            "end of each page, together with the exact error the validator prints.\n",
            "| Page | Documents |",
            "|---|---|",
        ]
        for page in PAGES:
            schema = self.schemas[page.schema]
            what = (
                f"`schema/{page.schema.file_name}`: {schema['description']}"
                if page.defs is None
                else f"part of `schema/{page.schema.file_name}`: "
                + ", ".join(f"`{d}`" for d in page.defs)
            )
            title = page.title or schema["title"]
            lines.append(f"| [{title}]({page.slug}.md) | {cell(prose(what))} |")
        return "\n".join(lines) + "\n"

    # -- sections --------------------------------------------------------------------------

    def _object_section(
        self, page: ReferencePage, title: str, schema: dict[str, Any], *, top: bool = False
    ) -> str:
        section = (page.schema, title)
        lines = [f"## {title}\n"]
        if not top and schema.get("description"):
            lines.append(f"{prose(schema['description'])}\n")
        required = set(schema.get("required", []))
        lines.append("| Field | Type and allowed values | Description | Example |")
        lines.append("|---|---|---|---|")
        for prop, spec in schema.get("properties", {}).items():
            if prop in required:
                presence = "**required**"
            elif "default" in spec:
                presence = f"default {code(flow(spec['default']))}"
            else:
                presence = "optional"
            allowed = self._allowed_text(page, spec)
            cells = [
                f"`{prop}`<br>{presence}",
                self._type_text(page, spec) + (f"<br>{allowed}" if allowed else ""),
                cell(prose(spec.get("description", ""))),
                self._example_cell(page, section, prop, spec),
            ]
            lines.append("| " + " | ".join(cells) + " |")
        conditions = conditions_text(schema)
        if conditions:
            lines.append("\n" + conditions)
        lines.append(self._snippet(section))
        return "\n".join(lines) + "\n"

    def _value_section(self, page: ReferencePage, title: str, schema: dict[str, Any]) -> str:
        text = f"## {title}\n\n{prose(schema.get('description', ''))}\n\n"
        if "enum" in schema:
            text += "Allowed values: " + ", ".join(f"`{v}`" for v in schema["enum"]) + ".\n"
        elif "oneOf" in schema:
            options = [self._type_text(page, option) for option in schema["oneOf"]]
            text += "Exactly one of: " + ", ".join(options) + ".\n"
        else:
            kind = schema.get("type", "any")
            found = constraint_text(schema)
            text += f"Type: {kind}" + (f", {found}" if found else "") + ".\n"
        return text

    def _rules_section(self, name: SchemaName, comment: str) -> str:
        head, numbered = numbered_rules(comment)
        lines = [
            "## Rules checked after the schema\n",
            f"{prose(head)}.\n" if numbered else f"{prose(comment)}\n",
        ]
        if name in (SchemaName.SIM, SchemaName.REAL):
            lines.append(
                "They are listed, each with the error it produces, under "
                "[RobotDescription: rules](robot.md#rules-checked-after-the-schema).\n"
            )
        examples = [e for e in self.rules if e.broken.schema is name]
        by_rule = {e.broken.rule: e for e in examples}
        if numbered:
            for number, text in numbered.items():
                lines.append(f"### Rule {number}: {prose(text)}\n")
                example = by_rule.get(number)
                lines.append(broken_text(example) if example else "No example yet.\n")
        else:
            for example in examples:
                lines.append(f"### {example.broken.rule}\n")
                lines.append(broken_text(example))
        return "\n".join(lines) + "\n"

    def _gripper_usage(self) -> str:
        section = (SchemaName.SIM, "SimGripperDescription")
        props = self.schemas[SchemaName.SIM]["$defs"]["SimGripperDescription"]["properties"]
        columns = ("joint", "read_mode", "write_mode", "ctrl_range", "qpos_addrs", "qpos_scale")
        lines = [
            "## Grippers in the manifests\n",
            "Every `sim.grippers[]` entry in `robots/`; a value in italics is the default.\n",
            "| Robot | " + " | ".join(f"`{c}`" for c in columns) + " |",
            "|---|" + "---|" * len(columns),
        ]
        for sample in sorted(self.examples.instances.get(section, []), key=lambda s: s.source):
            cells = []
            for column in columns:
                if column in sample.value:
                    cells.append(f"`{flow(sample.value[column])}`")
                else:
                    cells.append(f"*{flow(props[column].get('default', ''))}*")
            lines.append(
                f"| [{sample.source}](../robots/{sample.source}.md) | " + " | ".join(cells) + " |"
            )
        return "\n".join(lines) + "\n"

    # -- cells -----------------------------------------------------------------------------

    def _link(self, page: ReferencePage, schema: SchemaName, section: str) -> str:
        slug = self.home[schema, section]
        anchor = section.lower()
        target = f"#{anchor}" if slug == page.slug else f"{slug}.md#{anchor}"
        return f"[{section}]({target})"

    def _resolve(self, page: ReferencePage, ref: str) -> tuple[SchemaName, str, dict[str, Any]]:
        if ref.startswith("#/$defs/"):
            target = ref.removeprefix("#/$defs/")
            return page.schema, target, self.schemas[page.schema]["$defs"][target]
        other = SchemaName(ref.removesuffix(".schema.json"))
        return other, self.schemas[other]["title"], self.schemas[other]

    def _type_text(self, page: ReferencePage, spec: dict[str, Any]) -> str:
        if "$ref" in spec:
            schema, section, _ = self._resolve(page, str(spec["$ref"]))
            return self._link(page, schema, section)
        if "const" in spec:
            return f"`{json.dumps(spec['const'])}`"
        if "enum" in spec:
            return "string"
        if "oneOf" in spec:
            return " or ".join(self._type_text(page, option) for option in spec["oneOf"])
        kind = spec.get("type", "any")
        if kind == "array":
            return f"list of {self._type_text(page, spec.get('items', {}))}"
        if kind == "object" and isinstance(spec.get("additionalProperties"), dict):
            return f"map of name → {self._type_text(page, spec['additionalProperties'])}"
        return str(kind)

    def _allowed_text(self, page: ReferencePage, spec: dict[str, Any]) -> str:
        target = spec
        if "$ref" in spec:
            _, _, target = self._resolve(page, str(spec["$ref"]))
        if "enum" in target:
            return " \\| ".join(f"`{v}`" for v in target["enum"])
        if "const" in target:
            return f"only `{json.dumps(target['const'])}`"
        found = constraint_text(spec)
        values = spec.get("additionalProperties")
        if isinstance(values, dict):
            found = ", ".join(p for p in (found, constraint_text(values, "each value ")) if p)
        return found

    def _example_cell(
        self, page: ReferencePage, section: tuple[SchemaName, str], prop: str, spec: dict[str, Any]
    ) -> str:
        sample = self.examples.example(section, prop)
        if sample is None:
            if spec.get("examples"):
                return f"`{cell(short_flow(spec['examples'][0]))}` (schema example)"
            return "*not used by any manifest yet*"
        text = flow(sample.value)
        ref = spec.get("$ref") or spec.get("items", {}).get("$ref")
        if len(text) > MAX_EXAMPLE_CHARS and ref:
            schema, target, _ = self._resolve(page, str(ref))
            return f"see the {self._link(page, schema, target)} example"
        return f"`{cell(short_flow(sample.value))}` ({sample.source})"

    def _snippet(self, section: tuple[SchemaName, str]) -> str:
        instances = self.examples.instances.get(section, [])
        if not instances:
            return ""
        sample = instances[0]
        text = yaml(sample.value)
        if text.count("\n") > MAX_SNIPPET_LINES:
            robot = sample.source.split("/")[0]
            return (
                f"\nA complete example: `{file_of(sample)}`, shown on the "
                f"[{robot} page](../robots/{robot}.md).\n"
            )
        return f"\nExample from `{file_of(sample)}`:\n\n```yaml\n{text}```\n"
