"""Intent labels from true tracks: keep going, stop, turn away, start crossing."""

from __future__ import annotations

import math

import numpy as np
import pytest

from monopic.cases import Case
from sim.geometry.frames import Pose2D
from sim.scenario.track import Track
from sim.world.intent import Intent, IntentConfig, first_slow_time, intent_label

H = 0.01
ROBOT = Pose2D(0.0, 0.0, 0.0)  # at the origin heading east: robot frame = world frame


def walk(start: tuple[float, float], legs: list[tuple[float, tuple[float, float]]],
         t_end: float = 6.0, wobble=None) -> Track:  # fmt: skip
    """A Track of H-second pieces from `start`: each leg (from time, velocity) holds until
    the next; `wobble(t) -> (dx, dy)` adds a stride's surge or sway to the positions."""
    times = np.arange(0.0, t_end + H / 2, H)
    vel = np.zeros((len(times), 2))
    for at, v in legs:
        vel[times >= at - 1e-9] = v
    pos = np.array(start, dtype=float) + np.vstack([[0.0, 0.0], np.cumsum(vel[:-1] * H, axis=0)])
    if wobble is not None:
        pos = pos + np.array([wobble(t) for t in times])
    yaws = np.zeros(len(times))
    return Track.from_vertices(times, pos, yaws, vel[-1])


CROSS = (0.0, -1.4)  # from the robot's left toward and over its path


def test_steady_crossing_keeps_going_and_has_its_case() -> None:
    label = intent_label(walk((8.0, 3.0), [(0.0, CROSS)]), 2.0, ROBOT, 1.0)
    assert label.intent is Intent.KEEP_GOING and label.time is None
    assert label.case_now is Case.PERPENDICULAR_RIGHT


def test_standing_keeps_going_and_is_still() -> None:
    label = intent_label(walk((8.0, 3.0), []), 2.0, ROBOT, 1.0)
    assert (label.intent, label.case_now) == (Intent.KEEP_GOING, Case.STILL)


@pytest.mark.parametrize(("stop_in", "expected"), [(0.4, Intent.STOP), (1.0, Intent.STOP),
                                                   (1.02, Intent.KEEP_GOING)])  # fmt: skip
def test_stop_within_the_horizon_boundary_included(stop_in: float, expected: Intent) -> None:
    t = 2.0
    track = walk((8.0, 3.0), [(0.0, CROSS), (t + stop_in, (0.0, 0.0))])
    label = intent_label(track, t, ROBOT, 1.0)
    assert label.intent is expected
    if expected is Intent.STOP:
        assert label.time == pytest.approx(stop_in)


def test_a_stopped_walker_does_not_stop_again() -> None:
    track = walk((8.0, 3.0), [(0.0, CROSS), (1.0, (0.0, 0.0))])
    assert intent_label(track, 1.5, ROBOT, 1.0).intent is Intent.KEEP_GOING
    assert first_slow_time(track, 0.5, 1.0, 0.3) == pytest.approx(1.0)
    assert first_slow_time(track, 0.0, 0.5, 0.3) is None


def test_stepping_off_the_kerb_toward_the_path_starts_crossing() -> None:
    t = 2.0
    track = walk((8.0, 3.0), [(t + 0.3, CROSS)])
    label = intent_label(track, t, ROBOT, 1.0)
    assert label.intent is Intent.START_CROSSING
    # Trailing 0.5 s mean: 0.3 m/s toward the path after 0.5 * 0.3 / 1.4 s, on a 0.05 s grid.
    assert 0.3 + 0.107 <= label.time <= 0.3 + 0.107 + 0.05
    late = walk((8.0, 3.0), [(t + 0.95, CROSS)])
    assert intent_label(late, t, ROBOT, 1.0).intent is Intent.KEEP_GOING


def test_from_the_right_side_toward_is_plus_y() -> None:
    t = 2.0
    toward = walk((8.0, -3.0), [(t + 0.2, (0.0, 1.4))])
    away = walk((8.0, -3.0), [(t + 0.2, (0.0, -1.4))])
    assert intent_label(toward, t, ROBOT, 1.0).intent is Intent.START_CROSSING
    assert intent_label(away, t, ROBOT, 1.0).intent is Intent.TURN_AWAY  # walks off, away


def test_turning_to_walk_along_the_kerb_or_back_is_turning_away() -> None:
    t = 2.0
    for new in ((1.4, 0.0), (0.0, 1.4), (-1.0, 1.0)):
        track = walk((8.0, 3.0), [(0.0, CROSS), (t + 0.4, new)])
        label = intent_label(track, t, ROBOT, 1.0)
        assert label.intent is Intent.TURN_AWAY, new
        # An instant turn shows in the trailing 0.5 s mean after 0.25 s (90 degrees to
        # walking along: the direction must turn by 38 degrees first) to 0.35 s (turning
        # back: the mean passes through standing, where it has no direction).
        assert 0.4 < label.time <= 0.4 + 0.4


def test_walking_along_then_turning_in_starts_crossing_and_stepping_aside_turns_away() -> None:
    t = 2.0
    along = (-1.3, 0.0)  # toward the robot, 2 m to its left
    turn_in = walk((15.0, 2.0), [(0.0, along), (t + 0.3, (-0.9, -1.0))])
    aside = walk((15.0, 2.0), [(0.0, along), (t + 0.3, (-0.9, 1.0))])
    assert intent_label(turn_in, t, ROBOT, 1.0).intent is Intent.START_CROSSING
    assert intent_label(aside, t, ROBOT, 1.0).intent is Intent.TURN_AWAY
    on_line = walk((15.0, 0.0), [(0.0, along), (t + 0.3, (-0.9, 1.0))])
    assert intent_label(on_line, t, ROBOT, 1.0).intent is Intent.TURN_AWAY  # no side: away


def test_the_earliest_event_wins() -> None:
    t = 2.0
    turn_then_stop = walk((8.0, 3.0), [(0.0, CROSS), (t + 0.2, (1.4, 0.0)), (t + 0.7, (0, 0))])
    label = intent_label(turn_then_stop, t, ROBOT, 1.0)
    assert label.intent is Intent.TURN_AWAY and label.time < 0.7
    stop_then_walk_off = walk((8.0, 3.0), [(0.0, CROSS), (t + 0.2, (0, 0)), (t + 0.4, (0, 1.4))])
    label = intent_label(stop_then_walk_off, t, ROBOT, 1.0)
    assert (label.intent, label.time) == (Intent.STOP, pytest.approx(0.2))


def test_labels_are_in_the_robots_frame() -> None:
    # The same scene turned by 90 degrees about the origin, the robot heading north.
    t = 2.0
    legs = [(0.0, CROSS), (t + 0.4, (1.4, 0.0))]
    turned_legs = [(at, (-v[1], v[0])) for at, v in legs]
    plain = intent_label(walk((8.0, 3.0), legs), t, ROBOT, 1.0)
    turned = intent_label(walk((-3.0, 8.0), turned_legs), t, Pose2D(0.0, 0.0, math.pi / 2), 1.0)
    assert (turned.intent, turned.case_now) == (plain.intent, plain.case_now)
    assert turned.time == pytest.approx(plain.time)


def test_a_strides_surge_and_sway_are_not_turns() -> None:
    # 12 % of 1.4 m/s twice a 1.1 s stride along the walk, 2 cm of sway once a stride.
    def surge(t: float) -> tuple[float, float]:
        return 0.0, -0.12 * 1.4 / (2 * math.pi * 2 / 1.1) * math.sin(2 * math.pi * 2 * t / 1.1)

    def sway(t: float) -> tuple[float, float]:
        return 0.0, 0.02 * math.sin(2 * math.pi * t / 1.1)

    crossing = walk((8.0, 3.0), [(0.0, CROSS)], wobble=surge)
    along = walk((20.0, 2.0), [(0.0, (-1.4, 0.0))], wobble=sway)
    for track in (crossing, along):
        labels = {intent_label(track, 1.0 + k / 15, ROBOT, 1.0).intent for k in range(45)}
        assert labels == {Intent.KEEP_GOING}


def test_slowing_or_speeding_up_on_the_same_line_is_no_turn() -> None:
    t = 2.0
    for v in ((0.0, -0.6), (0.0, -2.2)):
        track = walk((8.0, 3.0), [(0.0, CROSS), (t + 0.3, v)])
        assert intent_label(track, t, ROBOT, 1.0).intent is Intent.KEEP_GOING, v
    along = walk((20.0, 2.0), [(0.0, (-1.4, 0.0)), (t + 0.3, (-0.5, 0.0))])
    assert intent_label(along, t, ROBOT, 1.0).intent is Intent.KEEP_GOING


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError):
        intent_label(walk((8.0, 3.0), []), 1.0, ROBOT, 0.0)
    with pytest.raises(ValueError):
        IntentConfig(smoothing=0.0)


def test_the_worlds_truth_carries_the_labels() -> None:
    # A rail target crossing from the left that stops at 2 s: the frames of the second
    # before say stop, with the time left; before and after, keep going.
    from sim.scenario.spec import Leg, PedestrianSpec, RoadLayout, RobotSpec, Scenario, SceneSpec
    from sim.world.world import World

    ped = PedestrianSpec(x=12.0, y=3.0, heading_deg=-90.0, speed=1.4, legs=(Leg(2.0, 0.0),))
    sc = Scenario(
        name="stop", pedestrian=ped, robot=RobotSpec(speed=2.0),
        scene=SceneSpec(road=RoadLayout(buildings=False)), duration=3.0,
    )  # fmt: skip
    with World(sc, render=False) as world:
        truths = [step.truth for step in world.run()]
    for truth in truths:  # frame times add up 1/15 s steps: allow their rounding
        if abs(truth.time - 2.0) < 1e-9:
            continue  # the stop itself: "now" or an instant before it
        if 1.0 - 1e-9 <= truth.time < 2.0:
            assert truth.pedestrian.intent is Intent.STOP
            assert truth.pedestrian.intent_time == pytest.approx(2.0 - truth.time)
            assert truth.pedestrian.case_now is Case.PERPENDICULAR_RIGHT
        else:
            assert (
                truth.pedestrian.intent is Intent.KEEP_GOING
                and truth.pedestrian.intent_time is None
            )
    row = truths[20].to_dict()
    assert (row["intent"], row["case_now"]) == ("stop", int(Case.PERPENDICULAR_RIGHT))


def test_the_pipelines_intent_vocabulary_is_the_simulators() -> None:
    """The intent tree (monopic) reads these labels from datasets; it cannot import sim."""
    from monopic.tree.intent import INTENTS

    assert tuple(i.value for i in Intent) == INTENTS
