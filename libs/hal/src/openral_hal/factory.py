"""build_hal: the one place that decides which HAL drives a robot.

* ``sim`` with a loaded scene → :class:`SimAttachedHAL` on the scene's backend (the scene
  owns physics and cameras);
* ``sim`` without one → :class:`MujocoArmHAL`, the robot alone in its own model;
* ``real`` → the robot's real driver: one registered for the robot by name in
  :data:`REAL_DRIVERS` (tests, a custom driver), else the driver of its manifest's
  ``real.driver`` kind, found among the installed ``openral.real_drivers`` entry points
  (``feetech``: :mod:`openral_real`, which sits above this layer, so it is never imported
  here). A real robot is never attached to a simulated scene.

The robot and the scene arrive loaded (:class:`~openral_core.LoadedRobot`,
:class:`~openral_core.models.DeployScene`): nothing here reads a file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from importlib.metadata import entry_points
from pathlib import Path
from typing import TypeGuard

from openral_core import LoadedRobot
from openral_core.models import DeployScene, RobotDescription
from openral_sim.rollout import SimRollout
from openral_sim.scene import build_scene, check_scene_robot

from openral_hal.errors import ConfigurationError
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.protocol import RobotHal, Tickable
from openral_hal.sim_attached import SimAttachedHAL


class HalMode(StrEnum):
    """Which HAL :func:`build_hal` makes."""

    SIM = "sim"
    REAL = "real"


MODES = tuple(mode.value for mode in HalMode)


@dataclass(frozen=True)
class RealOptions:
    """What a real driver is told beyond its transport (none of it is a robot fact)."""

    calibration_file: Path | None = None
    """The arm's calibration file (None: the driver's default place for ``arm_id``)."""
    arm_id: str | None = None
    """Which arm of this robot type (LeRobot's ``--robot.id``); None: the robot's name."""
    cameras: Mapping[str, str] = field(default_factory=dict)
    """RGB sensor → camera device, over the manifest's ``device`` entries."""
    twin_scene: DeployScene | None = None
    """A scene whose robot follows the measured joints (``deploy real --twin``): its
    cameras render the real pose and commands that would touch its fixed geometry are
    refused. None: the robot's own model alone."""


RealDriver = Callable[[LoadedRobot, str | None, RealOptions], RobotHal]
"""Factory of a robot's real-hardware HAL: ``factory(robot, transport, options)``."""
DRIVER_GROUP = "openral.real_drivers"
"""The entry-point group real drivers register under, by ``real.driver`` kind."""

EnvBuilder = Callable[[DeployScene, LoadedRobot], SimRollout]
"""Builds a scene backend from the loaded scene and robot (default: ``build_scene``)."""

REAL_DRIVERS: dict[str, RealDriver] = {}
"""Robot name → factory of its real-hardware HAL. Register with :func:`register_real_driver`."""


def register_real_driver(name: str, factory: RealDriver) -> None:
    """Make ``factory`` the real-hardware HAL of robot ``name`` (replacing any earlier one)."""
    REAL_DRIVERS[name] = factory


def can_tick(hal: RobotHal) -> TypeGuard[Tickable]:
    """True only for a simulated HAL a control loop may advance (a real one never is)."""
    return isinstance(hal, Tickable) and not hal.is_real


def build_hal(
    robot: LoadedRobot,
    *,
    mode: HalMode | str,
    transport: str | None = None,
    scene: DeployScene | None = None,
    env_builder: EnvBuilder | None = None,
    real_options: RealOptions | None = None,
) -> RobotHal:
    """The HAL for ``robot`` in ``mode``; not yet connected.

    Args:
        robot: The loaded robot.
        mode: ``sim`` or ``real``.
        transport: Passed to a real driver (address, bus or similar); unused in sim.
        scene: A loaded deploy scene to attach to (sim only).
        env_builder: Builds the scene backend; defaults to ``openral_sim.scene.build_scene``.
        real_options: Passed to a real driver (calibration, arm id, cameras).

    Raises:
        ConfigurationError: Unknown mode, a real robot with a scene, no real driver for the
            robot, or a driver that is no conforming real HAL.
        ManifestError: The scene is for another robot or cannot be built (located).
    """
    hal_mode = _mode(mode)
    if hal_mode is HalMode.REAL:
        if scene is not None:
            raise ConfigurationError(
                f"a real robot cannot attach to a simulated scene ({scene.scene.id}); drop the "
                "scene or use mode 'sim'"
            )
        return _real_hal(robot, transport, real_options or RealOptions())
    if scene is None:
        return MujocoArmHAL.from_robot(robot)
    check_scene_robot(scene, robot)
    builder = env_builder or build_scene
    return SimAttachedHAL(builder(scene, robot), robot, env_reset_seed=scene.seed)


def _mode(mode: HalMode | str) -> HalMode:
    try:
        return HalMode(mode)
    except ValueError:
        raise ConfigurationError(f"unknown HAL mode {mode!r}; expected one of {MODES}") from None


def _real_hal(robot: LoadedRobot, transport: str | None, options: RealOptions) -> RobotHal:
    """The robot's real driver's HAL, checked against the contract before anyone uses it."""
    name = robot.name
    factory = REAL_DRIVERS.get(name) or _installed_driver(robot.description)
    hal: object = factory(robot, transport, options)
    driver = f"the real driver of {name} ({type(hal).__name__})"
    try:
        return _conforming_real_hal(hal, driver)
    except ConfigurationError:
        raise
    except Exception as error:  # isinstance on a Protocol reads every property (Python 3.11)
        raise ConfigurationError(
            f"{driver}: a property raised {type(error).__name__} before connect(): {error}"
        ) from None


def _installed_driver(description: RobotDescription) -> RealDriver:
    """The installed driver of the manifest's ``real.driver`` kind.

    Raises:
        ConfigurationError: No ``real`` section and no registered driver, or no installed
            driver of that kind (or one that does not import).
    """
    if description.real is None:
        registered = ", ".join(sorted(REAL_DRIVERS)) or "<none>"
        raise ConfigurationError(
            f"no real driver registered for {description.name} and its manifest has no "
            f"`real` section; registered: {registered}"
        )
    kind = description.real.driver.value
    found = [point for point in entry_points(group=DRIVER_GROUP) if point.name == kind]
    if not found:
        raise ConfigurationError(
            f"no installed real driver of kind {kind!r} (entry point group {DRIVER_GROUP}); "
            "install it: pip install 'openral[real]'"
        )
    try:
        factory: RealDriver = found[0].load()
    except ImportError as error:
        raise ConfigurationError(
            f"the {kind} driver does not import ({error}); install it: pip install 'openral[real]'"
        ) from None
    return factory


def _conforming_real_hal(hal: object, driver: str) -> RobotHal:
    """``hal`` when it is a RobotHal, is real and cannot be ticked."""
    if not isinstance(hal, RobotHal):
        raise ConfigurationError(f"{driver} does not implement openral_hal.protocol.RobotHal")
    if isinstance(hal, Tickable):
        raise ConfigurationError(
            f"{driver} has tick(); a real HAL must never be stepped by the control loop"
        )
    if hal.is_real is not True:
        raise ConfigurationError(f"{driver} reports is_real={hal.is_real!r}; a real HAL is real")
    return hal
