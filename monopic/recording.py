"""rerun recordings of a pipeline run: the one logging module of the project.

Entity layout (sim/recording.py adds the simulator's on the same stream: camera/truth,
world, topdown, truth, ttc, alarm, robot):
- camera/image             the frame, JPEG-compressed
- camera/pose              BlazePose skeleton as keypoints (names, connections)
- camera/zone              the robot's zone on the image
- camera/prediction/point  predicted centre at the horizon; .../path the projected path
- features/{phi,vx,vy}     time series; latency/{stage} per-stage milliseconds
- events                   warnings as log events
Frames are indexed on the `frame` timeline and on `time` (seconds of the stream).
The file appears whole or not at all: it is written under a temporary name and renamed
by `close()`.

Callers that add their own entities (the simulator's sim.recording) log them on the same
stream, `RunRecording.rec`, after `set_time`, and pass their own blueprint; a frame the
pipeline did not process can still show its image (`log_image`).
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from monopic.output import temporary_sibling
from monopic.pipeline import FrameResult
from monopic.pose.skeleton import CONNECTIONS, LANDMARK_NAMES

JPEG_QUALITY = 80
LATENCY_STAGES = ("detect", "landmarks", "features", "predict", "warning", "total")


def blueprint() -> rrb.Blueprint:
    """Camera view on the left, time series stacked on the right."""
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="camera", name="camera"),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="features/phi", name="phi (deg)"),
                rrb.TimeSeriesView(
                    origin="features", contents=["features/vx", "features/vy"], name="v (px/s)"
                ),
                rrb.TimeSeriesView(origin="latency", name="latency (ms)"),
                rrb.TextLogView(origin="events", name="warnings"),
            ),
            column_shares=[3, 2],
        ),
        collapse_panels=True,
    )


def encoded_jpeg(image: np.ndarray, quality: int = JPEG_QUALITY) -> rr.EncodedImage:
    """An RGB uint8 image as a JPEG rerun image (a tenth of the raw size or less)."""
    ok, jpeg = cv2.imencode(
        ".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality]
    )
    if not ok:
        raise RuntimeError("JPEG encoding of a frame failed")
    return rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg")


class RunRecording:
    """Writes one run to a .rrd file."""

    def __init__(
        self,
        path: Path,
        application_id: str = "monopic",
        recording_id: str | None = None,
        *,
        layout: rrb.Blueprint | None = None,
    ):
        """`layout` replaces the default blueprint (e.g. one with the simulator's views)."""
        self.path = Path(path)
        self.tmp = temporary_sibling(self.path)
        self.rec = rr.RecordingStream(application_id, recording_id=recording_id)
        self.rec.save(str(self.tmp), default_blueprint=blueprint() if layout is None else layout)
        self.rec.log(
            "camera/pose",
            rr.AnnotationContext(
                rr.ClassDescription(
                    info=rr.AnnotationInfo(id=0, label="person"),
                    keypoint_annotations=[
                        rr.AnnotationInfo(id=i, label=name) for i, name in enumerate(LANDMARK_NAMES)
                    ],
                    keypoint_connections=list(CONNECTIONS),
                )
            ),
            static=True,
        )
        for name in ("phi", "vx", "vy"):
            self.rec.log(f"features/{name}", rr.SeriesLines(names=name), static=True)

    def log_frame(self, image: np.ndarray, result: FrameResult) -> None:
        """One processed frame: its image and everything the pipeline found."""
        self.set_time(result.frame_index, result.timestamp)
        self.log_image(image)
        self.log_result(result)

    def set_time(self, frame_index: int, timestamp: float) -> None:
        """Put what is logged next on this frame of both timelines."""
        self.rec.set_time("frame", sequence=frame_index)
        self.rec.set_time("time", duration=timestamp)

    def log_image(self, image: np.ndarray, entity: str = "camera/image") -> None:
        """An RGB image, JPEG-compressed, at the current time."""
        self.rec.log(entity, encoded_jpeg(image))

    def log_result(self, result: FrameResult) -> None:
        """The pipeline's outputs for the current frame (pose, zone, prediction, series)."""
        rec = self.rec
        pose = result.pose.pose
        if pose is not None:
            rec.log(
                "camera/pose",
                rr.Points2D(
                    pose.landmarks[:, :2],
                    class_ids=0,
                    keypoint_ids=np.arange(len(LANDMARK_NAMES)),
                    radii=-2.0,
                ),
            )
        else:
            rec.log("camera/pose", rr.Clear(recursive=False))
        w, p, f = result.warning, result.prediction, result.features
        if w is not None:
            colour = {"green": (40, 200, 60), "yellow": (240, 200, 0), "red": (230, 30, 30)}[w.risk]
            zone = np.vstack([w.zone, w.zone[:1]])
            rec.log("camera/zone", rr.LineStrips2D([zone], colors=[colour]))
            if w.collision:
                rec.log(
                    "events",
                    rr.TextLog(
                        f"COLLISION IMMINENT: case {int(p.case)} ({p.case.label})",
                        level=rr.TextLogLevel.WARN,
                    ),
                )
        else:
            rec.log("camera/zone", rr.Clear(recursive=False))
        if p is not None and f is not None:
            rec.log(
                "camera/prediction/point",
                rr.Points2D([p.center], radii=-6.0, labels=[f"case {int(p.case)}"]),
            )
            if result.path is not None:
                rec.log("camera/prediction/path", rr.LineStrips2D([result.path.image_path]))
        else:
            rec.log("camera/prediction", rr.Clear(recursive=True))
        if f is not None:
            for name, value in (("phi", f.phi), ("vx", f.vx), ("vy", f.vy)):
                if np.isfinite(value):
                    rec.log(f"features/{name}", rr.Scalars(value))
        for stage in LATENCY_STAGES:
            if stage in result.stage_ms:
                rec.log(f"latency/{stage}", rr.Scalars(result.stage_ms[stage]))

    def close(self) -> None:
        """Flush and move the finished file into place."""
        self.rec.flush()
        self.rec.disconnect()
        os.replace(self.tmp, self.path)

    def abort(self) -> None:
        """Drop the partial recording."""
        self.rec.disconnect()
        self.tmp.unlink(missing_ok=True)
