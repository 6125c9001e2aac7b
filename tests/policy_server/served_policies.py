"""Policies a policy server serves in the tests: plain classes, no openral import (the
separate venv has none), each as ``file.py:Class`` also runnable in-process."""

import json
import os
import time
from pathlib import Path

import numpy as np


class Sway:
    """Each joint around its hold, by the observation's own time and joints."""

    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        _, hold = obs["action_spec"]
        phase = obs["time_s"] + 0.1 * float(np.sum(obs["observation.state"][:2]))
        return np.asarray(hold, dtype=np.float64) + 0.05 * np.sin(2.0 * phase)


class SwayLogged(Sway):
    """Sway that appends the keys it is shown, a line per action, to the file
    ``$OPENRAL_TEST_SWAY_LOG``."""

    def act(self, obs):
        with Path(os.environ["OPENRAL_TEST_SWAY_LOG"]).open("a", encoding="utf-8") as log:
            log.write(json.dumps(sorted(obs)) + "\n")
        return super().act(obs)


class Swirl(Sway):
    """Sway shifted by the task state (the cube's randomised pose): each seed moves the arm
    its own way."""

    needs_privileged = True

    def act(self, obs):
        shift = float(np.sum(obs["observation.environment_state"]))
        _, hold = obs["action_spec"]
        return super().act(obs) + 0.05 * np.sin(shift) * np.ones_like(hold)


class Counter:
    """Says how many policies its server made before it (a fresh one per connection)."""

    made = 0
    required_slots = ("camera1",)
    needs_privileged = True
    action_mode = "ee_delta_pose"

    def __init__(self):
        Counter.made += 1
        self.number = Counter.made

    def act(self, obs):
        return np.array(
            [float(self.number), obs["time_s"], float(obs["observation.images.camera1"].sum())]
        )


class Slow:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        time.sleep(2.0)
        return obs["action_spec"][1]


class Raises:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        raise RuntimeError("weights not found")


class WrongWidth:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        return np.zeros(3)


class NotANumber:
    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        return np.full(len(obs["action_spec"][0]), np.nan)


OPENED_BY = os.getpid()  # as a module-level np.load or open() would hold a handle


class OpenedHere:
    """Acts only in the process that executed this file (its files are its own)."""

    required_slots = ()
    needs_privileged = False

    def act(self, obs):
        if os.getpid() != OPENED_BY:
            raise RuntimeError("this file was executed before the fork: its files are shared")
        return obs["action_spec"][1]
