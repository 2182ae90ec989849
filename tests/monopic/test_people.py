"""Everyone in view: boxes, motion, association, and the tracker on real pixels.

The tracker's tests run the real models on the shipped clip's walker, side by side with
their own mirror image (two real people walking toward each other), and on the clip
alone (everyone mode must warn as the one-pedestrian tracker does).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.frame import Frame
from monopic.people.association import associate
from monopic.people.box import ASPECT, detection_box, pose_box
from monopic.people.motion import DETECTION_NOISE, BoxMotion
from monopic.people.tracker import PeopleConfig, PeopleTracker, _belongs
from monopic.people.urgency import urgency
from monopic.pipeline import Pipeline, PipelineConfig
from monopic.pose.detector import Detection
from monopic.pose.tracker import TrackerConfig
from monopic.video import VideoSource
from tests.paths import DATA

CLIP = DATA / "walk_clip.mp4"


def _frames() -> list[Frame]:
    return list(VideoSource(str(CLIP)))


def test_a_detections_box_stands_on_the_hips_with_a_pedestrians_aspect() -> None:
    det = Detection(0.9, (0, 0, 1, 1), np.array([[100.0, 200.0], [100.0, 100.0], [0, 0], [0, 0]]))
    x0, y0, x1, y1 = detection_box(det)
    assert (x0 + x1) / 2 == pytest.approx(100.0)
    assert (x1 - x0) / (y1 - y0) == pytest.approx(ASPECT)
    assert y0 < 200 - 83 < 200 + 95 < y1  # head top above, soles below the landmark span


@st.composite
def _boxes(draw: st.DrawFn) -> list[tuple[float, float, float, float]]:
    """People standing apart: one per 100 px column, any height."""
    n = draw(st.integers(1, 6))
    out = []
    for i in range(n):
        h = draw(st.floats(40, 90))
        y = draw(st.floats(0, 300))
        out.append((i * 100.0 + 10, y, i * 100.0 + 10 + ASPECT * h, y + h))
    return out


@settings(max_examples=50, deadline=None)
@given(_boxes(), st.randoms(use_true_random=False), st.floats(-5, 5), st.floats(-5, 5))
def test_association_pairs_each_person_with_their_own_detection(boxes, rnd, dx, dy) -> None:
    order = list(range(len(boxes)))
    rnd.shuffle(order)
    moved = [(b[0] + dx, b[1] + dy, b[2] + dx, b[3] + dy) for b in boxes]
    detections = [moved[i] for i in order]
    got = associate(boxes, detections)
    assert sorted(got.pairs) == sorted((order[j], j) for j in range(len(order)))
    assert got.lone_tracks == [] and got.lone_detections == []


def test_no_pair_between_people_who_do_not_overlap() -> None:
    got = associate([(0, 0, 40, 100)], [(60, 0, 100, 100)])
    assert got.pairs == [] and got.lone_tracks == [0] and got.lone_detections == [0]


def test_a_box_walking_steadily_is_predicted_ahead() -> None:
    motion = BoxMotion((0.0, 0.0, 41.0, 100.0), 0.0)
    for k in range(1, 16):  # 50 px/s to the right, 15 fps
        x = 50.0 * k / 15
        motion.predict(k / 15)
        motion.update((x, 0.0, x + 41.0, 100.0), DETECTION_NOISE)
    x0, _, _, _ = motion.predict(2.0)  # one second after the last update
    assert x0 == pytest.approx(100.0, abs=5.0)
    assert motion.velocity[0] == pytest.approx(50.0, abs=5.0)


def test_urgency_ranks_the_person_on_the_path_and_near_first() -> None:
    w, h = 800, 400
    on_path_near = urgency((380, 200, 420, 390), (0, 0), w, h)
    aside_far = urgency((20, 10, 40, 60), (0, 0), w, h)
    aside_far_closing = urgency((20, 10, 40, 60), (400, 0), w, h)
    assert on_path_near > aside_far_closing > aside_far


def test_a_pose_on_a_neighbour_is_not_its_persons() -> None:
    tracker = PeopleTracker(TrackerConfig(), PeopleConfig())
    frame = _frames()[30]
    pose = None
    for t in range(3):
        result = tracker.process(frame.image, t / 15)
        if result.sightings and result.sightings[0].pose is not None:
            pose = result.sightings[0].pose
    assert pose is not None
    own = pose_box(pose)
    width = own[2] - own[0]
    beside = (own[0] + 1.5 * width, own[1], own[2] + 1.5 * width, own[3])
    assert _belongs(pose, own, [beside])
    assert not _belongs(pose, beside, [own])  # slid onto the neighbour
    # Spanning two people: its person's box holds only half of it, the rest is the other's.
    half = (own[0], own[1], (own[0] + own[2]) / 2, own[3])
    other = ((own[0] + own[2]) / 2, own[1], own[2], own[3])
    assert not _belongs(pose, half, [other])


def _two_walkers() -> list[Frame]:
    """The clip beside its mirror image: two real walkers heading for each other."""
    return [
        Frame(
            np.ascontiguousarray(np.hstack([f.image, f.image[:, ::-1]])), f.timestamp, None, f.index
        )
        for f in _frames()
    ]


def test_two_people_get_an_identity_each_and_keep_it() -> None:
    tracker = PeopleTracker(TrackerConfig(), PeopleConfig())
    frames = _two_walkers()
    width = frames[0].image.shape[1]
    tracks: dict[int, list[tuple[int, float]]] = {}
    for frame in frames:
        for s in tracker.process(frame.image, frame.timestamp).sightings:
            tracks.setdefault(s.person_id, []).append((frame.index, (s.box[0] + s.box[2]) / 2))
            if s.pose is not None:  # every pose inside the half of its own person
                xs = s.pose.landmarks[:, 0]
                left = (s.box[0] + s.box[2]) / 2 < width / 2
                assert (xs < width / 2).all() if left else (xs > width / 2).all()
    assert len(tracks) == 2, {k: len(v) for k, v in tracks.items()}
    for seen in tracks.values():
        # Found within a few frames (the wide frame's walkers are small for the whole-frame
        # look: tiles find them), then followed in every frame.
        assert seen[0][0] <= 8
        assert [k for k, _ in seen] == list(range(seen[0][0], len(frames)))
        xs = [x for _, x in seen]
        assert max(abs(b - a) for a, b in zip(xs, xs[1:], strict=False)) < 0.05 * width
    first, second = (np.mean([x for _, x in v]) for v in tracks.values())
    assert (first < width / 2) != (second < width / 2)  # one person each side


def test_a_budget_of_one_spreads_the_landmarks_and_keeps_both_people() -> None:
    tracker = PeopleTracker(TrackerConfig(), PeopleConfig(budget=1))
    frames = _two_walkers()
    runs, posed = [], {}
    for frame in frames:
        result = tracker.process(frame.image, frame.timestamp)
        runs.append(result.landmark_runs)
        for s in result.sightings:
            posed.setdefault(s.person_id, 0)
            posed[s.person_id] += s.pose is not None
    assert max(runs) == 1
    assert len(posed) == 2
    assert all(n >= len(frames) // 4 for n in posed.values()), posed  # each gets turns


def test_everyone_mode_warns_as_the_one_pedestrian_tracker_with_one_person() -> None:
    one = Pipeline(PipelineConfig())
    everyone = Pipeline(PipelineConfig(people=PeopleConfig()))
    for frame in _frames():
        a, b = one.process(frame), everyone.process(frame)
        assert (a.warning is None) == (b.warning is None), frame.index
        if a.warning is not None:
            assert (a.warning.collision, a.warning.risk) == (b.warning.collision, b.warning.risk)
            assert a.prediction.case == b.prediction.case
            assert np.allclose(a.prediction.center, b.prediction.center)
        assert b.person_id == (b.people[0].person_id if b.people else None)


def test_the_robots_warning_is_the_worst_persons_and_names_them() -> None:
    pipeline = Pipeline(PipelineConfig(people=PeopleConfig()))
    named = 0
    for frame in _two_walkers():
        result = pipeline.process(frame)
        risks = [p.warning.risk for p in result.people if p.warning is not None]
        if result.warning is None:
            assert not risks
            continue
        order = ["green", "yellow", "red"]
        assert order.index(result.warning.risk) == max(order.index(r) for r in risks)
        person = next(p for p in result.people if p.person_id == result.person_id)
        assert person.warning == result.warning
        named += 1
    assert named > 0


@pytest.mark.parametrize(
    "config",
    [dict(max_people=0), dict(budget=0), dict(detect_every=0), dict(report_coast=2.0)],
)
def test_people_config_refuses_nonsense(config: dict) -> None:
    with pytest.raises(ValueError):
        PeopleConfig(**config)


def test_at_most_max_people_are_followed() -> None:
    tracker = PeopleTracker(TrackerConfig(), PeopleConfig(max_people=1))
    seen = set()
    for frame in _two_walkers()[:20]:
        result = tracker.process(frame.image, frame.timestamp)
        assert len(result.sightings) <= 1
        seen.update(s.person_id for s in result.sightings)
    assert len(seen) == 1  # the one followed stays in view: no one else is taken on


def test_outputs_carry_each_person(tmp_path) -> None:
    """Two walkers through every output: one CSV row and one MOT line per person per
    frame, each drawn in their own colour, and an entity each in the .rrd read back."""
    from monopic.framelog import FRAME_COLUMNS, frame_rows, mot_rows
    from monopic.overlay import Variant, draw
    from monopic.people.colour import person_colour
    from monopic.recording import RunRecording
    from tests.rrd import rows_per_entity

    pipeline = Pipeline(PipelineConfig(people=PeopleConfig()))
    rrd = tmp_path / "two.rrd"
    both = None
    with RunRecording(rrd) as recording:
        for frame in _two_walkers():
            result = pipeline.process(frame)
            recording.log_frame(frame.image, result)
            rows = frame_rows(result, 15.0, 1.0)
            ids = [row[FRAME_COLUMNS.index("personId")] for row in rows]
            assert sorted(ids) == sorted(p.person_id for p in result.people)
            mot = mot_rows(result, frame.index + 1)
            assert [line[1] for line in mot] == [p.person_id for p in result.people]
            if len(result.people) == 2:
                both = (frame, result)
    assert both is not None
    frame, result = both
    drawn = draw(frame.image, result, Variant.WARNING, 15.0)
    for person in result.people:
        x0, y0, x1, y1 = (int(v) for v in person.box)
        inside = drawn[max(y0, 0) : y1 + 1, max(x0, 0) : x1 + 1].reshape(-1, 3)
        assert (inside == person_colour(person.person_id)).all(axis=1).any(), person.person_id
    entities = rows_per_entity(rrd)
    for person in result.people:
        assert entities[f"/camera/people/{person.person_id}/box"] > 0, entities


def test_a_reset_pipeline_runs_a_sequence_again_as_the_first_time() -> None:
    """reset() forgets the tracks and each person's features and last decisions: the
    same frames give the same people, identities and warnings again."""
    pipeline = Pipeline(PipelineConfig(people=PeopleConfig()))
    assert pipeline.tracker is None  # the one-pedestrian tracker's sessions are not loaded
    frames = _two_walkers()[:15]

    def run() -> list:
        out = []
        for frame in frames:
            r = pipeline.process(frame)
            out.append(
                [
                    (p.person_id, p.box, p.warning and (p.warning.collision, p.warning.risk))
                    for p in r.people
                ]
            )
        return out

    first = run()
    pipeline.reset()
    assert run() == first and any(len(people) == 2 for people in first)
