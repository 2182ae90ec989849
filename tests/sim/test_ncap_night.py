"""Night: the lamps and low beams, the night tests of the Euro NCAP grid, their mistakes."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import replace
from pathlib import Path

import pytest

from sim.scenario.files import load
from sim.scenario.lamps import LOW_BEAM, StreetLamp, regulation_table
from sim.scenario.lighting import NIGHT, PRESETS
from sim.scenario.ncap import Draw, grid, load_car, load_protocol, scenario_for
from sim.scenario.toml_table import FieldError
from tests.paths import ROOT, SCENARIOS, SHARED_DATA

PROTOCOL = load_protocol(ROOT / "scenarios/ncap/protocol.toml")
CAR = load_car(ROOT / "scenarios/ncap/car.toml")
CASE5 = (SCENARIOS / "cases" / "case5_perpendicular_right.toml").read_text()
OSC = SHARED_DATA / "osc-ncap"
needs_osc = pytest.mark.skipif(
    not (OSC / "OpenDRIVE").is_dir(),
    reason=f"the published Euro NCAP OpenSCENARIO files are not at {OSC} (set MONOPIC_SHARED_DATA)",
)
LANE_CENTRE_T = -14.0  # the car's lane -1 of the published road, 28 m wide
CONFLICT_S = 150.0  # VRU_initS of the published crossing tests


def _xodr_lamps(name: str) -> list[tuple[float, float, bool]]:
    root = ET.parse(OSC / "OpenDRIVE" / "NCAP" / name).getroot()
    return [
        (round(float(o.get("s")) - CONFLICT_S, 3), round(float(o.get("t")) - LANE_CENTRE_T, 3),
         not o.get("subtype", "").endswith("Off"))
        for o in root.iter("object") if o.get("type") == "streetLamp"
    ]  # fmt: skip


def _night_road(test: str) -> str | None:
    """The road the published standard-range variation gives a test's Night runs."""
    path = OSC / "OpenSCENARIO/NCAP/CA-FC_2026/Variations/StandardRange" / f"{test}.xosc"
    root = ET.parse(path).getroot()
    for values in root.iter("ParameterValueSet"):
        got = {a.get("parameterRef"): a.get("value") for a in values.iter("ParameterAssignment")}
        if got.get("LightingConditions") == "Night" and "RoadNetwork" in got:
            return Path(got["RoadNetwork"]).name
    return None


@needs_osc
@pytest.mark.parametrize(
    ("test", "xodr"),
    [
        ("cpna-night", "StraightRoad_NCAP_noRoadmarks_Streetlights_Nearside.xodr"),
        ("cpfa-night", "StraightRoad_NCAP_noRoadmarks_Streetlights.xodr"),
        ("cpnco-night", "StraightRoad_NCAP_noRoadmarks_Streetlights_Nearside.xodr"),
        ("cpla-night", None),
    ],
)
def test_each_night_test_drives_the_published_night_road_with_its_lamps(
    test: str, xodr: str | None
) -> None:
    assert _night_road(test.removesuffix("-night").upper()) == xodr
    layout = PROTOCOL.tests[test].lamps
    if xodr is None:
        assert layout is None
        return
    ours = PROTOCOL.lamps[layout]
    published = _xodr_lamps(xodr)
    assert sorted(zip(ours.along, ours.across, ours.on, strict=True)) == sorted(published)
    assert ours.height == 5.0


def test_a_night_test_is_dark_has_low_beams_and_its_roads_lamps() -> None:
    point = grid(PROTOCOL, ["cpna-night"])[0]
    s = scenario_for(PROTOCOL, CAR, point, Draw.nominal())
    assert s.scene.lighting.night and s.robot.headlamps == LOW_BEAM
    assert sum(lamp.on for lamp in s.scene.lamps) == 5 and len(s.scene.lamps) == 7
    assert s.pedestrian.anchor is not None
    assert min(abs(lamp.x - s.pedestrian.anchor.x) for lamp in s.scene.lamps) == 12.5
    day = scenario_for(PROTOCOL, CAR, grid(PROTOCOL, ["cpna"])[0], Draw.nominal())
    assert not day.scene.lamps and day.robot.headlamps is None
    # Same placement, only the light differs.
    assert s.pedestrian == day.pedestrian


def test_the_quick_grid_has_one_night_point() -> None:
    quick = grid(PROTOCOL, list(PROTOCOL.tests), quick=True)
    night = [p for p in quick if PROTOCOL.tests[p.test].lighting == "night"]
    assert [p.id for p in night] == ["cpna-night/AEB/40kmh/50"]


def test_a_night_test_without_headlamps_is_refused_in_one_line() -> None:
    car = replace(CAR, headlamps=None)
    with pytest.raises(FieldError) as err:
        scenario_for(PROTOCOL, car, grid(PROTOCOL, ["cpfa-night"])[0], Draw.nominal())
    assert "headlamps.beam = 'none'" in str(err.value) and "needs the car's headlamps" in str(
        err.value
    )


def test_a_night_scenario_file_without_headlamps_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "night.toml"
    path.write_text(CASE5.replace("[robot]\n", '[scene]\nlighting = "night"\n\n[robot]\n'))
    with pytest.raises(FieldError) as err:
        load(path)
    text = str(err.value)
    assert "robot.headlamps = 'none'" in text and "a night scene needs" in text, text
    path.write_text(
        CASE5.replace(
            "[robot]\n", '[scene]\nlighting = "night"\n\n[robot]\nheadlamps = "low-beam"\n'
        )
    )
    scenario = load(path).base
    assert scenario.robot.headlamps == LOW_BEAM and scenario.scene.lighting == NIGHT


def test_a_lamp_on_the_road_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "lamp.toml"
    lamps = "[[scene.lamps]]\nx = 10.0\ny = 0.5\n"
    path.write_text(CASE5.replace("[robot]\n", f"{lamps}\n[robot]\n"))
    with pytest.raises(FieldError) as err:
        load(path)
    assert "scene.lamps[0].y = 0.5" in str(err.value) and "on the road" in str(err.value)
    path.write_text(CASE5.replace("[robot]\n", "[[scene.lamps]]\nx = 10.0\ny = -6.0\n\n[robot]\n"))
    assert load(path).base.scene.lamps == (StreetLamp(10.0, -6.0),)


def test_a_protocol_lamp_on_the_road_is_refused(tmp_path: Path) -> None:
    text = (ROOT / "scenarios/ncap/protocol.toml").read_text()
    bad = text.replace("across = [-6.1, -6.1, -6.1, -6.1, -6.1, 8.1, 8.1]",
                       "across = [-6.1, -2.0, -6.1, -6.1, -6.1, 8.1, 8.1]", 1)  # fmt: skip
    assert bad != text
    path = tmp_path / "protocol.toml"
    path.write_text(bad.replace('"../families/', f'"{ROOT}/scenarios/families/'))
    with pytest.raises(FieldError) as err:
        load_protocol(path)
    assert "lamps.streetlights.across" in str(err.value) and "lamp 1 at -2 m" in str(err.value)


def test_an_unknown_lighting_name_is_refused_with_the_known_ones(tmp_path: Path) -> None:
    path = tmp_path / "dusk.toml"
    path.write_text(CASE5.replace("[robot]\n", '[scene]\nlighting = "nigth"\n\n[robot]\n'))
    with pytest.raises(FieldError) as err:
        load(path)
    assert "scene.lighting = 'nigth'" in str(err.value) and "night" in str(err.value)
    assert "night" in PRESETS


def test_the_low_beam_is_dark_above_its_cut_off_and_meets_the_central_points() -> None:
    rows = {name: (need, ours) for name, _, _, need, ours in regulation_table()}
    assert rows["B50L"][1] == 0 and rows["zone III (1 deg up)"][1] == 0
    for name in ("50V", "50R", "75R", "25L", "25R"):
        need, ours = rows[name]
        assert ours >= float(need.removeprefix(">= ").replace(",", "")), name
    assert LOW_BEAM.intensity(0.3, 0.0) == 0  # just under the horizon: above the cut-off


def test_a_lamp_that_is_off_gives_no_light() -> None:
    assert StreetLamp(0.0, 6.0, on=False).illuminance(0.0, 6.0) == 0.0
    lamp = StreetLamp(0.0, 6.0)
    assert lamp.illuminance(0.0, 6.0) == pytest.approx(1600 / 25)
    assert lamp.illuminance(100.0, 6.0) == 0.0  # beyond its cone


def test_the_calculators_halves_are_its_day_and_night_maxima() -> None:
    pytest.importorskip("euroncap_rating_2026")
    from sim.analysis.ncap_score import half_maximum

    tests = {"CPNA", "CPFA", "CPNCO", "CPLA"}
    assert half_maximum("day", tests) == pytest.approx(4.125)
    assert half_maximum("night", tests) == pytest.approx(3.375)


def _row(test: str, load_case: str, found: list[int], ahead: list[float]) -> dict:
    return {
        "policy": "rules/ground", "role": "grid", "test": test, "function": "AEB",
        "speed_kmh": 40.0, "impact": 0.5, "load_case": load_case,
        "outcome": {"target_found": found, "target_range_m": ahead},
    }  # fmt: skip


def test_detection_is_counted_by_band_on_the_points_run_by_day_and_at_night() -> None:
    from sim.analysis.ncap_report import detection_by_band, detection_table

    rows = [
        _row("cpna", "CPNA day", [1, 1, 0, -1], [35.0, 15.0, 5.0, 2.0]),
        _row("cpna-night", "CPNA night", [0, 1, -1], [35.0, 15.0, 5.0]),
        _row("cpfa", "CPFA day", [1, 1], [15.0, 12.0]),  # no night twin: left out
    ]
    bands = detection_by_band(rows, "rules/ground")
    assert bands is not None
    assert bands["day"] == [(0, 1), (1, 1), (0, 0), (1, 1), (0, 0)]
    assert bands["night"] == [(0, 0), (1, 1), (0, 0), (0, 1), (0, 0)]
    table = detection_table(rows, ["rules/ground"])
    assert "| rules/ground | 30-50 m | 1 / 1 (100%) | 0 / 1 (0%) |" in table
    assert detection_by_band(rows[:1], "rules/ground") is None


@pytest.mark.slow
def test_the_night_point_runs_and_is_scored_on_its_own_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    from monopic.cli.main import main

    pytest.importorskip("euroncap_rating_2026")
    out = tmp_path / "ncap"
    argv = ["ncap", "--tests", "cpna,cpna-night", "--quick", "--speeds-kmh", "40",
            "--runs-per-point", "1", "--policies", "rules/ground", "--no-near-misses",
            "--workers", "2", "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    rows = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert sorted(r["load_case"] for r in rows) == ["CPNA day"] * 2 + ["CPNA night"] * 2
    assert {r["lighting"] for r in rows if r["test"] == "cpna-night"} == {"night"}
    for row in rows:  # each frame: found, missed or out of sight, and how far ahead
        o = row["outcome"]
        assert len(o["target_found"]) == len(o["target_range_m"]) > 0
        assert set(o["target_found"]) <= {-1, 0, 1}
    printed = capsys.readouterr().out
    for half, top in (("day", "0.6875"), ("night", "0.5625")):
        assert f"| rules/ground | {half} | " in printed and f" / {top} |" in printed
    report = (out / "report.md").read_text()
    assert "## Detection by distance, day against night" in report
    assert list((out / "calculator" / "rules-ground" / "night").glob("ca_*_report.xlsx"))
