"""rerun recordings of a pipeline run: the one logging module of the project.

Entity layout (sim/recording/sim_recording.py adds the simulator's on the same stream: camera/truth,
world, topdown, truth, ttc, alarm, robot):
- camera/image             the frame, JPEG-compressed
- camera/pose              BlazePose skeleton as keypoints (names, connections)
- camera/zone              the robot's zone on the image
- camera/prediction/point  predicted centre at the horizon; .../path the projected path
  (these three are the robot's: the person whose warning is the worst)
- camera/people/{id}       everyone seen, one entity per identity: box (labelled with id
                           and case), pose, prediction; cleared when the person is gone
- features/{phi,vx,vy}     time series; latency/{stage} per-stage milliseconds
- events                   the warning's onset and end, each line starting with its time;
                           the onset names the person it is for (their id and box colour),
                           and a warning that passes to another person says so
Frames are indexed on the `frame` timeline and on `time` (seconds of the stream).
The file appears whole or not at all: it is written under a temporary name (monopic.output)
and renamed by `close()`; `abort()`, or a failed `close()`, deletes it, and a killed
writer's temporary of the same file is deleted when the file is started again.

Colours say who is speaking: the pipeline's estimates (skeleton, phi, the primary
predictor's point and path) are pink, each predictor has its own colour
(`predictor_colour`), the zone is coloured by risk (green, yellow, red), and the simulator
draws the truth in cyan. The camera view is framed on the image, whatever is drawn
outside it (the zone's near edge lies below the frame).

Callers that add their own entities (the simulator's sim.recording.sim_recording) log them
on the same stream, `RunRecording.rec`, after `set_time`, and `start` it with their own blueprint
before the first frame; a frame the pipeline did not process can still show its image
(`log_image`). Without a blueprint of the caller's, the file starts on the first image
with `blueprint(width, height)`.
"""

from __future__ import annotations

import os
from pathlib import Path

import cv2
import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from monopic.closing import WholeOrNothing
from monopic.output import remove_stale_temporaries, temporary_sibling
from monopic.people.colour import person_colour, person_colour_name
from monopic.pipeline import FrameResult
from monopic.pose.skeleton import CONNECTIONS, LANDMARK_NAMES
from monopic.rerun_file import release, save_with_blueprint

JPEG_QUALITY = 80
LATENCY_STAGES = ("detect", "landmarks", "features", "predict", "warning", "total")
PIPELINE_COLOUR = (255, 80, 200)  # the pipeline's estimates: skeleton, phi, primary's path
RISK_COLOURS = {"green": (40, 200, 60), "yellow": (240, 200, 0), "red": (230, 30, 30)}
FEATURE_COLOURS = {"phi": PIPELINE_COLOUR, "vx": (255, 150, 50), "vy": (170, 130, 255)}
# One colour per predictor in every view and recording; none is the truth's cyan.
PREDICTOR_COLOURS = {
    "rules/image": (255, 80, 200),
    "rules/ground": (255, 170, 230),
    "tree/image": (255, 190, 30),
    "tree/ground": (255, 230, 140),
    "constant-velocity/image": (150, 110, 255),
    "constant-velocity/ground": (200, 185, 255),
}
OTHER_COLOURS = ((255, 110, 70), (200, 160, 110), (230, 230, 230), (255, 60, 120))


def predictor_colour(key: str) -> tuple[int, int, int]:
    """The fixed colour of a predictor key ("rules/image"); unknown keys get a stable one."""
    if key in PREDICTOR_COLOURS:
        return PREDICTOR_COLOURS[key]
    return OTHER_COLOURS[sum(key.encode()) % len(OTHER_COLOURS)]


def image_bounds(width: int, height: int) -> rrb.VisualBounds2D:
    """A 2D view framed on a width x height image."""
    return rrb.VisualBounds2D(x_range=[0.0, float(width)], y_range=[0.0, float(height)])


def events_view(origin: str = "events", name: str = "warnings") -> rrb.TextLogView:
    """A text log of `origin`: level and text (which starts with the time, see `log_event`).

    The viewer sizes its time column too narrow to read ("+2..."), so the time is in the
    text instead.
    """
    return rrb.TextLogView(
        origin=origin,
        name=name,
        columns=rrb.TextLogColumns(
            timeline_columns=[
                rrb.encodings.TimelineColumn(timeline, visible=False)
                for timeline in ("time", "frame", "log_time")
            ],
            text_log_columns=[
                rrb.encodings.TextLogColumn("loglevel"),
                rrb.encodings.TextLogColumn("body"),
                rrb.encodings.TextLogColumn("entitypath", visible=False),
            ],
        ),
    )


def panels() -> list[rrb.BlueprintPart]:
    """Side panels hidden, the small time panel on the `time` timeline (seconds)."""
    return [
        rrb.BlueprintPanel(state="hidden"),
        rrb.SelectionPanel(state="hidden"),
        rrb.TimePanel(state="collapsed", timeline="time"),
    ]


def blueprint(width: int | None = None, height: int | None = None) -> rrb.Blueprint:
    """Camera view (framed on the image when its size is given) left, time series right."""
    bounds = image_bounds(width, height) if width and height else None
    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Spatial2DView(origin="camera", name="camera", visual_bounds=bounds),
            rrb.Vertical(
                rrb.TimeSeriesView(origin="features/phi", name="phi (deg)"),
                rrb.TimeSeriesView(
                    origin="features", contents=["features/vx", "features/vy"], name="v (px/s)"
                ),
                rrb.TimeSeriesView(origin="latency", name="latency (ms)"),
                events_view(),
            ),
            column_shares=[3, 2],
        ),
        *panels(),
    )


def encoded_jpeg(image: np.ndarray, quality: int = JPEG_QUALITY) -> rr.EncodedImage:
    """An RGB uint8 image as a JPEG rerun image (a tenth of the raw size or less)."""
    ok, jpeg = cv2.imencode(
        ".jpg", cv2.cvtColor(image, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, quality]
    )
    if not ok:
        raise RuntimeError("JPEG encoding of a frame failed")
    return rr.EncodedImage(contents=jpeg.tobytes(), media_type="image/jpeg")


def skeleton_context(label: str, colour: tuple[int, int, int]) -> rr.AnnotationContext:
    """BlazePose's 33 keypoints named and joined, so rerun draws points logged with
    class 0 and keypoint ids as a labelled skeleton."""
    return rr.AnnotationContext(
        rr.ClassDescription(
            info=rr.AnnotationInfo(id=0, label=label, color=colour),
            keypoint_annotations=[
                rr.AnnotationInfo(id=i, label=name) for i, name in enumerate(LANDMARK_NAMES)
            ],
            keypoint_connections=list(CONNECTIONS),
        )
    )


def _person_said(person_id: int | None) -> str:
    """'id 3 (violet box)': the person a warning is for, as camera/people draws them
    ('' when the warning names no one)."""
    if person_id is None:
        return ""
    return f"id {person_id} ({person_colour_name(person_id)} box)"


class RunRecording(WholeOrNothing):
    """Writes one run to a .rrd file."""

    def __init__(
        self,
        path: Path,
        application_id: str = "monopic",
        recording_id: str | None = None,
        *,
        layout: rrb.Blueprint | None = None,
    ):
        """`layout` replaces the default blueprint (or `start` it later, before the images)."""
        self.path = Path(path)
        self.tmp = temporary_sibling(self.path)
        self.rec = rr.RecordingStream(application_id, recording_id=recording_id)
        self._blueprint: rr.RecordingStream | None = None
        self.started = False
        self.time = 0.0  # seconds of the frame being logged
        self._warned = False  # the primary predictor's warning on the last processed frame
        self._warned_id: int | None = None  # the person that warning was for
        if layout is not None:
            self.start(layout)
        skeleton = skeleton_context("person", PIPELINE_COLOUR)
        self.rec.log("camera/pose", skeleton, static=True)
        self.rec.log("camera/people", skeleton, static=True)
        self._people: set[int] = set()  # identities with entities now
        for name, colour in FEATURE_COLOURS.items():
            self.rec.log(
                f"features/{name}", rr.SeriesLines(names=name, colors=[colour]), static=True
            )

    def start(self, layout: rrb.Blueprint) -> None:
        """Open the file with this blueprint; what was logged before is kept and written.

        What `rec.save(path, default_blueprint=layout)` does, without the blueprint stream
        rerun 0.41 would leak (monopic.rerun_file)."""
        if self.started:
            raise RuntimeError(f"{self.path}: the recording has already started")
        remove_stale_temporaries(self.path.parent, output=self.path)
        self._blueprint = save_with_blueprint(self.rec, self.tmp, layout)
        self.started = True

    def log_frame(self, image: np.ndarray, result: FrameResult) -> None:
        """One processed frame: its image and everything the pipeline found."""
        self.set_time(result.frame_index, result.timestamp)
        self.log_image(image)
        self.log_result(result)

    def set_time(self, frame_index: int, timestamp: float) -> None:
        """Put what is logged next on this frame of both timelines."""
        self.rec.set_time("frame", sequence=frame_index)
        self.rec.set_time("time", duration=timestamp)
        self.time = timestamp

    def log_event(
        self,
        text: str,
        level: str = rr.TextLogLevel.INFO,
        colour: tuple[int, int, int] | None = None,
    ) -> None:
        """A line in the events view at the current time: "2.07 s  text" (in `colour`:
        a person's, for a line about them)."""
        self.rec.log("events", rr.TextLog(f"{self.time:.2f} s  {text}", level=level, color=colour))

    def log_image(self, image: np.ndarray, entity: str = "camera/image") -> None:
        """An RGB image, JPEG-compressed, at the current time (the first one starts the file)."""
        if not self.started:
            self.start(blueprint(image.shape[1], image.shape[0]))
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
            zone = np.vstack([w.zone, w.zone[:1]])
            rec.log("camera/zone", rr.LineStrips2D([zone], colors=[RISK_COLOURS[w.risk]]))
            who = _person_said(result.person_id)
            pid = result.person_id
            colour = person_colour(pid) if pid is not None else None
            if w.collision and not self._warned:
                self.log_event(
                    f"COLLISION IMMINENT ({result.primary}): {who + ', ' if who else ''}"
                    f"case {int(p.case)} ({p.case.label})",
                    rr.TextLogLevel.WARN,
                    colour,
                )
            elif w.collision and pid is not None and pid != self._warned_id:
                self.log_event(
                    f"warning now for {who} ({result.primary})", rr.TextLogLevel.WARN, colour
                )
            elif self._warned and not w.collision:
                self.log_event(f"warning cleared ({result.primary})")
            self._warned = w.collision
            self._warned_id = result.person_id if w.collision else None
        else:
            rec.log("camera/zone", rr.Clear(recursive=False))
            self._warned = False
            self._warned_id = None
        if p is not None and f is not None:
            colour = predictor_colour(result.primary)
            rec.log(
                "camera/prediction/point",
                rr.Points2D(
                    [p.center],
                    radii=-6.0,
                    colors=[colour],
                    labels=[f"predicted: case {int(p.case)}"],
                ),
            )
            if result.path is not None:
                rec.log(
                    "camera/prediction/path",
                    rr.LineStrips2D([result.path.image_path], colors=[colour], radii=-1.5),
                )
        else:
            rec.log("camera/prediction", rr.Clear(recursive=True))
        if f is not None:
            for name, value in (("phi", f.phi), ("vx", f.vx), ("vy", f.vy)):
                if np.isfinite(value):
                    rec.log(f"features/{name}", rr.Scalars(value))
        for stage in LATENCY_STAGES:
            if stage in result.stage_ms:
                rec.log(f"latency/{stage}", rr.Scalars(result.stage_ms[stage]))
        self._log_people(result)

    def _log_people(self, result: FrameResult) -> None:
        """One entity per person seen; those gone since the last frame are cleared."""
        rec = self.rec
        present = set()
        for person in result.people:
            entity = f"camera/people/{person.person_id}"
            present.add(person.person_id)
            colour = person_colour(person.person_id)
            p = person.prediction
            label = f"id {person.person_id}" + (f" case {int(p.case)}" if p is not None else "")
            x0, y0, x1, y1 = person.box
            rec.log(
                f"{entity}/box",
                rr.Boxes2D(
                    mins=[[x0, y0]], sizes=[[x1 - x0, y1 - y0]], labels=[label], colors=[colour]
                ),
            )
            if person.pose is not None:
                rec.log(
                    f"{entity}/pose",
                    rr.Points2D(
                        person.pose.landmarks[:, :2],
                        class_ids=0,
                        keypoint_ids=np.arange(len(LANDMARK_NAMES)),
                        colors=[colour],
                        radii=-2.0,
                    ),
                )
            else:
                rec.log(f"{entity}/pose", rr.Clear(recursive=False))
            if p is not None:
                point = rr.Points2D([p.center], colors=[colour], radii=-5.0)
                rec.log(f"{entity}/prediction", point)
            else:
                rec.log(f"{entity}/prediction", rr.Clear(recursive=False))
        for gone in sorted(self._people - present):
            rec.log(f"camera/people/{gone}", rr.Clear(recursive=True))
        self._people = present

    def close(self) -> None:
        """Flush and move the finished file into place (or, if that fails or is
        interrupted, delete it)."""
        try:
            if not self.started:
                self.start(blueprint())
            self.rec.flush()
            self._release()
            os.replace(self.tmp, self.path)
        except BaseException:
            self.tmp.unlink(missing_ok=True)
            raise

    def abort(self) -> None:
        """Drop the partial recording."""
        try:
            self._release()
        finally:
            self.tmp.unlink(missing_ok=True)

    def _release(self) -> None:
        """Free the stream's native side at once (monopic.rerun_file.release)."""
        release(self.rec, self.started, self._blueprint)
        del self.rec
        self._blueprint = None
