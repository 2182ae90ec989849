"""Everyone in view, each followed with an identity: detection, association, landmarks.

Each frame:
1. every person's box moves on by their motion (monopic.people.motion);
2. when detection is due (every `detect_every` frames, and right after someone's
   landmarks were lost), the detector looks at the whole frame and the next tiles of the
   cascade (at most `search_budget` windows a frame, resuming where the last detection
   stopped, as the one-person search does); its boxes after non-max suppression across
   the windows are matched one-to-one to people's expected boxes (monopic.people.
   association); a match gives a person without landmarks a fresh region, a detection
   matching no one starts a new person;
3. the landmark model runs on at most `budget` people, most urgent first
   (monopic.people.urgency); a result is accepted only if it lies inside its own person's
   expected box (most of its visible landmarks inside it): a skeleton that slid onto a
   neighbour, or spans two people, is refused and the person keeps their box;
4. people seen (landmarks or a detection) update their motion; two people whose boxes
   have come to cover each other are one, and the younger goes; a person unseen for
   `max_coast` seconds is gone.
A person is reported once the landmark model has agreed a detection is a person (a
detection and a pose are two looks: from that frame on), or, box-only, once detected
`min_hits` times (a single spurious detection makes no one); and while seen within
`report_coast` seconds. `landmarks=False` is the box-only
baseline: the same detection and association, fed the detector's boxes alone.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from monopic.people.association import associate
from monopic.people.box import Box, detection_box, hips, pose_box, valid
from monopic.people.motion import DETECTION_NOISE, POSE_NOISE, BoxMotion
from monopic.people.urgency import turn, urgency
from monopic.pose.detector import Detection, iou
from monopic.pose.filtering import LandmarkFilter
from monopic.pose.landmarks import LandmarkModel, Pose
from monopic.pose.region import Region
from monopic.pose.search import ZOOM_MIN_SIDE, GroundBand, Window, search_windows
from monopic.pose.tracker import TrackerConfig, detector_for
from monopic.pose.warp import WideFrame

# A pose is its person's when this share of its visible landmarks lies inside the
# person's expected box grown by BOX_MARGIN of its height on each side.
MIN_INSIDE = 0.8
BOX_MARGIN = 0.1
VISIBLE = 0.5
# ... at most this share outside it on another person ...
MAX_ELSEWHERE = 0.2
# ... upright: the shoulders at least MIN_TORSO of the landmark height above the hips
# (about 0.34 for a standing adult, 0.30 at the least on PETS09's walkers) and at most
# MAX_LEAN of it to one side of them (0.07 at the most there) ...
MIN_TORSO = 0.2
MAX_LEAN = 0.2
# ... and its box at least this share of the expected height, at most its inverse.
MIN_HEIGHT_RATIO = 0.5
# Two people whose boxes overlap this much are one person followed twice.
SAME_PERSON_IOU = 0.7
# ... and so are two poses whose hips are this close, in heights (a torso is about a
# fifth of a height wide).
SAME_HIPS = 0.1
# A detection matching no one but overlapping someone this much is them, seen differently
# (a second detection of one person); below it, a neighbour.
NEW_PERSON_MAX_IOU = 0.5


@dataclass(frozen=True)
class PeopleConfig:
    """How many people, how often the detector looks, how much landmark work a frame."""

    max_people: int | None = None  # None: everyone found
    budget: int | None = None  # landmark-model runs a frame; None: everyone every frame
    # Frames between detections while everyone is followed by their landmarks: a person
    # entering is found within this many frames (more where tiles must find them).
    detect_every: int = 3
    max_coast: float = 1.0  # s a person is kept unseen (short occlusions)
    report_coast: float = 0.5  # s a person unseen is still reported, by their motion
    min_hits: int = 2  # box-only
    landmarks: bool = True  # False: the box-only baseline

    def __post_init__(self) -> None:
        if self.max_people is not None and self.max_people < 1:
            raise ValueError(f"max_people must be at least 1, got {self.max_people}")
        if self.budget is not None and self.budget < 1:
            raise ValueError(f"budget must be at least 1, got {self.budget}")
        if self.detect_every < 1:
            raise ValueError(f"detect_every must be at least 1, got {self.detect_every}")
        if not 0 <= self.report_coast <= self.max_coast:
            raise ValueError("report_coast must lie between 0 and max_coast")


@dataclass
class _Person:
    """The tracker's state of one person."""

    motion: BoxMotion
    region: Region | None  # where to run the landmark model next, if known
    filter: LandmarkFilter
    region_at: tuple[float, float] = (0.0, 0.0)  # the box centre when `region` was set
    region_frame: int = 0  # ... and the frame it was set in
    hits: int = 1
    person_id: int | None = None  # given when confirmed
    last_seen: float = 0.0
    last_landmarks: float = -np.inf
    pose: Pose | None = None  # this frame's accepted pose
    posed: bool = False  # a pose was ever accepted: the landmark model agrees it is a person
    seen: bool = False  # seen this frame (landmarks or detection)

    def set_region(self, region: Region | None, frame: int) -> None:
        self.region, self.region_frame = region, frame
        x0, y0, x1, y1 = self.motion.current()
        self.region_at = ((x0 + x1) / 2, (y0 + y1) / 2)

    def moved_region(self, frame: int) -> Region:
        """Where to run the landmark model in `frame`: the region as set, if set in the
        frame before (MediaPipe's tracking: the last pose's next region), else moved as the
        person's box has moved since (frames whose landmarks the budget skipped)."""
        assert self.region is not None
        if frame - self.region_frame <= 1:
            return self.region
        x0, y0, x1, y1 = self.motion.current()
        dx, dy = (x0 + x1) / 2 - self.region_at[0], (y0 + y1) / 2 - self.region_at[1]
        return replace(self.region, cx=self.region.cx + dx, cy=self.region.cy + dy)


@dataclass(frozen=True)
class Sighting:
    """One person in one frame: their identity, box and, when run and accepted, pose."""

    person_id: int
    box: Box
    velocity: tuple[float, float]  # the box centre's, px/s
    pose: Pose | None  # None: box only (their landmarks wait for the budget, or failed)
    seen: bool  # False: the box is the motion's estimate (not detected, no landmarks)


@dataclass(frozen=True)
class PeopleResult:
    sightings: tuple[Sighting, ...]
    detector_runs: int = 0
    landmark_runs: int = 0
    detect_ms: float = 0.0
    landmark_ms: float = 0.0


@dataclass
class PeopleTracker:
    config: TrackerConfig = field(default_factory=TrackerConfig)
    people: PeopleConfig = field(default_factory=PeopleConfig)

    def __post_init__(self) -> None:
        cfg = self.config
        self.detector = detector_for(cfg, None)
        self.landmarks = (
            LandmarkModel(cfg.threads, cfg.model, cfg.runtime, cfg.spin)
            if self.people.landmarks
            else None
        )
        self._wide = WideFrame()
        self.reset()

    def reset(self) -> None:
        """Forget everyone (e.g. at a cut in the video)."""
        self._people: list[_Person] = []
        self._next_id = 1
        self._next_tile = 0
        self._since_detection = self.people.detect_every  # detect on the first frame
        self._lost = False
        self._frame = 0  # frames processed

    def process(
        self, image: np.ndarray, timestamp: float, band: GroundBand | None = None
    ) -> PeopleResult:
        """Everyone in this RGB frame taken at `timestamp` (s: it drives each person's
        motion and landmark filters); `band`, from the camera when known, narrows the
        detector's tiles to where people can stand."""
        h, w = image.shape[:2]
        self._frame += 1
        self._wide.start(image)
        for person in self._people:
            person.motion.predict(timestamp)
            person.pose, person.seen = None, False

        detector_runs, detect_ms = 0, 0.0
        self._since_detection += 1
        if self._since_detection >= self.people.detect_every or self._lost or not self._people:
            t0 = time.perf_counter()
            detections, detector_runs = self._detect(w, h, band)
            detect_ms = (time.perf_counter() - t0) * 1e3
            self._since_detection, self._lost = 0, False
            self._match(detections, timestamp)

        t0 = time.perf_counter()
        landmark_runs = self._run_landmarks(w, h, timestamp) if self.landmarks else 0
        landmark_ms = (time.perf_counter() - t0) * 1e3
        self._merge_duplicates()
        self._people = [p for p in self._people if timestamp - p.last_seen <= self.people.max_coast]
        sightings = []
        for person in self._people:
            confirmed = (
                person.posed if self.people.landmarks else person.hits >= self.people.min_hits
            )
            if person.person_id is None and confirmed:
                person.person_id, self._next_id = self._next_id, self._next_id + 1
            if person.person_id is None:
                continue
            if timestamp - person.last_seen > self.people.report_coast:
                continue
            box = _box(person)
            sightings.append(
                Sighting(person.person_id, box, person.motion.velocity, person.pose, person.seen)
            )
        sightings.sort(key=lambda s: s.person_id)
        return PeopleResult(tuple(sightings), detector_runs, landmark_runs, detect_ms, landmark_ms)

    def _detect(self, w: int, h: int, band: GroundBand | None) -> tuple[list[Detection], int]:
        """The detector's people in the whole frame, around each person whose landmarks
        were lost (where they should be now: one window each, before anyone else's
        tile), and in the cascade's next tiles, within `search_budget` windows."""
        cfg = self.config
        lost = [_around(p.motion.current(), w, h) for p in self._people if p.region is None]
        levels = search_windows(w, h, cfg.acquire_tiles, cfg.far_tiles, cfg.tile_overlap, band)
        tiles = [win for level in levels for win in level]
        room = max(len(tiles) if cfg.search_budget == 0 else cfg.search_budget - 1, 0)
        # At least one tile a pass, so that people lost for long cannot keep the cascade
        # from reaching someone never found.
        lost = lost[: max(room - 1, 0)] if cfg.search_budget and tiles else lost
        take = min(len(tiles), max(room - len(lost), 0))
        start = self._next_tile % len(tiles) if tiles else 0
        chosen = [tiles[(start + k) % len(tiles)] for k in range(take)]
        self._next_tile = (start + take) % len(tiles) if tiles else 0
        windows = [Window(0, 0, w, h), *lost, *chosen]
        detections = self.detector.detect(self._wide.whole(), windows)
        return [d for d in detections if valid(detection_box(d))], len(windows)

    def _match(self, detections: list[Detection], timestamp: float) -> None:
        boxes = [detection_box(d) for d in detections]
        expected = [p.motion.current() for p in self._people]
        assignment = associate(expected, boxes)
        for i, j in assignment.pairs:
            person = self._people[i]
            person.motion.update(boxes[j], DETECTION_NOISE)
            person.hits += 1
            person.last_seen, person.seen = timestamp, True
            if person.region is None:
                person.set_region(_region(detections[j], self.config.region_scale), self._frame)
                person.filter.reset()
        room = (
            None if self.people.max_people is None else self.people.max_people - len(self._people)
        )
        for j in sorted(assignment.lone_detections, key=lambda j: -detections[j].score):
            if room is not None and room <= 0:
                break
            # A detection over someone already followed is them, seen differently.
            if any(iou(boxes[j], e) >= NEW_PERSON_MAX_IOU for e in expected):
                continue
            person = _Person(
                motion=BoxMotion(boxes[j], timestamp),
                region=None,
                filter=LandmarkFilter(self.config.smooth_landmarks, self.config.smooth_region),
                last_seen=timestamp,
                seen=True,
            )
            person.set_region(_region(detections[j], self.config.region_scale), self._frame)
            self._people.append(person)
            expected.append(boxes[j])
            if room is not None:
                room -= 1

    def _run_landmarks(self, w: int, h: int, timestamp: float) -> int:
        """The landmark model on the most urgent people with a region, within the budget."""
        assert self.landmarks is not None
        budget = self.people.budget or len(self._people)
        ready = [p for p in self._people if p.region is not None]
        ready.sort(
            key=lambda p: turn(
                urgency(p.motion.current(), p.motion.velocity, w, h),
                timestamp - p.last_landmarks,
            ),
            reverse=True,
        )
        runs = 0
        for person in ready[:budget]:
            region = person.moved_region(self._frame)
            pose = self.landmarks.run(self._wide.whole(), region)
            runs += 1
            expected = person.motion.current()
            others = [_box(p) for p in self._people if p is not person]
            slack = person.motion.position_spread()
            # A first pose on someone already followed is them, found again by a
            # neighbour's detection: it makes no one new.
            known = not person.posed and any(
                iou(pose_box(pose), other) >= NEW_PERSON_MAX_IOU for other in others
            )
            if (
                pose.score < self.config.min_pose_score
                or known
                or not _belongs(pose, expected, others, slack)
            ):
                person.region = None
                if person.posed:  # lost: the detector looks for them next frame
                    self._lost = True
                else:  # the landmark model does not confirm the detection: no one
                    person.last_seen = -np.inf
                continue
            pose = person.filter.apply(pose, timestamp)
            person.pose, person.posed = pose, True
            person.motion.update(pose_box(pose), POSE_NOISE)
            if not person.seen:
                person.hits += 1
            person.last_seen, person.last_landmarks, person.seen = timestamp, timestamp, True
            next_region = pose.next_region(self.config.region_scale)
            person.set_region(next_region if next_region.valid else None, self._frame)
        return runs

    def _merge_duplicates(self) -> None:
        """Two people whose boxes cover each other are one: keep the one seen more."""
        keep = sorted(self._people, key=lambda p: (p.person_id is None, -p.hits))
        kept: list[_Person] = []
        for person in keep:
            box = _box(person)
            if any(iou(box, _box(k)) >= SAME_PERSON_IOU for k in kept):
                continue
            if person.pose is not None and any(
                k.pose is not None and _same_hips(k.pose, person.pose) for k in kept
            ):
                continue
            kept.append(person)
        self._people = kept


def _same_hips(a: Pose, b: Pose) -> bool:
    """Two poses with their hips within SAME_HIPS of the taller's box height are one
    person found twice: two people's hips lie at least a torso's width apart."""
    (ax, ay), (bx, by) = hips(a), hips(b)
    height = max(a.box[3] - a.box[1], b.box[3] - b.box[1], 1.0)
    return bool(np.hypot(ax - bx, ay - by) <= SAME_HIPS * height)


def _around(box: Box, w: int, h: int) -> Window:
    """A square detector window on a person's expected box, twice their height (the
    detector finds people up to about half its window tall), never below ZOOM_MIN_SIDE."""
    x0, y0, x1, y1 = box
    side = max(2 * (y1 - y0), ZOOM_MIN_SIDE)
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    return Window(cx - side / 2, cy - side / 2, side, side)


def _box(person: _Person) -> Box:
    """Where a person is this frame: their accepted pose's box, else their motion's."""
    return pose_box(person.pose) if person.pose is not None else person.motion.current()


def _region(det: Detection, scale: float) -> Region | None:
    region = det.region(scale)
    return region if region.valid else None


def _belongs(pose: Pose, box: Box, others: list[Box], slack: float = 0.0) -> bool:
    """Whether the pose is its own person's, standing: most of its visible landmarks in
    `box` (grown by BOX_MARGIN and by `slack` px, two standard deviations of where the
    motion puts the person: wide after frames unseen), few of them outside it on someone
    else (`others`: a skeleton that slid onto a neighbour, or spans two people), about the
    box's height, and taller than wide (a pedestrian; the landmark model also finds
    bodies in clothes on the ground)."""
    visible = pose.visibility >= VISIBLE
    points = pose.landmarks[visible, :2] if visible.sum() >= 5 else pose.landmarks[:, :2]
    own = _within(points, box, BOX_MARGIN + slack / max(box[3] - box[1], 1.0))
    elsewhere = np.zeros(len(points), bool)
    for other in others:
        elsewhere |= _within(points, other, 0.0)
    elsewhere &= ~_within(points, box, 0.0)
    x0, y0, x1, y1 = pose.box
    if not _upright(pose):
        return False
    height_ratio = (pose_box(pose)[3] - pose_box(pose)[1]) / max(box[3] - box[1], 1.0)
    return bool(
        own.mean() >= MIN_INSIDE
        and elsewhere.mean() <= MAX_ELSEWHERE
        and y1 - y0 >= x1 - x0
        and MIN_HEIGHT_RATIO <= height_ratio <= 1 / MIN_HEIGHT_RATIO
    )


def _upright(pose: Pose) -> bool:
    """A standing person's skeleton: the nose above the shoulders, the shoulders at least
    MIN_TORSO of the landmark height above the hips, and the shoulders over the hips
    (within MAX_LEAN). A skeleton assembled from two people (one's head, the other's
    body) breaks these; a walker, even one leaning into a run, keeps them."""
    landmarks = pose.landmarks[:, :2]
    height = max(pose.box[3] - pose.box[1], 1.0)
    nose = landmarks[0]
    shoulders = landmarks[[11, 12]].mean(axis=0)
    hips_ = landmarks[[23, 24]].mean(axis=0)
    return bool(
        nose[1] < shoulders[1]
        and hips_[1] - shoulders[1] >= MIN_TORSO * height
        and abs(hips_[0] - shoulders[0]) <= MAX_LEAN * height
    )


def _within(points: np.ndarray, box: Box, margin: float) -> np.ndarray:
    """Which points lie in `box` grown by `margin` of its height on each side."""
    m = margin * (box[3] - box[1])
    x, y = points[:, 0], points[:, 1]
    return (x >= box[0] - m) & (x <= box[2] + m) & (y >= box[1] - m) & (y <= box[3] + m)
