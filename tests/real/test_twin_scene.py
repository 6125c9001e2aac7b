"""The twin scene of a real robot (``deploy real --twin``): posed at the measured joints, it
renders what the simulated scene renders at the same joints, and a path into its table is
refused naming the pair while a path above it passes."""

from __future__ import annotations

import numpy as np
import pytest
from openral_core.errors import OpenralError
from openral_core.loaded import LoadedRobot, open_robot_by_id
from openral_core.loader import load_scene
from openral_core.models import Backend, DeployScene
from openral_real.kinematic_twin import KinematicTwin, twin_for
from openral_sim.scene import build_scene

from tests.conftest import ROBOTS

TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


@pytest.fixture(scope="module")
def panda() -> LoadedRobot:
    return open_robot_by_id("franka_panda")


@pytest.fixture(scope="module")
def scene() -> DeployScene:
    return load_scene(TABLETOP)


@pytest.fixture(scope="module")
def twin(panda: LoadedRobot, scene: DeployScene) -> KinematicTwin:
    return KinematicTwin(panda, scene)


def _home(twin: KinematicTwin) -> np.ndarray:
    """The Panda's home joints (the scene's reset pose), gripper open in metres."""
    return np.array(twin.data.qpos[twin._qpos], dtype=np.float64)


def _posed(twin: KinematicTwin, joints: np.ndarray) -> None:
    zeros = np.zeros(len(joints))
    twin.pose(joints, zeros, zeros, 0.0)


def test_a_path_into_the_table_is_refused_naming_the_pair(twin: KinematicTwin) -> None:
    home = _home(twin)
    _posed(twin, home)
    down = home.copy()
    down[1], down[3] = 1.5, -1.0  # shoulder forward, elbow open: the hand reaches down
    line = twin.first_contact(down[None, :])
    assert line is not None and "\n" not in line
    assert "scene_table" in line
    assert any(link in line for link in ("hand", "finger", "link7", "link6")), line
    np.testing.assert_array_equal(twin.posed, home)  # screening moves nothing
    np.testing.assert_array_equal(twin.data.qpos[twin._qpos], home)


def test_a_path_above_the_table_passes(twin: KinematicTwin) -> None:
    home = _home(twin)
    _posed(twin, home)
    turned = home.copy()
    turned[0] += 0.6  # the base joint turns the arm over the table
    turned[6] -= 0.5
    assert twin.first_contact(np.vstack([turned, home])) is None


def test_nothing_is_screened_before_the_first_reading(
    panda: LoadedRobot, scene: DeployScene
) -> None:
    fresh = KinematicTwin(panda, scene)
    down = _home(fresh)
    down[1] = 1.5
    assert fresh.first_contact(down[None, :]) is None  # posed by the first reading first


def test_without_a_scene_nothing_is_refused(panda: LoadedRobot) -> None:
    alone = twin_for(panda, None)
    assert alone is not None and alone.sensors is None
    home = _home(alone)
    _posed(alone, home)
    down = home.copy()
    down[1] = 1.5
    assert alone.first_contact(down[None, :]) is None


def test_a_robosuite_scene_is_no_twin(panda: LoadedRobot, scene: DeployScene) -> None:
    other = scene.model_copy(
        update={"scene": scene.scene.model_copy(update={"backend": Backend.robosuite})}
    )
    with pytest.raises(OpenralError) as raised:  # a located scene error, or "not native"
        KinematicTwin(panda, other)
    assert "\n" not in str(raised.value)


def test_its_cameras_show_what_the_scene_shows_at_the_same_joints(
    twin: KinematicTwin, panda: LoadedRobot, scene: DeployScene
) -> None:
    joints = _home(twin)
    joints[0] += 0.4
    joints[3] += 0.3
    _posed(twin, joints)
    twin_frames = _frames(twin.sensors)
    simulated = build_scene(scene, panda, render_observations=False)
    simulated.reset(scene.seed)
    model, data = simulated.mujoco_handles()
    data.qpos[twin._qpos] = joints
    for _, others in twin._fingers:
        data.qpos[others] = joints[-1]
    import mujoco

    mujoco.mj_forward(model, data)
    sim_frames = _frames(simulated.sensors)
    assert twin_frames.keys() == sim_frames.keys() and twin_frames
    for name, frame in twin_frames.items():
        difference = np.abs(frame.astype(int) - sim_frames[name].astype(int)).mean()
        assert difference < 1.0, f"{name}: mean difference {difference:.2f} of 255"
    home = _home(KinematicTwin(panda, scene))
    _posed(twin, home)
    moved = _frames(twin.sensors)
    assert np.abs(moved["wrist"].astype(int) - twin_frames["wrist"].astype(int)).mean() > 2.0


def _frames(sensors: object) -> dict[str, np.ndarray]:
    """One frame of each camera the sensors serve."""
    capture = sensors.camera_capture()  # type: ignore[attr-defined]
    developer = capture.open()
    try:
        frames = {}
        for name in capture.sensors:
            capture.snapshot(name)
            frames[name] = np.array(developer.develop(name))
        return frames
    finally:
        developer.close()


def test_the_feetech_driver_serves_its_twin_scenes_cameras_and_one_source_each() -> None:
    from openral_hal.errors import ConfigurationError
    from openral_hal.factory import RealOptions
    from openral_real.feetech_hal import FeetechHal

    so101 = open_robot_by_id("so101")
    scene = load_scene(ROBOTS / "so101" / "scenes" / "tabletop.yaml")
    hal = FeetechHal(so101, "/dev/null", RealOptions(twin_scene=scene))  # nothing opened
    assert set(hal.camera_sensors()) == {"front", "wrist"}
    assert hal.mujoco_handles() is None  # the twin is posed once connected
    both = RealOptions(twin_scene=scene, cameras={"front": "/dev/video0"})
    with pytest.raises(ConfigurationError, match="camera front has a device"):
        FeetechHal(so101, "/dev/null", both)
