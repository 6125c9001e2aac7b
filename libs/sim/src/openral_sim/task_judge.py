"""How a native scene judges each control period: success and rewards.

The scene's ``success`` predicates (:mod:`openral_sim.success`) and its sparse and dense
rewards (:mod:`openral_sim.task_reward`) give one :class:`~openral_sim.observation.Outcome`
per period. Its ``options.horizon`` is told (:attr:`TaskJudge.horizon`) but never ends an
episode here: the gymnasium env and sweeps truncate there, while ``deploy sim`` runs on (a
world that reset itself under a ROS client would surprise it).
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
from openral_core.models import DeployScene
from openral_core.tcp_wiring import TcpWiring

from openral_sim.observation import Outcome
from openral_sim.success import SuccessCheck
from openral_sim.task_reward import dense_reward_of, sparse_reward


class TaskJudge:
    """The judge of one scene's episodes on its compiled model."""

    def __init__(
        self,
        scene: DeployScene,
        model: mujoco.MjModel,
        finger_qpos: Sequence[int],
        tcp: TcpWiring | None,
    ) -> None:
        """``finger_qpos``: qpos addresses of the gripper fingers' joints in ``model``.

        Raises:
            ManifestError: At ``reward``: a term the robot or the model cannot serve.
        """
        self.success = SuccessCheck(scene.success or [], model, finger_qpos)
        self.dense = dense_reward_of(scene, model, finger_qpos, tcp)
        """The dense reward (None: the scene declares none; its value is then 0)."""
        options = scene.scene.options
        self.horizon = options.horizon if options and options.horizon else None
        """Control periods per episode (None: no limit)."""

    def reset(self, data: mujoco.MjData) -> None:
        """A new episode, its scene settled in ``data``."""
        self.success.reset()
        if self.dense is not None:
            self.dense.reset(data)

    def judge(self, data: mujoco.MjData, period_s: float, steps: int) -> Outcome:
        """The outcome of control period number ``steps`` (from 1) of ``period_s`` [s]."""
        success = self.success.update(data, period_s)
        dense = self.dense.value(data, success) if self.dense is not None else 0.0
        return Outcome(
            reward=sparse_reward(success),
            success=success,
            steps=steps,
            dense_reward=dense,
        )
