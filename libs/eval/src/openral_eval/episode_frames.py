"""What one sweep episode keeps for a dataset: per control step the joint state, the action
as the env took it, whether the task had succeeded, and each dataset camera's latest frame.

An episode of a sweep with ``--dataset`` fills an :class:`EpisodeFrames` as it steps and
saves it next to the results (an ``.npz`` in a staging folder) when it ends; the sweep then
streams those files, in plan order, into one LeRobot dataset
(:mod:`openral_eval.dataset_export`). A camera slower than the control loop repeats its
latest frame, as a real camera's latest image is what a policy sees at each step.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import numpy.typing as npt
from openral_core.loaded import LoadedRobot

from openral_eval.lerobot_dataset import DatasetEpisode


def as_stored(
    action: npt.NDArray[np.float64],
    low: npt.NDArray[np.float64],
    high: npt.NDArray[np.float64],
) -> npt.NDArray[np.float64]:
    """``action`` as the dataset stores it (float32), still inside [``low``, ``high``]: a
    value that rounding pushed past its bound is moved one float32 step back inside (a
    joint target clamped to its limit, -0.0698 rad, rounds to just above it)."""
    stored = action.astype(np.float32)
    up, down = stored > high, stored < low
    stored[up] = np.nextafter(stored[up], np.float32(-np.inf))
    stored[down] = np.nextafter(stored[down], np.float32(np.inf))
    return stored.astype(np.float64)


def dataset_cameras(robot: LoadedRobot, rendered: tuple[str, ...]) -> dict[str, str]:
    """The robot's VLA slots whose camera the scene renders: slot → camera (sensor) name."""
    return {s.slot: s.sensor for s in robot.tables.vla_slots if s.sensor in rendered}


@dataclass
class EpisodeFrames:
    """The steps of one episode, collected for its dataset file at ``path``."""

    path: Path
    cameras: dict[str, str]
    """Slot → camera name."""
    states: list[npt.NDArray[np.float32]] = field(default_factory=list)
    actions: list[npt.NDArray[np.float32]] = field(default_factory=list)
    success: list[bool] = field(default_factory=list)
    frames: dict[str, list[npt.NDArray[np.uint8]]] = field(default_factory=dict)
    extra: dict[str, list[npt.NDArray[np.float32]]] = field(default_factory=dict)
    """More of what the policy saw, by key (``observation.velocity`` …)."""
    names: dict[str, tuple[str, ...]] = field(default_factory=dict)
    """The names of each extra key's values."""

    def add(
        self,
        state: npt.NDArray[np.float64],
        action: npt.NDArray[np.float64],
        succeeded: bool,
        images: dict[str, npt.NDArray[np.uint8]],
        extra: Mapping[str, tuple[tuple[str, ...], npt.NDArray[np.float64]]] | None = None,
    ) -> None:
        """One control step: the state the policy saw, the action taken, success after it,
        the latest image of each camera, and more of what the policy saw (key → its
        values' names and the values).

        Raises:
            ValueError: A dataset camera has no frame yet (the scene does not render it).
        """
        self.states.append(np.asarray(state, dtype=np.float32))
        self.actions.append(np.asarray(action, dtype=np.float32))
        self.success.append(bool(succeeded))
        for key, (names, values) in (extra or {}).items():
            self.names.setdefault(key, names)
            self.extra.setdefault(key, []).append(np.asarray(values, dtype=np.float32))
        for slot, camera in self.cameras.items():
            if camera not in images:
                raise ValueError(f"the scene renders no frame of {camera} (dataset slot {slot})")
            self.frames.setdefault(slot, []).append(images[camera])

    def save(self) -> None:
        """Write the steps to :attr:`path` (an uncompressed ``.npz``; read once, then
        deleted, by the export)."""
        self.path.parent.mkdir(parents=True, exist_ok=True)
        arrays: dict[str, npt.NDArray[np.generic]] = {
            "states": np.stack(self.states),
            "actions": np.stack(self.actions),
            "success": np.array(self.success, dtype=np.bool_),
        }
        arrays.update({f"frames.{slot}": np.stack(f) for slot, f in self.frames.items()})
        arrays.update({f"extra.{key}": np.stack(v) for key, v in self.extra.items()})
        arrays.update({f"names.{key}": np.array(n, dtype=np.str_) for key, n in self.names.items()})
        with self.path.open("wb") as file:
            np.savez(file, allow_pickle=False, **arrays)


def load_episode(path: Path, task: str) -> DatasetEpisode:
    """The dataset episode saved at ``path``, for ``task``."""
    with np.load(path) as saved:
        frames = {
            key.removeprefix("frames."): saved[key]
            for key in saved.files
            if key.startswith("frames.")
        }
        extra = {
            key.removeprefix("extra."): saved[key]
            for key in saved.files
            if key.startswith("extra.")
        }
        return DatasetEpisode(
            task=task,
            states=saved["states"],
            actions=saved["actions"],
            success=saved["success"],
            frames=frames,
            extra=extra,
        )


def extra_names(path: Path) -> dict[str, tuple[str, ...]]:
    """The extra keys of the episode saved at ``path`` and their values' names."""
    with np.load(path) as saved:
        return {
            key.removeprefix("names."): tuple(str(name) for name in saved[key])
            for key in saved.files
            if key.startswith("names.")
        }
