"""Several envs of one scene stepped at once: in processes of their own (gymnasium's
``AsyncVectorEnv``), on threads of this process, or one here and the others in workers that
share memory with it (the one that scales with cores)."""

from __future__ import annotations

from functools import partial
from pathlib import Path

import gymnasium
from openral_core.loader import load_scene
from openral_core.models import Backend

from openral_eval.process_vector_env import ProcessVectorEnv
from openral_eval.scene_env import make_env
from openral_eval.thread_vector_env import ThreadVectorEnv


def make_vector_env(
    scene: str | Path, num_envs: int, **config: object
) -> gymnasium.vector.AsyncVectorEnv:
    """``num_envs`` envs of ``scene`` (``config``: as :func:`make_env`), each in a process
    of its own: forked from this one when nothing is rendered, else started afresh with
    ``forkserver`` (a process forked after this one has rendered cannot render, see
    :mod:`openral_sim.gl_guard`; building an env renders nothing, but this process may have
    rendered before; a robosuite scene always renders). Call it under ``if __name__ ==
    "__main__":`` when rendering (a fresh process imports the main module).

    Raises:
        ValueError: ``num_envs`` below 1 (a bad config fails in the first env, built
            here to learn the spaces).
    """
    if num_envs < 1:
        raise ValueError(f"num_envs is {num_envs}; expected at least 1")
    renders = (
        config.get("sensors", True) is not False
        or config.get("render_mode") is not None
        or load_scene(Path(scene)).scene.backend is Backend.robosuite  # renders regardless
    )
    build = partial(make_env, str(scene), **config)
    return gymnasium.vector.AsyncVectorEnv(
        [build] * num_envs, context="forkserver" if renders else "fork"
    )


def make_thread_vector_env(scene: str | Path, num_envs: int, **config: object) -> ThreadVectorEnv:
    """``num_envs`` envs of ``scene`` (``config``: as :func:`make_env`) in this process,
    stepped at once on threads of their own (:mod:`openral_eval.thread_vector_env`).

    Raises:
        ValueError: ``num_envs`` below 1.
    """
    if num_envs < 1:
        raise ValueError(f"num_envs is {num_envs}; expected at least 1")
    return ThreadVectorEnv([partial(make_env, str(scene), **config)] * num_envs)


def make_process_vector_env(scene: str | Path, num_envs: int, **config: object) -> ProcessVectorEnv:
    """``num_envs`` envs of ``scene`` (``config``: as :func:`make_env`): the first in this
    process, each other in a worker process, all stepped at once
    (:mod:`openral_eval.process_vector_env`; it scales with cores).

    Raises:
        ValueError: ``num_envs`` below 1.
    """
    return ProcessVectorEnv(partial(make_env, str(scene), **config), num_envs)
