"""Simulated runs recorded to .rrd and read back with rerun's own reader; `monopic view`."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from rerun.chunk import RrdReader

from monopic.cases import Case
from monopic.cli.main import main
from sim.cases import place_case
from sim.recording import footprint_gap, polygon_gap, record_run, rectangle
from sim.world import World
from tests.rrd import column, rows_per_entity


def static_entities(path: Path) -> set[str]:
    return {
        chunk.entity_path for chunk in RrdReader(str(path)).stream().to_chunks() if chunk.is_static
    }


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
    scenario = place_case(
        Case.PERPENDICULAR_RIGHT, distance=2.0, robot_speed=2.0, meet_time=1.0, duration=1.4
    )
    rrd = tmp_path / "run.rrd"
    summary = record_run(scenario, rrd, topdown_every=3)
    assert rrd.exists() and summary.bytes == rrd.stat().st_size
    assert not list(tmp_path.glob(".*"))  # no temporary left behind
    n = summary.frames
    assert summary.contact_time is not None and n < scenario.frames  # stopped at contact

    counts = rows_per_entity(rrd)
    for entity in ("/camera/image", "/camera/pose", "/truth/phi", "/alarm/truth",
                   "/world/robot", "/world/pedestrian", "/world/truth/future", "/robot/speed",
                   "/truth/gap", "/latency/total"):  # fmt: skip
        assert counts[entity] == n, entity
    assert counts["/topdown/image"] == math.ceil(n / 3)
    # The pedestrian ends up 2 m ahead, its feet below the frame: not every frame has a pose.
    assert n // 2 <= summary.found <= n and counts["/features/phi"] <= summary.found
    # Every predictor's warning on every frame it decided (ground mode needs the feet).
    assert counts["/alarm/rules-image"] >= counts["/features/phi"] >= n // 2
    assert counts["/alarm/rules-ground"] >= 1
    assert counts["/camera/truth/foot"] == n
    assert counts["/ttc/truth"] == n  # on a collision course from the first frame
    assert counts["/events"] >= 2  # collision course and contact at least
    assert {"/world/road", "/world/robot/body", "/world/robot/camera", "/world/truth/path",
            "/world/pedestrian", "/camera/pose"} <= static_entities(rrd)  # fmt: skip

    # The truth series are the simulator's own values, frame by frame.
    truth = []
    with World(scenario, render=False) as world:
        for step in world.run():
            truth.append(step.truth)
            if len(truth) == n:
                break
    phi = [v[0] for v in column(rrd, "/truth/phi", "Scalars:scalars")]
    assert phi == pytest.approx([t.phi for t in truth])
    ttc = [v[0] for v in column(rrd, "/ttc/truth", "Scalars:scalars")]
    assert ttc == pytest.approx([t.time_to_collision for t in truth])
    assert ttc[0] == pytest.approx(truth[0].time_to_collision) and 0.5 < ttc[0] < 1.0
    gap = [v[0] for v in column(rrd, "/truth/gap", "Scalars:scalars")]
    assert gap[-1] == 0.0 and gap[0] == pytest.approx(
        footprint_gap(truth[0], scenario.pedestrian.footprint)
    )
    frames = column(rrd, "/truth/phi", "frame")
    assert frames == list(range(n))

    # A predictor missed the collision iff it never warned on a frame where one was coming.
    def raised(entity: str) -> set[int]:
        values = column(rrd, entity, "Scalars:scalars")
        return {f for f, v in zip(column(rrd, entity, "frame"), values, strict=True) if v[0]}

    coming = raised("/alarm/truth")
    assert coming and summary.false_alarms == ()
    for key in summary.warned:
        warned = raised(f"/alarm/{key.replace('/', '-')}")
        assert (key in summary.missed) == (not warned & coming), key
    events = [v[0] for v in column(rrd, "/events", "TextLog:text")]
    assert any(e.startswith("CONTACT") for e in events)
    assert any(e.startswith("truth: on a collision course") for e in events)


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
