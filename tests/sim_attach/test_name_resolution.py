"""Properties of resolve_joint_names: exact names win, prefixes are stripped only safely."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from openral_hal.errors import HalError
from openral_mujoco.name_resolution import resolve_joint_names, strip_robot_prefix

BASES = ("joint1", "joint2", "shoulder", "elbow", "wrist", "finger_joint1")
PREFIXES = ("", "robot0_", "robot1_", "robot12_", "gripper0_right_", "gripper0_left_", "gripper1_")

model_joints = st.lists(
    st.builds(lambda p, b: p + b, st.sampled_from(PREFIXES), st.sampled_from(BASES)),
    unique=True,
    max_size=12,
)


def _resolve_one(name: str, available: list[str]) -> str | None:
    try:
        return resolve_joint_names([name], available)[name]
    except HalError:
        return None


@given(model_joints, st.data())
def test_an_exact_name_always_resolves_to_itself(available: list[str], data: st.DataObject) -> None:
    if not available:
        return
    wanted = data.draw(st.lists(st.sampled_from(available), unique=True, min_size=1))
    assert resolve_joint_names(wanted, available) == {name: name for name in wanted}


@given(model_joints, st.sampled_from(BASES))
def test_a_stripped_name_is_used_only_when_unambiguous(available: list[str], base: str) -> None:
    carriers = [n for n in available if n != base and strip_robot_prefix(n) == base]
    resolved = _resolve_one(base, available)
    if base in available:
        assert resolved == base  # the exact name shadows every prefixed one
    elif len(carriers) == 1:
        assert resolved == carriers[0]
    else:
        assert resolved is None  # absent, or shared by several robots


@given(st.lists(st.sampled_from(BASES), unique=True, min_size=1))
def test_bimanual_prefixes_never_cross_resolve(bases: list[str]) -> None:
    available = [f"robot{k}_{b}" for b in bases for k in (0, 1)]
    with pytest.raises(HalError) as error:
        resolve_joint_names(bases, available)
    assert all(b in str(error.value) for b in bases)  # every missing joint is listed
    explicit = [f"robot1_{b}" for b in bases]
    assert resolve_joint_names(explicit, available) == {n: n for n in explicit}


@given(st.lists(st.sampled_from(BASES), unique=True, min_size=1))
def test_one_prefixed_robot_resolves_by_stripped_name(bases: list[str]) -> None:
    available = [f"robot0_{b}" for b in bases]
    assert resolve_joint_names(bases, available) == {b: f"robot0_{b}" for b in bases}


def test_the_error_lists_a_few_available_names() -> None:
    available = [f"robot0_j{i}" for i in range(20)]
    with pytest.raises(HalError) as error:
        resolve_joint_names(["shoulder", "elbow"], available)
    message = str(error.value)
    assert "shoulder" in message and "elbow" in message
    assert "robot0_j0" in message and "robot0_j19" not in message and "12 more" in message


@pytest.mark.parametrize(
    ("name", "stripped"),
    [
        ("robot0_joint1", "joint1"),
        ("gripper0_right_finger_joint1", "finger_joint1"),
        ("gripper1_finger_joint2", "finger_joint2"),
        ("robotic_joint", "robotic_joint"),  # no digits: not a robosuite prefix
        ("joint_robot0_x", "joint_robot0_x"),  # only a leading prefix counts
    ],
)
def test_robosuite_prefixes(name: str, stripped: str) -> None:
    assert strip_robot_prefix(name) == stripped
