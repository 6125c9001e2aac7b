"""``wave``: a scripted joint-space sine around the hold action (a stand-in for a VLA)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from openral_eval.observation_keys import image_key
from openral_eval.policy import Observation, PolicyConfigError, action_spec_of, time_of


@dataclass(frozen=True)
class WaveConfig:
    """A scripted joint-space wave around the hold action."""

    amplitude: float = 0.1
    """Peak offset added to the hold value (action units: rad for joint positions); small
    enough to stay well inside every manifest's joint limits around a resting pose."""
    period_s: float = 4.0
    """Seconds per full oscillation; slow enough for a 10 Hz camera to show the motion."""
    action_slots: tuple[str, ...] = ()
    """Action slots that wave; empty means every slot."""
    required_slots: tuple[str, ...] = ("camera1", "camera2")
    """Camera slots the policy insists on (the pair a typical two-camera VLA consumes)."""

    def __post_init__(self) -> None:
        if self.period_s <= 0:
            raise PolicyConfigError(f"wave period_s must be > 0, got {self.period_s:g}")


class WavePolicy:
    """``hold + amplitude * sin(2π t / period)`` on the configured action slots.

    It does not look at image content, but refuses to act without frames for its
    ``required_slots``, so a camera-less graph fails as a real VLA would.
    """

    config_type = WaveConfig
    """Its parameters (``--param key=value``)."""

    needs_privileged = False
    """It reads only the action spec and the clock."""

    def __init__(self, config: WaveConfig) -> None:
        self.config = config

    @property
    def required_slots(self) -> tuple[str, ...]:
        """Camera slots named by the config."""
        return self.config.required_slots

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        """The hold action with the sine added on the waving slots."""
        missing = [slot for slot in self.required_slots if image_key(slot) not in obs]
        if missing:
            raise ValueError(f"wave policy called without frames for {missing}")
        names, hold = action_spec_of(obs)
        unknown = sorted(set(self.config.action_slots) - set(names))
        if unknown:
            raise PolicyConfigError(
                f"wave action_slots {', '.join(unknown)} are not action slots; the HAL's are: "
                f"{', '.join(names)}"
            )
        waving = self.config.action_slots or names
        mask = np.array([name in waving for name in names], dtype=np.float64)
        offset = self.config.amplitude * math.sin(2 * math.pi * time_of(obs) / self.config.period_s)
        return np.asarray(hold, dtype=np.float64) + offset * mask
