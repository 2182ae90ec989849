"""Scenario runs in rerun: what monopic's RunRecording logs plus what only the simulator knows.

One module logs the pipeline (monopic/recording.py, RunRecording); this one adds, on
the same stream, the ground truth and the world around the camera, and lays the views
out so the story of a run (what the camera saw, what the pipeline made of it, what was
really going to happen) reads at a glance. Entities added to RunRecording's:

- camera/truth/{foot,centre,box,path}: the true foot point, torso centre and apparent box,
  and the true foot path over the next horizon seen by the current camera (the frame the
  ground-mode prediction is drawn in, so the two compare directly);
- world/...: a 3D view of the ground plane in the world frame of sim.geometry.frames (z up):
  world/road (edges, lanes, zebra crossing, parked cars; static), world/robot (a
  Transform3D per frame; below it, in the robot frame, the body, the camera frustum,
  the swept zone and world/robot/prediction/<predictor>: every ground-mode decision's
  predicted foot point), world/robot_trail, world/pedestrian (the 33 landmarks as a
  skeleton, the footprint), world/truth/{path,future} (the whole true path; the part
  within the horizon);
- topdown/image: highway-env's top-down view (sim.envs.crossing.TopDownViewer), every few
  frames;
- time series: truth/phi next to features/phi, and truth/head_yaw (the head turned from
  the shoulders: a human walker's head checks and turn leads); ttc/truth and
  ttc/<predictor> (ground mode's predicted time to contact); alarm/truth (contact within
  the horizon) and alarm/<predictor> (its warning), 0/1 scalars for tools and, on the
  same entities, a state lane each (StateChange: clear / collision course / contact for
  the truth; clear / near / WARNING / no decision for a predictor) so warnings line up
  against the truth at a glance; robot/speed and truth/gap (footprint distance),
  brake/command (closed loop); with a real camera (sim.sensor) sensor/exposure_ms,
  sensor/gain and sensor/subframes, the exposure each frame was taken with;
- events: first frame on a collision course, contact, pose found and lost, each
  predictor's warning onset, whom the robot's warning is for by the truth (at its onset
  and whenever it passes to another track: the track's id and box colour, the person it
  is matched to, sim.world.warned_for, or nobody, and whether they are on a collision
  course), and whatever the caller adds (`log_event`).

`SimRecording` is the per-frame API a runner calls (the sweep can record every run and
keep only the ones that went wrong: `close()` keeps the file, `abort()` drops it);
sim.runs.record.record_run runs one scenario through the pipeline and records it.

Colours: truth cyan, robot green, pedestrian orange, the pipeline pink, each predictor its
own (monopic.recording.predictor_colour) in the 3D view and the plots alike. The camera
view is framed on the image; the 3D view opens behind and above the robot's start, looking
toward where robot and pedestrian meet; plots and lanes span the whole run.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from monopic.closing import WholeOrNothing
from monopic.people.colour import person_colour
from monopic.pipeline import FrameResult
from monopic.pose.skeleton import LANDMARK_NAMES
from monopic.predict.base import Mode
from monopic.recording import (
    FEATURE_COLOURS,
    RISK_COLOURS,
    RunRecording,
    encoded_jpeg,
    events_view,
    image_bounds,
    panels,
    predictor_colour,
    skeleton_context,
)
from monopic.variants.zone import swept_ground_zone
from sim.recording.topdown import TopDownCamera
from sim.scenario.spec import Scenario
from sim.world.ground_truth import GroundTruth, footprint_gap, footprints
from sim.world.warned_for import warned_for
from sim.world.world import World, WorldStep

TRUTH_COLOUR = (0, 210, 255)
HEAD_COLOUR = (120, 120, 255)  # the true head yaw beside the true phi
ROBOT_COLOUR = (50, 200, 0)
ZONE_COLOUR = (150, 240, 150)  # the robot's swept zone on the ground
PEDESTRIAN_COLOUR = (255, 140, 0)
PERSON_COLOUR = (200, 200, 200)  # a person among several, not on a collision course
COURSE_COLOUR = (255, 60, 60)  # a person on a collision course within the horizon
ROAD_COLOUR = (150, 150, 150)
BRAKE_COLOUR = (255, 110, 70)
# State lanes (alarm/*): what a predictor said and what was really coming, colour for colour.
CLEAR, NEAR, WARNING, UNDECIDED = "clear", "near", "WARNING", "no decision"
COURSE, CONTACT = "collision course", "contact"
CLEAR_COLOUR = (45, 95, 60)
# Plots and lanes show the whole timeline: left to itself, each plot fits its own data (a
# predicted time to contact that exists for half a second fills the width, out of line with
# the plots beside it). (LinkAxis.LinkToGlobal would make rerun 0.41 ignore the range.)
WHOLE_RUN = rrb.TimeAxis(
    view_range=rrb.TimeRange(
        start=rrb.TimeRangeBoundary.absolute(seconds=0.0), end=rrb.TimeRangeBoundary.infinite()
    )
)
TOP_LEFT = rrb.PlotLegend(corner=rrb.Corner2D.LeftTop)
TOP_RIGHT = rrb.PlotLegend(corner=rrb.Corner2D.RightTop)
PREDICTOR_STATES = rr.StateConfiguration(
    values=[CLEAR, NEAR, WARNING, UNDECIDED],
    labels=["clear", "near (yellow)", "WARNING", "no decision"],
    colors=[CLEAR_COLOUR, RISK_COLOURS["yellow"], RISK_COLOURS["red"], (70, 70, 70)],
)
TRUTH_STATES = rr.StateConfiguration(
    values=[CLEAR, COURSE, CONTACT],
    labels=["truth: no collision coming", "truth: collision within the horizon", "truth: CONTACT"],
    colors=[CLEAR_COLOUR, RISK_COLOURS["red"], (140, 0, 0)],
)
ROBOT_BODY_HEIGHT = 0.4  # m, only for drawing
PATH_SAMPLES = 11  # points on the true path over the horizon
DEFAULT_TOPDOWN_EVERY = 3  # frames between top-down images (5 per second at 15 fps)


def entity_name(predictor: str) -> str:
    """A predictor key ("rules/ground") as one entity path part ("rules-ground")."""
    return predictor.replace("/", "-")


# -- footprints ----------------------------------------------------------------------


# -- the layout ----------------------------------------------------------------------


def sim_blueprint(
    width: int | None = None,
    height: int | None = None,
    eye: rrb.EyeControls3D | None = None,
    sensor: bool = False,
) -> rrb.Blueprint:
    """Camera big on the left; 3D world over the top-down view on the right; plots below.

    The camera view is framed on the width x height image when given; `eye` places the 3D
    view's eye (see `world_eye`); every plot and the warning lanes show the whole run.
    `sensor`: a real camera's exposure, gain and sub-frame draws get a plot of their own.
    """
    bounds = image_bounds(width, height) if width and height else None
    sensor_views = [
        rrb.TimeSeriesView(
            origin="sensor",
            name="camera: exposure (ms), gain, sub-frame draws",
            plot_legend=TOP_LEFT,
            axis_x=WHOLE_RUN,
        )
    ] if sensor else []  # fmt: skip
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial2DView(
                    origin="camera",
                    name="robot camera: pipeline (pink, zone by risk) and truth (cyan)",
                    visual_bounds=bounds,
                ),
                rrb.Vertical(
                    rrb.Spatial3DView(
                        origin="world",
                        name="world: truth cyan, robot green, pedestrian orange",
                        eye_controls=eye,
                    ),
                    rrb.Spatial2DView(origin="topdown", name="highway-env top-down"),
                    row_shares=[3, 2],
                ),
                column_shares=[3, 2],
            ),
            rrb.Horizontal(
                rrb.StateTimelineView(
                    origin="alarm", name="warnings vs truth (bottom lane)", time_view=WHOLE_RUN
                ),
                rrb.Vertical(
                    rrb.TimeSeriesView(
                        origin="ttc",
                        name="time to contact (s)",
                        plot_legend=TOP_RIGHT,
                        axis_x=WHOLE_RUN,
                    ),
                    rrb.TimeSeriesView(
                        origin="/",
                        contents=["robot/speed", "truth/gap", "brake/command"],
                        name="robot speed (m/s), footprint gap (m)",
                        plot_legend=TOP_RIGHT,
                        axis_x=WHOLE_RUN,
                    ),
                ),
                rrb.Vertical(
                    rrb.TimeSeriesView(
                        origin="/",
                        contents=["features/phi", "truth/phi", "truth/head_yaw"],
                        name="phi (deg): estimated vs true; true head yaw from the shoulders",
                        axis_x=WHOLE_RUN,
                    ),
                    rrb.TimeSeriesView(
                        origin="features",
                        contents=["features/vx", "features/vy"],
                        name="image velocity (px/s)",
                        axis_x=WHOLE_RUN,
                    ),
                ),
                rrb.Vertical(
                    events_view(name="events"),
                    rrb.TimeSeriesView(
                        origin="latency",
                        name="latency (ms)",
                        plot_legend=TOP_LEFT,
                        axis_x=WHOLE_RUN,
                    ),
                    *sensor_views,
                    row_shares=[3, 2, 2] if sensor else [3, 2],
                ),
                column_shares=[4, 3, 3, 4],
            ),
            row_shares=[5, 4],
        ),
        *panels(),
    )


def world_eye(start: np.ndarray, yaw: float, meet: np.ndarray) -> rrb.EyeControls3D:
    """An orbiting eye behind and above the robot's `start` (heading `yaw`) toward `meet`.

    `meet` is where the run's story happens (where robot and pedestrian come closest). The
    eye looks at a point two thirds of the way there, along the robot's heading and a
    little from its right (a crossing reads sideways), from high and far enough back to
    keep the robot in view from its first metre on.
    """
    start, meet = np.asarray(start, dtype=float)[:2], np.asarray(meet, dtype=float)[:2]
    span = max(float(np.linalg.norm(meet - start)), 3.0)
    forward = np.array([math.cos(yaw), math.sin(yaw)])
    right = np.array([math.sin(yaw), -math.cos(yaw)])
    target = start + (meet - start) * 2 / 3
    eye = target - (0.6 * span + 1.5) * forward + 0.25 * span * right
    return rrb.EyeControls3D(
        kind=rrb.Eye3DKind.Orbital,
        position=[float(eye[0]), float(eye[1]), 0.5 * span + 1.5],
        look_target=[float(target[0]), float(target[1]), 0.0],
        eye_up=[0.0, 0.0, 1.0],
    )


# -- highway-env's top-down view -------------------------------------------------------


# -- the recording ---------------------------------------------------------------------


@dataclass(frozen=True)
class RecordSummary:
    """What a recorded run amounted to."""

    path: Path
    frames: int
    found: int  # frames where the pipeline had a pose
    contact_time: float | None
    warned: dict[str, int]  # frames with a warning, per predictor
    collision_frames: int  # frames with a true collision within the horizon
    bytes: int
    missed: tuple[str, ...] = ()  # predictors that never warned while a collision was coming
    false_alarms: tuple[str, ...] = ()  # predictors that warned in a run without a collision
    primary: str = ""  # the pipeline's primary predictor (its warning is the robot's)


class SimRecording(WholeOrNothing):
    """One scenario run written to .rrd, frame by frame.

    Call `log_step(step, result)` right after each World step (result: the pipeline's
    FrameResult for step.frame, or None when the pipeline did not run on it), then
    `close()` to keep the file or `abort()` to drop it. Use as a context manager to get
    `abort()` on an exception and `close()` otherwise.
    """

    @property
    def rec(self) -> rr.RecordingStream:
        """The run's stream (not kept here: closing the run frees it)."""
        return self.run.rec

    def __init__(
        self,
        path: Path,
        world: World,
        *,
        topdown_every: int = DEFAULT_TOPDOWN_EVERY,
        application_id: str = "monopic-sim",
        recording_id: str | None = None,
    ) -> None:
        if topdown_every < 0:
            raise ValueError(f"topdown_every must be >= 0 (0: none), got {topdown_every}")
        self.world = world
        self.scenario: Scenario = world.scenario
        self.topdown_every = topdown_every
        # The file starts on the first step, when the blueprint can frame the world.
        self.run = RunRecording(Path(path), application_id, recording_id or self.scenario.name)
        self._topdown: TopDownCamera | None = None
        self._static_done = False
        self._people_static = False
        self._robot_trail: list[list[float]] = []
        self._was_found = False
        self._was_colliding = False
        self._contact_logged = False
        self._warning: dict[str, bool] = {}
        self._warned_track: int | None = None  # the track the robot's warning is for
        self._drawn: set[str] = set()  # predictors with a prediction in the world view
        self._styled: set[str] = set()  # predictors whose series and lane have their style
        self._lanes: dict[str, str] = {}  # entity -> state last logged on its lane
        self._colliding_now = False
        self.frames = 0
        self.found = 0
        self.contact_time: float | None = None
        self.warned: dict[str, int] = {}
        self.warned_in_time: dict[str, bool] = {}  # warned on a frame with a true collision
        self.collision_frames = 0
        self.primary = ""  # the pipeline's primary predictor, once a result was logged

    @property
    def path(self) -> Path:
        return self.run.path

    # -- static parts ------------------------------------------------------------------

    def _meeting_point(self, step: WorldStep) -> np.ndarray:
        """World (x, y) of the pedestrian where it comes closest to the robot's planned run."""
        scenario, r = self.scenario, step.truth.robot
        start = np.asarray(r.position, dtype=float)[:2]
        path = self.world.pedestrian.path if self.world.pedestrian else None
        if path is None:
            return np.asarray(step.truth.pedestrian.position_world, dtype=float)[:2]
        ahead = np.array([math.cos(r.yaw), math.sin(r.yaw)])
        times = np.linspace(0.0, scenario.duration, max(2, int(scenario.duration * 20) + 1))
        peds = np.array([path.state(float(t)).position for t in times])[:, :2]
        robots = start + np.outer(times * r.speed, ahead)
        return peds[int(np.argmin(np.linalg.norm(peds - robots, axis=1)))]

    def _log_static(self, step: WorldStep) -> None:
        rec, scenario = self.rec, self.scenario
        if not self.run.started:
            cam = self.world.camera
            r = step.truth.robot
            eye = world_eye(r.position, r.yaw, self._meeting_point(step))
            sensor = self.scenario.robot.camera.sensor is not None
            self.run.start(sim_blueprint(cam.width, cam.height, eye, sensor=sensor))
        rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
        skeleton = skeleton_context("pedestrian", PEDESTRIAN_COLOUR)
        rec.log("world/pedestrian", skeleton, static=True)
        self._log_road()
        robot = scenario.robot
        rec.log(
            "world/robot/body",
            rr.Boxes3D(
                centers=[[0.0, 0.0, ROBOT_BODY_HEIGHT / 2]],
                half_sizes=[[robot.length / 2, robot.width / 2, ROBOT_BODY_HEIGHT / 2]],
                colors=[ROBOT_COLOUR],
            ),
            static=True,
        )
        cam = self.world.camera
        rec.log(
            "world/robot/camera",
            rr.Transform3D(translation=cam.position, mat3x3=cam.axes.T),
            static=True,
        )
        rec.log(
            "world/robot/camera",
            rr.Pinhole(
                focal_length=[cam.fx, cam.fy],
                principal_point=[cam.cx, cam.cy],
                resolution=[cam.width, cam.height],
                camera_xyz=rr.ViewCoordinates.RDF,
                image_plane_distance=0.3,  # a small frustum: it must not hide the scene
            ),
            static=True,
        )
        path = self.world.pedestrian.path if self.world.pedestrian else None
        if path is not None:
            times = np.linspace(0.0, scenario.duration, max(2, int(scenario.duration * 10) + 1))
            pts = np.array([path.state(float(t)).position for t in times])
            rec.log(
                "world/truth/path",
                rr.LineStrips3D(
                    [np.column_stack([pts, np.full(len(pts), 0.01)])],
                    colors=[(*TRUTH_COLOUR, 110)],
                    radii=0.015,
                ),
                static=True,
            )
        rec.log(  # next to the truth, the pipeline's phi is an estimate
            "features/phi",
            rr.SeriesLines(names="estimated phi", colors=[FEATURE_COLOURS["phi"]]),
            static=True,
        )
        for name, colour, label in (
            ("truth/phi", TRUTH_COLOUR, "true phi"),
            ("truth/head_yaw", HEAD_COLOUR, "true head yaw from the shoulders (deg)"),
            ("ttc/truth", TRUTH_COLOUR, "true time to contact"),
            ("alarm/truth", TRUTH_COLOUR, "true: contact within the horizon"),
            ("robot/speed", ROBOT_COLOUR, "robot speed"),
            ("truth/gap", TRUTH_COLOUR, "footprint gap"),
            ("brake/command", BRAKE_COLOUR, "brake command (m/s^2)"),
        ):
            width = 3.0 if name.endswith("truth") else 2.0
            rec.log(name, rr.SeriesLines(names=label, colors=[colour], widths=width), static=True)
        rec.log("alarm/truth", TRUTH_STATES, static=True)
        self._static_done = True

    def _log_road(self) -> None:
        """Road edges, lane lines, pavements, crossing and parked cars over the run's stretch."""
        scenario, road = self.scenario, self.scenario.scene.road
        reach = scenario.robot.speed * scenario.duration + 2 * scenario.robot.length
        path = self.world.pedestrian.path if self.world.pedestrian else None
        xs = [0.0, reach]
        if path is not None:
            xs += [float(path.state(t).position[0]) for t in (0.0, scenario.duration)]
        x0, x1 = min(xs) - 5.0, max(xs) + 10.0
        y_right, y_left = road.edges
        kerb = 0.15
        lines, colours = [], []
        for y in (y_right, y_left):
            lines.append([[x0, y, 0.0], [x1, y, 0.0]])
            colours.append((235, 235, 235))
        for y in (y_right - kerb - road.pavement_width, y_left + kerb + road.pavement_width):
            lines.append([[x0, y, 0.0], [x1, y, 0.0]])
            colours.append(ROAD_COLOUR)
        for k in range(1, road.lanes):
            y = y_right + k * road.lane_width
            x = x0
            while x < x1:  # dashed lane line
                lines.append([[x, y, 0.0], [min(x + road.dash_length, x1), y, 0.0]])
                colours.append((200, 200, 200))
                x += road.dash_length + road.dash_gap
        if road.crosswalk_x is not None and x0 <= road.crosswalk_x <= x1:
            cx, h = road.crosswalk_x, road.crosswalk_length / 2
            lines.append(
                [
                    [cx - h, y_right, 0.0],
                    [cx + h, y_right, 0.0],
                    [cx + h, y_left, 0.0],
                    [cx - h, y_left, 0.0],
                    [cx - h, y_right, 0.0],
                ]
            )
            colours.append((255, 255, 255))
        self.rec.log("world/road", rr.LineStrips3D(lines, colors=colours, radii=0.03), static=True)
        occluders = scenario.scene.occluders
        turn = [rr.RotationAxisAngle(axis=(0, 0, 1), radians=o.yaw) for o in occluders]
        if occluders:
            self.rec.log(
                "world/road/parked_cars",
                rr.Boxes3D(
                    centers=[[o.x, o.y, o.height / 2] for o in occluders],
                    half_sizes=[[o.length / 2, o.width / 2, o.height / 2] for o in occluders],
                    rotations=turn,
                    colors=[tuple(int(255 * c) for c in o.colour) for o in occluders],
                ),
                static=True,
            )

    # -- per frame ---------------------------------------------------------------------

    def log_step(self, step: WorldStep, result: FrameResult | None) -> None:
        """One frame: the camera image, the pipeline's result if any, the truth, the world."""
        if not self._static_done:
            self._log_static(step)
        rec, truth = self.rec, step.truth
        self.run.set_time(step.index, step.time)
        if step.frame is not None:
            self.run.log_image(step.frame.image)
        self._colliding_now = truth.pedestrian.collision
        if result is not None:
            self.primary = self.primary or result.primary
            self.run.log_result(result)
        self._log_decisions(result)
        self._log_camera_truth(truth)
        self._log_world(step)
        if len(truth.people) > 1:
            self._log_people(truth)
        self._log_series(truth)
        self._log_events(step, result)
        self._log_warned_for(truth, result)
        if self.topdown_every and step.index % self.topdown_every == 0 and self.world.road:
            if self._topdown is None:
                self._topdown = TopDownCamera(self.world)
            rec.log("topdown/image", encoded_jpeg(self._topdown.render()))
        self.frames += 1
        self.collision_frames += int(truth.pedestrian.collision)

    def log_event(self, text: str, level: str = rr.TextLogLevel.INFO) -> None:
        """A line in the events view at the current frame (e.g. the closed loop's brake)."""
        self.run.log_event(text, level)

    def log_series(self, entity: str, value: float) -> None:
        """A scalar at the current frame (e.g. the closed loop's brake command)."""
        if math.isfinite(value):
            self.rec.log(entity, rr.Scalars(value))

    def _style(self, predictor: str) -> None:
        """A predictor's colour and name on its series, and its lane's states, once."""
        name = entity_name(predictor)
        if name in self._styled:
            return
        colour = predictor_colour(predictor)
        rec = self.rec
        rec.log(
            f"ttc/{name}", rr.SeriesLines(names=predictor, colors=[colour], widths=2.0), static=True
        )
        rec.log(f"alarm/{name}", rr.SeriesLines(names=predictor, colors=[colour]), static=True)
        rec.log(f"alarm/{name}", PREDICTOR_STATES, static=True)
        self._styled.add(name)

    def _lane(self, entity: str, state: str) -> None:
        """Move a state lane to `state` (logged only when it changes)."""
        if self._lanes.get(entity) != state:
            self.rec.log(entity, rr.StateChange(state=state))
            self._lanes[entity] = state

    def _log_decisions(self, result: FrameResult | None) -> None:
        """Every predictor's warning as 0/1 and a lane; ground mode's prediction in 3D."""
        rec = self.rec
        drawn, decided = set(), set()
        feats = result.features if result is not None else None
        for d in result.decisions if result is not None else ():
            self._style(d.predictor)
            name = entity_name(d.predictor)
            decided.add(name)
            rec.log(f"alarm/{name}", rr.Scalars(float(d.warning.collision)))
            risk = d.warning.risk
            lane = WARNING if d.warning.collision else NEAR if risk == "yellow" else CLEAR
            self._lane(f"alarm/{name}", lane)
            if d.warning.time_to_contact is not None:
                rec.log(f"ttc/{name}", rr.Scalars(d.warning.time_to_contact))
            warned = d.warning.collision
            self.warned[d.predictor] = self.warned.get(d.predictor, 0) + int(warned)
            in_time = self.warned_in_time.get(d.predictor, False)
            self.warned_in_time[d.predictor] = in_time or (warned and self._colliding_now)
            ground = d.prediction.ground
            if d.mode is not Mode.GROUND or ground is None or not (feats and feats.ground):
                continue
            g0 = feats.ground.position
            rec.log(
                f"world/robot/prediction/{name}",
                rr.LineStrips3D(
                    [[[g0[0], g0[1], 0.03], [ground[0], ground[1], 0.03]]],
                    colors=[predictor_colour(d.predictor)],
                    radii=0.03,
                ),
            )
            drawn.add(name)
        for name in self._styled - decided:  # known predictors that could not decide
            self._lane(f"alarm/{name}", UNDECIDED)
        for name in self._drawn - drawn:  # no ground prediction this frame
            rec.log(f"world/robot/prediction/{name}", rr.Clear(recursive=False))
        self._drawn = drawn

    def _log_camera_truth(self, truth: GroundTruth) -> None:
        rec = self.rec
        camera = self.world.camera
        foot = truth.pedestrian.foot_px
        if truth.pedestrian.in_frame and np.all(np.isfinite(foot)):
            rec.log(
                "camera/truth/foot",
                rr.Points2D([foot], colors=[TRUTH_COLOUR], radii=-5.0, labels=["truth"]),
            )
            rec.log(
                "camera/truth/centre",
                rr.Points2D([truth.pedestrian.centre_px], colors=[TRUTH_COLOUR], radii=-3.0),
            )
            rec.log(
                "camera/truth/box",
                rr.Boxes2D(
                    array=np.array(truth.pedestrian.box),
                    array_format=rr.Box2DFormat.XYXY,
                    colors=[TRUTH_COLOUR],
                ),
            )
        else:
            rec.log("camera/truth", rr.Clear(recursive=True))
            return
        future = self._future_path(truth)
        pose = truth.robot.pose
        local = pose.to_local(np.column_stack([future, np.zeros(len(future))]))
        px = camera.project(local)
        px = px[np.all(np.isfinite(px), axis=1)]
        if len(px) >= 2:
            rec.log(
                "camera/truth/path",
                rr.LineStrips2D([px], colors=[TRUTH_COLOUR], radii=-1.5),
            )
        else:
            rec.log("camera/truth/path", rr.Clear(recursive=False))

    def _future_path(self, truth: GroundTruth) -> np.ndarray:
        """World (x, y) of the true path from now to now + horizon."""
        path = self.world.pedestrian.path if self.world.pedestrian else None
        if path is None:
            return np.array(
                [truth.pedestrian.position_world, truth.pedestrian.future_position_world]
            )
        times = truth.time + np.linspace(0.0, truth.pedestrian.horizon, PATH_SAMPLES)
        return np.array([path.state(float(t)).position for t in times])

    def _log_world(self, step: WorldStep) -> None:
        rec, truth, scenario = self.rec, step.truth, self.scenario
        r = truth.robot
        rec.log(
            "world/robot",
            rr.Transform3D(
                translation=[float(r.position[0]), float(r.position[1]), 0.0],
                rotation=rr.RotationAxisAngle(axis=[0, 0, 1], radians=r.yaw),
            ),
        )
        zone = swept_ground_zone(scenario.robot.geometry(), r.speed, scenario.horizon)
        closed = np.vstack([zone, zone[:1]])
        rec.log(
            "world/robot/zone",
            rr.LineStrips3D(
                [np.column_stack([closed, np.full(len(closed), 0.02)])],
                colors=[ZONE_COLOUR],
                radii=0.03,
            ),
        )
        self._robot_trail.append([float(r.position[0]), float(r.position[1]), 0.02])
        if len(self._robot_trail) >= 2:
            rec.log(
                "world/robot_trail",
                rr.LineStrips3D([self._robot_trail], colors=[ROBOT_COLOUR], radii=0.02),
            )
        rec.log(
            "world/pedestrian",
            rr.Points3D(
                truth.pedestrian.body.landmarks_world,
                class_ids=0,
                keypoint_ids=np.arange(len(LANDMARK_NAMES)),
                radii=0.025,
            ),
        )
        _, ped = footprints(truth, scenario.pedestrian.footprint)
        ring = np.vstack([ped, ped[:1]])
        rec.log(
            "world/pedestrian/footprint",
            rr.LineStrips3D(
                [np.column_stack([ring, np.full(len(ring), 0.02)])],
                colors=[PEDESTRIAN_COLOUR],
                radii=0.02,
            ),
        )
        future = self._future_path(truth)
        rec.log(
            "world/truth/future",
            rr.LineStrips3D(
                [np.column_stack([future, np.full(len(future), 0.04)])],
                colors=[TRUTH_COLOUR],
                radii=0.04,
            ),
        )

    def _log_people(self, truth: GroundTruth) -> None:
        """With several people, each under their own name, the scripted one included: the
        skeleton and footprint in the world, the whole and the visible box in the camera,
        red while on a collision course, labelled with how much of them is hidden."""
        rec = self.rec
        if not self._people_static:
            rec.log("world/people", skeleton_context("person", PERSON_COLOUR), static=True)
            self._people_static = True
        for p in truth.people:
            colour = COURSE_COLOUR if p.collision else PERSON_COLOUR
            rec.log(
                f"world/people/{p.name}",
                rr.Points3D(
                    p.body.landmarks_world,
                    class_ids=0,
                    keypoint_ids=np.arange(len(LANDMARK_NAMES)),
                    radii=0.025,
                    colors=[colour],
                ),
            )
            ring = np.vstack([p.footprint_world, p.footprint_world[:1]])
            rec.log(
                f"world/people/{p.name}/footprint",
                rr.LineStrips3D(
                    [np.column_stack([ring, np.full(len(ring), 0.02)])], colors=[colour], radii=0.02
                ),
            )
            seen = p.visibility
            hidden = 0.0 if seen is None else seen.hidden
            label = f"{p.name}{' on course' if p.collision else ''}, {hidden:.0%} hidden"
            if not p.in_frame:
                rec.log(f"camera/people_truth/{p.name}", rr.Clear(recursive=True))
                continue
            rec.log(
                f"camera/people_truth/{p.name}/box",
                rr.Boxes2D(
                    array=np.array(p.box),
                    array_format=rr.Box2DFormat.XYXY,
                    colors=[colour],
                    labels=[label],
                ),  # fmt: skip
            )
            if seen is not None and np.all(np.isfinite(seen.box)):
                rec.log(
                    f"camera/people_truth/{p.name}/visible",
                    rr.Boxes2D(
                        array=np.array(seen.box),
                        array_format=rr.Box2DFormat.XYXY,
                        colors=[colour],
                        radii=-0.5,
                    ),  # fmt: skip
                )
            else:
                rec.log(f"camera/people_truth/{p.name}/visible", rr.Clear(recursive=False))
        rec.log("truth/threats", rr.Scalars(float(sum(p.collision for p in truth.people))))

    def _log_series(self, truth: GroundTruth) -> None:
        rec = self.rec
        rec.log("truth/phi", rr.Scalars(truth.pedestrian.phi))
        rec.log("truth/head_yaw", rr.Scalars(math.degrees(truth.pedestrian.head_yaw_shoulders)))
        if truth.pedestrian.time_to_collision is not None:
            rec.log("ttc/truth", rr.Scalars(truth.pedestrian.time_to_collision))
        rec.log("alarm/truth", rr.Scalars(float(truth.pedestrian.collision)))
        self._lane(
            "alarm/truth",
            CONTACT
            if truth.pedestrian.contact
            else COURSE
            if truth.pedestrian.collision
            else CLEAR,
        )
        rec.log("robot/speed", rr.Scalars(truth.robot.speed))
        rec.log("truth/gap", rr.Scalars(footprint_gap(truth, self.scenario.pedestrian.footprint)))
        if truth.camera is not None:  # a real camera's exposure of this frame (sim.sensor)
            rec.log("sensor/exposure_ms", rr.Scalars(1000.0 * truth.camera.exposure_s))
            rec.log("sensor/gain", rr.Scalars(truth.camera.gain))
            rec.log("sensor/subframes", rr.Scalars(float(truth.camera.subframes)))

    def _log_events(self, step: WorldStep, result: FrameResult | None) -> None:
        truth = step.truth
        if truth.pedestrian.collision and not self._was_colliding and not truth.pedestrian.contact:
            ttc = truth.pedestrian.time_to_collision
            self.log_event(
                f"truth: on a collision course, contact in {ttc:.2f} s"
                if ttc is not None
                else "truth: on a collision course",
                rr.TextLogLevel.WARN,
            )
        self._was_colliding = truth.pedestrian.collision
        if truth.pedestrian.contact and not self._contact_logged:
            self.contact_time = truth.time
            self._contact_logged = True
            self.log_event(
                f"CONTACT at {truth.time:.2f} s, robot at {truth.robot.speed:.2f} m/s",
                rr.TextLogLevel.ERROR,
            )
        if result is None:
            return
        found = result.pose.found
        self.found += int(found)
        if found != self._was_found:
            self.log_event("pose found" if found else "pose lost", rr.TextLogLevel.DEBUG)
        self._was_found = found
        for d in result.decisions:
            was = self._warning.get(d.predictor, False)
            if d.warning.collision and not was:
                self.log_event(f"{d.predictor}: warning on", rr.TextLogLevel.WARN)
            self._warning[d.predictor] = d.warning.collision
        for key, was in list(self._warning.items()):
            if was and result.decision(key) is None:
                self._warning[key] = False

    def _log_warned_for(self, truth: GroundTruth, result: FrameResult | None) -> None:
        """Whom the robot's warning is for, by the truth: at its onset and whenever it
        passes to another track (the events view, in that track's box colour)."""
        warning = result.warning if result is not None else None
        if result is None or warning is None or not warning.collision:
            self._warned_track = None
            return
        if result.person_id is None or result.person_id == self._warned_track:
            return
        self._warned_track = result.person_id
        who = warned_for(result, truth)
        assert who is not None  # a person id was given
        self.run.log_event(
            f"truth: the warning ({result.primary}) is for {who.said()}",
            rr.TextLogLevel.WARN,
            colour=person_colour(result.person_id),
        )

    # -- finishing -----------------------------------------------------------------------

    def missed(self) -> tuple[str, ...]:
        """Predictors that never warned on a frame where the footprints would meet in time."""
        if self.collision_frames == 0:
            return ()
        return tuple(p for p in self.warned if not self.warned_in_time.get(p, False))

    def false_alarms(self) -> tuple[str, ...]:
        """Predictors that warned although no collision was ever coming in this run."""
        if self.collision_frames > 0:
            return ()
        return tuple(p for p, n in self.warned.items() if n > 0)

    def went_wrong(self, predictor: str | None = None) -> bool:
        """A missed collision or a false alarm of `predictor` (default: the primary one).

        What a sweep keeps by default: `rec.close() if record_all or rec.went_wrong()
        else rec.abort()`.
        """
        key = predictor or self.primary
        if self.collision_frames > 0:
            return not self.warned_in_time.get(key, False)
        return self.warned.get(key, 0) > 0

    def summary(self) -> RecordSummary:
        size = self.path.stat().st_size if self.path.exists() else 0
        return RecordSummary(
            self.path,
            self.frames,
            self.found,
            self.contact_time,
            dict(self.warned),
            self.collision_frames,
            size,
            self.missed(),
            self.false_alarms(),
            self.primary,
        )

    def close(self) -> RecordSummary:
        """Finish the file and move it into place."""
        self._close_topdown()
        self.run.close()
        return self.summary()

    def abort(self) -> None:
        """Drop the recording (e.g. a sweep run that went right)."""
        self._close_topdown()
        self.run.abort()

    def _close_topdown(self) -> None:
        if self._topdown is not None:
            self._topdown.close()
            self._topdown = None
