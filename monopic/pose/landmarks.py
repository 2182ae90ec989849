"""BlazePose full landmark model (pose_landmark_full.onnx) run on a rotated region.

The model sees the region as 256x256 RGB in [0, 1] and returns 39 points x (x, y, z,
visibility logit, presence logit) in crop pixels: the 33 landmarks, then auxiliary points
whose first two (33 centre, 34 scale/rotation) give the next frame's region. z is in the
same scale as x; we return it in image pixels like x. The pose flag says whether a person
is in the crop at all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from monopic.pose.region import DEFAULT_SCALE, Region
from monopic.pose.sessions import LANDMARK_FILE, make_session, model_path
from monopic.pose.skeleton import NUM_LANDMARKS

INPUT_SIZE = 256
NUM_POINTS = 39


@dataclass(frozen=True)
class Pose:
    """One person's landmarks in image pixels."""

    landmarks: np.ndarray  # (33, 3): x, y in pixels; z in pixels (x scale), hips ~ 0
    visibility: np.ndarray  # (33,) probability the point is visible
    presence: np.ndarray  # (33,) probability the point is in the frame
    score: float  # pose flag: probability a person is in the region
    region: Region  # the crop the landmarks came from
    aux: np.ndarray  # (6, 2) auxiliary points in pixels (0 centre, 1 scale point)

    @property
    def box(self) -> tuple[float, float, float, float]:
        """Bounding box of the 33 landmarks (xmin, ymin, xmax, ymax)."""
        xy = self.landmarks[:, :2]
        return (
            float(xy[:, 0].min()),
            float(xy[:, 1].min()),
            float(xy[:, 0].max()),
            float(xy[:, 1].max()),
        )

    @property
    def height(self) -> float:
        """Apparent height: vertical extent of the landmarks in pixels."""
        y = self.landmarks[:, 1]
        return float(y.max() - y.min())

    def next_region(self, scale: float = DEFAULT_SCALE) -> Region:
        """The region to crop in the next frame, from the auxiliary points."""
        return Region.from_keypoints(tuple(self.aux[0]), tuple(self.aux[1]), scale)


class LandmarkModel:
    def __init__(self, threads: int = 1) -> None:
        self.session = make_session(model_path(LANDMARK_FILE), threads)
        self.input_name = self.session.get_inputs()[0].name
        names = {}
        for out in self.session.get_outputs():
            size = int(np.prod([d for d in out.shape if isinstance(d, int)]))
            names[size] = out.name
        self.points_name, self.flag_name = names[NUM_POINTS * 5], names[1]

    def run(self, image: np.ndarray, region: Region) -> Pose:
        crop = region.crop(image, INPUT_SIZE)
        tensor = crop.astype(np.float32) * (1.0 / 255.0)
        points, flag = self.session.run(
            [self.points_name, self.flag_name], {self.input_name: tensor[None]}
        )
        pts = points.reshape(NUM_POINTS, 5).astype(np.float64)
        xy = region.to_image(pts[:, :2], INPUT_SIZE)
        z = pts[:, 2] * (region.side / INPUT_SIZE)
        lm = np.column_stack([xy[:NUM_LANDMARKS], z[:NUM_LANDMARKS]])
        return Pose(
            landmarks=lm,
            visibility=_sigmoid(pts[:NUM_LANDMARKS, 3]),
            presence=_sigmoid(pts[:NUM_LANDMARKS, 4]),
            score=float(_flag_probability(float(np.ravel(flag)[0]))),
            region=region,
            aux=xy[NUM_LANDMARKS:],
        )


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 1.0 / (1.0 + np.exp(-np.clip(x, -100, 100)))


def _flag_probability(value: float) -> float:
    """The converted model emits the pose flag already as a probability."""
    return value
