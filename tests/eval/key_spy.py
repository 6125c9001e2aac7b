"""A policy that writes what it sees: each step's keys, each key's shape and dtype, and
its joint state, velocities and TCP, one JSON line per step into the file ``log`` (it may
run in a sweep's worker or in ``openral rskill run``'s process). It holds the robot still."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class SpyConfig:
    log: str = ""


class KeySpy:
    config_type = SpyConfig
    required_slots = ("camera1",)
    needs_privileged = False

    def __init__(self, config: SpyConfig) -> None:
        self.log = config.log

    def act(self, obs):
        seen = {
            key: [list(np.shape(value)), str(np.asarray(value).dtype)]
            for key, value in obs.items()
            if key.startswith("observation.")
        }
        vectors = ("observation.state", "observation.velocity", "observation.tcp_pose")
        line = {"keys": seen, **{k: np.asarray(obs[k]).tolist() for k in vectors if k in obs}}
        with Path(self.log).open("a", encoding="utf-8") as out:
            out.write(json.dumps(line) + "\n")
        return np.asarray(obs["action_spec"][1], dtype=np.float64)
