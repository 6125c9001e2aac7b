"""What a scene env is built from (:class:`EnvConfig`) and which reward it returns."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from enum import StrEnum

from openral_eval.env_actions import ActionMode


class RewardMode(StrEnum):
    """Which of the scene's rewards ``step`` returns (:mod:`openral_sim.task_reward`)."""

    SPARSE = "sparse"
    """1 at a step where the scene's success holds, else 0."""
    DENSE = "dense"
    """The scene's staged ``reward.dense`` (1 at success); robosuite: its own reward."""


@dataclass(frozen=True)
class EnvConfig:
    """Everything a scene env is built from."""

    scene: str
    """The scene file (``robots/<id>/scenes/<name>.yaml``)."""
    action_mode: ActionMode = ActionMode.JOINT_POSITION
    seed: int | None = None
    """Seeds the env's generator (the seeds of resets without one); None: from the OS."""
    privileged: bool = False
    """Add the scene's task state (object poses) as ``observation.environment_state``."""
    sensors: bool | tuple[str, ...] = True
    """Which cameras, depth sensors and lidars the observation carries: True all, False
    none, or these by manifest name (state sensors, joints and the base are always in)."""
    max_steps: int | None = None
    """Truncate after this many steps (None: the scene's horizon, if any)."""
    ee_preset: str = "robosuite"
    """The scale and gripper sign of ``ee_delta_pose``: ``robosuite`` or ``maniskill``."""
    reward_mode: RewardMode = RewardMode.SPARSE
    """The reward ``step`` returns."""
    keys: tuple[str, ...] | None = None
    """Keep only these observation keys (None: every key the scene has)."""
    flat: bool = False
    """The kept keys, in key order, as one float64 vector instead of a ``Dict``."""

    @classmethod
    def parse(cls, config: EnvConfig | Mapping[str, object]) -> EnvConfig:
        """``config`` as an :class:`EnvConfig` (a mapping: by field name).

        Raises:
            ValueError: An unknown key, an unknown action mode, or a missing scene.
        """
        if isinstance(config, EnvConfig):
            return replace(config, action_mode=_mode(config.action_mode)).checked()
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(config) - known)
        if unknown:
            raise ValueError(f"unknown env config keys {unknown}; valid: {sorted(known)}")
        if "scene" not in config:
            raise ValueError("env config needs 'scene': a scene file")
        built = cls(**config)  # type: ignore[arg-type]
        return replace(built, action_mode=_mode(built.action_mode)).checked()

    def checked(self) -> EnvConfig:
        """This config with ``reward_mode`` as a :class:`RewardMode` and ``keys`` a tuple
        (one key may be given alone).

        Raises:
            ValueError: An unknown reward mode.
        """
        wanted: object = self.keys
        kept = (wanted,) if isinstance(wanted, str) else self.keys
        try:
            kept = None if kept is None else tuple(str(key) for key in kept)
            return replace(self, reward_mode=RewardMode(self.reward_mode), keys=kept)
        except ValueError:
            valid = ", ".join(m.value for m in RewardMode)
            raise ValueError(f"unknown reward mode {self.reward_mode!r}; valid: {valid}") from None


def _mode(value: object) -> ActionMode:
    try:
        return ActionMode(str(value) if isinstance(value, str) else repr(value))
    except ValueError:
        valid = ", ".join(m.value for m in ActionMode)
        raise ValueError(f"unknown action mode {value!r}; valid: {valid}") from None


def merged_config(
    config: EnvConfig | Mapping[str, object] | None, settings: Mapping[str, object]
) -> EnvConfig | Mapping[str, object]:
    """``config`` with ``settings`` over it (both may be empty)."""
    if not settings and config is not None:
        return config
    base = asdict(config) if isinstance(config, EnvConfig) else dict(config or {})
    return {**base, **settings}
