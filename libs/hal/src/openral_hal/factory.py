"""build_hal: the one place that decides which HAL drives a robot.

* ``sim`` with a loaded scene → :class:`SimAttachedHAL` on the scene's backend (the scene
  owns physics and cameras);
* ``sim`` without one → :class:`MujocoArmHAL`, the robot alone in its own model;
* ``real`` → the driver registered for the robot in :data:`REAL_DRIVERS`. A real robot is
  never attached to a simulated scene.

The robot and the scene arrive loaded (:class:`~openral_core.LoadedRobot`,
:class:`~openral_core.models.DeployScene`): nothing here reads a file.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum
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

RealDriver = Callable[[RobotDescription, str | None], RobotHal]
"""Factory of a robot's real-hardware HAL: ``factory(description, transport)``."""

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
) -> RobotHal:
    """The HAL for ``robot`` in ``mode``; not yet connected.

    Args:
        robot: The loaded robot.
        mode: ``sim`` or ``real``.
        transport: Passed to a real driver (address, bus or similar); unused in sim.
        scene: A loaded deploy scene to attach to (sim only).
        env_builder: Builds the scene backend; defaults to ``openral_sim.scene.build_scene``.

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
        return _real_hal(robot.description, transport)
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


def _real_hal(description: RobotDescription, transport: str | None) -> RobotHal:
    """The registered driver's HAL, checked against the contract before anyone uses it."""
    factory = REAL_DRIVERS.get(description.name)
    if factory is None:
        registered = ", ".join(sorted(REAL_DRIVERS)) or "<none>"
        raise ConfigurationError(
            f"no real driver registered for {description.name}; registered: {registered}"
        )
    hal: object = factory(description, transport)
    driver = f"the real driver of {description.name} ({type(hal).__name__})"
    try:
        return _conforming_real_hal(hal, driver)
    except ConfigurationError:
        raise
    except Exception as error:  # isinstance on a Protocol reads every property (Python 3.11)
        raise ConfigurationError(
            f"{driver}: a property raised {type(error).__name__} before connect(): {error}"
        ) from None


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
