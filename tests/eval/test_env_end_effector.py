"""End-effector action modes of the env: the TCP moves as asked, inside every limit, and
a target out of reach stops at the workspace edge."""

from __future__ import annotations

from collections.abc import Iterator

import mujoco
import numpy as np
import pytest
from openral_core.models import LimitedJoint
from openral_eval.scene_env import SceneEnv, make_env
from openral_mujoco.errors import ActionRejected
from openral_sim import tcp_pose, tcp_sensors

from tests.conftest import ROBOTS

TABLETOP = ROBOTS / "franka_panda" / "scenes" / "tabletop.yaml"


@pytest.fixture(scope="module")
def panda() -> Iterator[SceneEnv]:
    env = make_env(TABLETOP, action_mode="ee_delta_pose", sensors=False)
    yield env
    env.close()


def _angle(q: np.ndarray, r: np.ndarray) -> float:
    """Angle between two unit quaternions [rad]."""
    return float(2 * np.arccos(min(1.0, abs(float(np.dot(q, r))))))


def _limits(env: SceneEnv) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    arm = [j for j in env.robot.description.joints if isinstance(j, LimitedJoint)][:7]
    low = np.array([j.position_limits[0] for j in arm])
    high = np.array([j.position_limits[1] for j in arm])
    speed = np.array([j.velocity_limit for j in arm])
    return low, high, speed


def test_deltas_move_the_tcp_a_centimetre_a_step_holding_its_orientation(panda: SceneEnv) -> None:
    obs, _ = panda.reset(seed=0)
    start = obs["observation.tcp_pose"]
    low, high, speed = _limits(panda)
    previous, moves, turns = start[:3], [], []
    for axis, sign in ((0, 1.0), (2, -1.0)):
        action = np.zeros(7)
        action[axis], action[6] = 0.2 * sign, -1.0  # 0.2 x 0.05 m = 1 cm a step; open
        for _ in range(20):  # the line: 20 of +x 0.2, then 20 of -z 0.2
            obs, *_ = panda.step(action)
            tcp = obs["observation.tcp_pose"]
            moves.append((tcp[:3] - previous) @ np.eye(3)[axis] * sign)
            previous = tcp[:3]
            turns.append(_angle(tcp[3:], start[3:]))
            q, v = obs["observation.state"][:7], obs["observation.velocity"][:7]
            assert np.all(q >= low) and np.all(q <= high)
            assert np.all(np.abs(v) <= speed)
    assert np.all(np.abs(np.array(moves) - 0.01) <= 0.002), np.round(moves, 4)
    assert max(turns) <= 0.01, max(turns)


@pytest.fixture(scope="module")
def panda_pose() -> Iterator[SceneEnv]:
    env = make_env(TABLETOP, action_mode="ee_pose", sensors=False)
    yield env
    env.close()


@pytest.mark.parametrize(
    ("x", "z"),
    [(1.05, None), (1.0, 0.1), (0.0, 1.05), (0.9, 0.9)],  # inside the reach box, out of reach
    ids=["ahead", "ahead-low", "above", "ahead-high"],
)
def test_a_pose_out_of_reach_stops_at_the_edge_and_does_not_wind_up(
    panda_pose: SceneEnv, x: float, z: float | None
) -> None:
    """Out and back again: without the IK's pull towards the start pose, two of these
    left the Panda straightened against joint 4's limit, 0.27 m from its start."""
    env = panda_pose
    obs, _ = env.reset(seed=0)
    start = obs["observation.tcp_pose"].copy()
    low, high, speed = _limits(env)
    far = np.concatenate([[x, 0.0, start[2] if z is None else z], start[3:], [1.0]])
    path = []
    for _ in range(100):  # 5 s
        obs, *_ = env.step(far)
        q, v = obs["observation.state"][:7], obs["observation.velocity"][:7]
        assert np.all(q >= low) and np.all(q <= high)
        assert np.all(np.abs(v) <= speed)
        path.append(obs["observation.tcp_pose"][:3].copy())
    assert np.linalg.norm(path[-1] - path[-5]) < 0.002  # stopped
    gone = np.linalg.norm(start[:3] - far[:3]) - np.linalg.norm(path[-1] - far[:3])
    assert gone > 0.1  # having gone towards it as far as it could
    back = np.concatenate([start, [1.0]])
    for _ in range(60):  # 3 s
        obs, *_ = env.step(back)
    assert np.linalg.norm(obs["observation.tcp_pose"][:3] - start[:3]) < 0.01


def test_modes_the_scene_or_robot_cannot_take_are_one_clear_error() -> None:
    with pytest.raises(ValueError, match="unknown ee preset 'libero'; valid: robosuite, maniskill"):
        make_env(TABLETOP, action_mode="ee_delta_pose", ee_preset="libero")
    robosuite = ROBOTS / "franka_panda" / "scenes" / "lift_robosuite.yaml"
    with pytest.raises(ValueError, match="ee_pose needs a native scene"):
        make_env(robosuite, action_mode="ee_pose")
    ur5e = ROBOTS / "ur5e" / "scenes" / "tabletop.yaml"  # no gripper: no tool centre point
    with pytest.raises(ValueError, match=r"sim\.tcp"):
        make_env(ur5e, action_mode="ee_delta_pose")


def test_a_five_joint_arm_puts_its_tcp_where_asked_first() -> None:
    """The so101 (5 arm joints) cannot hold any pose: asked for position and orientation,
    it reaches the position (the tool frame from its sim.tcp quat_wxyz points along the jaws)."""
    env = make_env(
        ROBOTS / "so101" / "scenes" / "tabletop.yaml", action_mode="ee_delta_pose", sensors=False
    )
    try:
        env.reset(seed=0)
        down = np.array([0.0, 0.0, -0.1, 0.0, 0.0, 0.0, -1.0])  # 5 mm a step down
        for _ in range(3):  # the arm's servos still settle under gravity after the reset
            obs, *_ = env.step(down)
        start = obs["observation.tcp_pose"][:3].copy()
        for _ in range(8):
            obs, *_ = env.step(down)
        moved = obs["observation.tcp_pose"][:3] - start
        assert abs(moved[2] + 0.04) < 0.005 and np.linalg.norm(moved[:2]) < 0.005, moved
    finally:
        env.close()


@pytest.mark.parametrize("mode", ["ee_delta_pose", "ee_pose"])
@pytest.mark.parametrize("robot", ["franka_panda", "panda_mobile", "so101"])
def test_gymnasium_check_env_passes_in_end_effector_modes(robot: str, mode: str) -> None:
    from gymnasium.utils.env_checker import check_env

    env = make_env(ROBOTS / robot / "scenes" / "tabletop.yaml", action_mode=mode, sensors=False)
    try:
        check_env(env, skip_render_check=True)
        base = ("base_vx_m_s", "base_vy_m_s", "base_wz_rad_s") if robot == "panda_mobile" else ()
        assert env.action_names[-len(base) or None :] == base or not base
    finally:
        env.close()


def test_an_ee_pose_without_an_orientation_is_refused_and_nothing_moves() -> None:
    env = make_env(TABLETOP, action_mode="ee_pose", sensors=False)
    try:
        obs, _ = env.reset(seed=0)
        before = env.hal.read_state()
        zero = np.concatenate([obs["observation.tcp_pose"][:3], np.zeros(4), [1.0]])
        with pytest.raises(ActionRejected, match=r"quaternion \(qw, qx, qy, qz\) has norm 0"):
            env.step(zero)
        after = env.hal.read_state()
        assert after.sim_time_s == before.sim_time_s
        np.testing.assert_array_equal(after.positions, before.positions)
        obs, *_ = env.step(
            np.concatenate([obs["observation.tcp_pose"], [1.0]])
        )  # a good one still works
        assert np.linalg.norm(obs["observation.tcp_pose"][:3] - zero[:3]) < 0.01
    finally:
        env.close()


@pytest.mark.parametrize(
    "scene",
    [
        TABLETOP,
        ROBOTS / "panda_mobile" / "scenes" / "room.yaml",
        ROBOTS / "so101" / "scenes" / "tabletop.yaml",
    ],
)
@pytest.mark.parametrize("read", ["sensors", "composed"])
def test_the_observed_tcp_pose_is_the_iks_own_tcp_in_the_base_frame(
    scene: object, read: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``tcp_vector`` (in every observation) against mink's composition the IK itself uses
    (base frame inverse times the TCP frame and flange), on random arm poses: read from the
    scene's TCP sensors, and composed from rows of the data as for a model without them.
    panda_mobile's arm root is offset from its base and moves; so101's TCP is on a site."""
    if read == "composed":  # a model without the sensors: the reader finds none
        monkeypatch.setattr(tcp_pose, "TCP_SENSORS", ("no_such_sensor", "nor_this_one"))
    env = make_env(scene, action_mode="ee_pose", sensors=False)
    try:
        env.reset(seed=0)
        command = env.actions.ee
        assert command is not None
        model, data = env.hal.mujoco_handles()
        reader = tcp_pose.TcpReader(command.ee, command.frames, data)
        assert (reader._sensors is not None) is (read == "sensors")
        arm = command.ee._arm_qpos
        rng = np.random.default_rng(3)
        for _ in range(20):
            data.qpos[arm] = model.qpos0[arm] + rng.uniform(-0.5, 0.5, len(arm))
            mujoco.mj_forward(model, data)  # what every scene step ends with
            mine = command.tcp_vector(data)
            np.testing.assert_array_equal(mine, reader.read())
            theirs = (
                command.base(data)
                .inverse()
                .multiply(command.ee.commanded_pose(data, data.qpos[arm]))
            )
            np.testing.assert_allclose(mine[:3], theirs.translation(), atol=1e-12)
            quat = theirs.rotation().wxyz  # a rotation has two quaternions: q and -q
            assert min(np.abs(mine[3:] - quat).max(), np.abs(mine[3:] + quat).max()) < 1e-12
    finally:
        env.close()


def test_the_tcp_site_is_drawn_by_no_camera() -> None:
    """The TCP's site sits in a group MuJoCo's default visual options leave out, so the
    scene's pictures are what they were before it."""
    env = make_env(TABLETOP, sensors=False)
    try:
        model, _ = env.hal.mujoco_handles()
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, tcp_sensors.TCP_SITE)
        assert site >= 0
        assert mujoco.MjvOption().sitegroup[model.site_group[site]] == 0
    finally:
        env.close()
