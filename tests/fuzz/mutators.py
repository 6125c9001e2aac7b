"""All mutators by name, how a case draws them, and how they are applied to a seed.

A mutation is recorded as ``(name, subseed)``: the mutator and the seed of the
:class:`random.Random` it runs with, so the same list always gives the same bytes. Tree
mutations run first, on the parsed seed (always clean YAML), and the tree is written back
once; text mutations then run on those bytes. So no mutator ever parses hostile text.
"""

from __future__ import annotations

import copy
import io
import json
import random
from collections.abc import Sequence
from functools import cache
from typing import Any

from openral_core.paths import repo_root
from ruamel.yaml import YAML
from ruamel.yaml.scalarbool import ScalarBoolean

from tests.fuzz.text_mutators import TEXT_MUTATORS
from tests.fuzz.tree_mutators import TREE_MUTATORS

Mutation = tuple[str, int]
"""A mutator's name and the seed of its random generator."""

MUTATOR_NAMES: tuple[str, ...] = (*sorted(TREE_MUTATORS), *sorted(TEXT_MUTATORS))
"""Every mutator, tree ones first; a case draws from these."""
TREE_SHARE = 0.65
"""Share of drawn mutations that work on the tree (they reach the stages after load)."""


@cache
def vocabulary() -> tuple[str, ...]:
    """Every property name in the robot and scene schemas, sorted."""
    names: set[str] = set()
    for schema in ("robot", "scene"):
        text = (repo_root() / "schema" / f"{schema}.schema.json").read_text(encoding="utf-8")
        _collect_properties(json.loads(text), names)
    return tuple(sorted(names))


def _collect_properties(node: object, names: set[str]) -> None:
    if isinstance(node, dict):
        properties = node.get("properties")
        if isinstance(properties, dict):
            names.update(str(key) for key in properties)
        for child in node.values():
            _collect_properties(child, names)
    elif isinstance(node, list):
        for child in node:
            _collect_properties(child, names)


def draw_mutations(rng: random.Random) -> tuple[Mutation, ...]:
    """One to three mutations, more often tree ones than text ones."""
    count = rng.choices((1, 2, 3), weights=(5, 3, 2))[0]
    drawn: list[Mutation] = []
    for _ in range(count):
        pool = TREE_MUTATORS if rng.random() < TREE_SHARE else TEXT_MUTATORS
        drawn.append((rng.choice(sorted(pool)), rng.randrange(2**32)))
    return tuple(drawn)


def apply_mutations(seed: bytes, mutations: Sequence[Mutation], donors: Sequence[bytes]) -> bytes:
    """The bytes of ``seed`` after ``mutations`` (tree ones first, then text ones, in order).

    Raises:
        KeyError: An unknown mutator name.
    """
    tree_ops = [m for m in mutations if m[0] in TREE_MUTATORS]
    text_ops = [m for m in mutations if m[0] not in TREE_MUTATORS]
    data = seed
    if tree_ops:
        tree = copy.deepcopy(_parsed(seed))
        for name, subseed in tree_ops:
            tree = TREE_MUTATORS[name](tree, random.Random(subseed), vocabulary())
        data = _dump(tree, flow=random.Random(tree_ops[0][1]).random() < 0.2)
    for name, subseed in text_ops:
        data = TEXT_MUTATORS[name](data, random.Random(subseed), donors)
    return data


@cache
def _parsed(seed: bytes) -> Any:
    """The round-trip tree of a seed (parsed once; each case mutates a deep copy)."""
    return YAML(typ="rt").load(seed.decode("utf-8"))


def _dump(tree: Any, *, flow: bool) -> bytes:
    """Write ``tree`` back: round-trip (the seed's comments and layout kept), or sometimes
    as plain data in flow style (``{a: [1, 2]}``, keys sorted)."""
    yaml = YAML(typ="rt")
    if flow:
        yaml = YAML(typ="safe", pure=True)
        yaml.default_flow_style = True
        tree = _plain(tree)
    yaml.allow_unicode = True
    stream = io.StringIO()
    yaml.dump(tree, stream)
    return stream.getvalue().encode("utf-8")


def _plain(node: Any) -> Any:
    """``node`` with ruamel's round-trip types turned into plain Python ones."""
    if isinstance(node, dict):
        return {str(key): _plain(value) for key, value in node.items()}
    if isinstance(node, list):
        return [_plain(item) for item in node]
    if isinstance(node, bool | ScalarBoolean):
        return bool(node)
    for kind in (int, float, str):
        if isinstance(node, kind):
            return kind(node)
    return node
