"""Frames from any video file or camera OpenCV reads, with their own timestamps, and
`open_source`, which picks the reader for what the user named (an image sequence's is
monopic.image_sequence).

Velocities are computed from timestamps, never from an assumed frame rate: a file's
frames carry the container's presentation times; a live camera's, the wall clock. A
frame rate given by the user is used where the file declares none, and refused where it
would be ignored.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2

from monopic.errors import UserError
from monopic.frame import EgoState, Frame
from monopic.image_sequence import ImageSequenceSource


@dataclass
class VideoSource:
    """Iterates RGB frames of a file (path) or a camera (integer index as text)."""

    source: str
    ego: EgoState | None = None
    # The user's rate for a file that declares none (a file that declares another, or a
    # camera, refuses it: it would be ignored).
    fallback_fps: float | None = None
    # A frame's number as tracks files count them (index + first_number), as in an
    # image sequence, whose numbering starts at its first file's.
    first_number: int = 1

    def __post_init__(self) -> None:
        self.live = self.source.isdigit()
        if self.live and self.fallback_fps is not None:
            raise UserError(
                f"--fps {self.fallback_fps:g}: camera {self.source}'s frames carry the wall "
                "clock's time; --fps gives a rate only to inputs without one"
            )
        if not self.live and not Path(self.source).is_file():
            raise UserError(f"{self.source}: no such video file")
        # FFmpeg would print its own diagnostics of a bad file; we report it in one line.
        os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")
        self.capture = cv2.VideoCapture(int(self.source) if self.live else self.source)
        if not self.capture.isOpened():
            raise UserError(f"{self.source}: OpenCV cannot open it as a video")
        self.width = int(self.capture.get(cv2.CAP_PROP_FRAME_WIDTH))
        self.height = int(self.capture.get(cv2.CAP_PROP_FRAME_HEIGHT))
        self.fps = float(self.capture.get(cv2.CAP_PROP_FPS) or 0.0)
        if self.fallback_fps is not None:
            if self.fps > 0 and self.fps != self.fallback_fps:
                self.capture.release()
                raise UserError(
                    f"--fps {self.fallback_fps:g}: {self.source} declares its own frame rate, "
                    f"{self.fps:g} fps; --fps gives a rate only to inputs without one"
                )
            self.fps = self.fallback_fps
        count = int(self.capture.get(cv2.CAP_PROP_FRAME_COUNT))
        self.frame_count = count if count > 0 and not self.live else None

    def __iter__(self) -> Iterator[Frame]:
        index, last_t, start = 0, None, time.monotonic()
        try:
            while True:
                ok, bgr = self.capture.read()
                if not ok:
                    if index == 0:
                        raise UserError(f"{self.source}: no frame could be decoded")
                    return
                if self.live:
                    t = time.monotonic() - start
                else:
                    t = self.capture.get(cv2.CAP_PROP_POS_MSEC) / 1000.0
                    if last_t is not None and t <= last_t:
                        # Some containers report no per-frame times: fall back to the
                        # declared rate, which is then the only timing the file has.
                        if self.fps <= 0:
                            raise UserError(f"{self.source}: frames carry no timestamps")
                        t = last_t + 1.0 / self.fps
                last_t = t
                rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
                yield Frame(rgb, t, self.ego, index)
                index += 1
        finally:
            self.capture.release()


def open_source(text: str, fps: float | None = None) -> VideoSource | ImageSequenceSource:
    """The frames `text` names: a camera index (digits), a video file, a MOTChallenge
    sequence folder, or a printf pattern of numbered images (img1/%06d.jpg).

    `fps` is the rate where the input has none of its own: a pattern outside a
    MOTChallenge folder needs it; a video file or a MOTChallenge folder keeps its own."""
    path = Path(text)
    if text.isdigit() or path.is_file():
        return VideoSource(text, fallback_fps=fps)
    if path.is_dir():
        return ImageSequenceSource.from_folder(path, fps)
    if "%" in path.name:
        return ImageSequenceSource.from_pattern(text, fps)
    return VideoSource(text)  # refuses it: no such file
