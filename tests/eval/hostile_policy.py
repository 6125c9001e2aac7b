"""Policies that break their episode, for ``--policy tests/eval/hostile_policy.py:X``: each
holds the arm for :data:`CALM_STEPS` steps, then one hangs in ``act``, one calls
``sys.exit``, one segfaults its process and one raises."""

from __future__ import annotations

import os
import signal
import sys
import threading

import numpy as np
import numpy.typing as npt
from openral_eval.policy import Observation

CALM_STEPS = 5
"""Steps each policy holds the arm before it breaks."""


class _Hostile:
    required_slots: tuple[str, ...] = ()
    needs_privileged = False

    def __init__(self) -> None:
        self.acted = 0

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        self.acted += 1
        if self.acted > CALM_STEPS:
            self.breaks()
        return np.asarray(obs["action_spec"][1], dtype=np.float64)

    def breaks(self) -> None:
        raise NotImplementedError


class Hangs(_Hostile):
    """Never returns from its ``act`` after the calm steps."""

    def breaks(self) -> None:
        threading.Event().wait()


class Exits(_Hostile):
    """Ends its process with exit status 3."""

    def breaks(self) -> None:
        sys.exit(3)


class Crashes(_Hostile):
    """Kills its process with SIGSEGV."""

    def breaks(self) -> None:
        os.kill(os.getpid(), signal.SIGSEGV)


class Raises(_Hostile):
    """Raises an error of its own."""

    def breaks(self) -> None:
        raise RuntimeError("the policy broke")
