"""One camera's frames as an MP4 file of a LeRobot dataset: ffmpeg (imageio-ffmpeg's) reads
raw RGB frames from a pipe; H.264 where that ffmpeg has libx264, else MPEG-4 part 2."""

from __future__ import annotations

import subprocess
import tempfile
from fractions import Fraction
from functools import cache
from pathlib import Path
from typing import IO

import numpy as np
import numpy.typing as npt
from openral_core.errors import OpenralError


@cache
def video_codec() -> tuple[str, tuple[str, ...]]:
    """(codec named in info.json, ffmpeg options): libx264 if imageio-ffmpeg's ffmpeg has it,
    else MPEG-4 part 2; a keyframe every 2 frames (as LeRobot's) keeps seeking to a frame cheap."""
    import imageio_ffmpeg

    exe = imageio_ffmpeg.get_ffmpeg_exe()
    run = subprocess.run([exe, "-hide_banner", "-encoders"], capture_output=True, text=True)
    encoders = {line.split()[1] for line in run.stdout.splitlines() if len(line.split()) > 1}
    if "libx264" in encoders:
        return "h264", ("-c:v", "libx264", "-preset", "medium", "-crf", "23", "-g", "2")
    return "mpeg4", ("-c:v", "mpeg4", "-q:v", "2", "-g", "2")


class VideoStream:
    """One camera's MP4: an ffmpeg process reading raw RGB frames from a pipe."""

    def __init__(self, path: Path, size: tuple[int, int], fps: float) -> None:
        import imageio_ffmpeg

        path.parent.mkdir(parents=True, exist_ok=True)
        rate = Fraction(fps).limit_denominator(10_000)
        command = [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-loglevel", "error"]
        command += ["-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{size[1]}x{size[0]}"]
        command += ["-framerate", f"{rate.numerator}/{rate.denominator}", "-i", "-", "-an"]
        command += [*video_codec()[1], "-pix_fmt", "yuv420p", str(path)]
        self.path, self.frames = path, 0
        self._log: IO[bytes] = tempfile.TemporaryFile()  # noqa: SIM115 (closed by close/kill)
        self._process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=self._log
        )

    def write(self, frames: npt.NDArray[np.uint8]) -> None:
        """Append ``(T, H, W, 3)`` frames."""
        assert self._process.stdin is not None
        try:
            for frame in frames:
                self._process.stdin.write(np.ascontiguousarray(frame).data)
        except BrokenPipeError:
            self.close()  # raises with ffmpeg's own words
        self.frames += len(frames)

    def close(self, finish: bool = True) -> None:
        """Finish the file (ffmpeg's failure is an :class:`OpenralError`), or stop ffmpeg."""
        if self._log.closed:
            return
        if not finish:
            self._process.kill()
        elif self._process.stdin is not None and not self._process.stdin.closed:
            self._process.stdin.close()
        failed = self._process.wait() != 0 and finish
        self._log.seek(0)
        said = self._log.read().decode(errors="replace").strip().splitlines() or ["?"]
        self._log.close()
        if failed:
            raise OpenralError(f"ffmpeg could not write {self.path.name}: {said[-1]}")
