"""build_hal: the one place that decides which HAL drives a robot.

* ``sim`` with a scene file → :class:`SimAttachedHAL` on the scene's backend (the scene owns
  physics and cameras);
* ``sim`` without one → :class:`MujocoArmHAL`, the robot alone in its own model;
* ``real`` → the driver registered for the robot in :data:`REAL_DRIVERS`. A real robot is
  never attached to a simulated scene.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from openral_core.loader import load_scene
from openral_core.located import error_at
from openral_core.models import RobotDescription
from openral_sim.rollout import SimRollout

from openral_hal.errors import ConfigurationError
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.sim_attached import SimAttachedHAL

MODES = ("sim", "real")

REAL_DRIVERS: dict[str, Callable[..., Any]] = {}
"""Robot name → factory of its real-hardware HAL, called as
``factory(description, transport=transport)``. Register with :func:`register_real_driver`."""


def register_real_driver(name: str, factory: Callable[..., Any]) -> None:
    """Make ``factory`` the real-hardware HAL of robot ``name`` (replacing any earlier one)."""
    REAL_DRIVERS[name] = factory


def can_idle_step(hal: object) -> bool:
    """True only for a simulated HAL that offers ``idle_step`` (a real one never does)."""
    return not getattr(hal, "is_real", True) and callable(getattr(hal, "idle_step", None))


def build_hal(
    description: RobotDescription,
    *,
    mode: str,
    transport: str | None = None,
    sim_env_yaml: str | Path | None = None,
    env_builder: Callable[[Path], SimRollout] | None = None,
) -> Any:
    """The HAL for ``description`` in ``mode``; not yet connected.

    Args:
        description: The robot's manifest.
        mode: ``sim`` or ``real``.
        transport: Passed to a real driver (address, bus or similar); unused in sim.
        sim_env_yaml: A deploy-scene file to attach to (sim only).
        env_builder: Builds the scene backend from the file; defaults to
            ``openral_sim.scene.build_sim_env_from_yaml`` with the robot as fallback.

    Raises:
        ConfigurationError: Unknown mode, a real robot with a scene, no real driver for the
            robot, or a driver whose HAL could idle-step.
        ManifestError: The scene file is invalid or is for another robot (located).
    """
    if mode not in MODES:
        raise ConfigurationError(f"unknown HAL mode {mode!r}; expected one of {MODES}")
    if mode == "real":
        if sim_env_yaml is not None:
            raise ConfigurationError(
                f"a real robot cannot attach to a simulated scene ({sim_env_yaml}); drop the "
                "scene or use mode 'sim'"
            )
        return _real_hal(description, transport)
    if sim_env_yaml is None:
        return MujocoArmHAL.from_description(description)
    path = Path(sim_env_yaml)
    seed = _scene_seed(path, description.name)
    builder = env_builder or _default_env_builder(description.name)
    return SimAttachedHAL(builder(path), description, env_reset_seed=seed)


def _real_hal(description: RobotDescription, transport: str | None) -> Any:
    factory = REAL_DRIVERS.get(description.name)
    if factory is None:
        registered = ", ".join(sorted(REAL_DRIVERS)) or "<none>"
        raise ConfigurationError(
            f"no real driver registered for {description.name}; registered: {registered}"
        )
    hal = factory(description, transport=transport)
    if hasattr(hal, "idle_step"):
        raise ConfigurationError(
            f"the real driver of {description.name} ({type(hal).__name__}) defines idle_step; "
            "a real HAL must never be stepped by the idle stepper"
        )
    return hal


def _scene_seed(path: Path, robot: str) -> int:
    """Reset seed of a scene file (0 when there is no file to read, e.g. a custom builder)."""
    if not path.is_file():
        return 0
    scene = load_scene(path)
    if scene.robot_id is not None and scene.robot_id != robot:
        message = f"the scene is for {scene.robot_id}, not {robot}"
        raise error_at(scene, ("robot_id",), message)
    return scene.seed


def _default_env_builder(robot: str) -> Callable[[Path], SimRollout]:
    from openral_sim.scene import build_sim_env_from_yaml

    def build(path: Path) -> SimRollout:
        return build_sim_env_from_yaml(path, robot_id_fallback=robot)

    return build
