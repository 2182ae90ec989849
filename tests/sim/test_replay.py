"""Replayed walks (sim/scenario/walkers/replay.py): the body is on the file's point at every
frame, the 0.4 s statistics are the file's, bad files and transforms are one line each,
and the shipped replay family loads and renders."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sim.analysis.realism import statistics
from sim.scenario.files import load
from sim.scenario.spec import Scenario
from sim.scenario.track_file import FRAME_TIME, read_track_file, rotation
from sim.scenario.walkers.replay import ReplayWalker
from sim.world.world import World
from tests.paths import ETH_UCY, SCENARIOS, needs_eth_ucy
from tests.sim.test_scenario_file import error_of, write

# Three people of a made-up file: in the world (rotated 90 degrees, moved by (10, 1)) one
# crosses the road at x = 8, one zig-zags along the far pavement, one arrives at frame 40
# and walks west along the near pavement.
ROTATE, OFFSET = 90.0, (10.0, 1.0)


def synthetic_rows() -> list[tuple[int, int, float, float]]:
    rows = []
    for k in range(21):
        rows.append((10 * k, 1, 5.0 - 0.5 * k, 2.0))
    for k in range(16):
        rows.append((10 * k, 2, 6.0 + 0.1 * (-1) ** k, 8.0 - 0.5 * k))
    for k in range(9):
        rows.append((40 + 10 * k, 3, -4.0, -5.0 + 0.4 * k))
    return rows


def track_text(rows: list[tuple[int, int, float, float]]) -> str:
    return "".join(f"{f}\t{p}.0\t{x:.4f}\t{y:.4f}\n" for f, p, x, y in rows)


def scenario_text(file: str = "tracks.txt", extra: str = "", start_frame: float = 15.0) -> str:
    return f"""
name = "replay-test"
kind = "collision"
scale = "small"
duration = 4.0
fps = 15

[replay]
file = "{file}"
people = "all"
scripted = 1
rotate_deg = {ROTATE}
offset = [{OFFSET[0]}, {OFFSET[1]}]
start_frame = {start_frame}
{extra}"""


def synthetic_scenario(tmp_path: Path) -> Path:
    (tmp_path / "tracks.txt").write_text(track_text(synthetic_rows()))
    return write(tmp_path, scenario_text())


def expected_at(walker: ReplayWalker, t: float) -> np.ndarray:
    """The file's position at run time t, interpolated linearly between its samples (and
    held before the first and after the last), moved into the world."""
    person = read_track_file(walker.file).person(walker.person)
    frame = walker.start_frame + t / FRAME_TIME
    xy = np.array([np.interp(frame, person.frames, person.positions[:, i]) for i in (0, 1)])
    return rotation(walker.rotate_deg) @ xy + np.asarray(walker.offset)


def worst_miss(s: Scenario) -> float:
    """The largest distance over every frame and every replayed person between the truth's
    footprint centre and the file's position then."""
    walkers = [p.behaviour for p in s.people]
    assert all(isinstance(w, ReplayWalker) for w in walkers)
    worst = 0.0
    frames = 0
    with World(s, render=False) as world:
        step = world.reset()
        while True:
            for truth, walker in zip(step.truth.people, walkers, strict=True):
                miss = np.linalg.norm(truth.position_world - expected_at(walker, step.time))
                worst = max(worst, float(miss))
            frames += 1
            if step.time + s.dt > s.duration + 1e-9:
                break
            step = world.step()
    assert frames == s.frames + 1
    return worst


def test_a_replayed_person_is_on_the_files_point_at_every_frame(tmp_path: Path) -> None:
    s = load(synthetic_scenario(tmp_path)).base
    assert [p.name for p in s.people] == ["p1", "p2", "p3"]
    assert worst_miss(s) < 0.02


@needs_eth_ucy
def test_real_hotel_walkers_are_on_the_files_points_at_every_frame(tmp_path: Path) -> None:
    text = scenario_text(str(ETH_UCY / "biwi_hotel.txt"), start_frame=16150)
    text = text.replace('people = "all"', "people = [372, 375, 378]").replace(
        "scripted = 1", "scripted = 375"
    )
    text = text.replace(f"rotate_deg = {ROTATE}", "rotate_deg = 0.0").replace(
        f"offset = [{OFFSET[0]}, {OFFSET[1]}]", "offset = [10.0, 5.0]"
    )
    text = text.replace("[replay]", "[scene.road]\npavement_width = 4.0\n[replay]")
    s = load(write(tmp_path, text)).base
    assert len(s.people) == 3
    assert worst_miss(s) < 0.02


def test_the_tracks_0_4_s_statistics_are_the_files(tmp_path: Path) -> None:
    s = load(synthetic_scenario(tmp_path)).base
    ours, theirs = [], []
    for person in s.people:
        walker = person.behaviour
        assert isinstance(walker, ReplayWalker)
        samples = walker.samples()
        later = samples.times >= 0  # the run starts at frame 15: samples before are not in it
        track = walker.track(person, s.duration, s.seed)
        ours.append(track.positions_at(samples.times[later]))
        file = read_track_file(walker.file).person(walker.person)
        theirs.append(file.positions[later])  # untransformed: the statistics do not see it
    mine, real = statistics(ours), statistics(theirs)
    assert sum(len(v) for v in real.values()) > 30
    for key in real:
        np.testing.assert_allclose(mine[key], real[key], atol=1e-9, err_msg=key)


def test_the_body_turns_smoothly_on_a_zig_zag_and_the_gait_follows_the_distance(
    tmp_path: Path,
) -> None:
    s = load(synthetic_scenario(tmp_path)).base
    zigzag = s.people[1]
    track = zigzag.behaviour.track(zigzag, s.duration, s.seed)
    walking = track.times < 5.0
    footprint_turns = np.ptp(np.unwrap(track.footprint_yaws[walking]))
    body_turns = np.ptp(np.unwrap(track.yaws[walking]))
    assert footprint_turns > math.radians(20)  # the file's 0.4 s pieces zig-zag
    assert body_turns < footprint_turns / 4
    assert track.phases is not None
    walked = np.sum(np.hypot(*np.diff(track.positions, axis=0).T))
    strides = track.phases[-1] - track.phases[0]
    assert 0.5 < walked / strides < 2.5  # a stride of about 1.0-1.6 m at these speeds
    # The same file, the same walk: no seed.
    again = zigzag.behaviour.track(zigzag, s.duration, seed=12345)
    np.testing.assert_array_equal(again.positions, track.positions)


def one_line(err: Exception) -> str:
    text = str(err)
    assert "\n" not in text
    return text


def test_a_gap_a_repeated_frame_and_a_missing_person_are_one_line_each(tmp_path: Path) -> None:
    rows = synthetic_rows()
    gap = [r for r in rows if not (r[1] == 2 and r[0] == 60)]
    (tmp_path / "tracks.txt").write_text(track_text(gap))
    path = write(tmp_path, scenario_text())
    text = one_line(error_of(path))
    assert "tracks.txt" in text and "person 2: frame 70" in text and "gap" in text

    repeated = [*rows, (50, 3, -4.0, -4.6)]
    (tmp_path / "tracks.txt").write_text(track_text(repeated))
    text = one_line(error_of(path))
    assert "person 3: frame 50 is repeated" in text and "tracks.txt" in text

    (tmp_path / "tracks.txt").write_text(track_text(rows))
    missing = write(tmp_path, scenario_text().replace("scripted = 1", "scripted = 7"), "m.toml")
    err = error_of(missing)
    assert err.field == "replay.scripted" and "no such person" in one_line(err)
    listed = scenario_text().replace('people = "all"', "people = [1, 9]")
    err = error_of(write(tmp_path, listed, "l.toml"))
    assert err.field == "replay.people" and "person 9" in one_line(err)
    alone = """
name = "one"
duration = 3.0
[pedestrian.behaviour]
model = "replay"
file = "tracks.txt"
person = 4
"""
    err = error_of(write(tmp_path, alone, "one.toml"))
    assert err.field == "pedestrian.behaviour.person" and "no such person" in one_line(err)
    assert "tracks.txt" in str(err)


def test_a_transform_that_puts_a_track_off_the_street_names_file_person_and_frame(
    tmp_path: Path,
) -> None:
    (tmp_path / "tracks.txt").write_text(track_text(synthetic_rows()))
    far = scenario_text().replace(f"offset = [{OFFSET[0]}, {OFFSET[1]}]", "offset = [10.0, 4.0]")
    err = error_of(write(tmp_path, far))
    text = one_line(err)
    assert err.field == "pedestrians.1.behaviour"  # the zig-zag, on the far pavement's edge
    assert "person 2 of" in text and "tracks.txt" in text and "off the street at frame" in text
    assert err.value["person"] == 2 and err.value["y"] > 8.4


def test_a_replayed_person_takes_no_path_and_no_speed(tmp_path: Path) -> None:
    (tmp_path / "tracks.txt").write_text(track_text(synthetic_rows()))
    base = """
name = "one"
duration = 3.0
[pedestrian]
{person}
[pedestrian.behaviour]
model = "replay"
file = "tracks.txt"
person = 1
rotate_deg = 90.0
offset = [10.0, 1.0]
"""
    s = load(write(tmp_path, base.format(person=""))).base
    assert s.pedestrian.speed == pytest.approx(0.5 / 0.4)
    assert (s.pedestrian.x, s.pedestrian.y) == pytest.approx((8.0, 6.0))
    err = error_of(write(tmp_path, base.format(person="speed = 1.0"), "v.toml"))
    assert err.field == "pedestrian.speed" and "file's speeds" in one_line(err)
    err = error_of(
        write(tmp_path, base.format(person="") + '[path]\nkind = "crossing"\n', "p.toml")
    )
    assert err.field == "path.kind" and "track file's" in one_line(err)


FAMILY = SCENARIOS / "families" / "small" / "crowd" / "replay_hotel.toml"


@needs_eth_ucy
@pytest.mark.slow
def test_the_replay_family_loads_and_a_short_run_renders_its_people() -> None:
    from dataclasses import replace

    f = load(FAMILY)
    assert f.kind == "collision" and len(f.base.people) == 17
    assert f.base.pedestrian.name == "p377"
    s = replace(f.base, duration=0.4)
    with World(s) as world:
        step = world.reset()
        for _ in range(3):
            step = world.step()
    assert step.frame is not None and step.frame.image.shape[:2] == (432, 768)
    assert step.frame.image.std() > 5  # a picture, not a blank
    seen = [p.name for p in step.truth.people if p.in_frame]
    assert "p377" in seen and len(seen) >= 5
