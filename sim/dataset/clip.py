"""The shipped end-to-end test clip: an adult walking across in front of a static camera.

Renders the frames and writes the per-frame ground truth (frame index, time, the
pedestrian's world placement, pixel position of every BlazePose landmark 0-32 as
MediaPipe numbers them with the person's own left/right, foot point, apparent box).
Deterministic: same ClipSpec, same frames and same CSV. tools/render_test_clip.py is
the command line around it.
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2

from monopic.camera import CameraModel
from sim.scenario import presets
from sim.scenario.spec import MannequinSpec
from sim.world.body import PedestrianTruth
from sim.world.mannequin import N_LANDMARKS
from sim.world.render import SceneRenderer
from sim.world.scene import Scene, SceneConfig


@dataclass(frozen=True)
class ClipSpec:
    """A straight crossing in front of a static robot on the road."""

    width: int = presets.CAMERA_WIDTH
    height: int = presets.CAMERA_HEIGHT
    fps: float = presets.FPS
    duration: float = presets.DURATION_S  # s
    vertical_fov_deg: float = presets.CAMERA_FOV_DEG
    camera_height: float = presets.CAMERA_MOUNT_HEIGHT  # m
    pitch_deg: float = presets.CAMERA_PITCH_DEG  # down
    robot_x: float = 0.0
    robot_y: float = -1.75  # centre of the eastbound lane
    distance: float = 2.7  # m ahead of the camera where the path crosses
    speed: float = 1.2  # m/s
    start_offset: float = 2.4  # m to the camera's left where the walk starts


def truth_header() -> list[str]:
    """Column names of the truth CSV."""
    cols = ["frame", "t", "ped_x", "ped_y", "ped_yaw", "speed", "gait_phase"]
    for i in range(N_LANDMARKS):
        cols += [f"lm{i}_u", f"lm{i}_v"]
    cols += ["foot_u", "foot_v", "box_u0", "box_v0", "box_u1", "box_v1"]
    return cols


def truth_row(index: int, t: float, truth: PedestrianTruth) -> list[str]:
    """One CSV row; pixels to 1/1000 px so the file is stable across runs."""
    values = [
        *truth.position,
        truth.yaw,
        truth.speed,
        truth.gait_phase,
        *truth.landmarks_px.reshape(-1),
        *truth.foot_px,
        *truth.box,
    ]
    return [str(index), f"{t:.4f}"] + [f"{v:.3f}" for v in values]


def clip_scene(clip: ClipSpec) -> Scene:
    """The scene of the clip with the robot in place, facing east along the road."""
    camera = CameraModel.from_fov(
        clip.width,
        clip.height,
        clip.vertical_fov_deg,
        mount_height=clip.camera_height,
        pitch_deg=clip.pitch_deg,
    )
    scene = Scene(SceneConfig(camera=camera, pedestrian=MannequinSpec.adult()))
    scene.set_camera_pose(clip.robot_x, clip.robot_y, 0.0)
    return scene


def walk(clip: ClipSpec, scene: Scene) -> Iterator[tuple[int, float]]:
    """Place the pedestrian for each frame in turn; yields (frame index, time in s).

    The walk goes from the camera's left (north) to its right (south), heading -90
    degrees, on a line `clip.distance` ahead of the camera.
    """
    n_frames = int(round(clip.duration * clip.fps))
    x = clip.robot_x + clip.distance
    phase = 0.0
    person = scene.pedestrians[0]
    for k in range(n_frames):
        t = k / clip.fps
        y = clip.robot_y + clip.start_offset - clip.speed * t
        person.pose_at(scene.model, scene.data, x, y, -math.pi / 2, phase, clip.speed)
        scene.update()
        yield k, t
        phase = person.gait.advance(phase, clip.speed, 1.0 / clip.fps)


def render_clip(
    clip: ClipSpec, video_path: Path, truth_path: Path, frames_dir: Path | None = None
) -> list[float]:
    """Render the clip (and PNGs of the raw frames if asked); returns per-frame render times (s)."""
    scene = clip_scene(clip)
    video_path.parent.mkdir(parents=True, exist_ok=True)
    if frames_dir is not None:
        frames_dir.mkdir(parents=True, exist_ok=True)
    writer = cv2.VideoWriter(
        str(video_path), cv2.VideoWriter_fourcc(*"mp4v"), clip.fps, (clip.width, clip.height)
    )
    if not writer.isOpened():
        raise RuntimeError(f"OpenCV cannot write {video_path} with the mp4v codec")
    times: list[float] = []
    with SceneRenderer(scene) as renderer:
        try:
            with truth_path.open("w", newline="") as fh:
                out = csv.writer(fh)
                out.writerow(truth_header())
                for k, t in walk(clip, scene):
                    start = time.perf_counter()
                    image = renderer.render()
                    times.append(time.perf_counter() - start)
                    bgr = cv2.cvtColor(image, cv2.COLOR_RGB2BGR)
                    writer.write(bgr)
                    if frames_dir is not None:
                        cv2.imwrite(str(frames_dir / f"frame_{k:03d}.png"), bgr)
                    body = scene.pedestrians[0].seen(scene.data, scene.camera, scene.robot_pose)
                    out.writerow(truth_row(k, t, body))
        finally:
            writer.release()
    return times
