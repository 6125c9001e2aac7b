"""A vector env whose envs step at once on threads of one process.

MuJoCo lets go of Python's lock while it steps, so two scenes stepped on two threads use
two cores, without the pipes and processes of gymnasium's ``AsyncVectorEnv`` (whose pipes
cost the parent about 0.1 ms a step here). :class:`ThreadVectorEnv` is gymnasium's
``SyncVectorEnv`` (same API, spaces, seeding, autoreset modes and info batching) whose
per-env work runs on one thread per env; each thread writes only its own env's slots, and
the batch is put together after all have finished, in env order, so the results are the
ones ``SyncVectorEnv`` gives for the same seeds and actions.

Cameras work too: every render takes the process's GL lock
(:mod:`openral_sim.gl_guard`), so renders of different envs take turns.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from copy import deepcopy
from typing import Any

import gymnasium
import numpy as np
import numpy.typing as npt
from gymnasium.vector import AutoresetMode, SyncVectorEnv
from gymnasium.vector.utils import concatenate, iterate

Info = dict[str, Any]
StepBatch = tuple[Any, npt.NDArray[np.float64], npt.NDArray[np.bool_], npt.NDArray[np.bool_], Info]
"""(observations, rewards, terminations, truncations, infos) of one vector step."""


_PLAIN = (bool, int, float)
"""Info value types batched into an array of their own type."""
_Plain = tuple[tuple[str, ...], tuple[type, ...], tuple[tuple[object, ...], ...]]
"""Plain infos of one step: (keys, value types, values per env)."""


class ThreadVectorEnv(SyncVectorEnv):
    """``SyncVectorEnv`` with its envs stepped and reset on threads of their own."""

    def __init__(
        self, env_fns: Sequence[Callable[[], gymnasium.Env[Any, Any]]], **kwargs: Any
    ) -> None:
        """``env_fns`` and ``kwargs`` as ``SyncVectorEnv`` takes them (``copy``,
        ``observation_mode``, ``autoreset_mode``); the envs are built here, on the calling
        thread."""
        super().__init__(env_fns, **kwargs)
        self._pool = ThreadPoolExecutor(self.num_envs, thread_name_prefix="openral-env")
        self._infos_cache: tuple[_Plain, Info] | None = None
        """The last plain infos and their batch (:meth:`_batched_infos`)."""

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: Info | None = None
    ) -> tuple[Any, Info]:
        """Reset every env at once (``seed``: as ``SyncVectorEnv`` takes it)."""
        if options is not None and "reset_mask" in options:  # a few envs: not worth threads
            return super().reset(seed=seed, options=options)
        seeds = _seeds(seed, self.num_envs)
        self._terminations = np.zeros((self.num_envs,), dtype=np.bool_)
        self._truncations = np.zeros((self.num_envs,), dtype=np.bool_)
        self._autoreset_envs = np.zeros((self.num_envs,), dtype=np.bool_)

        def reset_one(i: int) -> Info:
            self._env_obs[i], info = self.envs[i].reset(seed=seeds[i], options=options)
            return dict(info)

        infos: Info = {}
        for i, info in enumerate(self._pool.map(reset_one, range(self.num_envs))):
            infos = self._add_info(infos, info, i)
        self._observations = concatenate(
            self.single_observation_space, self._env_obs, self._observations
        )
        return deepcopy(self._observations) if self.copy else self._observations, infos

    def step(self, actions: Any) -> StepBatch:
        """Step every env at once with its action (autoreset as ``SyncVectorEnv``)."""
        batch = list(iterate(self.action_space, actions))
        stepped = self._pool.map(self._step_one, range(self.num_envs), batch)
        infos = self._batched_infos(
            [(i, part) for i, parts in enumerate(stepped) for part in parts]
        )
        self._observations = concatenate(
            self.single_observation_space, self._env_obs, self._observations
        )
        self._autoreset_envs = np.logical_or(self._terminations, self._truncations)
        return (
            deepcopy(self._observations) if self.copy else self._observations,
            np.copy(self._rewards),
            np.copy(self._terminations),
            np.copy(self._truncations),
            infos,
        )

    def _step_one(self, i: int, action: Any) -> list[Info]:
        """Env ``i``'s share of a step (its own slots only); the infos to add, in order."""
        env, mode = self.envs[i], self.autoreset_mode
        if mode == AutoresetMode.NEXT_STEP and self._autoreset_envs[i]:
            self._env_obs[i], info = env.reset()
            self._rewards[i], self._terminations[i], self._truncations[i] = 0.0, False, False
            return [dict(info)]
        if mode == AutoresetMode.DISABLED:
            assert not self._autoreset_envs[i], f"env {i} needs a reset first"
        obs, reward, terminated, truncated, info = env.step(action)
        self._env_obs[i], self._rewards[i] = obs, float(reward)
        self._terminations[i], self._truncations[i] = terminated, truncated
        if mode == AutoresetMode.SAME_STEP and (terminated or truncated):
            final = {"final_obs": obs, "final_info": info}
            self._env_obs[i], info = env.reset()
            return [final, dict(info)]
        return [dict(info)]

    def _batched_infos(self, parts: list[tuple[int, Info]]) -> Info:
        """The vector info of one step's ``(env, info)`` parts, as ``_add_info`` one by one
        makes it. The common case (one info per env, in env order, the same keys, plain
        numbers of one type per key) is built a key at a time, and copied from the last
        step's when nothing changed (a few microseconds a step less)."""
        plain = _plain(parts, self.num_envs)
        if plain is None:
            out: Info = {}
            for i, info in parts:
                out = self._add_info(out, info, i)
            return out
        cached = self._infos_cache
        if cached is None or cached[0] != plain:
            keys, types, values = plain
            built: Info = {}
            for k, (key, kind) in enumerate(zip(keys, types, strict=True)):
                built[key] = np.array([row[k] for row in values], dtype=kind)
                built[f"_{key}"] = np.ones(self.num_envs, dtype=np.bool_)
            cached = self._infos_cache = (plain, built)
        return {key: value.copy() for key, value in cached[1].items()}

    def close_extras(self, **kwargs: Any) -> None:
        """Close every env, then the threads."""
        super().close_extras(**kwargs)
        self._pool.shutdown(wait=True)


def _plain(parts: list[tuple[int, Info]], count: int) -> _Plain | None:
    """(keys, value types, values per env) when ``parts`` is one info per env, in env
    order, each with the same keys and plain numbers of the same types; else None."""
    if len(parts) != count or not parts:
        return None
    first = parts[0][1]
    keys, types = tuple(first), tuple(map(type, first.values()))
    if not all(kind in _PLAIN for kind in types):
        return None
    values = []
    for n, (i, info) in enumerate(parts):
        if i != n or tuple(info) != keys or tuple(map(type, info.values())) != types:
            return None
        values.append(tuple(info.values()))
    return keys, types, tuple(values)


def _seeds(seed: int | list[int | None] | None, count: int) -> list[int | None]:
    """One seed per env, as ``SyncVectorEnv`` spreads them.

    Raises:
        ValueError: A list of the wrong length.
    """
    if seed is None:
        return [None] * count
    if isinstance(seed, int):
        return [seed + i for i in range(count)]
    if len(seed) != count:
        raise ValueError(f"{len(seed)} seeds for {count} envs; expected one per env")
    return list(seed)
