"""Simulated runs recorded to .rrd and read back with rerun's own reader; `monopic view`.

What the viewer shows is checked on the file: the blueprint (read back from its own store),
the state lanes, the events. Screenshots of the real viewer: tools/view/screenshot.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from monopic.cases import Case
from monopic.cli.main import main
from monopic.recording import RunRecording, predictor_colour
from sim.geometry.polygons import polygon_gap, rectangle
from sim.recording.sim_recording import PREDICTOR_STATES, world_eye
from sim.runs.record import record_run
from sim.scenario.cases import CasePlacement
from sim.world.ground_truth import footprint_gap
from sim.world.world import World
from tests.rrd import column


def static_entities(path: Path) -> set[str]:
    return {
        chunk.entity_path for chunk in RrdReader(str(path)).stream().to_chunks() if chunk.is_static
    }


def timed(path: Path, entity: str, name: str, timeline: str = "frame") -> list[tuple]:
    """(time, value) of one component of an entity, in time order, rows without it skipped.

    An entity can hold several archetypes (alarm/*: the 0/1 scalar and the state lane),
    logged as separate rows, so a chunk's rows need not all have `name`.
    """
    rows: list[tuple] = []
    for chunk in RrdReader(str(path)).stream().to_chunks():
        if chunk.entity_path == entity and not chunk.is_static:
            batch = chunk.to_record_batch().to_pydict()
            if name in batch:
                rows += [(t, v) for t, v in zip(batch[timeline], batch[name], strict=True) if v]
    return sorted(rows, key=lambda row: row[0])


def values(path: Path, entity: str, name: str = "Scalars:scalars") -> list:
    """One component's values (first element of each row), in frame order."""
    return [v[0] for _, v in timed(path, entity, name)]


def blueprint_views(path: Path) -> dict[str, dict]:
    """The views of the file's default blueprint by name: their class, origin and settings."""
    reader = RrdReader(str(path))
    (store,) = reader.blueprints()
    parts: dict[str, dict] = {}
    for chunk in reader.stream(store=store).to_chunks():
        if chunk.entity_path.startswith("/view/"):
            view, _, part = chunk.entity_path.removeprefix("/view/").partition("/")
            batch = chunk.to_record_batch().to_pydict()
            parts.setdefault(view, {}).update(  # each component: a one-instance list
                {
                    f"{part}:{k.split(':')[-1]}" if part else k: v[0][0]
                    for k, v in batch.items()
                    if ":" in k  # not the timeline columns
                }
            )
    views = {}
    for p in parts.values():
        views[p["ViewBlueprint:display_name"]] = {
            "class": p["ViewBlueprint:class_identifier"],
            "origin": p["ViewBlueprint:space_origin"],
            **{k: v for k, v in p.items() if not k.startswith("ViewBlueprint")},
        }
    return views


def test_polygon_gap():
    a = rectangle(np.array([0.0, 0.0]), 0.0, 2.0, 1.0)  # x in [-1, 1], y in [-0.5, 0.5]
    assert polygon_gap(a, rectangle(np.array([3.0, 0.0]), 0.0, 2.0, 1.0)) == pytest.approx(1.0)
    assert polygon_gap(a, rectangle(np.array([0.5, 0.2]), 0.3, 0.5, 0.5)) == 0.0
    turned = rectangle(np.array([2.0, 2.0]), math.pi / 4, 1.0, 1.0)  # corner toward a
    expected = math.hypot(1.0, 1.5) - math.sqrt(0.5)  # corner (1, 0.5) to the diamond
    assert polygon_gap(a, turned) == pytest.approx(expected, abs=0.2)
    # Crossing bars overlap although no corner lies inside the other.
    assert (
        polygon_gap(rectangle(np.zeros(2), 0.0, 4.0, 0.2), rectangle(np.zeros(2), 0.0, 0.2, 4.0))
        == 0.0
    )


@pytest.mark.slow
def test_recording_holds_camera_truth_world_and_series(tmp_path):
    # On a collision course: the robot at 2 m/s meets the crossing pedestrian at 1 s.
    scenario = CasePlacement(
        Case.PERPENDICULAR_RIGHT, distance=2.0, robot_speed=2.0, meet_time=1.0, duration=1.4
    ).scenario()
    rrd = tmp_path / "run.rrd"
    summary = record_run(scenario, rrd, topdown_every=3)
    assert rrd.exists() and summary.bytes == rrd.stat().st_size
    assert not list(tmp_path.glob(".*"))  # no temporary left behind
    n = summary.frames
    assert summary.contact_time is not None and n < scenario.frames  # stopped at contact

    def count(entity: str, name: str = "Scalars:scalars") -> int:
        return len(timed(rrd, entity, name))

    for entity in ("/truth/phi", "/alarm/truth", "/robot/speed", "/truth/gap", "/latency/total"):
        assert count(entity) == n, entity
    for entity, name in (
        ("/camera/image", "EncodedImage:blob"),
        ("/world/robot", "Transform3D:translation"),
        ("/world/pedestrian", "Points3D:positions"),
        ("/world/truth/future", "LineStrips3D:strips"),
    ):
        assert count(entity, name) == n, entity
    assert count("/topdown/image", "EncodedImage:blob") == math.ceil(n / 3)
    # The pedestrian ends up 2 m ahead, its feet below the frame: not every frame has a pose.
    assert n // 2 <= summary.found <= n and count("/features/phi") <= summary.found
    # Every predictor's warning on every frame it decided (ground mode needs the feet).
    assert count("/alarm/rules-image") >= count("/features/phi") >= n // 2
    assert count("/alarm/rules-ground") >= 1
    assert count("/camera/truth/foot", "Points2D:positions") == n
    assert count("/ttc/truth") == n  # on a collision course from the first frame
    assert {"/world/road", "/world/robot/body", "/world/robot/camera", "/world/truth/path",
            "/world/pedestrian", "/camera/pose"} <= static_entities(rrd)  # fmt: skip

    # The truth series are the simulator's own values, frame by frame.
    truth = []
    with World(scenario, render=False) as world:
        for step in world.run():
            truth.append(step.truth)
            if len(truth) == n:
                break
    phi = values(rrd, "/truth/phi")
    assert phi == pytest.approx([t.pedestrian.phi for t in truth])
    ttc = values(rrd, "/ttc/truth")
    assert ttc == pytest.approx([t.pedestrian.time_to_collision for t in truth])
    assert ttc[0] == pytest.approx(truth[0].pedestrian.time_to_collision) and 0.5 < ttc[0] < 1.0
    gap = values(rrd, "/truth/gap")
    assert gap[-1] == 0.0 and gap[0] == pytest.approx(
        footprint_gap(truth[0], scenario.pedestrian.footprint)
    )
    frames = column(rrd, "/truth/phi", "frame")
    assert frames == list(range(n))

    # A predictor missed the collision iff it never warned on a frame where one was coming.
    def raised(entity: str) -> set[int]:
        return {f for f, v in timed(rrd, entity, "Scalars:scalars") if v[0]}

    coming = raised("/alarm/truth")
    assert coming and summary.false_alarms == ()
    for key in summary.warned:
        warned = raised(f"/alarm/{key.replace('/', '-')}")
        assert (key in summary.missed) == (not warned & coming), key

    # The state lanes tell the same story, logged only where the state changes.
    assert values(rrd, "/alarm/truth", "StateChange:state") == ["collision course", "contact"]
    states = set(PREDICTOR_STATES.as_component_batches()[0].as_arrow_array().to_pylist())
    for key in summary.warned:
        entity = f"/alarm/{key.replace('/', '-')}"
        lane = timed(rrd, entity, "StateChange:state")
        assert lane and {v[0] for _, v in lane} <= states, key
        assert all(a[1] != b[1] for a, b in zip(lane, lane[1:], strict=False)), key
        warned_frames = raised(entity)
        for f, _ in timed(rrd, entity, "Scalars:scalars"):  # WARNING exactly when it warned
            state = [s for t, s in lane if t <= f][-1][0]
            assert (state == "WARNING") == (f in warned_frames), (key, f)

    # Events start with their time; the primary's warning is logged where it starts only.
    events = timed(rrd, "/events", "TextLog:text", "time")
    assert events and all(text[0].startswith(f"{t.total_seconds():.2f} s  ") for t, text in events)
    texts = [text[0].split("  ", 1)[1] for _, text in events]
    assert any(e.startswith("CONTACT at") for e in texts)
    assert any(e.startswith("truth: on a collision course") for e in texts)
    assert summary.primary == "rules/image"
    primary = f"/alarm/{summary.primary.replace('/', '-')}"
    by_frame = dict(timed(rrd, primary, "Scalars:scalars"))
    onsets = sum(1 for f in range(n) if by_frame.get(f, [0])[0] and not by_frame.get(f - 1, [0])[0])
    assert sum(e.startswith("COLLISION IMMINENT") for e in texts) == onsets

    # The layout: camera framed on the image, 3D eye on where they meet, lanes, plots.
    views = blueprint_views(rrd)
    camera = next(v for v in views.values() if v["origin"] == "camera")
    assert camera["class"] == "2D"
    assert camera["VisualBounds2D:range"] == {"x_range": [0.0, 768.0], "y_range": [0.0, 432.0]}
    world = next(v for v in views.values() if v["origin"] == "world")
    target = np.array(world["EyeControls3D:look_target"])
    eye = np.array(world["EyeControls3D:position"])
    meet = truth[-1].pedestrian.position_world  # contact: the pedestrian where they met
    start = truth[0].robot.position[:2]
    assert np.linalg.norm(target[:2] - (start + (meet - start) * 2 / 3)) < 0.5
    assert target[2] == 0.0 and eye[0] < start[0] and eye[2] > 1.0  # behind the start, above
    ttc_axis = next(v for v in views.values() if v["origin"] == "ttc")["TimeAxis:view_range"]
    assert ttc_axis == {"start": 0, "end": None}  # the whole run, as every plot and the lanes
    lanes = next(v for v in views.values() if v["class"] == "StateTimeline")
    assert lanes["origin"] == "alarm"
    plotted = {v["origin"] for v in views.values() if v["class"] == "TimeSeries"}
    assert {"ttc", "latency", "features"} <= plotted
    assert any(v["class"] == "TextLog" and v["origin"] == "events" for v in views.values())


def test_world_eye_looks_toward_the_meeting_point_from_behind():
    eye = world_eye(np.array([0.0, 0.0]), 0.0, np.array([6.0, 1.5]))
    target = np.array(eye.look_target.as_arrow_array().to_pylist()[0])
    position = np.array(eye.position.as_arrow_array().to_pylist()[0])
    assert target == pytest.approx([4.0, 1.0, 0.0])  # two thirds of the way
    assert position[0] < 0.0 and position[1] < 1.0 and position[2] > 2.0  # behind, right, up
    turned = world_eye(np.array([0.0, 0.0]), math.pi / 2, np.array([0.0, 6.0]))
    assert np.array(turned.position.as_arrow_array().to_pylist()[0])[1] < 0.0  # behind in +y


def test_run_recording_starts_on_the_first_image_framed_on_it(tmp_path):
    rrd = tmp_path / "video.rrd"
    rec = RunRecording(rrd)
    assert not rec.started and not rrd.exists()
    rec.set_time(0, 0.0)
    rec.log_image(np.zeros((48, 64, 3), dtype=np.uint8))
    assert rec.started
    rec.set_time(1, 0.5)
    rec.log_event("hello")
    rec.close()
    views = blueprint_views(rrd)
    assert views["camera"]["VisualBounds2D:range"] == {
        "x_range": [0.0, 64.0],
        "y_range": [0.0, 48.0],
    }
    assert column(rrd, "/camera/image", "frame") == [0]
    assert column(rrd, "/events", "TextLog:text") == [["0.50 s  hello"]]
    # The static annotation logged before the file started is in it too.
    assert "/camera/pose" in static_entities(rrd)

    empty = tmp_path / "empty.rrd"
    RunRecording(empty).close()  # no frame at all: still a readable file
    assert "camera" in blueprint_views(empty)


def test_predictor_colours_are_fixed_and_never_the_truths():
    keys = ["rules/image", "rules/ground", "tree/image", "constant-velocity/ground", "x/y"]
    colours = [predictor_colour(k) for k in keys]
    assert len(set(colours[:4])) == 4 and (0, 210, 255) not in colours
    assert predictor_colour("x/y") == colours[-1]  # stable for unknown keys too


def test_view_without_display_says_how(tmp_path, monkeypatch, capsys):
    rrd = tmp_path / "x.rrd"
    rrd.write_bytes(b"RRF2" + bytes(12))
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    assert main(["view", str(rrd)]) == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and f"rerun --serve-web {rrd}" in err


@pytest.mark.parametrize(
    ("content", "expected"), [(None, "no such file"), (b"hello", "not a rerun recording")]
)
def test_view_rejects_missing_or_foreign_files(tmp_path, capsys, content, expected):
    path = tmp_path / "x.rrd"
    if content is not None:
        path.write_bytes(content)
    assert main(["view", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err and str(path) in err


@pytest.mark.parametrize(
    ("scenario", "expected"), [("12", "case numbers run from 1 to 9"), ("walk", "not a case")]
)
def test_record_rejects_unknown_scenarios(capsys, scenario, expected):
    assert main(["record", scenario]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and expected in err
