"""Documents drawn from a bundled schema, with hypothesis-jsonschema's per-draw work cached.

hypothesis-jsonschema 0.23 builds the strategy of an object's property again every time
a document draws that property: it resolves references, canonicalises and merges the
property's subschemas on each draw. With our schemas that is about 1.5 s per drawn
document, almost all of it spent rebuilding the same strategies. Strategies are
immutable, so this module caches them by (canonical schema, alphabet, formats): the
documents drawn, and their distribution, are exactly those of the uncached library.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any

import hypothesis_jsonschema._from_schema as library
from hypothesis import strategies as st
from hypothesis_jsonschema import from_schema
from hypothesis_jsonschema._encode import encode_canonical_json
from openral_core.schemas import SchemaName

from tests.properties.schema_bundle import bundled_schema

Build = Callable[..., st.SearchStrategy[Any]]


def _cached(build: Build) -> Build:
    """``build`` memoised on its schema argument's canonical JSON and its keywords' ids."""
    memo: dict[tuple[str, int, int], st.SearchStrategy[Any]] = {}

    def cached(schema: Any, *, alphabet: Any, custom_formats: Any) -> st.SearchStrategy[Any]:
        key = (encode_canonical_json(schema), id(alphabet), id(custom_formats))
        if key not in memo:
            memo[key] = build(schema, alphabet=alphabet, custom_formats=custom_formats)
        return memo[key]

    cached.__wrapped__ = build  # type: ignore[attr-defined]
    return cached


def _install() -> None:
    """Cache the library's two strategy builders (once per process)."""
    for name in ("__from_schema", "merged_as_strategies"):
        build = getattr(library, name)
        if not hasattr(build, "__wrapped__"):
            setattr(library, name, _cached(build))


@cache
def documents(name: SchemaName) -> st.SearchStrategy[Any]:
    """Every document schema ``name`` accepts, as hypothesis-jsonschema draws them (one
    strategy per schema and process, so that its cached parts are found again)."""
    _install()
    return from_schema(bundled_schema(name))
