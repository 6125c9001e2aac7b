"""What one step of a scene yields, typed: the observation and the step's outcome.

Every backend (native, robosuite) fills the same frozen dataclasses; nothing downstream
reads a backend's own dictionaries. Fields a backend cannot provide stay empty (or None),
they are never guessed:

- :class:`Observation` — the instant's joint sample (manifest order and units), the sensor
  frames that were due at this instant (RGB images, depth frames, lidar scans, state-sensor
  readings, by manifest sensor name), the mobile base's odometry, and the task state a
  privileged policy may read (object poses, robosuite's object-state vector);
- :class:`Outcome` — reward, success (the scene's own check: the native scene's ``success``
  predicates, robosuite's ``_check_success``), terminated, truncated, and the step count;
- :class:`StepResult` — one of each.

Sensor frames follow :mod:`openral_sim.sensor_schedule`: a frame appears in the observation
of the step at which its sensor is due, not at every step.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from openral_mujoco.state import FloatArray, JointStateSample

from openral_sim.base_drive import BaseOdometry
from openral_sim.depth_cloud import DepthFrame
from openral_sim.lidar_scan import Ranges
from openral_sim.state_sensors import Reading

ImageArray = npt.NDArray[np.uint8]
"""An H x W x 3 RGB frame, top row first."""


@dataclass(frozen=True)
class LidarScan:
    """One scan of a lidar: REP 117 ranges [m] (±inf out of range) at a simulated time [s]."""

    ranges: Ranges
    sim_time_s: float


@dataclass(frozen=True)
class Observation:
    """What a scene shows at one instant (see the module doc)."""

    time_s: float
    """Simulated time of the state [s]."""
    joints: JointStateSample | None = None
    """Every manifest joint, manifest order and units (None: the backend cannot tell)."""
    images: Mapping[str, ImageArray] = field(default_factory=dict)
    """RGB frames of the cameras due now, by manifest sensor name."""
    depth: Mapping[str, DepthFrame] = field(default_factory=dict)
    """Depth frames (image and cloud) of the depth sensors due now."""
    scans: Mapping[str, LidarScan] = field(default_factory=dict)
    """Lidar scans due now."""
    readings: Mapping[str, Reading] = field(default_factory=dict)
    """IMU, force-torque and pose readings due now."""
    odometry: BaseOdometry | None = None
    """The mobile base's odometry (None: no mobile base)."""
    task_state: Mapping[str, FloatArray] = field(default_factory=dict)
    """Privileged task state by name: ``<object>_pos`` [m] and ``<object>_quat`` (w, x, y,
    z) of every scene object; on robosuite, its own object observations (``cube_pos``,
    ``robot0_eef_pos``, ...)."""


@dataclass(frozen=True)
class Outcome:
    """How one step ended (gymnasium's reward/terminated/truncated, plus success)."""

    reward: float = 0.0
    """The sparse reward: 1 where success holds (robosuite: its own reward)."""
    success: bool = False
    """The scene's own success check holds at this step."""
    terminated: bool = False
    """The task ended the episode (robosuite: e.g. a collision in Wipe)."""
    truncated: bool = False
    """The scene's horizon ended the episode."""
    steps: int = 0
    """Steps since the last reset."""
    dense_reward: float = 0.0
    """The scene's dense reward (:mod:`openral_sim.task_reward`; robosuite: its own reward;
    0 for a scene that declares none)."""

    @property
    def done(self) -> bool:
        """The episode is over (terminated or truncated); the next step must reset first."""
        return self.terminated or self.truncated


@dataclass(frozen=True)
class StepResult:
    """What one ``SimRollout.step`` returns."""

    obs: Observation
    outcome: Outcome = Outcome()
