"""How schema values become Markdown text on the reference pages: types, constraints,
conditions, YAML snippets, diffs of rule breaks, and cells a table can hold."""

from __future__ import annotations

import html
from io import StringIO
from typing import Any

from ruamel.yaml import YAML

from openral_codegen.manifest_examples import Sample
from openral_codegen.rule_examples import RuleExample

CONSTRAINTS = (
    ("minimum", "≥ {}"),
    ("exclusiveMinimum", "> {}"),
    ("maximum", "≤ {}"),
    ("exclusiveMaximum", "< {}"),
    ("minLength", "length ≥ {}"),
    ("maxLength", "length ≤ {}"),
    ("minItems", "items ≥ {}"),
    ("maxItems", "items ≤ {}"),
)


def file_of(sample: Sample) -> str:
    robot, _, scene = sample.source.partition("/")
    return f"robots/{robot}/scenes/{scene}.yaml" if scene else f"robots/{robot}/robot.yaml"


def broken_text(example: RuleExample) -> str:
    broken = example.broken
    return (
        f"Checked in `{broken.checked_in}`. Break it with this edit of `{broken.file}`:\n\n"
        f"```diff\n{diff(broken.old, broken.new)}```\n\nand the validator reports:\n\n"
        f"```text\n{example.error}\n```\n"
    )


def diff(old: str, new: str) -> str:
    """A unified-diff body for replacing ``old`` with ``new`` (context kept on insertions)."""
    old_lines, new_lines = old.rstrip("\n").split("\n"), new.rstrip("\n").split("\n")
    if new_lines[: len(old_lines)] == old_lines:
        body = [f" {line}" for line in old_lines]
        body += [f"+{line}" for line in new_lines[len(old_lines) :]]
    else:
        body = [f"-{line}" for line in old_lines] + [f"+{line}" for line in new_lines]
    return "\n".join(body) + "\n"


def yaml(value: Any) -> str:
    """Block YAML with innermost lists and maps in flow style (as manifests are written)."""
    yaml = YAML(typ="safe", pure=True)
    yaml.default_flow_style = None
    yaml.width = 4096  # never fold a long value (an mjcf_uri) onto its own line
    yaml.indent(mapping=2, sequence=4, offset=2)
    yaml.representer.sort_base_mapping_type_on_output = False
    stream = StringIO()
    yaml.dump(value, stream)
    return stream.getvalue()


def constraint_text(spec: dict[str, Any], prefix: str = "") -> str:
    found = [prefix + fmt.format(spec[key]) for key, fmt in CONSTRAINTS if key in spec]
    if "pattern" in spec:
        found.append(f"{prefix}matches {code(spec['pattern'])}")
    items = spec.get("items")
    if isinstance(items, dict):
        found += [f"each {fmt.format(items[key])}" for key, fmt in CONSTRAINTS if key in items]
        if "pattern" in items:
            found.append(f"each matches {code(items['pattern'])}")
        if "enum" in items:
            found.append("each one of " + ", ".join(f"`{v}`" for v in items["enum"]))
    if spec.get("uniqueItems"):
        found.append("unique items")
    names = spec.get("propertyNames")
    if isinstance(names, dict) and "pattern" in names:
        found.append(f"names match {code(names['pattern'])}")
    return cell(", ".join(found))


def conditions_text(schema: dict[str, Any]) -> str:
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
                notes.append(f"- {prefix}: {rule_text(rule)}.")
    return "Conditional rules:\n\n" + "\n".join(notes) + "\n" if notes else ""


def rule_text(rule: dict[str, Any]) -> str:
    parts = []
    if "required" in rule:
        parts.append("requires " + ", ".join(f"`{k}`" for k in rule["required"]))
    forbidden = rule.get("not", {})
    keys = list(forbidden.get("required", []))
    for option in forbidden.get("anyOf", []):
        keys += option.get("required", [])
    if keys:
        parts.append("does not allow " + ", ".join(f"`{k}`" for k in keys))
    for key, spec in rule.get("properties", {}).items():
        ref = str(spec.get("$ref", ""))
        if ref.startswith("#/$defs/"):
            name = ref.removeprefix("#/$defs/")
            parts.append(f"`{key}` must be a [{name}](#{name.lower()})")
    return "; ".join(parts)


def prose(text: str) -> str:
    """Schema text as Markdown: ``<`` and ``>`` outside backticks are shown, not taken as HTML."""
    parts = text.split("`")
    for index in range(0, len(parts), 2):  # even parts lie outside code spans
        parts[index] = html.escape(parts[index], quote=False)
    return "`".join(parts)


def code(text: str) -> str:
    """Inline code that survives a table cell (a ``|`` inside backticks would show its ``\\``;
    inside ``<code>`` a ``[...](...)`` would still read as a link, so brackets are escaped)."""
    if "|" not in text:
        return f"`{text}`"
    escaped = html.escape(text).replace("|", "&#124;").replace("[", "&#91;").replace("]", "&#93;")
    return "<code>" + escaped + "</code>"


def cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")
