"""The official Euro NCAP 2026 rating calculator, filled with the grid's results and run.

The calculator (PyPI euroncap-rating-2026, the project's `[ncap]` extra) scores crash
avoidance in three of its own steps, each run here as its command line runs it, in a
child process whose working folder is the calculator's folder under the output:

1. `crash_avoidance generate-template` writes ca_template.xlsx;
2. we fill its grey input cells: per claimed pedestrian load case the prediction colour
   of every matrix cell (ours: the colour band the calculator itself gives the grid
   point's worst run; cells not run and the night matrices "Red", i.e. no claim), the
   prediction method ("VTA": our predictions are virtual tests), the robustness layers
   ("NO": none claimed, none tested), and the FCW choice of the CPLA 50-80 km/h rows;
   `crash_avoidance preprocess` then picks the verification test points (its own random
   choice, seeded so a rerun picks the same) into ca_preprocessed_template.xlsx;
3. we fill each verification point's measured value from the grid point's independent
   verification run (relative impact speed in km/h, or the FCW's TTC in s), and
   `crash_avoidance compute-score` writes the scored report, which is read back.

Colour bands come from the calculator's own code (matrix_processing.ComputedTestPoint),
so nothing of its scoring is reimplemented here. The calculator is imported only inside
the functions that need it, so the simulator loads without the extra.
"""

from __future__ import annotations

import glob
import subprocess
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from monopic.errors import UserError

CALCULATOR_PIN = "euroncap-rating-2026==5.4.9"
PRED_SHEET = "FC - Ped & Cyc pred."
ROBUST_SHEET = "FC - Ped & Cyc robust. pred."
VERIF_SHEET = "FC - Ped & Cyc verif."
PEDESTRIAN_TESTS = ("CPLA", "CPNA", "CPFA", "CPNCO")  # the robustness/input columns we fill
PREPROCESS_SEED = 2026  # the calculator's random choice of verification points, fixed
NO_CLAIM = "Red"  # a cell not run: the prediction that claims nothing


def calculator_version() -> str | None:
    """The installed calculator's version, or None without the extra."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("euroncap-rating-2026")
    except PackageNotFoundError:
        return None


def require_calculator() -> str:
    """The installed version, or a one-line UserError saying how to install it."""
    found = calculator_version()
    if found is None:
        raise UserError(
            "monopic ncap needs the Euro NCAP rating calculator: "
            f"pip install -c requirements.lock -e '.[ncap]' ({CALCULATOR_PIN})"
        )
    return found


def kmh(value: float) -> str:
    return f"{value:g} km/h"


def percent(value: float) -> str:
    return f"{round(value * 100):d}%"


def band_colour(load_case: str, function: str, speed_kmh: float, value: float) -> str:
    """The calculator's colour band ("Green", ...) of a measured value at a matrix cell.

    `value`: relative impact speed in km/h (AEB rows, 0 when avoided) or the FCW's TTC
    in s (FCW rows). Read from matrix_processing.ComputedTestPoint.measured_color, the
    true colour of a test point with no tolerance applied.
    """
    from euroncap_rating_2026 import common
    from euroncap_rating_2026.crash_avoidance import matrix_processing as mp

    attributes = {"VUT speed": kmh(speed_kmh), "Function": function}
    point = mp.TestPoint(
        row=0,
        col=0,
        color=common.PredictionColor.GREEN,
        test_range=mp.TestRange.STANDARD,
        attributes=attributes,
        total_rows=10,
    )
    computed = mp.ComputedTestPoint(test_point=point, test_name=load_case, value=float(value))
    if computed.measured_color is None:
        raise ValueError(f"the calculator gives no colour band for {load_case} {function}")
    return str(computed.measured_color.value).capitalize()


@dataclass(frozen=True)
class Cell:
    """One matrix cell we fill: its prediction colour, and its verification value."""

    load_case: str
    function: str
    speed_kmh: float
    impact: float
    colour: str  # our prediction
    verification: float | None  # the verification run's value (None: not run)


@dataclass
class LoadCaseScore:
    """The calculator's points for one load case (its Scenario Scores rows)."""

    scenario: str  # "CPNA"
    standard: float
    extended: float
    robustness: float
    max_standard: float
    max_extended: float
    max_robustness: float

    @property
    def total(self) -> float:
        return self.standard + self.extended + self.robustness

    @property
    def max_total(self) -> float:
        return self.max_standard + self.max_extended + self.max_robustness


@dataclass
class CalculatorScore:
    """What compute-score wrote: per load case, the pedestrian & cyclist total, the checks."""

    version: str
    report: Path
    load_cases: dict[str, LoadCaseScore]
    ped_cyc_score: float  # Frontal Collisions, Pedestrian & cyclist (all its load cases)
    ped_cyc_max: float
    verification: list[dict[str, Any]] = field(default_factory=list)  # rows of the verif sheet

    @property
    def pedestrian_score(self) -> float:
        return sum(s.total for s in self.load_cases.values())

    @property
    def pedestrian_max(self) -> float:
        return sum(s.max_total for s in self.load_cases.values())


def _run_calculator(folder: Path, *args: str) -> None:
    """One calculator command in a child process (its log goes to `folder`)."""
    code = (
        "import random, sys; random.seed(int(sys.argv[1])); "
        "from euroncap_rating_2026.cli import cli; cli(sys.argv[2:])"
    )
    cmd = [sys.executable, "-c", code, str(PREPROCESS_SEED), "crash_avoidance", *args]
    done = subprocess.run(cmd, cwd=folder, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or done.stdout.strip().splitlines() or ["?"])[-1]
        raise RuntimeError(f"the rating calculator's {args[0]} failed: {last}")


def _matrices(ws: Any) -> dict[str, dict[str, Any]]:
    """Where each load case's matrix lies on the prediction sheet (1-based rows/columns).

    A matrix starts at a row whose column A names it; the next row holds the impact
    locations; speed rows follow until a blank row. Columns of the header row name the
    attribute columns (Target speed, Function, Day/Night).
    """
    from euroncap_rating_2026.crash_avoidance import data_model

    out: dict[str, dict[str, Any]] = {}
    r = 1
    while r <= ws.max_row:
        name = ws.cell(r, 1).value
        if isinstance(name, str) and name in data_model.MATRIX_INDICES:
            idx = data_model.MATRIX_INDICES[name]
            cols = range(idx["start_col"] + 1, idx["start_col"] + idx["n_cols"] + 1)
            header = {ws.cell(r, c).value: c for c in range(1, 6) if ws.cell(r, c).value}
            impacts = {float(ws.cell(r + 1, c).value): c for c in cols}
            rows = []
            k = r + 2
            while k <= ws.max_row and ws.cell(k, 1).value:
                rows.append(k)
                k += 1
            out[name] = {"header": header, "impacts": impacts, "rows": rows}
            r = k
        r += 1
    return out


def _row_for(ws: Any, m: dict[str, Any], function: str, speed_kmh: float) -> int | None:
    """The sheet row of a matrix's speed row for this function (CPLA has two bands)."""
    fcol = m["header"].get("Function")
    for r in m["rows"]:
        if ws.cell(r, 1).value != kmh(speed_kmh):
            continue
        if fcol is None:
            return r
        value = ws.cell(r, fcol).value
        band = "AEB" if value == "AEB" else "FCW"  # blank: the manufacturer's choice band
        if band == function:
            return r
    return None


def fill_template(path: Path, cells: list[Cell], claimed: set[str]) -> None:
    """Fill ca_template.xlsx's grey cells for the claimed tests (module docstring, step 2)."""
    import openpyxl
    from openpyxl.utils import range_boundaries

    wb = openpyxl.load_workbook(path)
    ws = wb[PRED_SHEET]
    matrices = _matrices(ws)
    claimed_cases = [
        name for name in matrices if name.split(" ")[0] in claimed and " " in name
    ]  # "CPNA day", "CPNA night", ...
    for name in claimed_cases:  # no claim, unless a cell was run
        m = matrices[name]
        fcol = m["header"].get("Function")
        for r in m["rows"]:
            if fcol is not None and ws.cell(r, fcol).value is None:
                ws.cell(r, fcol).value = "FCW"  # the choice band: our warning is an FCW
            for c in m["impacts"].values():
                ws.cell(r, c).value = NO_CLAIM
    for cell in cells:
        m = matrices.get(cell.load_case)
        if m is None:
            raise ValueError(f"the calculator's template has no matrix {cell.load_case!r}")
        r = _row_for(ws, m, cell.function, cell.speed_kmh)
        c = m["impacts"].get(cell.impact)
        if r is None or c is None:
            raise ValueError(f"{cell.load_case}: no cell {cell.function} "
                             f"{kmh(cell.speed_kmh)} {percent(cell.impact)}")  # fmt: skip
        ws.cell(r, c).value = cell.colour
    ip = wb["Input parameters"]
    scenario = None
    for r in range(2, ip.max_row + 1):
        scenario = ip.cell(r, 5).value or scenario
        if scenario in claimed and str(ip.cell(r, 6).value).startswith("Prediction"):
            ip.cell(r, 7).value = "VTA"
    rb = wb[ROBUST_SHEET]
    for dv in rb.data_validations.dataValidation:
        for rng in dv.sqref.ranges:
            c0, r0, c1, r1 = range_boundaries(rng.coord)
            for r in range(r0, r1 + 1):
                for c in range(c0, c1 + 1):
                    if rb.cell(1, c).value in claimed:
                        rb.cell(r, c).value = "NO"
    wb.save(path)


def _verification_key(row: Mapping[str, Any]) -> tuple[str, str, float, float]:
    impact = float(str(row["Impact location"]).rstrip("%")) / 100
    speed = float(str(row["VUT speed"]).replace(" km/h", ""))
    function = str(row.get("Function") or "AEB")
    return str(row["Scenario"]), function, speed, round(impact, 4)


def fill_verification(path: Path, cells: list[Cell]) -> int:
    """Write each selected verification point's measured value; returns how many."""
    import openpyxl

    values = {
        (c.load_case, c.function, c.speed_kmh, round(c.impact, 4)): c.verification for c in cells
    }
    wb = openpyxl.load_workbook(path)
    ws = wb[VERIF_SHEET]
    header_row = next(r for r in range(1, ws.max_row + 1)
                      if ws.cell(r, 1).value == "Scenario" and ws.cell(r, 2).value)  # fmt: skip
    header = {ws.cell(header_row, c).value: c for c in range(1, ws.max_column + 1)}
    filled = 0
    for r in range(header_row + 1, ws.max_row + 1):
        if not ws.cell(r, 1).value:
            continue
        row = {name: ws.cell(r, c).value for name, c in header.items() if name}
        key = _verification_key(row)
        value = values.get(key)
        if value is None:
            raise ValueError(f"the calculator chose {key} for verification, which was not run")
        ws.cell(r, header["Value"]).value = round(float(value), 2)
        filled += 1
    wb.save(path)
    return filled


def read_report(path: Path, version: str) -> CalculatorScore:
    """The pedestrian load cases' points, the Ped & Cyc total and the verification rows."""
    import openpyxl

    wb = openpyxl.load_workbook(path, data_only=True)
    scores: dict[str, LoadCaseScore] = {}
    scenario = None
    for row in wb["Scenario Scores"].iter_rows(min_row=2, values_only=True):
        scenario = row[4] or scenario
        if scenario not in PEDESTRIAN_TESTS:
            continue
        s = scores.setdefault(scenario, LoadCaseScore(scenario, 0, 0, 0, 0, 0, 0))
        value = float(row[6]) if isinstance(row[6], int | float) else 0.0
        top = float(row[7])
        setattr(s, row[5].lower(), value)
        setattr(s, f"max_{row[5].lower()}", top)
    ped, ped_max = 0.0, 0.0
    element = None
    for row in wb["Test Scores"].iter_rows(min_row=2, values_only=True):
        element = row[1] or element
        if element == "Frontal Collisions" and row[2] == "Pedestrian & cyclist":
            ped = float(row[3]) if isinstance(row[3], int | float) else 0.0
            ped_max = float(row[4])
    ws = wb[VERIF_SHEET]
    rows = list(ws.iter_rows(values_only=True))
    k = next(i for i, r in enumerate(rows) if r[0] == "Scenario" and r[1])
    names = rows[k]
    verification = [dict(zip(names, r, strict=False)) for r in rows[k + 1 :] if r[0]]
    return CalculatorScore(version, path, scores, ped, ped_max, verification)


HALVES = ("day", "night")


def half_of(load_case: str) -> str | None:
    """ "day" or "night" for a load case that has both ("CPNA night"), else None."""
    last = load_case.rsplit(" ", 1)[-1]
    return last if last in HALVES else None


def half_maximum(half: str, scenarios: set[str]) -> float:
    """The calculator's most points for one half (standard, extended and robustness layers
    of its TOTAL_SCORES) over the claimed tests: day 4.125 and night 3.375 for all four."""
    from euroncap_rating_2026.crash_avoidance import data_model

    return sum(
        sum(v or 0.0 for v in layers.values())
        for name, layers in data_model.TOTAL_SCORES.items()
        if half_of(name) == half and name.split(" ")[0] in scenarios
    )


def score_halves(folder: Path, cells: list[Cell], claimed: set[str]) -> dict[str, CalculatorScore]:
    """The calculator run once per half that has cells, the other half's matrices left
    Red: each half's points on their own, from the official scoring (folder/day, /night)."""
    out = {}
    for half in HALVES:
        own = [c for c in cells if half_of(c.load_case) == half]
        if own:
            out[half] = score(folder / half, own, claimed)
    return out


def score(folder: Path, cells: list[Cell], claimed: set[str]) -> CalculatorScore:
    """Run the calculator's three steps in `folder` (made fresh) and read its report."""
    version = require_calculator()
    folder.mkdir(parents=True, exist_ok=True)
    for old in folder.glob("ca_*.xlsx"):
        old.unlink()
    _run_calculator(folder, "generate-template")
    template = folder / "ca_template.xlsx"
    fill_template(template, cells, claimed)
    _run_calculator(folder, "preprocess", "-i", template.name, "-o", ".")
    pre = folder / "ca_preprocessed_template.xlsx"
    fill_verification(pre, cells)
    _run_calculator(folder, "compute-score", "-i", pre.name, "-o", ".")
    reports = sorted(glob.glob(str(folder / "ca_*_report.xlsx")))
    if not reports:
        raise RuntimeError("the rating calculator's compute-score wrote no report")
    return read_report(Path(reports[-1]), version)
