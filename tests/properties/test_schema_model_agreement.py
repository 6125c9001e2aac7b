"""Drift guards: the JSON Schemas and the generated models accept exactly the same documents.

Documents are drawn from the schemas themselves (hypothesis-jsonschema), then mutated.
A document must be accepted or rejected alike by jsonschema, by the model in JSON mode
(how the loader calls it) and by the model in Python mode (``model_validate(dict)``, how a
user calls the class); never by only some of them.
"""

from __future__ import annotations

import copy
import json
from typing import Any

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st
from openral_core.models import DeployScene, RealDescription, RobotDescription, SimDescription
from openral_core.schemas import SchemaName, validator
from pydantic import BaseModel, ValidationError

from tests.properties.schema_strategy import documents

MODELS: dict[SchemaName, type[BaseModel]] = {
    SchemaName.ROBOT: RobotDescription,
    SchemaName.SIM: SimDescription,
    SchemaName.REAL: RealDescription,
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
    """The model's verdict; JSON mode and Python mode must give the same one."""
    verdicts = set()
    for validate in (
        lambda: MODELS[name].model_validate_json(json.dumps(document), strict=True),
        lambda: MODELS[name].model_validate(copy.deepcopy(document)),
    ):
        try:
            validate()
            verdicts.add(True)
        except ValidationError:
            verdicts.add(False)
    assert len(verdicts) == 1, f"JSON mode and Python mode disagree on {document!r}"
    return verdicts.pop()


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


WRONG_TYPE_VALUES = st.sampled_from(
    ["text", 3, 2.5, True, None, [], {}, 1e9, -1e9, 1.0, "2.5", "3"]
)


@st.composite
def mutated(draw: st.DrawFn, name: SchemaName) -> tuple[str, Any]:
    """A schema-valid document with one random mutation applied."""
    document = draw(documents(name))
    nodes = _nodes(document)
    kind = draw(st.sampled_from(["extra_key", "wrong_type", "drop_key", "out_of_range", "as_text"]))
    objects = [(p, n) for p, n in nodes if isinstance(n, dict)]
    if kind == "extra_key":
        path, node = draw(st.sampled_from(objects))
        # A null value is wrong for every map of the contract too (they map to numbers,
        # names or objects, never null), so the extra key is invalid whether the object is
        # a model or a map (a string was not, once maps of link and joint names came).
        return kind, _replace(document, path, {**node, "zz_unknown_field": None})
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
    if kind == "as_text":
        # A lax model would coerce "2.175" to a number and "true"/1 to a bool.
        return kind, _replace(document, path, json.dumps(leaf) if not isinstance(leaf, str) else 1)
    if kind == "out_of_range" and isinstance(leaf, int | float) and not isinstance(leaf, bool):
        return kind, _replace(document, path, draw(st.sampled_from([1e7, -1e7, 10**7, -1])))
    return kind, _replace(document, path, draw(WRONG_TYPE_VALUES))


@pytest.mark.parametrize("name", list(SchemaName), ids=lambda n: n.value)
def test_documents_drawn_from_the_schema_are_accepted_by_the_model(name: SchemaName) -> None:
    @SETTINGS
    @given(documents(name))
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


def _manifests() -> list[tuple[str, Any]]:
    from openral_core import robot_ids
    from openral_core.paths import robots_dir
    from ruamel.yaml import YAML

    yaml = YAML(typ="safe")
    return [(rid, yaml.load(robots_dir() / rid / "robot.yaml")) for rid in robot_ids()]


@pytest.mark.parametrize(("robot", "manifest"), _manifests(), ids=lambda v: str(v)[:20])
def test_every_number_and_flag_of_a_manifest_as_text_is_refused_alike(
    robot: str, manifest: Any
) -> None:
    """Each numeric or boolean leaf of a real manifest, written as text ("2.175", "true")
    or a number written as a bool, gets the schema's verdict from the model in both modes."""
    assert _model_accepts(SchemaName.ROBOT, manifest), robot
    leaves = [
        (path, leaf)
        for path, leaf in _nodes(manifest)
        if path and isinstance(leaf, bool | int | float)
    ]
    assert leaves, robot
    for path, leaf in leaves:
        for wrong in (json.dumps(leaf), not leaf if isinstance(leaf, bool) else True):
            document = _replace(manifest, path, wrong)
            verdict = _schema_accepts(SchemaName.ROBOT, document)
            assert verdict == _model_accepts(SchemaName.ROBOT, document), (robot, path, wrong)
            if not isinstance(leaf, bool) or wrong != (not leaf):
                assert not verdict, (robot, path, wrong)
