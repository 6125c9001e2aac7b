"""IMU, force-torque and pose sensors of the native scenes, read from MuJoCo's sensors.

- The Panda and the UR5e holding still: |wrist force| = weight of the bodies beyond the
  sensor (the site body's subtree mass in the robot's own model, times 9.81) within 2 %.
- The UR10e reads the model's own ``force``/``torque`` sensors at its TCP site.
- g1 and h1, welded in their default scenes: the pelvis IMU reads 9.81 ± 0.05 m/s² along
  its up axis and an angular velocity within ±0.01 rad/s; its orientation is the pelvis's.
- Reading changes nothing: two runs, one reading every step, are bit for bit equal; nor
  does skipping the sensors between control periods (the scene computes them once, at
  the end of each).
- ``robot check`` names a wrong MJCF sensor (unknown, wrong type, elsewhere, or named at a
  site the scene creates) at its line and column, with the closest names.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
from openral_cli.main import app
from openral_core import open_robot_by_id
from openral_core.loaded import open_robot
from openral_core.loader import load_scene
from openral_mujoco.mjcf_uri import resolve_mjcf_uri
from openral_sim.native_scene import NativeScene
from openral_sim.scene import build_scene
from openral_sim.state_sensors import ImuReading, PoseReading, WrenchReading
from typer.testing import CliRunner

from tests.conftest import ROBOTS, ManifestWriter

GRAVITY = 9.81
HOLD_STEPS = 40
"""Control steps (2 s at 20 Hz) the robot holds still before it is read."""
runner = CliRunner()


def scene(robot_id: str) -> NativeScene:
    robot = open_robot_by_id(robot_id)
    built = build_scene(load_scene(ROBOTS / robot_id / "scenes" / "tabletop.yaml"), robot)
    assert isinstance(built, NativeScene)
    built.render_observations = False
    built.reset(seed=0)
    return built


def held(robot_id: str) -> NativeScene:
    env = scene(robot_id)
    hold = env.hold_action()
    for _ in range(HOLD_STEPS):
        env.step(hold)
    return env


def weight_beyond(robot_id: str, site: str, body: str | None) -> float:
    """Weight [N] of the site body's subtree in the robot's own model (not the scene's)."""
    robot = open_robot_by_id(robot_id).description
    assert robot.sim is not None
    model = mujoco.MjModel.from_xml_path(str(resolve_mjcf_uri(robot.sim.mjcf_uri)))
    if body is None:
        index = model.site_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)]
    else:
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    return float(model.body_subtreemass[index]) * GRAVITY


@pytest.mark.parametrize(
    ("robot_id", "site", "body"),
    [("franka_panda", "ft_sensor", "hand"), ("ur5e", "attachment_site", None)],
)
def test_a_still_wrist_sensor_reads_the_weight_beyond_it(
    robot_id: str, site: str, body: str | None
) -> None:
    reading = held(robot_id).state_sensors.read("wrist_ft", held(robot_id).data)
    assert isinstance(reading, WrenchReading)
    weight = weight_beyond(robot_id, site, body)
    assert weight > 1.0
    print(f"{robot_id}: |F| {np.linalg.norm(reading.force):.4f} N, weight {weight:.4f} N")
    assert np.linalg.norm(reading.force) == pytest.approx(weight, rel=0.02)


def test_the_ur10e_reads_its_models_own_force_and_torque_sensors() -> None:
    env = held("ur10e")
    reading = env.state_sensors.read("wrist_ft", env.data)
    assert isinstance(reading, WrenchReading)
    model, data = env.model, env.data
    for name, value in (("force", reading.force), ("torque", reading.torque)):
        index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
        adr = model.sensor_adr[index]
        assert np.array_equal(value, data.sensordata[adr : adr + 3])
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "wrist_ft_force") < 0


@pytest.mark.parametrize("robot_id", ["g1", "h1"])
def test_a_welded_pelvis_imu_reads_gravity_up_and_no_rotation(robot_id: str) -> None:
    env = held(robot_id)
    reading = env.state_sensors.read("pelvis_imu", env.data)
    assert isinstance(reading, ImuReading)
    site = env.state_sensors.sensors["pelvis_imu"].site
    index = mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_SITE, site)
    up = env.data.site_xmat[index].reshape(3, 3).T @ np.array([0.0, 0.0, 1.0])  # in its frame
    along_up = float(reading.linear_acceleration @ up)
    print(
        f"{robot_id}: acceleration {reading.linear_acceleration.round(4)}, gyro "
        f"{reading.angular_velocity.round(5)}"
    )
    assert along_up == pytest.approx(GRAVITY, abs=0.05)
    assert np.abs(reading.angular_velocity).max() < 0.01
    wxyz = np.empty(4)
    mujoco.mju_mat2Quat(wxyz, env.data.site_xmat[index])
    xyzw = np.array([*wxyz[1:], wxyz[0]])
    assert (
        min(
            np.abs(reading.orientation_xyzw - xyzw).max(),
            np.abs(reading.orientation_xyzw + xyzw).max(),
        )
        < 1e-6
    )


def test_reading_changes_nothing_in_the_simulation() -> None:
    plain, read = scene("franka_panda"), scene("franka_panda")
    hold = plain.hold_action()
    for _ in range(10):
        plain.step(hold)
        read.step(hold)
        read.state_sensors.read("wrist_ft", read.data)
    for field in ("qpos", "qvel", "qacc_warmstart", "sensordata"):
        assert np.array_equal(getattr(plain.data, field), getattr(read.data, field)), field


def test_a_pose_sensor_reads_its_site_in_the_world(write_manifest: ManifestWriter) -> None:
    line = (
        "  - {name: tool_pose, kind: pose, site: attachment_site, rate_hz: 50.0,"
        " frame_id: tool_pose_frame}"
    )
    manifest = write_manifest(
        ("sensors:\n", f"sensors:\n{line}\n"), base=ROBOTS / "ur5e" / "robot.yaml", folder="ur5e"
    )
    robot = open_robot(manifest)
    env = build_scene(load_scene(ROBOTS / "ur5e" / "scenes" / "tabletop.yaml"), robot)
    assert isinstance(env, NativeScene)
    env.render_observations = False
    env.reset(seed=0)
    env.step(env.hold_action())
    reading = env.state_sensors.read("tool_pose", env.data)
    assert isinstance(reading, PoseReading)
    index = mujoco.mj_name2id(env.model, mujoco.mjtObj.mjOBJ_SITE, "attachment_site")
    assert np.allclose(reading.position, env.data.site_xpos[index], atol=1e-9)
    assert abs(np.linalg.norm(reading.orientation_xyzw) - 1.0) < 1e-9
    assert reading.sim_time_s == env.data.time


CHECKS = {
    "unknown": (
        ("site: TCP\n    force: force", "site: TCP\n    force: forse"),
        [
            [
                "sensors[2].force",
                "forse, a force at site TCP",
                "not in the model (did you mean force?)",
            ]
        ],
    ),
    "type": (
        ("site: TCP\n    force: force", "site: TCP\n    force: torque"),
        [["sensors[2].force", "torque, a force at site TCP", "a torque sensor"]],
    ),
    "site": (
        ("site: TCP\n    force: force", "site: flange\n    force: force"),
        [
            ["sensors[2].force", "force, a force at site flange", "a sensor at TCP"],
            ["sensors[2].torque", "torque, a torque at site flange", "a sensor at TCP"],
        ],
    ),
    "named at a created site": (
        ("mount_body: pelvis,", "mount_body: pelvis, gyro: imu-gyro,"),
        [
            [
                "sensors[3].gyro",
                "imu-gyro, a gyro at site imu_in_pelvis",
                "a site the scene creates (leave it out: the scene adds the sensor)",
            ]
        ],
    ),
}


@pytest.mark.parametrize("case", CHECKS)
def test_robot_check_locates_a_wrong_mjcf_sensor(write_manifest: ManifestWriter, case: str) -> None:
    edit, expected = CHECKS[case]
    robot_id = "h1" if case == "named at a created site" else "ur10e"
    manifest = write_manifest(edit, base=ROBOTS / robot_id / "robot.yaml", folder=robot_id)
    result = runner.invoke(app, ["robot", "check", str(manifest)], env={"COLUMNS": "250"})
    assert result.exit_code == 1
    rows = [
        [cell.strip() for cell in line.split("│")]
        for line in result.stdout.splitlines()
        if "MISMATCH" in line
    ]
    assert [row[2:5] for row in rows] == expected
    assert all(row[1].startswith(f"{Path('robot.yaml')}:") for row in rows)


def test_skipping_the_sensors_between_control_periods_changes_nothing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A scene computes its sensors only at the end of a control period: the state and
    every sensor value then are bit for bit those of a scene that computed them at every
    physics step (a mobile base too: g1's IMU, panda_mobile's base drive)."""
    import contextlib

    from openral_sim import native_scene

    for robot_id in ("franka_panda", "g1", "panda_mobile"):
        skipping = scene(robot_id)
        monkeypatch.setattr(native_scene, "sensors_skipped", lambda _: contextlib.nullcontext())
        every_step = scene(robot_id)
        monkeypatch.undo()
        rng = np.random.default_rng(0)
        hold = skipping.hold_action()
        for _ in range(10):
            action = hold + rng.uniform(-0.05, 0.05, hold.shape)
            skipping.step(action)
            every_step.step(action)
            for field in ("qpos", "qvel", "qacc_warmstart", "sensordata"):
                mine, theirs = getattr(skipping.data, field), getattr(every_step.data, field)
                assert np.array_equal(mine, theirs), (robot_id, field)
        assert int(skipping.model.opt.disableflags) == int(every_step.model.opt.disableflags)


def test_a_model_with_its_sensors_off_keeps_them_off_and_an_error_restores_the_flags() -> None:
    from openral_mujoco.sensor_skip import sensors_skipped

    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody/></mujoco>")
    off = int(mujoco.mjtDisableBit.mjDSBL_SENSOR)
    with sensors_skipped(model):
        assert model.opt.disableflags & off
    assert not model.opt.disableflags & off
    model.opt.disableflags = off | int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
    with pytest.raises(RuntimeError), sensors_skipped(model):
        raise RuntimeError("a step diverged")
    assert model.opt.disableflags == off | int(mujoco.mjtDisableBit.mjDSBL_GRAVITY)
