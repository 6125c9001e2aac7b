"""MP4 videos of episodes: one camera, one video frame per frame of that camera.

Written with imageio-ffmpeg, whose wheel ships the ffmpeg binary (H.264, yuv420p, at the
camera's rate, :mod:`openral_sim.sensor_schedule`). The frames come from the scene's
observations, which carry a camera's frame at the steps it is due; no path or no camera
gives a writer that does nothing.
"""

from __future__ import annotations

from collections.abc import Generator
from pathlib import Path
from typing import Any

from openral_sim.observation import Observation


class VideoWriter:
    """Frames of one camera into one MP4 file (see the module doc)."""

    def __init__(self, path: Path | None, camera: str | None, fps: float) -> None:
        """Nothing is written until the first frame of ``camera`` reaches :meth:`add`."""
        self.path, self.camera, self.fps = path, camera, fps
        self.frames = 0
        self._writer: Generator[Any, Any, None] | None = None
        self._last_time_s: float | None = None

    @classmethod
    def for_camera(cls, path: str | None, camera: str | None, fps: float) -> VideoWriter:
        """A writer of ``camera`` (frames at ``fps`` [Hz]) to ``path`` (a no-op without
        either)."""
        if path is None or camera is None:
            return cls(None, None, 1.0)
        return cls(Path(path), camera, fps)

    def add(self, obs: Observation) -> None:
        """Append the camera's frame when ``obs`` carries a new one."""
        if self.path is None or self.camera is None or self.camera not in obs.images:
            return
        if obs.time_s == self._last_time_s:
            return  # the same observation again (the episode's last one)
        self._last_time_s = obs.time_s
        frame = obs.images[self.camera]
        if self._writer is None:
            import imageio_ffmpeg

            self.path.parent.mkdir(parents=True, exist_ok=True)
            height, width = frame.shape[:2]
            self._writer = imageio_ffmpeg.write_frames(
                str(self.path),
                (width, height),
                fps=self.fps,
                codec="libx264",
                pix_fmt_out="yuv420p",
                macro_block_size=1,
                ffmpeg_log_level="error",
            )
            self._writer.send(None)
        self._writer.send(frame.tobytes())
        self.frames += 1

    def close(self) -> None:
        """Finish the file (idempotent)."""
        if self._writer is not None:
            self._writer.close()
            self._writer = None
