"""Checks a native scene makes against the robot's model before it composes anything.

Each refuses one field of the scene file, at its line and column (what needs only the file,
such as unique object names, the loader already checked).
"""

from __future__ import annotations

import mujoco
from openral_core.errors import did_you_mean
from openral_core.located import error_at
from openral_core.models import DeployScene, DepthSensor, RgbSensor, RobotDescription

MAX_PHYSICS_STEPS_PER_CONTROL = 1_000
"""Most physics steps one control period may take. A period runs in one callback of the
graph's executor; at 1,000 steps (1 Hz on a 1 ms model) the slowest robot here takes ~80 ms,
so an E-stop request still gets its answer within 100 ms."""


def physics_steps_per_control(scene: DeployScene, timestep_s: float) -> int:
    """Physics steps of ``timestep_s`` [s] per control period of ``scene``.

    Raises:
        ManifestError: At ``scene.options.control_freq_hz`` when the rate is faster than the
            physics step or needs more than :data:`MAX_PHYSICS_STEPS_PER_CONTROL` steps.
    """
    options = scene.scene.options
    control_hz = options.control_freq_hz if options and options.control_freq_hz else 20.0
    steps = round(1.0 / (control_hz * timestep_s))
    field = ("scene", "options", "control_freq_hz")
    physics_hz = 1.0 / timestep_s
    if steps < 1:
        message = (
            f"{control_hz:g} Hz is faster than the model's physics ({physics_hz:g} Hz, a "
            f"{timestep_s:g} s step); use at most {physics_hz:g} Hz"
        )
        raise error_at(scene, field, message)
    if steps > MAX_PHYSICS_STEPS_PER_CONTROL:
        message = (
            f"{control_hz:g} Hz needs {steps} physics steps of {timestep_s:g} s per control "
            f"period; at most {MAX_PHYSICS_STEPS_PER_CONTROL} are allowed (use at least "
            f"{physics_hz / MAX_PHYSICS_STEPS_PER_CONTROL:g} Hz)"
        )
        raise error_at(scene, field, message)
    return int(steps)


def check_object_names(scene: DeployScene, *models: mujoco.MjModel | None) -> None:
    """Refuse a scene object whose body or joint name one of ``models`` (the robot's, its
    mobile base's; None is skipped) already uses."""
    options = scene.scene.options
    for index, obj in enumerate(options.objects or [] if options else []):
        for kind, name in (
            (mujoco.mjtObj.mjOBJ_BODY, f"scene_{obj.name}"),
            (mujoco.mjtObj.mjOBJ_JOINT, f"scene_{obj.name}_joint"),
            (mujoco.mjtObj.mjOBJ_GEOM, f"scene_{obj.name}_geom"),
        ):
            if any(m is not None and mujoco.mj_name2id(m, kind, name) >= 0 for m in models):
                message = f"the robot's model already has an element named {name!r}; rename it"
                raise error_at(scene, ("scene", "options", "objects", index, "name"), message)


def check_weld(scene: DeployScene, robot: RobotDescription) -> None:
    """Refuse ``base_pose.weld`` on a robot whose base is fixed (only a floating base welds)."""
    pose = scene.base_pose
    if pose is not None and pose.weld and not (robot.sim and robot.sim.floating_base):
        message = (
            f"robot {robot.name!r} has a fixed base; only a floating base can be welded in place"
        )
        raise error_at(scene, ("base_pose", "weld"), message)


def check_scene_cameras(scene: DeployScene, robot: RobotDescription) -> None:
    """Refuse a name in ``scene.cameras`` that is no camera sensor (rgb or depth) of
    ``robot``, at that list item, with the closest names (a native scene's rule).

    Raises:
        ManifestError: At ``scene.cameras[i]``.
    """
    known = [s.name for s in robot.sensors if isinstance(s, RgbSensor | DepthSensor)]
    for index, name in enumerate(scene.scene.cameras):
        if name not in known:
            message = (
                f"{name!r} is not a camera sensor of robot {robot.name!r}"
                f"{did_you_mean(name, known)}; its camera sensors are: "
                f"{', '.join(known) or '(none)'}"
            )
            raise error_at(scene, ("scene", "cameras", index), message)


def state_parts_per_control(scene: DeployScene, substeps: int, timestep_s: float) -> int:
    """In how many equal parts a control period of ``substeps`` physics steps of
    ``timestep_s`` [s] is stepped, so the state advances at about ``options.state_rate_hz``:
    the divisor of ``substeps`` nearest the asked rate (ties: the faster); 1 when the rate
    is left at its default and the control rate is faster.

    Raises:
        ManifestError: At ``scene.options.state_rate_hz`` when it is slower than the control
            rate (rule 7 of the scene schema).
    """
    options = scene.scene.options
    given = options is not None and "state_rate_hz" in options.model_fields_set
    state_hz = options.state_rate_hz if options else 100.0
    control_hz = 1.0 / (substeps * timestep_s)
    if not given and state_hz < control_hz:  # the default never slows a faster control rate
        return 1
    if state_hz < control_hz * (1.0 - 1e-9):
        message = (
            f"{state_hz:g} Hz is slower than the control rate ({control_hz:g} Hz); the state "
            f"advances at least once per action: use at least {control_hz:g} Hz"
        )
        raise error_at(scene, ("scene", "options", "state_rate_hz"), message)
    wanted = state_hz / control_hz
    divisors = [n for n in range(1, substeps + 1) if substeps % n == 0]
    return min(divisors, key=lambda n: (abs(n - wanted), -n))
