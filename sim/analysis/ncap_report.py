"""The Euro NCAP grid's results: per grid point worst and mean, colour matrices, report.md.

A grid point's prediction is the calculator's colour band of its worst grid run (the
highest relative impact speed, or the shortest FCW TTC): a manufacturer claims what its
virtual tests show at worst. Its verification value is the mean of its verification
runs (one by default), run apart from the prediction's. The calculator (sim.analysis.
ncap_score) turns predictions and verification values into points; this module writes
what it said beside the project's own figures: impact speed, speed reduction and warning
TTC per grid point (worst and mean), recall and lead time, the near misses' braking, and
where runs name whom the car braked for (the people tracker, several people), the brakes
for the wrong person (nobody, or someone not on a collision course) apart from the right.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from monopic.errors import UserError
from monopic.output import atomic_path
from sim.analysis.ncap_score import (
    CalculatorScore,
    Cell,
    band_colour,
    calculator_version,
    percent,
    read_report,
)
from sim.analysis.triage import Rerunning, ncap_triage_lines
from sim.runs.ncap_grid import DECLARED, GRID, MEASURED, NEAR_MISS, VERIFY, LatencySetting
from sim.scenario.ncap import CarSpec, Protocol
from sim.sensor.spec import IDEAL
from sim.world.warned_for import NOBODY

COLOURS = {  # the calculator's own RGB (common.PREDICTION_COLOR_MAP)
    "Green": (0 / 255, 153 / 255, 51 / 255),
    "Yellow": (255 / 255, 221 / 255, 51 / 255),
    "Orange": (255 / 255, 153 / 255, 51 / 255),
    "Brown": (150 / 255, 75 / 255, 0 / 255),
    "Red": (255 / 255, 51 / 255, 51 / 255),
}
NOT_RUN = (0.85, 0.85, 0.85)
RESULTS = "results.jsonl"  # the grid's results file in its output folder


def value(row: dict[str, Any]) -> float:
    """What the calculator judges a run by: relative impact speed (km/h) or FCW TTC (s)."""
    o = row["outcome"]
    if row["function"] == "FCW":
        return 0.0 if o["warning_ttc"] is None else float(o["warning_ttc"])
    rel = o["relative_impact_speed"]
    return 0.0 if not o["contact"] or rel is None else float(rel) * 3.6


@dataclass(frozen=True)
class PointSummary:
    """One grid point under one policy: its grid runs and its verification runs."""

    policy: str
    test: str
    load_case: str
    function: str
    speed_kmh: float
    impact: float
    runs: int
    contacts: int
    worst: float  # the judged value at worst (max impact speed / min TTC)
    mean: float
    impact_kmh_worst: float  # relative impact speed, km/h (0: avoided)
    impact_kmh_mean: float
    reduction_kmh_mean: float
    warning_ttc_worst: float | None  # s (None: a run without warning)
    warning_ttc_mean: float | None
    verification: float | None
    colour: str  # the prediction: the calculator's band of `worst`


def summarise(rows: Sequence[dict[str, Any]]) -> list[PointSummary]:
    """Per (policy, grid point), in the rows' order."""
    groups: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        if row["role"] in (GRID, VERIFY):
            key = (row["policy"], row["test"], row["load_case"], row["function"],
                   row["speed_kmh"], row["impact"])  # fmt: skip
            groups[key].append(row)
    out = []
    for (policy, test, case, function, speed, impact), members in groups.items():
        grid = [r for r in members if r["role"] == GRID]
        verify = [r for r in members if r["role"] == VERIFY]
        if not grid:
            continue
        values = [value(r) for r in grid]
        impacts = [value(r) if function == "AEB" else _impact_kmh(r) for r in grid]
        ttcs = [r["outcome"]["warning_ttc"] for r in grid]
        worst = min(values) if function == "FCW" else max(values)
        out.append(
            PointSummary(
                policy=policy,
                test=test,
                load_case=case,
                function=function,
                speed_kmh=speed,
                impact=impact,
                runs=len(grid),
                contacts=sum(r["outcome"]["contact"] for r in grid),
                worst=worst,
                mean=float(np.mean(values)),
                impact_kmh_worst=max(impacts),
                impact_kmh_mean=float(np.mean(impacts)),
                reduction_kmh_mean=float(
                    np.mean([r["outcome"]["speed_reduction"] * 3.6 for r in grid])
                ),
                warning_ttc_worst=None if None in ttcs else float(min(ttcs)),
                warning_ttc_mean=float(np.mean([t for t in ttcs if t is not None]))
                if any(t is not None for t in ttcs)
                else None,
                verification=float(np.mean([value(r) for r in verify])) if verify else None,
                colour=band_colour(case, function, speed, worst),
            )
        )
    return out


def _impact_kmh(row: dict[str, Any]) -> float:
    o = row["outcome"]
    rel = o["relative_impact_speed"]
    return 0.0 if not o["contact"] or rel is None else float(rel) * 3.6


def cells(points: Sequence[PointSummary], policy: str) -> list[Cell]:
    return [
        Cell(p.load_case, p.function, p.speed_kmh, p.impact, p.colour, p.verification)
        for p in points
        if p.policy == policy
    ]


@dataclass(frozen=True)
class NearMissSummary:
    policy: str
    runs: int
    braked: int
    warned: int
    contacts: int


def near_misses(rows: Sequence[dict[str, Any]]) -> list[NearMissSummary]:
    by: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        if row["role"] == NEAR_MISS:
            by[row["policy"]].append(row)
    return [
        NearMissSummary(
            policy,
            len(rs),
            sum(r["outcome"]["brake_time"] is not None for r in rs),
            sum(r["outcome"]["warned_frames"] > 0 for r in rs),
            sum(r["outcome"]["contact"] for r in rs),
        )
        for policy, rs in by.items()
    ]


@dataclass(frozen=True)
class BrakedFor:
    """One policy's braked runs by whom the car braked for (runs that name it only)."""

    policy: str
    braked: int  # braked runs that name whom they braked for
    right: int  # for someone on a collision course then
    bystander: int  # for someone not on a collision course
    nobody: int  # for a phantom track

    @property
    def wrong(self) -> int:
        return self.bystander + self.nobody


def braked_for(rows: Sequence[dict[str, Any]]) -> list[BrakedFor]:
    """Per policy (in the rows' order), the braked runs counted by whom they braked for;
    empty when no row names it (one-tracker runs of one person do not)."""
    by: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for row in rows:
        o = row["outcome"]
        if o["brake_time"] is not None and o.get("braked_for") is not None:
            by[row["policy"]].append(o)
    out = []
    for policy, os_ in by.items():
        nobody = sum(o["braked_for"] == NOBODY for o in os_)
        right = sum(o["braked_for"] != NOBODY and bool(o.get("braked_for_on_course")) for o in os_)
        out.append(BrakedFor(policy, len(os_), right, len(os_) - right - nobody, nobody))
    return out


def braked_for_lines(rows: Sequence[dict[str, Any]]) -> list[str]:
    """The report's section on whom the car braked for (none when no row names it)."""
    counts = braked_for(rows)
    if not counts:
        return []
    lines = [
        "## Whom the car braked for",
        "",
        "At the frame whose warning made the brake act, the warned track matched to the "
        "truth's people by box overlap: braking for the wrong person is braking for someone "
        "not on a collision course then (the footprints would not meet at constant speeds), "
        "or for nobody (a track that is no one).",
        "",
        "| policy | braked | for the person on course | wrong person | of them: someone "
        "else | of them: nobody |",
        "|" + " --- |" * 6,
    ]
    for c in counts:
        lines.append(
            f"| {c.policy} | {c.braked} | {c.right} | {c.wrong} | {c.bystander} | {c.nobody} |"
        )
    return [*lines, ""]


@dataclass(frozen=True)
class MeasuredLatency:
    """The pipeline's per-frame latencies the runs measured (whatever latency they applied)."""

    runs: int
    frames: int
    p50_ms: float
    p95_ms: float


def measured_latency(rows: Sequence[dict[str, Any]]) -> MeasuredLatency | None:
    """p50 and p95 over every processed frame of `rows` (None: no frame measured)."""
    values = [v for r in rows for v in r["outcome"].get("latencies_ms", ())]
    if not values:
        return None
    p50, p95 = np.percentile(values, [50, 95])
    return MeasuredLatency(len(rows), len(values), float(p50), float(p95))


def latency_line(latency: LatencySetting, car: CarSpec, rows: Sequence[dict[str, Any]]) -> str:
    """The latency applied and, beside it, the one the host measured during the runs."""
    if latency.source == DECLARED:
        applied = f"declared {latency.ms:g} ms ({car.path} latency_ms)"
    elif latency.source == MEASURED:
        applied = "the measured one, per frame"
    else:
        applied = f"fixed {latency.ms:g} ms (--latency-ms)"
    if latency.source != DECLARED:
        applied += (
            "; the car file declares none"
            if car.latency_ms is None
            else f"; the car file declares {car.latency_ms:g} ms"
        )
    m = measured_latency(rows)
    measured = "no frame measured"
    if m is not None:
        measured = f"p50 {m.p50_ms:.1f} ms, p95 {m.p95_ms:.1f} ms over {m.frames} frames"
        measured += f" of {m.runs} runs"
    return f"Latency applied: {applied}. Pipeline latency measured during the runs: {measured}."


def plot_matrices(
    protocol: Protocol, points: Sequence[PointSummary], policy: str, tests: list[str], out: Path
) -> None:
    """One picture per policy: each load case's matrix, cells coloured by the prediction;
    one row of matrices per lighting (day, then night)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mine = {(p.test, p.function, p.speed_kmh, p.impact): p for p in points if p.policy == policy}
    lightings = list(dict.fromkeys(protocol.tests[t].lighting for t in tests))
    grid = [[t for t in tests if protocol.tests[t].lighting == light] for light in lightings]
    ncols = max(len(g) for g in grid)
    fig, axes = plt.subplots(
        len(grid), ncols, figsize=(4.2 * ncols, 4.8 * len(grid)), squeeze=False
    )
    for r, row_tests in enumerate(grid):
        for ax in axes[r][len(row_tests) :]:
            ax.set_visible(False)
    placed = [(axes[r][c], key) for r, g in enumerate(grid) for c, key in enumerate(g)]
    for ax, key in placed:
        test = protocol.tests[key]
        rows = [(row.function, v) for row in test.rows for v in row.speeds_kmh]
        cols = list(test.impact_locations)
        for i, (function, v) in enumerate(rows):
            for j, impact in enumerate(cols):
                p = mine.get((key, function, v, impact))
                colour = COLOURS[p.colour] if p is not None else NOT_RUN
                ax.add_patch(plt.Rectangle((j, i), 1, 1, facecolor=colour, edgecolor="white"))
                if p is not None:
                    text = (f"{p.worst:.1f}s\n{p.mean:.1f}" if function == "FCW"
                            else f"{p.worst:.0f}\n{p.mean:.0f}")  # fmt: skip
                    ax.text(j + 0.5, i + 0.5, text, ha="center", va="center", fontsize=8)
        ax.set_xlim(0, len(cols))
        ax.set_ylim(len(rows), 0)
        ax.set_xticks([j + 0.5 for j in range(len(cols))], [percent(c) for c in cols])
        ax.set_yticks(
            [i + 0.5 for i in range(len(rows))],
            [f"{v:g} km/h{' FCW' if f == 'FCW' else ''}" for f, v in rows],
        )
        ax.set_title(f"{test.load_case} ({test.target_speed_kmh:g} km/h target)", fontsize=10)
        ax.set_xlabel("impact location")
    fig.suptitle(
        f"{policy}: prediction colour (worst run)\ncells: worst / mean impact km/h "
        "(FCW: TTC s); grey: not run",
        fontsize=9,
    )
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)


def _f(x: float | None, fmt: str = ".1f") -> str:
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, fmt)


def points_table(points: Sequence[PointSummary], policy: str) -> str:
    lines = [
        "| load case | function | speed | impact | runs | contacts | impact km/h worst / mean "
        "| speed reduction km/h mean | warning TTC s worst / mean | verification | prediction |",
        "|" + " --- |" * 11,
    ]
    for p in points:
        if p.policy != policy:
            continue
        verification = _f(p.verification, ".2f" if p.function == "FCW" else ".1f")
        lines.append(
            f"| {p.load_case} | {p.function} | {p.speed_kmh:g} km/h | {percent(p.impact)} "
            f"| {p.runs} | {p.contacts} | {_f(p.impact_kmh_worst)} / {_f(p.impact_kmh_mean)} "
            f"| {_f(p.reduction_kmh_mean)} | {_f(p.warning_ttc_worst, '.2f')} / "
            f"{_f(p.warning_ttc_mean, '.2f')} | {verification} | {p.colour} |"
        )
    return "\n".join(lines)


@dataclass(frozen=True)
class Beside:
    """Another grid's calculator points (e.g. the same grid under the ideal camera)."""

    folder: Path
    camera: str
    scores: dict[str, CalculatorScore]


def beside_scores(folder: Path) -> Beside:
    """The points another `monopic ncap` output folder's calculator wrote, per policy, and
    the camera its runs had; a folder that holds no scored grid is refused in one line."""
    results = folder / "results.jsonl"
    reports = sorted((folder / "calculator").glob("*/ca_*_report.xlsx"))
    if not results.is_file() or not reports:
        raise UserError(
            f"--beside {folder}: no scored grid there (results.jsonl and "
            "calculator/*/ca_*_report.xlsx, as monopic ncap --out writes them)"
        )
    camera = IDEAL
    with results.open() as f:
        for line in f:
            row = json.loads(line)
            if "outcome" in row:
                camera = str(row.get("camera", IDEAL))
                break
    version = calculator_version() or "?"
    scores = {}
    for report in reports:
        policy = report.parent.name.replace("-", "/", 1)
        scores[policy] = read_report(report, version)
    return Beside(folder, camera, scores)


def camera_line(car: Any, beside: Beside | None) -> str:
    """Which camera the grid saw, and which the other grid beside it saw."""
    name = car.camera_name
    text = (
        "Camera: the ideal camera (the renderer's frames as they are)."
        if name == IDEAL
        else f"Camera: {name} (sim.sensor: exposure and auto-exposure, motion blur over the "
        "exposure, shot and read noise, gain, 12-bit digitiser, tone curve; "
        "scenarios/README.md gives its figures and their sources)."
    )
    if beside is not None:
        text += f" Beside it: the same calculator's points under the {beside.camera} camera."
    return text


def score_table(scores: dict[str, CalculatorScore], claimed: set[str]) -> str:
    """The calculator's points per load case (tests not run: not claimed, "-")."""
    lines = [
        "| policy | CPNA | CPFA | CPNCO | CPLA | pedestrian total | Frontal Collisions, Ped & Cyc "
        "(test score) |",
        "|" + " --- |" * 7,
    ]
    for policy, s in scores.items():
        cells_ = []
        for name in ("CPNA", "CPFA", "CPNCO", "CPLA"):
            lc = s.load_cases.get(name)
            if lc is None or name not in claimed:
                cells_.append("not run")
            else:
                cells_.append(f"{lc.total:.3g} / {lc.max_total:g}")
        lines.append(
            f"| {policy} | {' | '.join(cells_)} | {s.pedestrian_score:.3g} / "
            f"{s.pedestrian_max:g} | {s.ped_cyc_score:.3g} / {s.ped_cyc_max:g} |"
        )
    return "\n".join(lines)


def halves_table(
    halves: dict[str, dict[str, CalculatorScore]],
    claimed: set[str],
    tests: Sequence[str],
    protocol: Any,
) -> str:
    """Day and night points on their own lines: the calculator run once per half with
    the other half's matrices Red (sim.analysis.ncap_score.score_halves)."""
    from sim.analysis.ncap_score import half_maximum

    lines = [
        "| policy | half | CPNA | CPFA | CPNCO | CPLA | pedestrian points |",
        "|" + " --- |" * 7,
    ]
    for policy, by_half in halves.items():
        for half, s in by_half.items():
            run = {protocol.tests[t].load_case.split(" ")[0] for t in tests
                   if protocol.tests[t].load_case.endswith(" " + half)}  # fmt: skip
            cells_ = []
            for name in ("CPNA", "CPFA", "CPNCO", "CPLA"):
                lc = s.load_cases.get(name)
                cells_.append("not run" if lc is None or name not in run else f"{lc.total:.3g}")
            top = half_maximum(half, claimed)
            lines.append(f"| {policy} | {half} | {' | '.join(cells_)} | "
                         f"{s.pedestrian_score:.3g} / {top:g} |")  # fmt: skip
    return "\n".join(lines)


BANDS_M = (0.0, 10.0, 20.0, 30.0, 50.0, float("inf"))  # distance ahead of the car's front


def detection_by_band(
    rows: Sequence[dict[str, Any]], policy: str
) -> dict[str, list[tuple[int, int]]] | None:
    """{half: [(found, in sight) per distance band]} over the grid runs of the points run
    both by day and at night (the same calculator scenario, "CPNA day" and "CPNA night",
    function, speed and impact), from each run's per-frame SightLog; None when no point
    was run in both halves."""
    from sim.analysis.ncap_score import half_of

    runs = [r for r in rows if r["policy"] == policy and r["role"] == GRID
            and r["outcome"].get("target_found")]  # fmt: skip

    def key(r: dict[str, Any]) -> tuple[str, str, float, float]:
        scenario = r["load_case"].split(" ")[0]
        return (scenario, r["function"], r["speed_kmh"], r["impact"])

    halves = {h: {key(r) for r in runs if half_of(r["load_case"]) == h} for h in ("day", "night")}
    both = halves["day"] & halves["night"]
    if not both:
        return None
    out: dict[str, list[tuple[int, int]]] = {}
    for half in ("day", "night"):
        counts = [[0, 0] for _ in BANDS_M[:-1]]
        for r in runs:
            if half_of(r["load_case"]) != half or key(r) not in both:
                continue
            o = r["outcome"]
            for found, ahead in zip(o["target_found"], o["target_range_m"], strict=True):
                if found < 0:
                    continue
                b = int(np.searchsorted(BANDS_M, ahead, side="right")) - 1
                counts[b][0] += found
                counts[b][1] += 1
        out[half] = [(f, n) for f, n in counts]
    return out


def detection_table(rows: Sequence[dict[str, Any]], policies: Sequence[str]) -> str:
    """Detection by distance band, day against night on the same grid points (Markdown;
    empty when no point was run in both halves)."""
    lines = []
    for policy in policies:
        bands = detection_by_band(rows, policy)
        if bands is None:
            continue
        if not lines:
            head = "| policy | distance ahead | day: found / in sight | night: found / in sight |"
            lines = [head, "|" + " --- |" * 4]
        for k, (lo, hi) in enumerate(zip(BANDS_M[:-1], BANDS_M[1:], strict=True)):
            span = f"{lo:g}-{hi:g} m" if np.isfinite(hi) else f">= {lo:g} m"
            cells = []
            for half in ("day", "night"):
                f, n = bands[half][k]
                cells.append(f"{f} / {n} ({f / n:.0%})" if n else "-")
            lines.append(f"| {policy} | {span} | {' | '.join(cells)} |")
    return "\n".join(lines)


def _detection_lines(rows: Sequence[dict[str, Any]], policies: Sequence[str]) -> list[str]:
    table = detection_table(rows, policies)
    if not table:
        return []
    return [
        "## Detection by distance, day against night",
        "",
        "Frames where the target was in sight (at least half of its landmarks in the image "
        "and unoccluded) and the pipeline had a track on it (paired with its box as warnings "
        "are), by its distance ahead of the car's front; only the grid points run both by "
        "day and at night.",
        "",
        table,
        "",
    ]


def _halves_lines(
    halves: dict[str, dict[str, CalculatorScore]] | None,
    claimed: set[str],
    tests: Sequence[str],
    protocol: Any,
) -> list[str]:
    if not halves or not any(halves.values()):
        return []
    return [
        "Day and night on their own lines (the calculator run once per half, the other "
        "half's matrices Red; night cases carry no robustness points):",
        "",
        halves_table(halves, claimed, tests, protocol),
        "",
    ]


def _beside_lines(beside: Beside | None, claimed: set[str]) -> list[str]:
    if beside is None:
        return []
    return [
        f"The same grid under the {beside.camera} camera (`{beside.folder}`):",
        "",
        score_table(beside.scores, claimed),
        "",
    ]


def recall_lead(rows: Sequence[dict[str, Any]], policy: str) -> tuple[int, int, float | None]:
    """(warned, collision runs, median lead s) over the grid runs of a policy."""
    grid = [r for r in rows if r["policy"] == policy and r["role"] == GRID]
    leads = [r["outcome"]["warning_ttc"] for r in grid if r["outcome"]["warning_ttc"] is not None]
    return len(leads), len(grid), float(np.median(leads)) if leads else None


def render(
    *,
    protocol: Protocol,
    car: Any,
    tests: list[str],
    quick: bool,
    speeds: list[float] | None,
    seeds: int,
    rows: Sequence[dict[str, Any]],
    points: Sequence[PointSummary],
    scores: dict[str, CalculatorScore],
    pictures: list[tuple[str, str]],
    command: str,
    machine: str,
    wall_s: float,
    ran_now: int,
    version: str,
    left_unscored: str,
    out: Path,
    latency: LatencySetting,
    beside: Beside | None = None,
    halves: dict[str, dict[str, CalculatorScore]] | None = None,
) -> str:
    """DIR/report.md: the calculator's points first, then how they came about."""
    claimed = {protocol.tests[t].load_case.split(" ")[0] for t in tests}
    grid_runs = sum(r["role"] == GRID for r in rows)
    verify_runs = sum(r["role"] == VERIFY for r in rows)
    nm_runs = sum(r["role"] == NEAR_MISS for r in rows)
    run_wall = sum(r.get("wall_s", 0.0) for r in rows)
    t = protocol.timing
    tol = protocol.tolerances
    lines = [
        "# Euro NCAP 2026 pedestrian tests at car scale",
        "",
        f"Command: `{command}`. Grid: {'the --quick grid' if quick else 'the full grid'} of "
        f"{', '.join(tests)}{'' if speeds is None else f' at {speeds} km/h'}: "
        f"{len(points) // max(1, len(scores))} grid points per policy, {seeds} jittered runs "
        f"each plus {car.verification_seeds} verification run; {grid_runs} grid, "
        f"{verify_runs} verification and {nm_runs} "
        f"near-miss runs. Machine: {machine}. Wall time of this command {wall_s / 60:.1f} min "
        f"({ran_now} runs now, the rest resumed); run time summed over all runs "
        f"{run_wall / 60:.1f} min.",
        "",
        latency_line(latency, car, rows),
        "",
        camera_line(car, beside),
        "",
        f"Scored by the official rating calculator euroncap-rating-2026 {version} "
        "(`crash_avoidance generate-template`, `preprocess`, `compute-score`; files in "
        f"`{out.name}/calculator/`). Protocol: {protocol.protocol}.",
        "",
        "## Points (the calculator's compute-score)",
        "",
        "Per load case: standard + extended + robustness points of the calculator's Scenario "
        "Scores over their maximum (day and night together; a half not run is claimed Red).",
        "",
        score_table(scores, claimed),
        "",
        *_halves_lines(halves, claimed, tests, protocol),
        *_beside_lines(beside, claimed),
        f"Left unscored: {left_unscored}.",
        "",
        *_detection_lines(rows, list(scores)),
    ]
    for policy, name in pictures:
        lines += [f"![{policy} colour matrices]({name})", ""]
    lines += [
        "## Verification tests the calculator chose",
        "",
        "The calculator's preprocess picks the points (its own random choice, seeded); each "
        "gets the value of the point's independent verification run; Colour is the colour "
        "compute-score applied.",
        "",
    ]
    for policy, s in scores.items():
        lines += [f"**{policy}**", "", "| load case | function | speed | impact | prediction "
                  "| value | expected | colour |", "|" + " --- |" * 8]  # fmt: skip
        for v in s.verification:
            lines.append(
                f"| {v.get('Scenario')} | {v.get('Function') or 'AEB'} | {v.get('VUT speed')} "
                f"| {v.get('Impact location')} | {v.get('OEM Prediction')} | {v.get('Value')} "
                f"| {v.get('Expected value')} | {v.get('Colour')} |"
            )
        lines.append("")
    lines += ["## Per grid point", ""]
    for policy in scores:
        warned, n, lead = recall_lead(rows, policy)
        lines += [
            f"**{policy}**: warned in {warned} of {n} grid runs, median warning TTC "
            f"{_f(lead, '.2f')} s.",
            "",
            points_table(points, policy),
            "",
        ]
    lines += [
        "## Unnecessary braking on car-scale near misses",
        "",
        "| policy | runs | braked (unnecessary) | warned | contacts |",
        "|" + " --- |" * 5,
    ]
    for nm in near_misses(rows):
        lines.append(f"| {nm.policy} | {nm.runs} | {nm.braked} | {nm.warned} | {nm.contacts} |")
    lines += ["", *braked_for_lines(rows)]
    lines += [*ncap_triage_lines(rows, Rerunning(out / RESULTS, out, out))]
    lines += [
        "## How the runs were made",
        "",
        f"- Timing: each run starts {t.impact_time:g} s before the nominal impact (T0 = TTC "
        f"{t.steady_state_ttc:g} s of the protocol plus {t.acquisition:g} s for the pipeline to "
        f"acquire), {t.fps:g} frames/s.",
        f"- Tolerances drawn per run: car speed +{tol.vut_speed_kmh[0]:g}..+"
        f"{tol.vut_speed_kmh[1]:g} km/h, car path +-{tol.vut_lateral:g} m, target speed "
        f"+-{tol.target_speed_kmh:g} km/h, target path +-{tol.target_lateral:g} m, impact point "
        f"+-{tol.impact_point:g} m.",
        f"- AEB: brakes on the first warning after the pipeline's latency "
        f"({latency.describe()}) plus {car.brake_delay:g} s, building up at {car.jerk:g} "
        f"m/s^3 to {car.deceleration:g} m/s^2; FCW = that warning. Body pitch "
        f"{car.pitch.gain:g} deg per m/s^2 at {car.pitch.frequency:g} Hz, damping "
        f"{car.pitch.damping:g} (the camera and the truth dip; the pipeline keeps its nominal "
        "camera).",
        "- Prediction per grid point: the calculator's colour band of the worst grid run; "
        "verification value: the verification run. Cells not run: Red (no claim).",
        f"- Sources of every figure: `{protocol.path}` and `{car.path}` (comments).",
        "",
    ]
    return "\n".join(lines)
