"""Policies that break their episode's process, for ``--policy tests/eval/hostile_policy.py:X``:
one hangs in ``act``, one calls ``sys.exit``, one segfaults its process."""

from __future__ import annotations

import os
import signal
import sys
import threading

import numpy as np
import numpy.typing as npt
from openral_eval.policy import Observation


class _Hostile:
    required_slots: tuple[str, ...] = ()
    needs_privileged = False


class Hangs(_Hostile):
    """Never returns from its first ``act``."""

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        threading.Event().wait()
        raise AssertionError("unreachable")


class Exits(_Hostile):
    """Ends its process with exit status 3 on its first ``act``."""

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        sys.exit(3)


class Crashes(_Hostile):
    """Kills its process with SIGSEGV on its first ``act``."""

    def act(self, obs: Observation) -> npt.NDArray[np.float64]:
        os.kill(os.getpid(), signal.SIGSEGV)
        raise AssertionError("unreachable")
