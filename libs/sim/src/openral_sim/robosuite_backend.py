"""The robosuite scene backend: a robosuite environment as a SimRollout.

A deploy scene with ``scene.backend: robosuite`` maps onto ``robosuite.make`` like this:

- **environment**: ``scene.assets`` names the robosuite environment exactly (``Lift``,
  ``PickPlaceCan``, ...). When the file leaves ``assets`` out, ``scene.id`` is the environment
  name written in snake case (``lift`` → ``Lift``, ``pick_place_can`` → ``PickPlaceCan``): the
  schema keeps ids lower case, so the id is matched against robosuite's environments ignoring
  case and underscores.
- **robot**: the robot manifest's ``sim.robosuite_robot`` (``Panda`` for franka_panda).
- **cameras**: each name in ``scene.cameras`` is an rgb sensor of the robot; it renders the
  robosuite camera its ``robosuite_camera`` names (``wrist`` → ``robot0_eye_in_hand``), else
  the camera of the sensor's own name (``agentview``).
- **options**: ``control_freq_hz``, ``horizon`` (robosuite's own default of 1000 steps when
  left out) and ``controller`` (a composite controller name such as ``BASIC``; the robot's
  default composite controller when left out). ``seed`` seeds object placement and
  initialisation noise.

The action is whatever the robosuite controller takes (``env.action_dim`` values; for the
Panda's default controller: a 6-D OSC pose delta and one gripper value, each in [-1, 1]).
Images come out top row first (robosuite renders them upside down). ``mujoco_handles`` gives
the environment's raw ``mujoco.MjModel`` / ``MjData``; resets keep them (``hard_reset`` is off),
so a HAL attached once stays attached.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, cast

from openral_mujoco.display import use_offscreen_gl

from openral_sim.robosuite_quiet import quiet_robosuite_notices

use_offscreen_gl()  # robosuite picks its GL backend on import


quiet_robosuite_notices()  # before robosuite's import logs them


import mujoco
import numpy as np
import numpy.typing as npt
import robosuite
from openral_core.errors import OpenralError
from openral_core.located import error_at, source_of
from openral_core.models import DeployScene, RgbSensor, RobotDescription
from openral_core.registry import load_robot_by_id

from openral_sim.gl_guard import claim_gl
from openral_sim.observation import Observation, Outcome, StepResult
from openral_sim.sensor_schedule import SensorSchedule, sensor_rates

_NATIVE_ONLY_OPTIONS = ("table_height_m", "objects", "state_rate_hz")


class RobosuiteError(OpenralError):
    """A scene the robosuite backend cannot build."""


class RobosuiteRollout:
    """A robosuite environment with offscreen cameras (a SimRollout)."""

    def __init__(
        self,
        env_name: str,
        robot: str,
        cameras: Mapping[str, str],
        width: int,
        height: int,
        control_freq_hz: float = 20.0,
        horizon: int | None = None,
        controller: str | None = None,
        seed: int = 0,
    ) -> None:
        """Build the environment.

        Args:
            env_name: robosuite environment name, such as ``Lift``.
            robot: robosuite robot name, such as ``Panda``.
            cameras: openral camera name → robosuite camera it renders, such as
                ``{"wrist": "robot0_eye_in_hand"}``.
            width: Image width [px] of every camera.
            height: Image height [px] of every camera.
            control_freq_hz: Actions per simulated second.
            horizon: Steps per episode; robosuite's default (1000) when None.
            controller: Composite controller name (``BASIC``, ...) or a JSON config path;
                the robot's default composite controller when None.
            seed: Seed of object placement and initialisation noise.

        Raises:
            RobosuiteError: Unknown environment, robot, controller or camera.
        """
        _check_names(env_name, robot, controller)
        self._cameras = dict(cameras)
        self._names = tuple(self._cameras)
        self._control_period_s = 1.0 / control_freq_hz
        options: dict[str, Any] = {"control_freq": control_freq_hz, "seed": seed}
        if horizon is not None:
            options["horizon"] = horizon
        if controller is not None:
            options["controller_configs"] = robosuite.load_composite_controller_config(
                controller=controller, robot=robot
            )
        self.env: Any = _make_env(env_name, robot, self._cameras, (width, height), options)
        self._flip = robosuite.macros.IMAGE_CONVENTION == "opengl"
        self.schedule = SensorSchedule(dict.fromkeys(self._names, control_freq_hz))
        """When each camera's frame enters the observation (robosuite renders every step;
        :func:`build_robosuite_rollout` sets each camera's manifest rate)."""

    # -- SimRollout ------------------------------------------------------------------------

    @property
    def control_period_s(self) -> float:
        """Simulated time one step advances: 1 / ``control_freq_hz`` [s]."""
        return self._control_period_s

    @property
    def action_dim(self) -> int:
        """Width of the controller's action (``env.action_dim``)."""
        return int(self.env.action_dim)

    @property
    def action_limits(self) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Lower and upper bound of every action value (``env.action_spec``)."""
        low, high = self.env.action_spec
        return np.asarray(low, dtype=np.float64), np.asarray(high, dtype=np.float64)

    @property
    def camera_models(self) -> dict[str, str]:
        """openral camera name → robosuite (MJCF) camera name."""
        return dict(self._cameras)

    @property
    def camera_names(self) -> tuple[str, ...]:
        """openral camera names rendered into ``obs["images"]``."""
        return self._names

    def reset(self, seed: int | None = None) -> Observation:
        """New episode; ``seed`` reseeds object placement and initialisation noise."""
        if seed is not None:
            # the env's generator is shared with its placement sampler: reseed it in place
            rng: np.random.Generator = self.env.rng
            rng.bit_generator.state = np.random.default_rng(seed).bit_generator.state
        self._make_current()
        self.schedule.restart()
        return self._observe(self.env.reset())

    def step(self, action: npt.NDArray[np.floating[Any]]) -> StepResult:
        """Apply ``action`` (``action_dim`` values) for one control period.

        The episode ends at the horizon (``truncated``) or when the task itself says so
        (``terminated``, e.g. Wipe on a collision). ``success`` is the environment's own
        success check (robosuite's ``step`` reports none in its info).
        """
        values = np.asarray(action, dtype=np.float64)
        if values.shape != (self.action_dim,):
            raise RobosuiteError(f"action has shape {values.shape}; expected ({self.action_dim},)")
        self._make_current()
        raw, reward, done, _ = self.env.step(values)
        at_horizon = bool(done) and int(self.env.timestep) >= int(self.env.horizon)
        outcome = Outcome(
            reward=float(reward),
            success=bool(self.env._check_success()),
            terminated=bool(done) and not at_horizon,
            truncated=at_horizon,
            steps=int(self.env.timestep),
            dense_reward=float(reward),  # robosuite's own, shaped or not as it was made
        )
        return StepResult(self._observe(raw), outcome)

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The environment's raw MuJoCo model and data (not robosuite's wrappers)."""
        sim = self.env.sim
        return cast(mujoco.MjModel, sim.model._model), cast(mujoco.MjData, sim.data._data)

    def close(self) -> None:
        """Free the simulation and its render context."""
        if getattr(self.env, "sim", None) is not None:
            self.env.close()

    # -- internals -------------------------------------------------------------------------

    def _make_current(self) -> None:
        """robosuite renders into whichever GL context is current; make it ours, so several
        rollouts in one process do not draw into each other's context."""
        context = getattr(self.env.sim, "_render_context_offscreen", None)
        if context is not None:
            context.gl_ctx.make_current()

    def _observe(self, raw: dict[str, Any]) -> Observation:
        """The typed observation of robosuite's: the frames due now, top row first, and
        every non-image entry as task state."""
        time_s = float(self.env.sim.data.time)
        images: dict[str, npt.NDArray[np.uint8]] = {}
        for name in self.schedule.due(time_s):
            image = np.asarray(raw[f"{self._cameras[name]}_image"], dtype=np.uint8)
            images[name] = np.ascontiguousarray(image[::-1] if self._flip else image)
        state = {
            key: np.asarray(value, dtype=np.float64)
            for key, value in raw.items()
            if not key.endswith(("_image", "_depth", "_segmentation"))
        }
        return Observation(time_s=time_s, images=images, task_state=state)


def robosuite_env_name(scene: DeployScene) -> str:
    """The robosuite environment a scene names (see the module docstring).

    Raises:
        ManifestError: At ``scene.assets`` (or ``scene.id``) when it names no environment.
    """
    spec = scene.scene
    available = ", ".join(sorted(robosuite.ALL_ENVIRONMENTS))
    if "assets" in spec.model_fields_set:
        if spec.assets not in robosuite.ALL_ENVIRONMENTS:
            message = f"unknown robosuite environment {spec.assets!r}; available: {available}"
            raise error_at(scene, ("scene", "assets"), message)
        return spec.assets
    wanted = spec.id.replace("_", "").lower()
    for name in robosuite.ALL_ENVIRONMENTS:
        if name.lower() == wanted:
            return str(name)
    message = (
        f"{spec.id!r} names no robosuite environment and scene.assets is not set; set "
        f"scene.assets to one of: {available}"
    )
    raise error_at(scene, ("scene", "id"), message)


def build_robosuite_rollout(
    scene: DeployScene,
    robot: RobotDescription | None = None,
    *,
    frame_rate_hz: float | None = None,
) -> RobosuiteRollout:
    """The robosuite environment a deploy scene describes.

    Args:
        scene: A scene with ``scene.backend: robosuite``.
        robot: The scene's robot; read from ``robots/<robot_id>/`` when None.
        frame_rate_hz: Overrides every camera's rate in the observations (see
            :func:`~openral_sim.sensor_schedule.sensor_rates`).

    Raises:
        ManifestError: At the scene file's field that robosuite cannot serve: no robot, a
            robot without ``sim.robosuite_robot``, a camera that is no rgb sensor of the
            robot, an unknown environment or controller, an option or a base pose that
            belongs to the native backend, or an environment robosuite fails to build (e.g.
            a camera it does not have); at the manifest's ``sim.robosuite_robot`` when
            robosuite has no such robot.
    """
    if robot is None:
        if scene.robot_id is None:
            raise error_at(scene, (), "the scene names no robot; add robot_id")
        robot = load_robot_by_id(scene.robot_id)
    robot_class = _robosuite_robot(scene, robot)
    cameras = _robosuite_cameras(scene, robot)
    _check_scene_options(scene)
    options = scene.scene.options
    env_name = robosuite_env_name(scene)
    control_freq_hz = options.control_freq_hz if options else 20.0
    try:
        rollout = RobosuiteRollout(
            env_name=env_name,
            robot=robot_class,
            cameras=cameras,
            width=scene.scene.observation.width,
            height=scene.scene.observation.height,
            control_freq_hz=control_freq_hz,
            horizon=options.horizon if options else None,
            controller=options.controller if options else None,
            seed=scene.seed,
        )
    except RobosuiteError as error:
        raise error_at(scene, ("scene",), str(error)) from None
    rates = sensor_rates(robot, control_freq_hz, frame_rate_hz=frame_rate_hz, sensors=cameras)
    rollout.schedule = SensorSchedule(rates)
    return rollout


def _check_names(env_name: str, robot: str, controller: str | None) -> None:
    """Refuse an environment, robot or composite controller robosuite does not have."""
    if env_name not in robosuite.ALL_ENVIRONMENTS:
        raise RobosuiteError(
            f"unknown robosuite environment {env_name!r}; "
            f"available: {', '.join(sorted(robosuite.ALL_ENVIRONMENTS))}"
        )
    if robot not in robosuite.ALL_ROBOTS:
        raise RobosuiteError(
            f"unknown robosuite robot {robot!r}; "
            f"available: {', '.join(sorted(robosuite.ALL_ROBOTS))}"
        )
    if (
        controller is not None
        and not controller.endswith(".json")
        and controller not in robosuite.ALL_COMPOSITE_CONTROLLERS
    ):
        raise RobosuiteError(
            f"unknown robosuite composite controller {controller!r}; "
            f"available: {', '.join(sorted(robosuite.ALL_COMPOSITE_CONTROLLERS))}"
        )


def _make_env(
    env_name: str,
    robot: str,
    cameras: Mapping[str, str],
    size: tuple[int, int],
    options: Mapping[str, Any],
) -> Any:
    """``robosuite.make`` with offscreen cameras; ``options`` are passed on as they are."""
    width, height = size
    if cameras:
        claim_gl()  # robosuite's offscreen renderer
    try:
        return robosuite.make(
            env_name,
            robots=robot,
            has_renderer=False,
            has_offscreen_renderer=bool(cameras),
            use_camera_obs=bool(cameras),
            camera_names=list(cameras.values()) or "agentview",
            camera_heights=height,
            camera_widths=width,
            ignore_done=False,
            hard_reset=False,  # keep one MjModel/MjData and render context for life
            **options,
        )
    except (AssertionError, ValueError, KeyError) as error:
        # robosuite reports e.g. a camera missing from the model this way
        raise RobosuiteError(
            f"robosuite could not build {env_name!r} with {robot!r} and cameras "
            f"{list(cameras.values())}: {error!r}"
        ) from error


def _check_scene_options(scene: DeployScene) -> None:
    """Refuse native-only options, an unknown controller and a base pose (located)."""
    options = scene.scene.options
    if options is not None:
        for key in _NATIVE_ONLY_OPTIONS:  # given in the file (a default is not)
            if key in options.model_fields_set:
                message = "applies to the native backend only"
                raise error_at(scene, ("scene", "options", key), message)
        controller = options.controller
        if controller is not None and controller not in robosuite.ALL_COMPOSITE_CONTROLLERS:
            message = (
                f"unknown robosuite composite controller {controller!r}; available: "
                f"{', '.join(sorted(robosuite.ALL_COMPOSITE_CONTROLLERS))}"
            )
            raise error_at(scene, ("scene", "options", "controller"), message)
    pose = scene.base_pose
    if pose is not None and (any(pose.position_m or []) or pose.yaw_deg or pose.weld):
        raise error_at(scene, ("base_pose",), "robosuite environments place the robot themselves")


def _robosuite_robot(scene: DeployScene, robot: RobotDescription) -> str:
    """The robosuite robot class of ``robot``'s ``sim.robosuite_robot`` (located errors)."""
    name = robot.sim.robosuite_robot if robot.sim is not None else None
    if name is None:
        manifest = source_of(robot)
        where = f" of {manifest.file}" if manifest is not None else ""
        message = (
            f"{robot.name!r} has no robosuite model; add sim.robosuite_robot{where} (the "
            f"robosuite robot class, one of: {', '.join(sorted(robosuite.ALL_ROBOTS))})"
        )
        raise error_at(scene, _robot_field(scene), message)
    if name not in robosuite.ALL_ROBOTS:
        message = (
            f"robosuite has no robot {name!r}; available: {', '.join(sorted(robosuite.ALL_ROBOTS))}"
        )
        raise error_at(robot, ("sim", "robosuite_robot"), message)
    return name


def _robot_field(scene: DeployScene) -> tuple[str, ...]:
    """The scene field an error about its robot points at: ``robot_id`` when the file
    names the robot, else ``scene.backend`` (the robot came from elsewhere)."""
    document = source_of(scene)
    named = document is None or (isinstance(document.data, dict) and "robot_id" in document.data)
    return ("robot_id",) if named and scene.robot_id is not None else ("scene", "backend")


def _robosuite_cameras(scene: DeployScene, robot: RobotDescription) -> dict[str, str]:
    """Scene camera → robosuite camera: each an rgb sensor's ``robosuite_camera``, else
    its name (located error at a camera that is no rgb sensor of ``robot``)."""
    sensors = {sensor.name: sensor for sensor in robot.sensors}
    cameras: dict[str, str] = {}
    for index, name in enumerate(scene.scene.cameras):
        sensor = sensors.get(name)
        if not isinstance(sensor, RgbSensor):
            rgb = [s.name for s in sensors.values() if isinstance(s, RgbSensor)]
            message = (
                f"{name!r} is not an rgb sensor of {robot.name}; "
                f"robosuite renders its rgb sensors: {', '.join(rgb) or 'none'}"
            )
            raise error_at(scene, ("scene", "cameras", index), message)
        cameras[name] = sensor.robosuite_camera or name
    return cameras
