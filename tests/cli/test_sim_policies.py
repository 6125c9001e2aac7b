"""``openral sim policies`` lists every policy buildable by name with its parameters and
their defaults, and a plug-in that does not load as its one-line reason."""

from __future__ import annotations

import os
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest
from openral_eval import policies

OPENRAL = Path(sys.executable).parent / "openral"


def test_the_command_lists_each_built_in_policy_with_its_defaults() -> None:
    env = {**os.environ, "COLUMNS": "250"}
    result = subprocess.run(
        [str(OPENRAL), "sim", "policies"], capture_output=True, text=True, env=env, timeout=60
    )
    assert result.returncode == 0, result.stderr
    rows = {line.split("│")[1].strip(): line for line in result.stdout.splitlines() if "│" in line}
    assert set(rows) == {"wave", "scripted_lift", "osc_lift"}
    assert "amplitude=0.1, period_s=4.0" in rows["wave"]
    assert "required_slots=camera1,camera2" in rows["wave"]
    assert "object=red_cube" in rows["scripted_lift"]
    assert result.stdout.strip().endswith("package.module:ClassName")


def test_a_plug_in_that_does_not_load_is_listed_with_its_reason(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    broken = metadata.EntryPoint("broken_vla", "no_such_package_xyz:ENTRY", "openral.policies")
    monkeypatch.setattr(metadata, "entry_points", lambda group: [broken])
    listings = {listing.name: listing for listing in policies.available_policies()}
    assert list(listings)[:3] == ["wave", "scripted_lift", "osc_lift"]
    assert listings["broken_vla"].parameters == ()
    assert "does not load (ModuleNotFoundError" in listings["broken_vla"].problem
