"""Mutations of a parsed document: valid YAML whose content is wrong.

Each mutator takes the document tree (dicts, lists, scalars; already a private copy it may
change in place), a seeded :class:`random.Random` and the key vocabulary (every property
name of the schemas) and returns the new tree.
"""

from __future__ import annotations

import copy
import math
import random
from collections.abc import Callable, Sequence
from typing import Any

from openral_core.paths import repo_root

NodePath = tuple[str | int, ...]
TreeMutator = Callable[[Any, random.Random, Sequence[str]], Any]

BOUNDARY_NUMBERS: tuple[Any, ...] = (
    0,
    -1,
    1,
    0.0,
    -0.0,
    1e-8,
    -1e-8,
    5e-324,
    1e308,
    -1e308,
    2**31,
    2**63,
    2**64 + 1,
    10**50,
    10**99,
    1e20,
    3.5,
    math.inf,
    -math.inf,
    math.nan,
    "NaN",
    "inf",
    "1e3",
    "0x10",
)
"""Zero, signs, tiny, huge, non-finite and numbers written as strings."""
HOSTILE_STRINGS = (
    "",
    " ",
    "..",
    "../../etc/passwd",
    "/etc/passwd",
    "x" * 5000,
    "jöint",
    "joint\x00",
    "名前",
    "${HOME}",
    "%s%n",
    "<mujoco/>",
    "robot.yaml",
    "world",
    "-",
    "1",
    "true",
    "null",
    "a b",
    "line\nbreak",
)
"""Empty, path-like, huge, non-ASCII, control, format-string and keyword strings."""
_REPO = repo_root()
FIELD_VALUES: dict[str, tuple[Any, ...]] = {
    "mjcf_uri": (
        "file:../../etc/passwd",
        "file:/etc/passwd",
        "file:/dev/zero",
        "file:/dev/stdin",
        "file:/proc/self/environ",
        "file:robot.yaml",
        "file:README.md",
        "file:.",
        "file:mjcf",
        "file:mjcf/../../rizon4/mjcf/rizon4.xml",
        f"file:{_REPO}/robots/rizon4/mjcf/rizon4.xml",
        "file:",
        "pkg:mujoco/../../../etc/passwd",
        "pkg:openral/robot.yaml",
        "pkg:robosuite/robosuite/models/assets/arenas/table_arena.xml",
        "robosuite:robots/panda/robot.xml",
        "robosuite:../../../../etc/passwd",
        "pkg:gym-aloha/../../../etc/passwd",
        "pkg:gym-aloha/gym_aloha/assets/bimanual_viperx_transfer_cube.xml",
        "pkg:openarm-mujoco/../../x",
        "gym_aloha:bimanual_viperx_transfer_cube",  # a removed scheme
        "robot_descriptions:os",
        "http://example.invalid/robot.xml",
    ),
    "floating_base": (True, False, "yes", 1, None),
    "base": ("fixed", "floating", "mobile", "", None),
    "robot_id": ("franka_panda", "rizon4", "g1", "nobody", "../franka_panda", "", None),
    "backend": ("native", "robosuite", "gazebo", ""),
    "assets": ("tabletop", "Lift", "Stack", "", "../../etc/passwd", "PickPlace"),
    "cameras": ([], ["agentview", "agentview"], ["nowhere"], ["wrist"], "agentview"),
    "mount_body": ("world", "", "link0", "no_such_body", "torso"),
    "kind": ("rgb", "depth", "lidar", "imu", ""),
    "read_mode": ("passthrough", "normalized", "bogus"),
    "write_mode": ("passthrough", "normalized", "bogus"),
    "shape": ("box", "sphere", "cylinder", "mesh", "torus"),
    "type": ("revolute", "prismatic", "continuous", "free", "ball"),
    "keyframe_index": (0, 1, 99, -1, None),
    "seed": (0, -1, 2**32, 2**64, 10**99),
}
"""Values to try for fields whose meaning the fuzzer knows, by key name."""


def _paths(tree: Any, path: NodePath = ()) -> list[NodePath]:
    """Every node's path below the root, depth first."""
    found: list[NodePath] = []
    items: list[tuple[str | int, Any]] = []
    if isinstance(tree, dict):
        items = list(tree.items())
    elif isinstance(tree, list):
        items = list(enumerate(tree))
    for key, child in items:
        found.append((*path, key))
        found.extend(_paths(child, (*path, key)))
    return found


def _get(tree: Any, path: NodePath) -> Any:
    for key in path:
        tree = tree[key]
    return tree


def _set(tree: Any, path: NodePath, value: Any) -> Any:
    if not path:
        return value
    _get(tree, path[:-1])[path[-1]] = value
    return tree


def _pick(tree: Any, rng: random.Random, keep: Callable[[Any], bool]) -> NodePath | None:
    paths = [p for p in _paths(tree) if keep(_get(tree, p))]
    return rng.choice(paths) if paths else None


def _containers(tree: Any, kind: type) -> list[NodePath]:
    roots: list[NodePath] = [()] if isinstance(tree, kind) else []
    return roots + [p for p in _paths(tree) if isinstance(_get(tree, p), kind)]


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def drop_key(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Delete one key anywhere (a required field goes missing)."""
    path = _pick(tree, rng, lambda _: True)
    if path is None or not isinstance(path[-1], str):
        return tree
    del _get(tree, path[:-1])[path[-1]]
    return tree


def add_key(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Add a schema key (or an unknown one) to a mapping, with a random value."""
    mappings = _containers(tree, dict)
    if not mappings:
        return tree
    key = rng.choice([*vocabulary, "fuzz_unknown", "Name", "name "])
    value = rng.choice([*BOUNDARY_NUMBERS, *HOSTILE_STRINGS, *FIELD_VALUES.get(key, ()), {}, []])
    _get(tree, rng.choice(mappings))[key] = value
    return tree


def rename_key(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Rename one key: a typo, a case change or another schema key."""
    path = _pick(tree, rng, lambda _: True)
    if path is None or not isinstance(path[-1], str):
        return tree
    old = path[-1]
    new = rng.choice([old.upper(), old + "s", old[:-1], f"{old} ", rng.choice(vocabulary)])
    parent = _get(tree, path[:-1])
    renamed = {(new if k == old else k): v for k, v in parent.items()}
    return _set(tree, path[:-1], renamed)


def swap_type(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Replace one node by a value of another type."""
    path = _pick(tree, rng, lambda _: True)
    if path is None:
        return tree
    choices: list[Any] = [None, True, 1, 1.5, "text", [], {}, [1, 2, 3], {"x": 1}, "1.0"]
    return _set(tree, path, rng.choice(choices))


def boundary_number(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Replace one number by a boundary or absurd value."""
    path = _pick(tree, rng, _is_number)
    if path is None:
        return tree
    return _set(tree, path, rng.choice(BOUNDARY_NUMBERS))


def scale_number(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Multiply one number by a large or tiny factor or flip its sign."""
    path = _pick(tree, rng, _is_number)
    if path is None:
        return tree
    value = _get(tree, path)
    factor = rng.choice((-1, 1e-6, 1e6, 1e12, 1000))
    scaled = value * factor
    return _set(tree, path, int(scaled) if isinstance(value, int) else float(scaled))


def perturb_number(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Nudge one number to a plausible wrong value (x0.5, x1.1, x2, +1, -1, ...).

    Unlike :func:`boundary_number` the result usually passes the schema, so the case reaches
    robot check, the model and the scene.
    """
    path = _pick(tree, rng, _is_number)
    if path is None:
        return tree
    value = _get(tree, path)
    if isinstance(value, int):
        return _set(tree, path, value + rng.choice((-2, -1, 1, 2, 7)))
    return _set(tree, path, float(value) * rng.choice((0.0, 0.5, 0.9, 1.1, 2.0, 10.0, -1.0)))


def swap_strings(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Exchange two strings of the document (two joint, camera or body names, ...)."""
    paths = [p for p in _paths(tree) if isinstance(_get(tree, p), str)]
    if len(paths) < 2:
        return tree
    a, b = rng.sample(paths, 2)
    first, second = _get(tree, a), _get(tree, b)
    _set(tree, a, second)
    return _set(tree, b, first)


def duplicate_item(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Repeat one list item (two joints, cameras or objects with the same name)."""
    lists = [p for p in _containers(tree, list) if _get(tree, p)]
    if not lists:
        return tree
    items = _get(tree, rng.choice(lists))
    item = rng.choice(items)
    shared = rng.random() < 0.2  # the same object twice: the dump writes an anchor and alias
    items.insert(rng.randrange(len(items) + 1), item if shared else copy.deepcopy(item))
    return tree


def drop_item(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Remove one list item, empty a list, or reverse it."""
    lists = [p for p in _containers(tree, list) if _get(tree, p)]
    if not lists:
        return tree
    items = _get(tree, rng.choice(lists))
    choice = rng.randrange(3)
    if choice == 0:
        del items[rng.randrange(len(items))]
    elif choice == 1:
        items.clear()
    else:
        items.reverse()
    return tree


def change_reference(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Replace one string by another string of the document or a hostile one."""
    path = _pick(tree, rng, lambda v: isinstance(v, str))
    if path is None:
        return tree
    others = [_get(tree, p) for p in _paths(tree) if isinstance(_get(tree, p), str)]
    return _set(tree, path, rng.choice([*others, *others, *HOSTILE_STRINGS]))


def known_field(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Set a field the fuzzer knows (mjcf_uri, floating_base, robot_id, cameras, ...)."""
    paths = [p for p in _paths(tree) if isinstance(p[-1], str) and p[-1] in FIELD_VALUES]
    if paths and rng.random() < 0.8:
        path = rng.choice(paths)
        return _set(tree, path, copy.deepcopy(rng.choice(FIELD_VALUES[str(path[-1])])))
    mappings = _containers(tree, dict)
    if mappings:
        key = rng.choice(sorted(FIELD_VALUES))
        _get(tree, rng.choice(mappings))[key] = copy.deepcopy(rng.choice(FIELD_VALUES[key]))
    return tree


def toggle_bool(tree: Any, rng: random.Random, vocabulary: Sequence[str]) -> Any:
    """Flip one boolean, or set ``sim.floating_base`` when the document has a sim block."""
    path = _pick(tree, rng, lambda v: isinstance(v, bool))
    sim = tree.get("sim") if isinstance(tree, dict) else None
    if isinstance(sim, dict) and (path is None or rng.random() < 0.5):
        sim["floating_base"] = not sim.get("floating_base", False)
        return tree
    if path is None:
        return tree
    return _set(tree, path, not _get(tree, path))


TREE_MUTATORS: dict[str, TreeMutator] = {
    "drop_key": drop_key,
    "add_key": add_key,
    "rename_key": rename_key,
    "swap_type": swap_type,
    "boundary_number": boundary_number,
    "scale_number": scale_number,
    "perturb_number": perturb_number,
    "swap_strings": swap_strings,
    "duplicate_item": duplicate_item,
    "drop_item": drop_item,
    "change_reference": change_reference,
    "known_field": known_field,
    "toggle_bool": toggle_bool,
}
"""Every tree mutator by name (the name is what a case records)."""
