"""Drift guards: the JSON Schemas and the generated models accept exactly the same documents.

Documents are drawn from the schemas themselves (hypothesis-jsonschema), then mutated.
A document must be accepted or rejected by both jsonschema and the strict pydantic model;
never by only one of them.
"""

from __future__ import annotations

import copy
import json
from typing import Any

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from hypothesis_jsonschema import from_schema
from openral_core.models import DeployScene, RobotDescription, SimDescription
from openral_core.schemas import SchemaName, validator
from pydantic import BaseModel, ValidationError

from tests.properties.schema_bundle import bundled_schema

MODELS: dict[SchemaName, type[BaseModel]] = {
    SchemaName.ROBOT: RobotDescription,
    SchemaName.SIM: SimDescription,
    SchemaName.SCENE: DeployScene,
}
# Shrinking these large documents can take minutes; a failure is reported unshrunk
# (the document is printed in full), which is readable enough for schema documents.
SETTINGS = settings(
    max_examples=40,
    deadline=None,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.filter_too_much,
        HealthCheck.data_too_large,
    ],
)


def _schema_accepts(name: SchemaName, document: Any) -> bool:
    return bool(validator(name).is_valid(document))


def _model_accepts(name: SchemaName, document: Any) -> bool:
    try:
        MODELS[name].model_validate_json(json.dumps(document), strict=True)
    except ValidationError:
        return False
    return True


def _nodes(document: Any, path: tuple[Any, ...] = ()) -> list[tuple[tuple[Any, ...], Any]]:
    """Every (path, node) pair of a JSON document, the root included."""
    found = [(path, document)]
    if isinstance(document, dict):
        for key, value in document.items():
            found += _nodes(value, (*path, key))
    elif isinstance(document, list):
        for index, value in enumerate(document):
            found += _nodes(value, (*path, index))
    return found


def _replace(document: Any, path: tuple[Any, ...], value: Any) -> Any:
    if not path:
        return value
    result = copy.deepcopy(document)
    parent = result
    for step in path[:-1]:
        parent = parent[step]
    parent[path[-1]] = value
    return result


WRONG_TYPE_VALUES = st.sampled_from(["text", 3, 2.5, True, None, [], {}, 1e9, -1e9, 1.0])


@st.composite
def mutated(draw: st.DrawFn, name: SchemaName) -> tuple[str, Any]:
    """A schema-valid document with one random mutation applied."""
    document = draw(from_schema(bundled_schema(name)))
    nodes = _nodes(document)
    kind = draw(st.sampled_from(["extra_key", "wrong_type", "drop_key", "out_of_range"]))
    objects = [(p, n) for p, n in nodes if isinstance(n, dict)]
    if kind == "extra_key":
        path, node = draw(st.sampled_from(objects))
        # A string value is wrong for every map of the contract too (all map to numbers),
        # so the extra key is invalid whether the object is a model or a map.
        return kind, _replace(document, path, {**node, "zz_unknown_field": "x"})
    if kind == "drop_key":
        candidates = [(p, n) for p, n in objects if n]
        if not candidates:
            return kind, document
        path, node = draw(st.sampled_from(candidates))
        key = draw(st.sampled_from(sorted(node)))
        return kind, _replace(document, path, {k: v for k, v in node.items() if k != key})
    leaves = [(p, n) for p, n in nodes if p and not isinstance(n, dict | list)]
    if not leaves:
        return kind, document
    path, leaf = draw(st.sampled_from(leaves))
    if kind == "out_of_range" and isinstance(leaf, int | float) and not isinstance(leaf, bool):
        return kind, _replace(document, path, draw(st.sampled_from([1e7, -1e7, 10**7, -1])))
    return kind, _replace(document, path, draw(WRONG_TYPE_VALUES))


@pytest.mark.parametrize("name", list(SchemaName), ids=lambda n: n.value)
def test_documents_drawn_from_the_schema_are_accepted_by_the_model(name: SchemaName) -> None:
    @SETTINGS
    @given(from_schema(bundled_schema(name)))
    def check(document: Any) -> None:
        assert _schema_accepts(name, document)
        assert _model_accepts(name, document)

    check()


@pytest.mark.parametrize("name", list(SchemaName), ids=lambda n: n.value)
def test_mutated_documents_get_the_same_verdict_from_schema_and_model(name: SchemaName) -> None:
    @SETTINGS
    @given(mutated(name))
    def check(case: tuple[str, Any]) -> None:
        kind, document = case
        verdict = _schema_accepts(name, document)
        assert verdict == _model_accepts(name, document), (kind, document)
        if kind == "extra_key":
            assert not verdict

    check()
