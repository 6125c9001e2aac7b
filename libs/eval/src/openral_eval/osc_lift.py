"""``osc_lift``: a scripted lift for an operational-space controller (robosuite's Lift).

It reads the task state a robosuite scene reports (:attr:`Observation.task_state
<openral_sim.observation.Observation.task_state>`): the object's position
(``<object>_pos``) and the end effector's (``robot0_eef_pos``). Its action is the one
robosuite's default Panda controller takes: a position delta (three values in [-1, 1],
scaled by the controller), a rotation delta (left at zero) and the gripper (-1 open,
+1 closed, the last value). The phases are those of ``scripted_lift``: ``approach`` above
the object, ``descend`` onto it, ``close`` for ``close_s``, ``lift`` ``lift_m`` above where
it started. It uses no randomness and no wall clock.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from openral_mujoco.state import FloatArray

from openral_eval.policy import (
    Observation,
    PolicyConfigError,
    action_spec_of,
    task_state_of,
    time_of,
)

PHASES = ("approach", "descend", "close", "lift")


@dataclass(frozen=True)
class OscLiftConfig:
    """Parameters of :class:`OscLift` (``-p key=value``)."""

    object: str = "cube"
    """The task-state object to lift (its ``<object>_pos`` entry)."""
    effector: str = "robot0_eef"
    """The task-state end effector (its ``<effector>_pos`` entry)."""
    approach_m: float = 0.08
    lift_m: float = 0.15
    close_s: float = 0.5
    gain: float = 10.0
    """Position delta per metre of error (clipped to [-1, 1]) [1/m]."""
    reached_m: float = 0.01
    """A phase's target counts as reached within this distance [m]."""

    def __post_init__(self) -> None:
        if self.gain <= 0 or self.close_s < 0 or self.reached_m <= 0:
            raise PolicyConfigError("osc_lift gain and reached_m must be > 0, close_s >= 0")


class OscLift:
    """The four-phase lift of the module doc; one instance per episode."""

    config_type = OscLiftConfig
    """Its parameters (``--param key=value``)."""

    needs_privileged = True
    """It reads the task state (only an evaluation episode gives it)."""
    required_slots: tuple[str, ...] = ()

    def __init__(self, config: OscLiftConfig) -> None:
        self.config = config
        self.phase = PHASES[0]
        self._start: FloatArray | None = None
        self._closing_since_s: float | None = None

    def act(self, obs: Observation) -> FloatArray:
        """Position delta towards the phase's target, no rotation, the gripper last."""
        state = task_state_of(obs)
        keys = (f"{self.config.object}_pos", f"{self.config.effector}_pos")
        if state is None or any(key not in state for key in keys):
            have = ", ".join(sorted(state or {})) or "none"
            raise PolicyConfigError(f"osc_lift needs task state {keys}; the scene reports {have}")
        names, _ = action_spec_of(obs)
        if len(names) < 4:
            raise PolicyConfigError(f"osc_lift needs a position delta and a gripper; got {names}")
        target, gripper = self._phase_target(state[keys[0]], state[keys[1]], time_of(obs))
        action = np.zeros(len(names))
        action[:3] = np.clip(self.config.gain * (target - state[keys[1]]), -1.0, 1.0)
        action[-1] = gripper
        return action

    def _phase_target(
        self, cube: FloatArray, effector: FloatArray, time_s: float
    ) -> tuple[FloatArray, float]:
        """Where the effector should go now, and the gripper command."""
        config = self.config
        if self._start is None:
            self._start = np.array(cube, dtype=np.float64)
        above = cube + np.array([0.0, 0.0, config.approach_m])
        if self.phase == "approach":
            if np.linalg.norm(above - effector) < config.reached_m:
                self.phase = "descend"
            return above, -1.0
        if self.phase == "descend":
            if np.linalg.norm(cube - effector) < config.reached_m:
                self.phase = "close"
            return cube, -1.0
        if self.phase == "close":
            if self._closing_since_s is None:
                self._closing_since_s = time_s
            if time_s - self._closing_since_s >= config.close_s:
                self.phase = "lift"
            return cube, 1.0
        return self._start + np.array([0.0, 0.0, config.lift_m]), 1.0
