"""The SimRollout protocol every scene backend implements."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any, Protocol, runtime_checkable

import mujoco
import numpy as np
import numpy.typing as npt
from openral_mujoco.robot_addresses import RobotAddresses
from openral_mujoco.state import JointStateSample

from openral_sim.base_drive import BaseDrive
from openral_sim.frame_tree import FrameTree
from openral_sim.observation import Observation, StepResult
from openral_sim.sensor_sources import CameraSource, DepthSource, LidarSource, StateSensorSource
from openral_sim.task_judge import TaskJudge

__all__ = [
    "HoldingRollout",
    "ManifestRollout",
    "Observation",
    "SceneRollout",
    "SensorSuite",
    "SimRollout",
    "StepResult",
]


@runtime_checkable
class SimRollout(Protocol):
    """A simulated scene that owns physics and rendering; a HAL attaches to it."""

    @property
    def action_dim(self) -> int | None:
        """Width of the action ``step`` expects, or None when the backend cannot tell."""
        ...

    @property
    def camera_names(self) -> tuple[str, ...]:
        """Cameras whose frames observations carry (``obs.images``)."""
        ...

    @property
    def control_period_s(self) -> float:
        """Simulated time one ``step`` advances [s]."""
        ...

    @property
    def camera_models(self) -> Mapping[str, str]:
        """Camera name in ``obs.images`` → the MJCF camera of ``mujoco_handles()``'s model
        that renders it (empty for a non-MuJoCo backend)."""
        ...

    def reset(self, seed: int | None = None) -> Observation:
        """Start a new episode; returns its first observation."""
        ...

    def step(self, action: npt.NDArray[np.floating[Any]]) -> StepResult:
        """Apply ``action`` for one control period and advance."""
        ...

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        """The live MuJoCo (model, data), or None for a non-MuJoCo backend."""
        ...

    def close(self) -> None:
        """Release renderers and other resources."""
        ...


@runtime_checkable
class HoldingRollout(SimRollout, Protocol):
    """A rollout that can say which action keeps its robot still, slot by slot.

    A position-controlled scene holds with its current targets, not with zeros (which
    would drive every joint towards 0 rad); a backend that does not implement this is
    held with a zero action, the hold of velocity and delta controllers.
    """

    @property
    def action_names(self) -> tuple[str, ...]:
        """One name per action slot."""
        ...

    def hold_action(self) -> npt.NDArray[np.float64]:
        """The action that keeps the robot where it is commanded to be now."""
        ...


@runtime_checkable
class ManifestRollout(HoldingRollout, Protocol):
    """A rollout that drives its robot by the manifest's contract: the action slots are the
    manifest joints (in manifest units) and it reports their state in the same units.

    A HAL attached to it delegates joint state to it instead of reading raw ``qpos``.
    """

    def step(self, action: npt.NDArray[np.floating[Any]], *, glide: bool = False) -> StepResult:
        """Apply ``action`` for one control period; with ``glide`` the set point moves to it
        at constant speed over the period (the next sample of a smooth path)."""
        ...

    def joint_state(self) -> JointStateSample:
        """Every manifest joint, in manifest order and units."""
        ...

    def hold_current_pose(self) -> None:
        """Make the present pose the targets (after an E-stop, so nothing jumps)."""
        ...


@runtime_checkable
class SensorSuite(CameraSource, DepthSource, LidarSource, StateSensorSource, Protocol):
    """Every sensor kind a scene can serve, behind one object."""


@runtime_checkable
class SceneRollout(ManifestRollout, Protocol):
    """A rollout that serves its sensors off its step, lays out its TF frames and may carry
    a mobile base (the native scene): a bridge renders its sensors on threads of its own
    at their rates, and a HAL attached to it publishes them all.

    Only attributes and methods, no properties: ``isinstance`` on Python 3.11 would
    evaluate a property (laying out the frames, say)."""

    sensors: SensorSuite
    """The scene's sensors as sources."""
    render_observations: bool
    """Whether ``reset``/``step`` make sensor frames for their observations."""
    observed: frozenset[str] | None
    """The sensors whose frames observations carry (None: all)."""
    base: BaseDrive | None
    """The mobile base's drive (None: none)."""
    horizon: int | None
    """Steps per episode (None: none): the env and sweeps truncate there."""
    addresses: RobotAddresses
    """Where the robot's joints are in the scene's model, per manifest joint."""
    parts: int
    """Parts of a control period ``step_part`` steps (the scene's state rate)."""
    task: TaskJudge
    """Success and rewards of each control period (:mod:`openral_sim.task_judge`)."""

    def render_cameras(
        self,
        data: mujoco.MjData,
        sensors: Iterable[str] | None = None,
        renderer: mujoco.Renderer | None = None,
    ) -> dict[str, npt.NDArray[np.uint8]]:
        """Fresh frames of the cameras of ``sensors`` (default: all) as ``data`` places
        them, by sensor name."""
        ...

    def step_part(
        self, action: npt.NDArray[np.floating[Any]] | None, *, glide: bool = False
    ) -> StepResult:
        """One part of a control period: ``action`` starts a new period with it; None steps
        the next part of the period in force (after its end: a new one, holding)."""
        ...

    def frames(self) -> FrameTree:
        """The TF frames of the robot and of the sensors it serves, laid out once.

        Raises:
            HalError: A layout a URDF tree cannot state.
        """
        ...
