"""build_hal: which HAL a loaded robot gets, the real-driver contract and can_tick.

The real drivers here are small honest fakes: one conforms to ``RobotHal``; the others
break the contract in one way each (not a HAL, idle-steppable, not real).
"""

from __future__ import annotations

import re
import time
from pathlib import Path
from typing import Any, ClassVar

import mujoco
import numpy as np
import numpy.typing as npt
import pytest
from openral_core import LoadedRobot, open_robot, open_robot_by_id
from openral_core.errors import ManifestError
from openral_core.loader import load_scene
from openral_core.models import DeployScene, RobotDescription
from openral_hal.errors import ConfigurationError, EStopLatched
from openral_hal.factory import (
    HalMode,
    RealOptions,
    build_hal,
    can_tick,
    register_real_driver,
)
from openral_hal.mujoco_arm import MujocoArmHAL
from openral_hal.protocol import EStopLatch, RobotHal, Tickable
from openral_hal.sim_attached import SimAttachedHAL
from openral_mujoco.state import FloatArray, JointStateSample
from openral_sim.observation import Observation, StepResult
from openral_sim.rollout import SimRollout

from tests.sim_attach.fake_arm import NO_SENSORS, write_fake_arm

SCENE_YAML = """\
schema_version: "0.1"
robot_id: {robot}
seed: 7
scene: {{id: t, backend: native, observation: {{width: 32, height: 32}}, cameras: []}}
"""


class RealArm(EStopLatch):
    """A conforming real driver: holds what it is told, refuses while E-stopped."""

    is_real = True

    def __init__(self, robot: LoadedRobot, transport: str | None, options: RealOptions) -> None:
        self._description, self.transport, self.options = robot.description, transport, options
        self._positions = np.zeros(len(robot.description.joints))
        self._connected = False

    @property
    def description(self) -> RobotDescription:
        return self._description

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(joint.name for joint in self._description.joints)

    @property
    def action_names(self) -> tuple[str, ...]:
        return self.joint_names

    @property
    def connected(self) -> bool:
        return self._connected

    def connect(self) -> None:
        self._connected = True

    def disconnect(self) -> None:
        self._connected = False

    def read_state(self) -> JointStateSample:
        zeros = np.zeros_like(self._positions)
        return JointStateSample(
            self.joint_names, self._positions.copy(), zeros, zeros, time.monotonic_ns()
        )

    def hold_action(self) -> FloatArray:
        return self._positions.copy()

    def send_action(self, action: object) -> None:
        self._refuse_when_estopped()
        self._positions = np.asarray(action, dtype=np.float64)


class SteppingRealArm(RealArm):
    """Breaks the contract: a real HAL that a control loop could tick."""

    control_period_s = 0.02

    def tick(self, action: object | None, *, glide: bool = False) -> bool:
        return True

    def reset(self) -> str:
        return "reset"


class SimulatedArm(RealArm):
    """Breaks the contract: registered as a real driver but not real."""

    is_real = False


class UnreadyArm(RealArm):
    """Breaks the contract: a property that raises before connect()."""

    @property
    def action_names(self) -> tuple[str, ...]:
        raise RuntimeError("no bus yet")


class NotAHal:
    """Breaks the contract: no HAL at all."""

    def __init__(self, robot: LoadedRobot, transport: str | None, options: RealOptions) -> None:
        self.description = robot.description


class StillRollout:
    """A scene backend that reports joint positions and never moves."""

    action_dim = 2
    camera_names: tuple[str, ...] = ()
    camera_models: ClassVar[dict[str, str]] = {}
    control_period_s = 0.05

    def reset(self, seed: int | None = None) -> Observation:
        positions, zeros = np.array([0.1, 0.2]), np.zeros(2)
        return Observation(0.0, JointStateSample(("a", "b"), positions, zeros, zeros, 0))

    def step(self, action: npt.NDArray[np.floating[Any]]) -> StepResult:
        return StepResult(self.reset())

    def mujoco_handles(self) -> tuple[mujoco.MjModel, mujoco.MjData] | None:
        return None

    def close(self) -> None:
        pass


@pytest.fixture
def arm(tmp_path: Path) -> LoadedRobot:
    return open_robot(write_fake_arm(tmp_path, NO_SENSORS))


def scene_for(tmp_path: Path, robot: str) -> DeployScene:
    path = tmp_path / "scene.yaml"
    path.write_text(SCENE_YAML.format(robot=robot))
    return load_scene(path)


@pytest.fixture
def no_drivers(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    drivers: dict[str, Any] = {}
    monkeypatch.setattr("openral_hal.factory.REAL_DRIVERS", drivers)
    return drivers


def test_sim_without_a_scene_gives_the_bare_twin() -> None:
    hal = build_hal(open_robot_by_id("franka_panda"), mode=HalMode.SIM)
    assert isinstance(hal, MujocoArmHAL) and isinstance(hal, RobotHal)
    hal.connect()  # isinstance on a Protocol reads its properties (Python 3.11)
    assert hal.is_real is False and can_tick(hal)  # the robot alone is ticked too
    assert hal.control_period_s == pytest.approx(0.02)


def test_sim_with_a_scene_attaches_to_what_the_builder_makes_of_the_loaded_objects(
    tmp_path: Path, arm: LoadedRobot
) -> None:
    scene = scene_for(tmp_path, "fake_arm")
    calls: list[tuple[DeployScene, LoadedRobot]] = []

    def builder(given_scene: DeployScene, robot: LoadedRobot) -> SimRollout:
        calls.append((given_scene, robot))
        return StillRollout()

    hal = build_hal(arm, mode="sim", scene=scene, env_builder=builder)
    assert isinstance(hal, SimAttachedHAL) and hal.env_reset_seed == 7
    assert len(calls) == 1 and calls[0][0] is scene and calls[0][1] is arm
    hal.connect()  # isinstance on a Protocol reads its properties (Python 3.11)
    assert can_tick(hal) and isinstance(hal, Tickable)
    assert hal.read_state().names == ("joint1", "joint2")


def test_a_scene_for_another_robot_is_one_located_error(tmp_path: Path, arm: LoadedRobot) -> None:
    scene = scene_for(tmp_path, "ur5e")

    def builder(given_scene: DeployScene, robot: LoadedRobot) -> SimRollout:
        raise AssertionError("the scene must be refused before anything is built")

    with pytest.raises(ManifestError) as raised:
        build_hal(arm, mode="sim", scene=scene, env_builder=builder)
    file = re.escape(str(tmp_path / "scene.yaml"))
    pattern = rf"{file}:2:\d+: robot_id: the scene is for ur5e, not fake_arm"
    assert re.fullmatch(pattern, str(raised.value))


def test_real_never_attaches_a_scene(tmp_path: Path, arm: LoadedRobot) -> None:
    with pytest.raises(ConfigurationError, match="real robot cannot attach"):
        build_hal(arm, mode="real", scene=scene_for(tmp_path, "fake_arm"))


def test_real_without_a_driver_names_the_robot_and_the_registered_ones(
    arm: LoadedRobot, no_drivers: dict[str, Any]
) -> None:
    no_drivers["other_arm"] = RealArm
    with pytest.raises(ConfigurationError, match="no real driver registered for fake_arm") as e:
        build_hal(arm, mode="real")
    assert "registered: other_arm" in str(e.value)


def test_a_conforming_real_driver_is_built_with_the_transport_and_drives(
    arm: LoadedRobot, no_drivers: dict[str, Any]
) -> None:
    register_real_driver("fake_arm", RealArm)
    assert no_drivers == {"fake_arm": RealArm}
    hal = build_hal(arm, mode=HalMode.REAL, transport="can0")
    assert isinstance(hal, RealArm) and hal.transport == "can0"
    assert hal.description is arm.description and not can_tick(hal)
    hal.connect()
    hal.send_action([0.5, -0.5])
    assert hal.read_state().positions.tolist() == [0.5, -0.5]
    hal.estop()
    with pytest.raises(EStopLatched):
        hal.send_action([0.0, 0.0])
    assert hal.hold_action().tolist() == [0.5, -0.5]


@pytest.mark.parametrize(
    ("driver", "problem"),
    [
        (NotAHal, "(NotAHal) does not implement openral_hal.protocol.RobotHal"),
        (SteppingRealArm, "(SteppingRealArm) has tick(); a real HAL must never be stepped"),
        (SimulatedArm, "(SimulatedArm) reports is_real=False; a real HAL is real"),
        (UnreadyArm, "(UnreadyArm): a property raised RuntimeError before connect(): no bus yet"),
    ],
)
def test_a_driver_breaking_the_contract_is_one_line(
    arm: LoadedRobot, no_drivers: dict[str, Any], driver: type, problem: str
) -> None:
    no_drivers["fake_arm"] = driver
    with pytest.raises(ConfigurationError) as raised:
        build_hal(arm, mode="real")
    message = str(raised.value)
    assert message.startswith(f"the real driver of fake_arm {problem}")
    assert "\n" not in message


def test_is_real_wins_over_tick() -> None:
    stepping = SteppingRealArm(open_robot_by_id("franka_panda"), None, RealOptions())
    assert isinstance(stepping, Tickable) and not can_tick(stepping)


@pytest.mark.parametrize("mode", ["replay", "SIM", ""])
def test_an_unknown_mode_is_refused(arm: LoadedRobot, mode: str) -> None:
    with pytest.raises(ConfigurationError, match=rf"unknown HAL mode '{mode}'"):
        build_hal(arm, mode=mode)
