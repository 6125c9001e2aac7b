"""Whether a policy can run on a scene, checked once before a sweep's first episode.

A sweep used to find a policy that does not fit its scene in every episode, one error per
seed. :func:`check_policy_fits` says it once, in one line, before anything runs: a mode
the scene or robot cannot take (an end-effector mode needs a native scene and a robot with
``sim.tcp``), camera slots the robot does not have, or privileged state a robosuite scene
does not hand over.
"""

from __future__ import annotations

from openral_hal.tool_centre import ee_command
from openral_sim.rollout import SceneRollout

from openral_eval.episode import scene_for
from openral_eval.policy import PolicyAdapter, PolicyConfigError, action_mode


def check_policy_fits(policy: PolicyAdapter, name: str, scene: str) -> None:
    """Refuse ``policy`` (called ``name``) on ``scene`` (a scene file) in one line.

    Raises:
        PolicyConfigError: Its mode, camera slots or needs do not fit the scene.
    """
    mode = action_mode(policy)  # an unknown mode is refused here
    hal, robot = scene_for(scene)
    native = isinstance(hal.env, SceneRollout)
    if mode != "joint_position" and (not native or ee_command(hal, robot) is None):
        raise PolicyConfigError(
            f"policy {name} acts in {mode}, which needs a native scene and a robot with a "
            f"tool centre point (sim.tcp); {scene} ({robot.name}) has none"
        )
    slots = {slot.slot for slot in robot.tables.vla_slots}
    missing = [slot for slot in policy.required_slots if slot not in slots]
    if missing:
        raise PolicyConfigError(
            f"policy {name} needs camera slots {missing}; {robot.name} has {sorted(slots)}"
        )
    if policy.needs_privileged and not native and not hal.last_observation().task_state:
        raise PolicyConfigError(
            f"policy {name} reads privileged state, which {scene} does not hand over"
        )
