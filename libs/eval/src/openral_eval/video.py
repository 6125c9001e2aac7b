"""MP4 videos of episodes: the scene's first camera, one frame per control step.

Written with imageio-ffmpeg, whose wheel ships the ffmpeg binary (H.264, yuv420p, at the
control rate). A scene without cameras, or no path, gives a writer that does nothing.
"""

from __future__ import annotations

from collections.abc import Generator
from pathlib import Path
from typing import Any

from openral_sim.native_scene import NativeScene
from openral_sim.rollout import SimRollout


class VideoWriter:
    """Frames of one camera into one MP4 file (see the module doc)."""

    def __init__(self, path: Path | None, camera: str | None, fps: float) -> None:
        """Nothing is written until the first :meth:`add`."""
        self.path, self.camera, self.fps = path, camera, fps
        self.frames = 0
        self._writer: Generator[Any, Any, None] | None = None

    @classmethod
    def for_scene(cls, path: str | None, env: SimRollout) -> VideoWriter:
        """A writer of ``env``'s first camera to ``path`` (a no-op without either)."""
        camera = env.camera_names[0] if env.camera_names else None
        if path is None or camera is None or not isinstance(env, NativeScene):
            return cls(None, None, 1.0)
        return cls(Path(path), camera, 1.0 / env.control_period_s)

    def add(self, env: SimRollout) -> None:
        """Render the camera as the scene is now and append the frame."""
        if self.path is None or self.camera is None or not isinstance(env, NativeScene):
            return
        frame = env.render_cameras(env.data, [self.camera])[self.camera]
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
