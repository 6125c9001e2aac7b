"""Evaluating policies on simulated scenes: the policy registry, episodes, sweeps and the
gymnasium env of a scene file.

Between the HAL and the apps: an episode drives a scene through the same HAL contract as
``deploy sim`` (:class:`~openral_hal.sim_attached.SimAttachedHAL`), without ROS.
``make_env``, ``make_vector_env``, ``make_thread_vector_env``, ``make_process_vector_env``
and ``SceneEnv`` are imported
on first use (gymnasium is not loaded by the CLI's other commands).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from openral_eval.scene_env import EnvConfig, SceneEnv, make_env
    from openral_eval.vector_envs import (
        make_process_vector_env,
        make_thread_vector_env,
        make_vector_env,
    )

__all__ = [
    "EnvConfig",
    "SceneEnv",
    "make_env",
    "make_process_vector_env",
    "make_thread_vector_env",
    "make_vector_env",
]


def __getattr__(name: str) -> object:
    """``make_env``, ``SceneEnv`` and ``EnvConfig`` from :mod:`openral_eval.scene_env`, the
    vector envs from :mod:`openral_eval.vector_envs`."""
    if name in __all__:
        from openral_eval import scene_env, vector_envs

        return getattr(
            vector_envs if name.startswith("make_") and name != "make_env" else scene_env, name
        )
    raise AttributeError(f"module 'openral_eval' has no attribute {name!r}")
