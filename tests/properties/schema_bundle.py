"""A schema with every cross-file ``$ref`` inlined, for hypothesis-jsonschema.

hypothesis-jsonschema cannot follow references between files; the property tests draw
documents from these bundles instead of from :func:`openral_core.schemas.load_schema`.
"""

from __future__ import annotations

import json
from typing import Any

from openral_core.schemas import SchemaName, load_schema


def bundled_schema(name: SchemaName) -> dict[str, Any]:
    """Schema ``name`` with every cross-file ``$ref`` inlined into its own ``$defs``.

    Tools that cannot follow references between files (hypothesis-jsonschema) use this.
    """
    root: dict[str, Any] = json.loads(json.dumps(load_schema(name)))
    defs: dict[str, Any] = root.setdefault("$defs", {})

    def inline(node: Any) -> Any:
        if isinstance(node, dict):
            ref = node.get("$ref")
            if isinstance(ref, str) and not ref.startswith("#"):
                other = SchemaName(ref.removesuffix(".schema.json"))
                _adopt(other)
                rest = {k: inline(v) for k, v in node.items() if k != "$ref"}
                return {"$ref": f"#/$defs/{other.value}", **rest}
            return {key: inline(value) for key, value in node.items()}
        if isinstance(node, list):
            return [inline(item) for item in node]
        return node

    def _adopt(other: SchemaName) -> None:
        if other.value in defs:
            return
        copy = json.loads(json.dumps(load_schema(other)))
        prefix = f"{other.value}__"
        for def_name, definition in copy.pop("$defs", {}).items():
            defs[prefix + def_name] = _rename_refs(definition, prefix)
        for key in ("$schema", "$id", "$comment"):
            copy.pop(key, None)
        defs[other.value] = _rename_refs(copy, prefix)

    for key in list(root):
        if key != "$defs":
            root[key] = inline(root[key])
    for def_name in list(defs):
        defs[def_name] = inline(defs[def_name])
    return root


def _rename_refs(node: Any, prefix: str) -> Any:
    if isinstance(node, dict):
        renamed = {key: _rename_refs(value, prefix) for key, value in node.items()}
        ref = renamed.get("$ref")
        if isinstance(ref, str) and ref.startswith("#/$defs/"):
            renamed["$ref"] = "#/$defs/" + prefix + ref.removeprefix("#/$defs/")
        return renamed
    if isinstance(node, list):
        return [_rename_refs(item, prefix) for item in node]
    return node
