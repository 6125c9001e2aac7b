"""How a native scene splits a control period for its state rate (scene option
``state_rate_hz``): the divisor of the period's physics steps nearest the asked rate, never
slower than the control rate; an explicit rate slower than it is refused at its field."""

from __future__ import annotations

from pathlib import Path

import pytest
from openral_core import load_scene
from openral_core.errors import ManifestError
from openral_sim.scene_checks import state_parts_per_control

from tests.conftest import ROBOTS

TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


def _scene(tmp_path: Path, options: str) -> object:
    text = TABLETOP.read_text().replace("    control_freq_hz: 20.0\n", options)
    file = tmp_path / "tabletop.yaml"
    file.write_text(text)
    return load_scene(file)


@pytest.mark.parametrize(
    ("options", "substeps", "parts"),
    [
        ("    control_freq_hz: 20.0\n", 25, 5),  # 100 Hz state over 20 Hz actions
        ("    control_freq_hz: 20.0\n    state_rate_hz: 500.0\n", 25, 25),
        ("    control_freq_hz: 20.0\n    state_rate_hz: 20.0\n", 25, 1),
        ("    control_freq_hz: 20.0\n    state_rate_hz: 75.0\n", 25, 5),  # 4 does not divide
        ("    control_freq_hz: 500.0\n", 1, 1),  # the default never slows it
    ],
)
def test_the_parts_divide_the_period_near_the_asked_rate(
    tmp_path: Path, options: str, substeps: int, parts: int
) -> None:
    scene = _scene(tmp_path, options)
    assert state_parts_per_control(scene, substeps, 0.002) == parts  # type: ignore[arg-type]


def test_an_explicit_rate_below_the_control_rate_is_refused_at_its_field(tmp_path: Path) -> None:
    scene = _scene(tmp_path, "    control_freq_hz: 50.0\n    state_rate_hz: 25.0\n")
    with pytest.raises(ManifestError, match=r"state_rate_hz: 25 Hz is slower than the control"):
        state_parts_per_control(scene, 10, 0.002)  # type: ignore[arg-type]
