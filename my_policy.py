"""A policy in one file: the first joint swings around the pose the robot holds."""

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WaveConfig:
    amplitude: float = 0.1  # rad
    period_s: float = 2.0


class Wave:
    config_type = WaveConfig  # its fields are the -p key=value parameters
    required_slots = ()  # VLA camera slots it needs frames for: none
    needs_privileged = False  # it never reads the simulation itself

    def __init__(self, config: WaveConfig) -> None:
        self.config = config

    def act(self, obs):
        names, hold = obs["action_spec"]  # one value per action slot, manifest units
        action = np.array(hold, dtype=np.float64)
        phase = 2 * math.pi * obs["time_s"] / self.config.period_s
        action[0] += self.config.amplitude * math.sin(phase)
        return action
