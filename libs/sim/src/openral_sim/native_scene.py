"""The native scene backend: any manifest's robot composed into a tabletop with MjSpec.

The scene adds a floor, lights, optionally a table and a pedestal, the objects the scene file
lists, and a camera per manifest camera sensor it names (:mod:`openral_sim.scene_compose`,
:mod:`openral_sim.scene_cameras`); every fault of the scene file or the manifest is reported
at its field's line and column. The robot is driven by ``MujocoArmHAL``'s
:class:`~openral_mujoco.joint_driver.JointDriver` (one value per manifest joint in manifest
units, clamped and slewed by the manifest's limits); only the addresses differ.

A robot with a ``mobile_base`` rides its base (:mod:`openral_sim.scene_base`):
:attr:`NativeScene.base` takes velocity commands and reads odometry, updated every
:data:`~openral_sim.base_drive.BASE_UPDATE_STEPS` physics steps; it is no slot of the action.

``reset``/``step`` return an :class:`~openral_sim.observation.Observation` (joints, odometry,
objects' poses, frames of the sensors due: :mod:`openral_sim.sensor_schedule`). ``step``
advances one control period; :meth:`NativeScene.step_part` steps it in parts at the scene's
``state_rate_hz`` (``deploy sim``'s fresh state). With ``render_observations`` off no frame
is made (``deploy sim`` renders on threads of its own through :attr:`NativeScene.sensors`);
:attr:`NativeScene.observed` narrows the frames to the sensors a caller reads.
"""

from __future__ import annotations

import functools
import time
from collections.abc import Iterable

import mujoco
import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot
from openral_core.located import error_at
from openral_core.models import DeployScene, NativeAssets, RobotDescription
from openral_core.tables import HalWiring
from openral_mujoco.errors import HalError
from openral_mujoco.joint_driver import JointDriver
from openral_mujoco.robot_addresses import RobotAddresses, locate_robot
from openral_mujoco.robot_bodies import robot_bodies, root_body
from openral_mujoco.sensor_skip import sensors_skipped
from openral_mujoco.state import FloatArray, JointStateSample

from openral_sim.base_drive import BASE_UPDATE_STEPS, BaseDrive
from openral_sim.depth_cloud import DepthCamera, DepthFrame
from openral_sim.frame_tree import FrameTree, scene_frame_tree
from openral_sim.observation import Observation, Outcome, StepResult
from openral_sim.randomization import Randomizer
from openral_sim.range_sensors import RangeSensors
from openral_sim.scene_cameras import camera_sensors
from openral_sim.scene_checks import physics_steps_per_control, state_parts_per_control
from openral_sim.scene_compose import compose
from openral_sim.scene_geometry import (
    hold_base_where_it_is,
    object_poses,
    place_floating_base,
)
from openral_sim.scene_sensors import SceneSensors
from openral_sim.task_judge import TaskJudge


class NativeScene:
    """A MuJoCo scene composed from a loaded robot and a deploy-scene file (a SimRollout
    whose action and joint state follow the manifest's contract)."""

    def __init__(self, scene: DeployScene, robot: LoadedRobot, *, render_observations: bool = True):
        """Compose ``scene`` around ``robot`` (both as loaded, so errors point into them).

        Args:
            scene: The loaded deploy-scene file.
            robot: The loaded robot it names.
            render_observations: Render every camera into ``obs["images"]`` on each
                ``reset``/``step`` (False: leave it empty; see :meth:`render_cameras`).

        Raises:
            ManifestError: At the field of the scene file or manifest that cannot be built:
                an unknown camera, a manifest that disagrees with its model, an
                object name the model already uses, a weld on a fixed base, a control rate
                the model's physics step cannot serve, a robot joint not found in the scene.
        """
        self.scene = scene
        self.robot = robot
        description = robot.description
        if not isinstance(scene.scene.assets, NativeAssets):  # the schema's if/then: never
            expected = ", ".join(a.value for a in NativeAssets)
            message = f"{scene.scene.assets!r} is not a native scene; expected one of {expected}"
            raise error_at(scene, ("scene", "assets"), message)
        wiring = robot.tables.hal_wiring
        if wiring is None:
            raise error_at(scene, ("robot_id",), f"robot {robot.name!r} has no sim block")
        self.wiring: HalWiring = wiring
        cameras = camera_sensors(scene, description)
        composed = compose(scene, description, robot.folder, cameras)
        self.model = composed.model
        self.data = mujoco.MjData(self.model)
        try:
            addresses = locate_robot(wiring, composed.robot_model, self.model)
        except HalError as error:
            raise error_at(description, ("joints",), str(error)) from None
        self.driver = JointDriver(description, wiring, self.model, addresses)
        base = robot.tables.mobile_base
        self.base = None if base is None else BaseDrive(base, self.model, self.data)
        """The mobile base's drive and odometry (None for a robot without a mobile base)."""
        self._root_body = root_body(self.model, description)
        self._setup_sensors(scene, robot, cameras)
        self._root_qpos = int(self.model.jnt_qposadr[self.model.body_jntadr[self._root_body]])
        self._width = scene.scene.observation.width
        self._height = scene.scene.observation.height
        self.substeps = physics_steps_per_control(scene, self.model.opt.timestep)
        self.parts = state_parts_per_control(scene, self.substeps, self.model.opt.timestep)
        """Parts of a control period :meth:`step_part` steps (``options.state_rate_hz``)."""
        self._part = self.parts  # parts of the current period stepped (all: it has ended)
        self._outcome = Outcome()
        self.render_observations = render_observations
        """Whether observations carry sensor frames; may be changed at any time."""
        self.observed: frozenset[str] | None = None
        """The sensors whose frames observations carry (None: every one served)."""
        self._steps = 0
        self.sensors.reschedule(1.0 / self.control_period_s)
        self._setup_episodes(scene, description, cameras, addresses)

    def _setup_sensors(
        self, scene: DeployScene, robot: LoadedRobot, cameras: dict[str, str]
    ) -> None:
        """The depth cameras and lidars, and every sensor as sources."""
        description = robot.description
        robot_ids = robot_bodies(self.model, description)
        self.range_sensors = RangeSensors(
            self.model, description, cameras, robot_ids, self._root_body
        )
        """Depth cameras and lidars (:class:`~openral_sim.range_sensors.RangeSensors`)."""
        depth = self.range_sensors.depth
        self._sensors = {name: cam for name, cam in cameras.items() if name not in depth}
        size = (scene.scene.observation.height, scene.scene.observation.width)
        offset = self.base.root_in_base_frame if self.base is not None else (0.0, 0.0, 0.0)
        self.sensors = SceneSensors(
            self.model,
            self.data,
            description,
            self._sensors,
            self.range_sensors,
            size,
            robot.tables.frames,
            offset,
        )
        """Every sensor the scene serves, as sensor sources (:mod:`openral_sim.scene_sensors`)."""
        self.state_sensors = self.sensors.state
        """IMU, force-torque and pose sensors (:class:`~openral_sim.state_sensors.StateSensors`)."""

    def _setup_episodes(
        self,
        scene: DeployScene,
        description: RobotDescription,
        cameras: dict[str, str],
        addresses: RobotAddresses,
    ) -> None:
        """The scene file's seeded randomisation and success predicates."""
        self.addresses = addresses
        """Where the robot's joints are in :attr:`model` (per manifest joint)."""
        self._cameras = dict(cameras)
        fixed = [  # the cameras the scene places (not on the robot, not the model's own)
            cameras[s.name]
            for s in description.sensors
            if s.name in cameras and s.mount_body is None and getattr(s, "camera", None) is None
        ]
        self.randomizer = Randomizer(scene, self.model, fixed)
        """The scene's seeded randomisation (:mod:`openral_sim.randomization`)."""
        self._arm_qpos = addresses.qpos[addresses.arm_slots]
        fingers = [int(a) for g in addresses.grippers for a in g.finger_qpos]
        self.task = TaskJudge(scene, self.model, fingers, self.wiring.tcp)
        """Success, rewards and horizon (:mod:`openral_sim.task_judge`)."""
        self.horizon = self.task.horizon
        options = scene.scene.options
        self._objects = {
            obj.name: mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{obj.name}")
            for obj in (options.objects if options and options.objects else [])
        }

    # -- SimRollout ------------------------------------------------------------------------

    @property
    def action_dim(self) -> int:
        """One value per manifest joint."""
        return len(self.wiring.joint_names)

    @property
    def control_period_s(self) -> float:
        """Simulated time one step advances: ``substeps`` physics steps [s]."""
        return self.substeps * float(self.model.opt.timestep)

    @property
    def action_names(self) -> tuple[str, ...]:
        """The manifest joints, in manifest order."""
        return self.wiring.joint_names

    def hold_action(self) -> FloatArray:
        """The action in force now: arm targets and gripper commands (the start pose after a
        reset)."""
        return self.driver.hold_action(self.data)

    @property
    def camera_names(self) -> tuple[str, ...]:
        """Manifest sensor names this scene renders (into ``obs["images"]`` while
        :attr:`render_observations`, else by :meth:`render_cameras`)."""
        return tuple(self._sensors)

    @property
    def base_frame(self) -> str:
        """MJCF name of the robot's root body, the frame depth clouds are given in."""
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_BODY, self._root_body) or ""

    @functools.cached_property
    def frame_tree(self) -> FrameTree:
        """The TF frames of the robot and of the sensors this scene serves
        (:mod:`openral_sim.frame_tree`), laid out once.

        Raises:
            HalError: A layout a URDF tree cannot state, or two frames of one name.
        """
        return scene_frame_tree(self.model, self.robot, self.addresses, self._cameras, self.base)

    def frames(self) -> FrameTree:
        """:attr:`frame_tree` (the :class:`~openral_sim.rollout.SceneRollout` method)."""
        return self.frame_tree

    @property
    def depth_cameras(self) -> dict[str, DepthCamera]:
        """The depth sensors the scene file names, by sensor name."""
        return self.range_sensors.depth

    def depth_frame(
        self, name: str, data: mujoco.MjData, renderer: mujoco.Renderer | None = None
    ) -> DepthFrame:
        """Depth image and cloud of depth sensor ``name`` (see
        :meth:`openral_sim.range_sensors.RangeSensors.depth_frame`)."""
        return self.range_sensors.depth_frame(name, data, renderer)

    @property
    def image_size(self) -> tuple[int, int]:
        """(height, width) of every camera frame [px]: the scene's ``observation`` size."""
        return self._height, self._width

    @property
    def camera_models(self) -> dict[str, str]:
        """Sensor name → MJCF camera of the composed model."""
        return dict(self._sensors)

    def reset(self, seed: int | None = None) -> Observation:
        """Keyframe (if any) at the scene's base pose, the start pose held, then the
        manifest's settle steps, as ``MujocoArmHAL.connect`` does.

        The scene's ``randomization`` is drawn from ``seed`` (:mod:`openral_sim.randomization`);
        without one, every seed gives the same episode.
        """
        mujoco.mj_resetData(self.model, self.data)
        self.driver.reset_to_keyframe(self.model, self.data)
        if self.wiring.keyframe_index is not None and self.wiring.floating_base:
            self._place_floating_base()
        self.randomizer.apply(self.data, seed, self._arm_qpos)
        hold_base_where_it_is(self.model, self.data, self._root_body)
        self.driver.start(self.model, self.data)
        if self.base is not None:
            self.base.reset()
        self._advance(self.wiring.settle_steps_default)
        if self.base is not None:  # the odometry frame: where the base settled, exactly
            self.base.reset()
        self.task.reset(self.data)
        self._steps, self._part, self._outcome = 0, self.parts, Outcome()
        self.sensors.schedule.restart()
        return self._observe()

    def step(self, action: npt.NDArray[np.floating], *, glide: bool = False) -> StepResult:
        """Apply ``action`` (one value per manifest joint) for one control period; with
        ``glide`` the arm's set point moves to it at constant speed over the period, that
        speed fed forward (the next sample of a smooth path, see
        :class:`~openral_mujoco.joint_driver.JointDriver`). The outcome's ``success`` says
        whether the scene's ``success`` predicates all hold now (a sweep ends the episode on
        it; ``deploy sim`` does not: the world never resets under a ROS client by itself).

        Raises:
            ActionRejected: Wrong type, width, or a non-finite value; nothing is changed.
            SimulationDiverged: MuJoCo met a NaN/Inf state and reset it.
        """
        glide_s = self.control_period_s if glide else None
        self.driver.command(action, self.data, glide_s=glide_s)
        self._advance(self.substeps)
        self._part = self.parts
        return StepResult(self._observe(), self._period_ended())

    def step_part(self, action: FloatArray | None, *, glide: bool = False) -> StepResult:
        """One of the :attr:`parts` of a control period (they step it exactly as
        :meth:`step` does): ``action`` starts a new period with it (``glide`` as in
        :meth:`step`); None steps the next part of the period in force, or, once it has
        ended, starts the next one with the targets in force. The outcome is updated when a
        period ends.

        Raises:
            ActionRejected: As :meth:`step`; nothing is changed.
            SimulationDiverged: As :meth:`step`.
        """
        if action is not None or self._part >= self.parts:
            held = action is None
            command = self.hold_action() if held else action
            glide_s = self.control_period_s if glide and not held else None
            self.driver.command(command, self.data, glide_s=glide_s)
            self._part = 0
        self._advance(self.substeps // self.parts)
        self._part += 1
        ended = self._part == self.parts
        return StepResult(self._observe(), self._period_ended() if ended else self._outcome)

    def _period_ended(self) -> Outcome:
        """Count a control period and judge the episode (success, rewards)."""
        self._steps += 1
        self._outcome = self.task.judge(self.data, self.control_period_s, self._steps)
        return self._outcome

    def joint_state(self) -> JointStateSample:
        """Every manifest joint, in manifest order and units (as ``MujocoArmHAL`` reports)."""
        positions, velocities, efforts = self.driver.read(self.data)
        return JointStateSample(
            names=self.wiring.joint_names,
            positions=positions,
            velocities=velocities,
            efforts=efforts,
            stamp_ns=time.monotonic_ns(),
            sim_time_s=float(self.data.time),
        )

    def hold_current_pose(self) -> None:
        """Make the present pose the targets (after an E-stop, so nothing jumps)."""
        self.driver.hold_current_pose(self.data)

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The scene's live (model, data)."""
        return self.model, self.data

    def render_cameras(
        self,
        data: mujoco.MjData,
        sensors: Iterable[str] | None = None,
        renderer: mujoco.Renderer | None = None,
    ) -> dict[str, npt.NDArray[np.uint8]]:
        """Fresh frames (H x W x 3 uint8) of the cameras of ``sensors`` (default: all) as
        ``data`` places them, by sensor name.

        ``data`` must belong to this scene's model and hold the kinematics the cameras see
        (after ``mj_step``, ``mj_forward`` or ``mj_kinematics`` + ``mj_camlight``); it is only
        read. ``renderer``: one of :attr:`model` at :attr:`image_size`, created on the calling
        thread; None uses the scene's own (it belongs to the thread that first used it).

        Raises:
            KeyError: A sensor this scene does not render.
        """
        names = self.camera_names if sensors is None else tuple(sensors)
        return self.sensors.render(data, names, renderer)

    def close(self) -> None:
        """Free the offscreen renderers."""
        self.sensors.close()

    # -- internals -------------------------------------------------------------------------

    def _observe(self) -> Observation:
        wanted = self.observed if self.render_observations else frozenset()
        images, depth, scans, readings = self.sensors.due_frames(wanted)
        return Observation(
            time_s=float(self.data.time),
            joints=self.joint_state(),
            images=images,
            depth=depth,
            scans=scans,
            readings=readings,
            odometry=self.base.odometry() if self.base is not None else None,
            task_state=object_poses(self.data, self._objects),
        )

    def _advance(self, steps: int) -> None:
        """``steps`` physics steps; a mobile base's drive is updated before every
        :data:`BASE_UPDATE_STEPS` of them (the joint driver slews in chunks of that size
        too, so chunking changes nothing of the arm's motion)."""
        base, model, data = self.base, self.model, self.data
        timestep = float(model.opt.timestep)
        with sensors_skipped(model):  # read only after the last step: see sensor_skip
            if base is None:
                self.driver.advance(model, data, steps)
            while base is not None and steps > 0:
                chunk = min(steps, BASE_UPDATE_STEPS)
                base.update(chunk * timestep)
                self.driver.advance(model, data, chunk)
                steps -= chunk
        # mj_step leaves the poses (bodies, sites, cameras) of the state *before* its last
        # step: compute them, and the sensors, for the state the data now holds, so that
        # /tf, cameras, lidars and sensors show the instant they are stamped with (15 us
        # on the Panda; the trajectory is bit for bit the same).
        mujoco.mj_forward(model, data)

    def _place_floating_base(self) -> None:
        """Keyframe free-joint poses are world poses: move them to the scene's base pose
        (the robot's free joint; objects may have their own)."""
        place_floating_base(self.data, self._root_qpos, self.scene.base_pose)
