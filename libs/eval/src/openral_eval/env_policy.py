"""A policy in the gymnasium env's own loop, seeing what it sees in a sweep.

The env's observation is the one every path shares (:mod:`openral_eval.observation_keys`);
a policy's adds two things only a policy needs, the action spec and the time.
:func:`policy_observation` adds them, so a policy class written for ``openral sim sweep``
or ``openral rskill run`` steps an env unchanged::

    env = make_env(scene, seed=0)
    obs, _ = env.reset(seed=3)
    for _ in range(100):
        action = policy.act(policy_observation(env, obs))
        obs, reward, terminated, truncated, info = env.step(action)
"""

from __future__ import annotations

from collections.abc import Mapping

from openral_eval import observation_keys as keys
from openral_eval.policy import Observation
from openral_eval.scene_env import SceneEnv


def policy_observation(env: SceneEnv, obs: Mapping[str, object]) -> Observation:
    """``obs`` (``env``'s latest, a ``Dict``) as a policy sees it at ``env``'s step: plus
    ``action_spec`` (the HAL's slots and hold action) and ``time_s`` (steps times the
    control period [s]).

    Raises:
        ValueError: ``obs`` is a flat vector (``EnvConfig.flat``), not the ``Dict``.
    """
    if not isinstance(obs, Mapping):
        raise ValueError("a policy reads the observation by key: make the env without flat=True")
    hal = env.hal
    seen: Observation = dict(obs)
    seen[keys.ACTION_SPEC] = (hal.action_names, hal.hold_action())
    seen[keys.TIME_S] = env.steps * hal.control_period_s
    return seen
