"""Each scenario default is written once (sim.scenario.presets) and scenarios/README.md's key
tables say what the loader does: a minimal scenario file gets the presets' values, every
documented default is the one a file without the key gets, every documented range is the
one the loader accepts (closed ends accepted, open ends and just beyond refused), so a
preset changed without the README (or the README without the code) fails here."""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Any

from monopic.cases import Case
from monopic.horizon import HORIZON_S
from sim.scenario import presets
from sim.scenario.cases import CasePlacement
from sim.scenario.families import CAR, SMALL, Scale
from sim.scenario.files import ScenarioFileError, build, with_values
from sim.scenario.spec import CameraSpec, PedestrianSpec, RobotSpec, Scenario
from tests.paths import SCENARIOS

README = SCENARIOS / "README.md"
FILE = Path("<minimal>")
# Everything at its default but what a file must say: a walking case (its pedestrian
# walks at the default speed) ...
MINIMAL: dict[str, Any] = {"name": "minimal", "path": {"kind": "case", "case": 5}}
# ... and, to try one value at a time at the ends of its range, a standing person before a
# standing robot (no run length or robot size drives anyone off the street).
STILL: dict[str, Any] = {
    "name": "still",
    "robot": {"speed": 0.0},
    "path": {"kind": "case", "case": int(Case.STILL)},
}

Getter = Callable[[Scenario], float]


def attributes(part: Callable[[Scenario], Any], keys: str) -> dict[str, Getter]:
    """Getters of keys (space-separated) that are attributes of a part of the Scenario."""
    return {key: (lambda s, key=key: getattr(part(s), key)) for key in keys.split()}


# The documented keys with a default, by table (the README's `[table]` before it; "top"
# for the top level), and where a minimal file's Scenario holds the value.
DEFAULTS: dict[str, dict[str, Getter]] = {
    "top": {
        "horizon": lambda s: s.horizon,
        "duration": lambda s: s.duration,
        "fps": lambda s: 1.0 / s.dt,
        "seed": lambda s: s.seed,
    },
    "[robot]": attributes(
        lambda s: s.robot, "speed width length max_speed max_acceleration max_deceleration"
    ),
    "[robot.camera]": attributes(
        lambda s: s.robot.camera,
        "width height vertical_fov_deg mount_height pitch_deg mount_forward",
    ),
    "[robot.pitch]": attributes(lambda s: s.robot.pitch, "gain frequency damping"),
    "[pedestrian]": attributes(lambda s: s.pedestrian, "speed footprint"),
}
# Ranges the presets module holds, as the README writes them: (low, high).
PRESET_RANGES = {
    ("top", "horizon"): (0.0, presets.MAX_HORIZON_S),
    ("top", "duration"): (0.0, presets.MAX_DURATION_S),
    ("top", "fps"): presets.FPS_RANGE,
    ("[pedestrian]", "height"): presets.HEIGHT_RANGE,
    ("[pedestrian]", "speed"): (0.0, presets.MAX_PEDESTRIAN_SPEED),
}
SCALE_NAMES = tuple(s.value for s in Scale)
VALUE_COLUMNS = ("default", *SCALE_NAMES)
INTEGERS = {("top", "seed"), ("[robot.camera]", "width"), ("[robot.camera]", "height")}


# -- reading the README's tables ------------------------------------------------------


def readme_tables(text: str) -> dict[str, list[dict[str, str]]]:
    """The README's tables by the table of the file they document: the first `[...]` of the
    paragraph before them, "top" after "Top level:", else that paragraph's first line.
    Each row maps the header's cells to the row's."""
    tables: dict[str, list[dict[str, str]]] = {}
    title, header, new_paragraph = "", None, True
    for line in text.splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if header is None:
                header = cells
                tables.setdefault(title, [])
            elif not set("".join(cells)) <= set("-: "):
                tables[title].append(dict(zip(header, cells, strict=True)))
            continue
        header = None
        if not line.strip():
            new_paragraph = True
        elif new_paragraph:
            named = re.match(r"`(\[[\w.]+\])`", line)
            title = "top" if line == "Top level:" else named.group(1) if named else line
            new_paragraph = False
    return tables


def keyed(rows: list[dict[str, str]]) -> dict[str, dict[str, str]]:
    """Rows by key; a row of several keys (`width`, `height`) splits its value cells (the
    defaults: "768, 432"), and its range holds for each."""
    out: dict[str, dict[str, str]] = {}
    for row in rows:
        keys = re.findall(r"`([^`]+)`", row["key"])
        for i, key in enumerate(keys):
            out[key] = {
                col: cell.split(", ")[i] if len(keys) > 1 and col in VALUE_COLUMNS else cell
                for col, cell in row.items()
            }
    return out


def number(cell: str) -> float:
    return float(cell.strip("` "))


RANGE = re.compile(r"([\[(])\s*(-?[\d.]+)\s*,\s*(-?[\d.]+|2\^31)\s*([\])])")


def parse_range(cell: str) -> tuple[float, float, bool, bool] | None:
    """(low, high, low open, high open) of the first numeric range in a cell, else None."""
    m = RANGE.search(cell)
    if m is None:
        return None
    high = 2.0**31 if m.group(3) == "2^31" else float(m.group(3))
    return float(m.group(2)), high, m.group(1) == "(", m.group(4) == ")"


# -- what the loader does -------------------------------------------------------------


@cache
def minimal(scale: str = "small") -> Scenario:
    return build(FILE, {**MINIMAL, "scale": scale})


def refused(dotted: str, value: float) -> bool:
    """Whether the loader refuses `value` for the key (another key's refusal is not)."""
    try:
        build(FILE, with_values(STILL, {dotted: value}))
    except ScenarioFileError as err:
        return err.field == dotted
    return False


def range_problems(table: str, key: str, span: tuple[float, float, bool, bool]) -> list[str]:
    """How the loader's range for the key differs from the README's `span`."""
    low, high, low_open, high_open = span
    dotted = key if table == "top" else f"{table.strip('[]')}.{key}"
    integer = (table, key) in INTEGERS
    out = []
    for bound, sign, is_open in ((low, -1, low_open), (high, 1, high_open)):
        step = 1 if integer else 1e-6 * max(1.0, abs(bound))
        at = int(bound) if integer else bound
        inside, beyond = at - sign * step, at + sign * step
        if is_open and not refused(dotted, at):
            out.append(f"the README's open end {bound:g} is accepted")
        if is_open and refused(dotted, inside):
            out.append(f"just inside the README's open end {bound:g} is refused")
        if not is_open and refused(dotted, at):
            out.append(f"the README's closed end {bound:g} is refused")
        if not is_open and not refused(dotted, beyond):
            out.append(f"just beyond the README's end {bound:g} is accepted")
    return out


def readme_mismatches(text: str) -> list[str]:
    """Every documented default and range that is not the presets' and the loader's."""
    tables = readme_tables(text)
    out = []
    for table, getters in DEFAULTS.items():
        rows = keyed(tables.get(table, []))
        for key, get in getters.items():
            row = rows.get(key)
            if row is None:
                out.append(f"{table} {key}: not documented")
                continue
            columns = SCALE_NAMES if "small" in row else ("default",)
            for column in columns:
                cell = row[column]
                if column == "default" and key == "horizon":  # "preset (small 1.0, car 2.0)"
                    said = dict(re.findall(r"(small|car) ([\d.]+)", cell))
                    found = {s: minimal(s).horizon for s in said}
                    if set(said) != set(SCALE_NAMES) or any(
                        float(said[s]) != found[s] for s in said
                    ):
                        out.append(f"{table} {key}: README {cell!r}, loader {found}")
                    continue
                scale = column if column in SCALE_NAMES else "small"
                if not math.isclose(number(cell), get(minimal(scale)), abs_tol=1e-12):
                    out.append(
                        f"{table} {key} ({column}): README {cell}, loader {get(minimal(scale))}"
                    )
    for table in DEFAULTS:
        for key, row in keyed(tables.get(table, [])).items():
            cell = row.get("range", row.get("range / values", ""))
            span = parse_range(cell)
            preset = PRESET_RANGES.get((table, key))
            if preset is not None and (span is None or span[:2] != tuple(preset)):
                out.append(f"{table} {key}: README range {cell!r}, presets {preset}")
                continue
            if span is not None:
                out += [f"{table} {key}: {p}" for p in range_problems(table, key, span)]
    return out


# -- the tests ------------------------------------------------------------------------


def test_the_readme_documents_the_presets_and_the_loaders_ranges():
    assert readme_mismatches(README.read_text(encoding="utf-8")) == []


def test_a_wrong_readme_default_or_range_or_a_missing_row_is_found():
    text = README.read_text(encoding="utf-8")
    changes = {
        "| `duration` | number, s | 4.0 |": "| `duration` | number, s | 5.0 |",
        "| `vertical_fov_deg` | degrees | 65 |": "| `vertical_fov_deg` | degrees | 60 |",
        "| `footprint` | m | 0.5 | (0, 2]": "| `footprint` | m | 0.5 | [0, 2]",
        "| 768, 432 | 768, 432 | [64, 4096] |": "| 768, 432 | 768, 432 | [32, 4096] |",
        "| `fps` | number | 15 | [1, 60] |": "| `fps` | number | 15 | [1, 50] |",
        "preset (small 1.0, car 2.0)": "preset (small 1.5, car 2.0)",
    }
    for old, new in changes.items():
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    text = "\n".join(line for line in text.splitlines() if not line.startswith("| `damping`"))
    found = readme_mismatches(text)
    assert sorted(found) == sorted(
        [
            "top duration (default): README 5.0, loader 4.0",
            "[robot.camera] vertical_fov_deg (small): README 60, loader 65.0",
            "[pedestrian] footprint: the README's closed end 0 is refused",
            "[robot.camera] width: the README's closed end 32 is refused",
            "[robot.camera] height: the README's closed end 32 is refused",
            "top fps: README range '[1, 50]', presets (1.0, 60.0)",
            "top horizon: README 'preset (small 1.5, car 2.0)', loader "
            + str({"small": 1.0, "car": 2.0}),
            "[robot.pitch] damping: not documented",
        ]
    )


def test_a_minimal_file_gets_the_presets():
    small, car = minimal("small"), minimal("car")
    assert (small.duration, small.dt, small.horizon) == (
        presets.DURATION_S, 1.0 / presets.FPS, presets.HORIZON_S
    )  # fmt: skip
    assert presets.HORIZON_S is HORIZON_S  # the pipeline's, not a copy
    assert (small.pedestrian.speed, small.pedestrian.footprint) == (
        presets.PEDESTRIAN_SPEED, presets.FOOTPRINT
    )  # fmt: skip
    camera = CameraSpec(
        width=presets.CAMERA_WIDTH,
        height=presets.CAMERA_HEIGHT,
        vertical_fov_deg=presets.CAMERA_FOV_DEG,
        mount_height=presets.CAMERA_MOUNT_HEIGHT,
        pitch_deg=presets.CAMERA_PITCH_DEG,
    )
    assert small.robot.camera == camera == CameraSpec()
    assert (small.robot.speed, small.robot.width, small.robot.length) == (
        presets.ROBOT_SPEED, presets.ROBOT_WIDTH, presets.ROBOT_LENGTH
    )  # fmt: skip
    assert small.robot == SMALL.robot and car.robot == CAR.robot
    assert (small.horizon, car.horizon) == (SMALL.horizon, CAR.horizon)


def test_the_dataclasses_and_the_placement_default_to_the_presets():
    s = Scenario("s", PedestrianSpec(0.0, 0.0, 0.0, 1.0))
    assert (s.duration, s.dt, s.horizon) == (presets.DURATION_S, 1 / presets.FPS, HORIZON_S)
    assert s.pedestrian.footprint == presets.FOOTPRINT
    assert s.robot == RobotSpec() and s.robot.camera == CameraSpec()
    p = CasePlacement(Case.PERPENDICULAR_RIGHT)
    assert (p.duration, p.dt, p.horizon) == (presets.DURATION_S, 1 / presets.FPS, HORIZON_S)
    assert (p.pedestrian_speed, p.robot_speed) == (presets.PEDESTRIAN_SPEED, presets.ROBOT_SPEED)
    # The placement's scenario is the one a minimal file with the same case gives.
    placed = p.scenario(robot=SMALL.robot)
    assert placed.pedestrian.speed == minimal().pedestrian.speed
    assert (placed.duration, placed.dt, placed.horizon) == (
        minimal().duration, minimal().dt, minimal().horizon
    )  # fmt: skip
