"""An episode renders each camera at the camera's own rate, only the cameras it reads.

The franka tabletop's cameras are 10 Hz sensors on a 20 Hz control loop: a policy that
observes both gets a frame of each every other step (the latest frame in between), and a
policy that observes none makes the scene render nothing.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import ClassVar

import numpy as np
import pytest
from openral_eval.episode import EpisodeSpec, close_scenes, run_episode
from openral_eval.policies import POLICIES, PolicyEntry
from openral_eval.policy import Observation
from openral_eval.wave import WaveConfig

from tests.conftest import ROBOTS

SCENE = str(ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml")


@pytest.fixture(autouse=True, scope="module")
def _scenes_closed() -> Iterator[None]:
    """This process's episode scenes are freed while EGL is still up."""
    yield
    close_scenes()


class FrameLog:
    """Turns the first joint a little further each step (so each new frame differs from
    the one before); keeps, per step, the frames it was given."""

    required_slots = ("camera1", "camera2")
    needs_privileged = False
    seen: ClassVar[list[tuple[np.ndarray, np.ndarray]]] = []

    def __init__(self, config: WaveConfig) -> None:
        FrameLog.seen = []

    def act(self, obs: Observation) -> np.ndarray:
        FrameLog.seen.append((obs["observation.images.camera1"], obs["observation.images.camera2"]))
        action = np.array(obs["action_spec"][1], dtype=np.float64)
        action[0] += 0.02 * len(FrameLog.seen)
        return action


def test_cameras_render_at_their_rate_and_only_when_read(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setitem(POLICIES, "frame_log", PolicyEntry(WaveConfig, FrameLog))
    watching = run_episode(EpisodeSpec(SCENE, 0, "frame_log", (), 20))
    assert watching.error is None and watching.steps == 20
    assert watching.frames == 2 + 10 * 2  # the reset's pair, then a pair every other step
    pairs = zip(FrameLog.seen, FrameLog.seen[1:], strict=False)
    fresh = [not np.array_equal(a[0], b[0]) and not np.array_equal(a[1], b[1]) for a, b in pairs]
    assert fresh == [step % 2 == 0 for step in range(1, 20)]  # a new frame at even steps
    blind = run_episode(EpisodeSpec(SCENE, 0, "wave", (("required_slots", ""),), 20))
    assert blind.error is None and blind.frames == 0
