"""Self-collision avoidance of the end-effector IK (``sim.ik_collision_pairs``): on the
Panda, a target that folds the hand into its base stops at the margin with the pairs and
goes through the base's links without them; the pairs are built from the manifest's bodies
and a missing body is one error naming the field."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest
from openral_core.loaded import LoadedRobot
from openral_eval import make_env
from openral_mujoco.errors import HalError
from openral_sim.self_collision import collision_limit

SCENE = "robots/franka_panda/scenes/tabletop.yaml"
FOLDING = np.array([-0.1, 0.15, 0.15, 0.0, 1.0, 0.0, 0.0, 1.0])
"""An ee_pose (base frame, pointing down, gripper open) behind the arm's own shoulder."""


def _with_pairs(robot: LoadedRobot, pairs: tuple[tuple[tuple[str, ...], ...], ...]) -> LoadedRobot:
    wiring = robot.tables.hal_wiring
    assert wiring is not None
    wiring = dataclasses.replace(wiring, ik_collision_pairs=pairs)  # type: ignore[arg-type]
    return dataclasses.replace(robot, tables=dataclasses.replace(robot.tables, hal_wiring=wiring))


def _closest_approach(strip: bool, shift_m: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> float:
    """The smallest distance [m] between the hand group and the base's links the IK's
    commanded configuration reaches over 150 steps towards :data:`FOLDING` moved by
    ``shift_m``."""
    env = make_env(SCENE, action_mode="ee_pose", seed=0, sensors=False, max_steps=1000)
    try:
        ik = env.unwrapped.actions.ee.ee  # type: ignore[attr-defined]
        model = env.unwrapped.hal.mujoco_handles()[0]  # type: ignore[attr-defined]
        gauge = collision_limit(model, env.unwrapped.robot)  # type: ignore[attr-defined]
        assert gauge is not None
        if strip:
            ik._collisions = None
        env.reset(seed=0)
        closest = np.inf
        for _ in range(150):
            env.step(FOLDING + np.array([*shift_m, 0, 0, 0, 0, 0]))
            data = ik.configuration.data
            closest = min(closest, min(gauge._distance(data, a, b) for a, b in gauge.pairs))
        return float(closest)
    finally:
        env.close()


def test_the_hand_stops_at_the_margin_and_goes_through_without_the_pairs() -> None:
    deepest = (0.05, 0.0, -0.05)  # of these, the one that goes deepest without the pairs
    shifts = [(0, 0, 0), (0, -0.05, 0), (0.05, 0, 0.05), (-0.03, 0.03, -0.03), deepest]
    with_pairs = min(_closest_approach(strip=False, shift_m=shift) for shift in shifts)
    without = _closest_approach(strip=True, shift_m=deepest)
    print(f"closest approach: {with_pairs:.4f} m with the pairs, {without:.4f} m without")
    assert with_pairs >= 0.01 - 1e-3  # the manifest's margin, to a millimetre
    assert without < 0.0  # the same target drives the hand into the arm's links


def test_pairs_come_from_the_manifest_bodies() -> None:
    env = make_env(SCENE, sensors=False)
    try:
        model: mujoco.MjModel = env.unwrapped.hal.mujoco_handles()[0]  # type: ignore[attr-defined]
        robot: LoadedRobot = env.unwrapped.robot  # type: ignore[attr-defined]
    finally:
        env.close()
    limit = collision_limit(model, robot)
    assert limit is not None and limit.margin_m == 0.01
    bodies = {model.body(model.geom_bodyid[g]).name for pair in limit.pairs for g in pair}
    assert bodies == {"hand", "left_finger", "right_finger", "link0", "link1", "link2", "link3"}
    welded = _with_pairs(robot, ((("hand",), ("link7",)),))  # parent and child only
    assert collision_limit(model, welded) is None
    missing = _with_pairs(robot, ((("hand",), ("link9",)),))
    with pytest.raises(HalError, match=r"sim\.ik_collision_pairs\[0\]\.avoid: .* no body 'link9'"):
        collision_limit(model, missing)
