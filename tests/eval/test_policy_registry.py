"""Policies registered by installed packages under the ``openral.policies`` entry points.

A fake distribution (a ``dist-info`` folder with an ``entry_points.txt`` on ``sys.path``)
registers a working policy, one whose module does not import, and one that is not a
PolicyEntry; each is found by name, or refused with one line naming the entry point.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from openral_eval.policies import PolicyConfigError, make_policy

PLUGIN = """
from dataclasses import dataclass
from openral_eval.policies import PolicyEntry, WaveConfig, WavePolicy

@dataclass(frozen=True)
class Config(WaveConfig):
    amplitude: float = 0.3

ENTRY = PolicyEntry(Config, WavePolicy)
NOT_AN_ENTRY = 42


class Undeclared:  # acts, but says nothing of what it needs
    def __init__(self, config):
        self.config = config

    def act(self, obs):
        return obs["action_spec"][1]


UNDECLARED = PolicyEntry(WaveConfig, Undeclared)
"""


@pytest.fixture
def plugin(tmp_path: Path) -> Iterator[None]:
    (tmp_path / "my_policies.py").write_text(PLUGIN)
    info = tmp_path / "my_policies-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: my-policies\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(
        "[openral.policies]\n"
        "big_wave = my_policies:ENTRY\n"
        "broken = my_missing_module:ENTRY\n"
        "not_entry = my_policies:NOT_AN_ENTRY\n"
        "undeclared = my_policies:UNDECLARED\n"
    )
    sys.path.insert(0, str(tmp_path))
    try:
        yield
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("my_policies", None)


def test_a_registered_policy_is_built_by_name(plugin: None) -> None:
    policy = make_policy("big_wave", {"period_s": "2.0"})
    assert policy.config.amplitude == 0.3 and policy.config.period_s == 2.0  # type: ignore[attr-defined]


def test_broken_registrations_are_one_line_each(plugin: None) -> None:
    with pytest.raises(PolicyConfigError) as missing:
        make_policy("broken")
    assert "entry point 'my_missing_module:ENTRY' of my-policies does not load" in str(
        missing.value
    )
    with pytest.raises(PolicyConfigError) as wrong:
        make_policy("not_entry")
    assert "is a int, not a PolicyEntry" in str(wrong.value)
    with pytest.raises(PolicyConfigError) as unknown:
        make_policy("dance")
    assert str(unknown.value).startswith("unknown policy 'dance'; available: wave, scripted_lift")
    assert "big_wave" in str(unknown.value)


def test_a_policy_that_does_not_declare_its_needs_is_refused(plugin: None) -> None:
    with pytest.raises(PolicyConfigError) as refused:
        make_policy("undeclared")
    assert str(refused.value).startswith(
        "policy 'undeclared' (Undeclared) lacks required_slots, needs_privileged;"
    )
