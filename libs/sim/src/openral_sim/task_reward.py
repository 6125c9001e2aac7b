"""A scene's rewards for training: sparse and staged dense (the scene file's ``reward``).

- **sparse**: 1 at a control step where the scene's ``success`` holds, else 0;
- **dense**: the weighted mean of the ``reward.dense`` terms, each between 0 and 1, and 1 at
  a step where ``success`` holds, so success is always worth the most:

  - ``reach``: 1 - tanh(``scale_per_m`` x the distance from the tool centre point
    (``sim.tcp``) to the object's centre);
  - ``grasp``: 1 while every finger of the gripper touches the object (as
    ``gripper_holds``);
  - ``lift``: while held, the fraction of the way from the object's height at reset to
    ``z_m`` (0 to 1);
  - ``place``: while held, 1 - tanh(``scale_per_m`` x the distance from the object's centre
    to the box from ``min_m`` to ``max_m``; 0 inside).

Only ``data`` is read; one evaluation costs a few microseconds (a distance or two and one
pass over the contacts).
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np
from openral_core.located import error_at
from openral_core.models import (
    DeployScene,
    GraspReward,
    LiftReward,
    PlaceReward,
    ReachReward,
    TaskReward,
)
from openral_core.tcp_wiring import TcpWiring
from openral_mujoco.errors import HalError

from openral_sim.success import finger_bodies, fingers_touch
from openral_sim.tcp_frame import TcpFrame


def dense_reward_of(
    scene: DeployScene, model: mujoco.MjModel, finger_qpos: Sequence[int], tcp: TcpWiring | None
) -> DenseReward | None:
    """The dense reward ``scene`` declares (None: it declares none).

    Raises:
        ManifestError: At ``reward``: a term the robot or the model cannot serve.
    """
    if scene.reward is None:
        return None
    try:
        return DenseReward(scene.reward, model, finger_qpos, tcp)
    except HalError as error:
        raise error_at(scene, ("reward",), str(error)) from None


def sparse_reward(success: bool) -> float:
    """1 at a step where success holds, else 0."""
    return 1.0 if success else 0.0


class DenseReward:
    """The ``reward.dense`` terms of one scene on its compiled model (see the module doc)."""

    def __init__(
        self,
        reward: TaskReward,
        model: mujoco.MjModel,
        finger_qpos: Sequence[int],
        tcp: TcpWiring | None,
    ) -> None:
        """``finger_qpos``: qpos addresses of the gripper fingers' joints in ``model``.

        Raises:
            HalError: A ``reach`` term for a robot without ``sim.tcp``, or a TCP frame the
                model does not have.
        """
        self.terms = tuple(reward.dense)
        self._bodies = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"scene_{term.object}")
            for term in self.terms
        ]
        self._weights = np.array([term.weight or 1.0 for term in self.terms])
        self._fingers = finger_bodies(model, finger_qpos)
        self._geom_body = model.geom_bodyid.copy()
        self._start_z = np.zeros(len(self.terms))
        self._tcp = (
            _tcp_frame(model, tcp) if any(isinstance(t, ReachReward) for t in self.terms) else None
        )

    def reset(self, data: mujoco.MjData) -> None:
        """Note where each object starts (call once the episode's scene has settled)."""
        self._start_z = np.array([float(data.xpos[body][2]) for body in self._bodies])

    def value(self, data: mujoco.MjData, success: bool) -> float:
        """The dense reward of the state in ``data`` (1 when ``success`` holds)."""
        if success:
            return 1.0
        held: dict[int, bool] = {}
        total = 0.0
        for index, (term, body) in enumerate(zip(self.terms, self._bodies, strict=True)):
            total += self._weights[index] * self._term(index, term, body, data, held)
        return float(total / self._weights.sum())

    def _term(
        self,
        index: int,
        term: ReachReward | GraspReward | LiftReward | PlaceReward,
        body: int,
        data: mujoco.MjData,
        held: dict[int, bool],
    ) -> float:
        centre = data.xpos[body]
        if isinstance(term, ReachReward):
            assert self._tcp is not None
            gap = float(np.linalg.norm(self._tcp.position(data) - centre))
            return _closeness(gap, term.scale_per_m)
        if body not in held:
            held[body] = fingers_touch(body, data, self._fingers, self._geom_body)
        if isinstance(term, GraspReward) or not held[body]:
            return 1.0 if held[body] else 0.0
        if isinstance(term, LiftReward):
            start, goal = self._start_z[index], term.z_m
            if goal <= start:
                return 1.0 if centre[2] >= goal else 0.0
            return float(np.clip((centre[2] - start) / (goal - start), 0.0, 1.0))
        low, high = np.asarray(term.min_m), np.asarray(term.max_m)
        outside = np.maximum(np.maximum(low - centre, centre - high), 0.0)
        return _closeness(float(np.linalg.norm(outside)), term.scale_per_m)


def _closeness(distance_m: float, scale_per_m: float | None) -> float:
    """1 - tanh(scale x distance): 1 at the target, towards 0 far from it."""
    return 1.0 - float(np.tanh((scale_per_m or 10.0) * distance_m))


def _tcp_frame(model: mujoco.MjModel, tcp: TcpWiring | None) -> TcpFrame:
    if tcp is None:
        raise HalError(
            "reward.dense has a reach term, which needs the robot's tool centre point "
            "(sim.tcp in its manifest)"
        )
    return TcpFrame.locate(model, tcp)
