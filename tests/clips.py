"""Tiny video files the tests write where they need a real file OpenCV reads."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np


def tiny_clip(folder: Path, frames: int = 3, fps: float = 15.0) -> Path:
    """`folder`/c.mp4: `frames` black 64x48 frames at `fps`, in a container that declares it."""
    clip = folder / "c.mp4"
    w = cv2.VideoWriter(str(clip), cv2.VideoWriter_fourcc(*"mp4v"), fps, (64, 48))
    for _ in range(frames):
        w.write(np.zeros((48, 64, 3), np.uint8))
    w.release()
    return clip
