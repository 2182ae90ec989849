"""How much warning a stop gives: real pedestrians' stops beside the simulated walker's.

A collision warning can tell a walker about to stop from one who keeps going only once
the slowing shows in its motion reading; given the simulator's stop timing, that reading
must lag the truth by less than about 0.2 s. Whether real stops give more warning (the
slowing begins earlier, longer before standstill) is a question about real walkers. This
finds stop events, a walker at a steady pace who comes to a standstill and stays there,
with one detector (`Settings`) in real ETH/UCY tracks (read in place with sim.analysis.
realism's reader) and in the project's own `human` walkers of the kerb-stop family
(sim.scenario.path.pedestrian_path, the runs of a dataset spec drawn as `monopic dataset`
draws them, sampled at the real data's 0.4 s steps), and measures on one time axis
aligned at standstill (t = 0 where the speed first falls under `Settings.standstill`):
the speed relative to the walker's cruise speed, and how long before standstill it last
fell below 90 % and 70 % of that cruise (the slowing's onset).

    .venv/bin/python -m studies.intent.stop_timing [--real FILE...] [--walkers 40]
        [--out docs/intent/stop-timing.md] [--plot docs/images/stop-timing.png]

Speeds are position differences over one step, placed at the step's middle; crossings of
a threshold are interpolated linearly between those samples, in real and simulated
tracks alike.
"""

from __future__ import annotations

import argparse
import datetime
import math
import os
import shlex
import sys
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from monopic.errors import UserError
from monopic.output import atomic_path, write_text_atomically
from sim.analysis.realism import STEP, read_tracks
from sim.analysis.tracks import run_track
from sim.runs.sweep import expand_spec, load_spec

ROOT = Path(__file__).resolve().parents[2]
# Real data is read where it is kept, never copied: $MONOPIC_SHARED_DATA, else
# ../shared/data beside the checkout (as tests/paths.py).
SHARED_DATA = Path(os.environ.get("MONOPIC_SHARED_DATA") or ROOT.parent / "shared" / "data")
REAL_DATA = SHARED_DATA / "eth-ucy-calibration"
REAL_FILES = (REAL_DATA / "biwi_hotel.txt", REAL_DATA / "crowds_zara01.txt")
FAMILY_FILE = "nearmiss_kerb_stop.toml"
RUN_UP = ROOT / "scenarios" / "datasets" / "intent-runup-probe-7m.toml"
TRAINED = ROOT / "scenarios" / "datasets" / "intent-train.toml"
# (label, dataset spec, step): the kerb-stop walkers with the run-up probe's 7 m run-up
# (they reach their pace before the kerb), the same at the camera's 15 fps (what 2.5 Hz
# sampling costs), and as the tree is trained on them (a 3 m walk from standing); all at
# intent-train's ranges of walking speed (1.1-1.5 m/s) and stop_lead (0.4-0.8 s).
SIMULATED = (
    ("sim, 7 m run-up", RUN_UP, STEP),
    ("sim, 7 m run-up, 15 fps", RUN_UP, 1 / 15),
    ("sim, as trained", TRAINED, STEP),
)
AFTER_RUN = 2.0  # s sampled past a run's end, so a stop near its end is seen standing


@dataclass(frozen=True)
class Settings:
    """The stop detector's thresholds: one place, the same for real and simulated tracks.

    - `moving` 0.6 m/s: the slowest pace that is still walking somewhere (the ETH/UCY
      scenes' median speeds are 1.15-1.28 m/s, strolls 0.6-0.8 m/s); below it a "cruise"
      is dawdling and no scale to measure slowing against.
    - `cruise_s` 1.2 s: three 0.4 s steps, about two steps of the feet: a steady pace, and
      a median of three samples that one bad annotation cannot move.
    - `standstill` 0.15 m/s: 6 cm per 0.4 s step, above the jitter of a standing person's
      annotation (zara01's interpolated stands drift 0.03-0.11 m/s) and far below walking.
    - `dwell_s` 0.8 s: two 0.4 s steps below `standstill`: a stop, not one jittered step.
    - `lookback_s` 6 s: how far before standstill the slowing may begin (the simulated
      walker takes about stop_lead + stop_time, at most 2 s; a walker slowing at an easy
      0.3 m/s2 from 1.5 m/s takes 5 s).
    - `drop` 0.2: the cruise window is sought going back from standstill while the speed
      rises (the slowing seen backwards) or dips no more than this share below its
      highest so far (stride and annotation jitter); a deeper dip is earlier, slower
      walking and ends the search. Of the windows ending in the stretch searched, the one
      of the highest median is the cruise, so a gentle slowing is not taken for a slower
      cruise.
    - `levels` 90 % and 70 % of cruise: the slowing's first sign, and a clear one.
    """

    moving: float = 0.6  # m/s
    cruise_s: float = 1.2  # s
    standstill: float = 0.15  # m/s
    dwell_s: float = 0.8  # s
    lookback_s: float = 6.0  # s
    drop: float = 0.2
    levels: tuple[float, ...] = (0.9, 0.7)


@dataclass(frozen=True, eq=False)
class StopEvent:
    """One stop: where in its track, the cruise it slowed from, its onsets and profile."""

    track: int  # index of the track in its set
    t0: float  # s, standstill in the track's own clock (its first position at 0)
    cruise: float  # m/s, median speed of the cruise_s window before slowing began
    onsets: tuple[float, ...]  # s before standstill the speed last fell below each level
    times: np.ndarray  # s from standstill, of each speed sample from the cruise window on
    ratio: np.ndarray  # speed / cruise at those times


@dataclass(frozen=True, eq=False)
class TrackGroup:
    """Tracks to look for stops in: a real scene, or one set of simulated walkers."""

    name: str
    kind: str  # "real" or "simulated"
    step: float  # s between positions
    tracks: tuple[np.ndarray, ...]
    notes: str = ""  # where the tracks come from (simulated)


@dataclass(frozen=True)
class StopSet:
    """The stop events of one group (or of several pooled)."""

    name: str
    kind: str
    step: float
    tracks: int
    events: tuple[StopEvent, ...]
    notes: str = ""
    pooled: bool = False  # the events of other sets, together


def speeds(track: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, speeds): each step's distance / step, at the step's middle (s from the
    track's first position)."""
    v = np.hypot(*np.diff(track, axis=0).T) / step
    return (np.arange(len(v)) + 0.5) * step, v


def _crossing(t: np.ndarray, v: np.ndarray, i: int, level: float) -> float:
    """When the speed falls through `level` between samples i (>= level) and i + 1."""
    return float(t[i] + (v[i] - level) / (v[i] - v[i + 1]) * (t[i + 1] - t[i]))


def find_stops(
    track: np.ndarray, step: float, settings: Settings = Settings(), index: int = 0
) -> list[StopEvent]:
    """Every stop event of one gap-free track of positions `step` seconds apart."""
    if len(track) < 3:
        return []
    t, v = speeds(track, step)
    still = v < settings.standstill
    window = max(1, round(settings.cruise_s / step))
    dwell = max(1, math.ceil(settings.dwell_s / step - 1e-9))
    lookback = max(1, round(settings.lookback_s / step))
    events = []
    j = 1
    while j < len(v):
        if not (still[j] and not still[j - 1]):
            j += 1
            continue
        run = int(np.argmin(still[j:])) if not still[j:].all() else len(v) - j
        if run >= dwell:
            event = _event(t, v, j, window, dwell, lookback, settings, index)
            if event is not None:
                events.append(event)
        j += run
    return events


def _event(
    t: np.ndarray,
    v: np.ndarray,
    j: int,
    window: int,
    dwell: int,
    lookback: int,
    settings: Settings,
    index: int,
) -> StopEvent | None:
    """The stop whose standstill begins at sample j, if a steady cruise came before it.

    Going back from j while the speed rises (or falls no more than `drop` below its
    highest so far), for at most `lookback` samples; of the cruise windows (`window`
    samples, every one at least `moving`) ending there, the one of the highest median
    (the latest of equal ones) is the cruise."""
    earliest, top = j - 1, v[j - 1]
    for i in range(j - 1, max(j - 1 - lookback, -1), -1):
        if v[i] < settings.standstill or v[i] < (1 - settings.drop) * top:
            break
        earliest, top = i, max(top, v[i])
    cruise, first = -math.inf, -1
    for end in range(j - 1, earliest - 1, -1):
        start = end - window + 1
        if start < 0:
            break
        if np.all(v[start : end + 1] >= settings.moving):
            median = float(np.median(v[start : end + 1]))
            if median > cruise:
                cruise, first = median, start
    if first < 0:
        return None
    t0 = _crossing(t, v, j - 1, settings.standstill)
    onsets = []
    for level in settings.levels:  # half the window is at least the cruise: found
        above = np.flatnonzero(v[first:j] >= level * cruise)
        onsets.append(t0 - _crossing(t, v, first + int(above[-1]), level * cruise))
    end = min(j + dwell, len(v))
    return StopEvent(index, t0, cruise, tuple(onsets), t[first:end] - t0, v[first:end] / cruise)


def stop_set(group: TrackGroup, settings: Settings) -> StopSet:
    """The detector run over every track of the group."""
    events = [e for i, p in enumerate(group.tracks) for e in find_stops(p, group.step, settings, i)]
    return StopSet(group.name, group.kind, group.step, len(group.tracks), tuple(events),
                   group.notes)  # fmt: skip


def pooled(name: str, sets: Sequence[StopSet]) -> StopSet:
    """Several sets' events as one (same kind and step)."""
    events = tuple(e for st in sets for e in st.events)
    tracks = sum(st.tracks for st in sets)
    return StopSet(name, sets[0].kind, sets[0].step, tracks, events, pooled=True)


# -- the tracks ------------------------------------------------------------------------


def real_group(path: Path) -> TrackGroup:
    """A real scene's gap-free tracks (sim.analysis.realism's reader), checked."""
    if not path.is_file():
        raise UserError(f"{path}: no such track file")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an empty file: numpy's warning, then ours
        tracks = read_tracks(path).tracks
    if not tracks:
        raise UserError(f"{path}: no tracks (rows of `frame person x y`)")
    for p in tracks:
        bad = p[~np.isfinite(p)]
        if len(bad):
            raise UserError(f"{path}: a position is {bad[0]}, not a finite number")
    return TrackGroup(path.stem, "real", STEP, tracks)


def simulated_group(name: str, spec: Path, walkers: int, step: float) -> TrackGroup:
    """The first `walkers` kerb-stop runs of a dataset spec, drawn as `monopic dataset`
    draws them (more runs than the spec's extend its own draws), each walked by its
    behaviour with the run's seed and sampled every `step` s from t = 0 to AFTER_RUN past
    the run's end (sim.analysis.tracks.run_track)."""
    base = load_spec(spec)
    includes = []
    for inc in base.includes:
        files = tuple(f for f in inc.files if f.name == FAMILY_FILE)
        if files:
            includes.append(replace(inc, files=files, runs=walkers))
    if not includes:
        raise UserError(f"{spec}: no [[include]] draws {FAMILY_FILE}")
    tracks, plan = [], []
    for run in expand_spec(replace(base, includes=tuple(includes)))[:walkers]:
        tracks.append(run_track(run, step, AFTER_RUN).positions)
        plan.append(run.scenario.pedestrian.speed)
    shown = spec.relative_to(ROOT) if spec.is_relative_to(ROOT) else spec
    notes = (
        f"`{shown}`, the kerb-stop family's first {len(tracks)} runs (walking "
        f"{min(plan):.2f}-{max(plan):.2f} m/s)"
    )
    return TrackGroup(name, "simulated", step, tuple(tracks), notes)


# -- the report ------------------------------------------------------------------------


def quantiles(values: Sequence[float]) -> str:
    """p10 / p50 / p90, or a dash for no values."""
    if not len(values):
        return "-"
    return " / ".join(f"{np.percentile(values, q):.2f}" for q in (10, 50, 90))


def table(sets: Sequence[StopSet], settings: Settings) -> list[str]:
    """One row per set: events, cruise, p10 / p50 / p90 of each onset."""
    head = [
        "set",
        "sampled every (s)",
        "tracks",
        "stop events",
        "cruise p50 (m/s)",
        *(f"{100 * level:.0f} % onset p10 / p50 / p90 (s)" for level in settings.levels),
    ]
    lines = ["| " + " | ".join(head) + " |", "| --- |" + " ---: |" * 4 + " --- |" * len(
        settings.levels)]  # fmt: skip
    for st in sets:
        cruise = f"{np.median([e.cruise for e in st.events]):.2f}" if st.events else "-"
        cells = [f"{st.name} ({st.kind})", f"{st.step:.2g}", str(st.tracks), str(len(st.events))]
        cells += [cruise]
        cells += [quantiles([e.onsets[k] for e in st.events]) for k in range(len(settings.levels))]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def report_text(
    sets: Sequence[StopSet],
    settings: Settings,
    command: str,
    plot: str,
    loose: tuple[Settings, Sequence[StopSet]] | None = None,
) -> str:
    """The Markdown report: the detector, the table of every set, the simulated sets'
    sources, the looser detector's table, each real event."""
    s = settings
    lines = [
        "# Stop timing: real pedestrians beside the simulated walker",
        "",
        f"`{command}` ({datetime.date.today().isoformat()})",
        "",
        f"A stop event (studies/intent/stop_timing.py, `Settings`): at least {s.moving:g} m/s for "
        f"{s.cruise_s:g} s (the cruise window; its median is the cruise speed), then under "
        f"{s.standstill:g} m/s for at least {s.dwell_s:g} s. The cruise window is the one "
        f"of the highest median within the {s.lookback_s:g} s before standstill (going "
        f"back until the speed drops {100 * s.drop:.0f} % below its highest). Onset: how "
        "long before standstill (t = 0, the speed's first crossing under the standstill "
        "threshold) the speed last fell below that share of cruise; speeds are each step's "
        "distance / step, crossings interpolated between them. Real scenes are read in "
        "place from the ETH/UCY files (0.4 s steps); simulated walkers are the kerb-stop "
        "family's `human` walkers with their run seeds, sampled the same way.",
        "",
        *table(sets, s),
    ]
    sims = [st for st in sets if st.kind == "simulated"]
    if sims:
        lines += ["", "Simulated sets:", ""]
        lines += [f"- {st.name}: {st.notes}; {len(st.events)} stop events." for st in sims]
    if loose is not None:
        other, loose_sets = loose
        lines += [
            "",
            f"The same with a looser detector (at least {other.moving:g} m/s, standstill "
            f"under {other.standstill:g} m/s for {other.dwell_s:g} s): how much the few real "
            "events depend on the thresholds.",
            "",
            *table(loose_sets, other),
        ]
    real = [(st, e) for st in sets if st.kind == "real" and not st.pooled for e in st.events]
    if real:
        lines += [
            "",
            "Every real event (track: its index among the scene's gap-free tracks):",
            "",
            "| scene | track | standstill at (s into track) | cruise (m/s) | "
            + " | ".join(f"{100 * level:.0f} % onset (s)" for level in s.levels)
            + " |",
            "| --- | ---: | ---: | ---: |" + " ---: |" * len(s.levels),
        ]
        for st, e in real:
            onsets = " | ".join(f"{x:.2f}" for x in e.onsets)
            lines.append(f"| {st.name} | {e.track} | {e.t0:.1f} | {e.cruise:.2f} | {onsets} |")
    lines += ["", f"![speed over cruise before standstill]({plot})", ""]
    return "\n".join(lines)


GRID = np.arange(-5.0, 1.0 + 1e-9, 0.1)  # s from standstill, where profiles are compared


def profile_band(events: Sequence[StopEvent]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """p10, median, p90 of speed / cruise over GRID (NaN where fewer than two events)."""
    rows = np.array([np.interp(GRID, e.times, e.ratio, left=np.nan, right=np.nan)
                     for e in events]).reshape(len(events), len(GRID))  # fmt: skip
    enough = np.sum(np.isfinite(rows), axis=0) >= 2
    out = []
    for q in (10, 50, 90):
        band = np.full(len(GRID), np.nan)
        if enough.any():
            band[enough] = np.nanpercentile(rows[:, enough], q, axis=0)
        out.append(band)
    return out[0], out[1], out[2]


def plot_stops(sets: Sequence[StopSet], settings: Settings, path: Path) -> None:
    """Speed / cruise against time to standstill (median, p10-p90 band) per set, and each
    event's onsets."""
    fig = Figure(figsize=(12, 4.8), layout="constrained")
    ax, right = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    drawn = [st for st in sets if st.events]
    for k, st in enumerate(drawn):
        colour = f"C{k}"
        low, mid, high = profile_band(st.events)
        style = "-" if st.kind == "real" else "--"
        ax.plot(GRID, mid, style, color=colour, lw=1.8, label=f"{st.name} ({len(st.events)})")
        ax.fill_between(GRID, low, high, color=colour, alpha=0.15, lw=0)
        for m, marker in zip(range(len(settings.levels)), ("o", "x", "s", "^"), strict=False):
            x = [e.onsets[m] for e in st.events]
            right.plot(x, k + 0.12 * (m - 0.5) + np.zeros(len(x)), marker, color=colour,
                       alpha=0.7, ms=6)  # fmt: skip
    for level in settings.levels:
        ax.axhline(level, color="grey", lw=0.8, ls=":")
    ax.axvline(0.0, color="black", lw=0.8)
    ax.set_xlabel("time from standstill (s)")
    ax.set_ylabel("speed / cruise speed")
    ax.set_xlim(GRID[0], GRID[-1])
    ax.set_ylim(0, 1.5)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower left", title="events", title_fontsize=8)
    ax.set_title("median and p10-p90 band (solid: real, dashed: simulated)", fontsize=9)
    levels = " and ".join(
        f"{100 * x:.0f} % ({m})"
        for x, m in zip(settings.levels, ("o", "x", "s", "^"), strict=False)
    )
    right.set_title(f"onsets: last fall below {levels} of cruise", fontsize=9)
    right.set_yticks(range(len(drawn)), [st.name for st in drawn], fontsize=8)
    right.set_xlabel("seconds before standstill")
    right.set_xlim(left=0)
    right.grid(alpha=0.3)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=100, format="png")


def summary(sets: Sequence[StopSet], settings: Settings) -> list[str]:
    out = []
    for st in sets:
        parts = [
            f"{100 * level:.0f} % onset p10/p50/p90 {quantiles([e.onsets[k] for e in st.events])} s"
            for k, level in enumerate(settings.levels)
        ]
        out.append(f"{st.name}: {len(st.events)} stops in {st.tracks} tracks; " + "; ".join(parts))
    return out


LOOSE = Settings(moving=0.5, standstill=0.2, dwell_s=0.4)  # a check on the thresholds


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real", nargs="+", type=Path, default=list(REAL_FILES), metavar="FILE",
                    help="ETH/UCY track files (`frame person x y`, 0.4 s steps)")  # fmt: skip
    ap.add_argument("--walkers", type=int, default=40, help="simulated walkers per set")
    ap.add_argument("--out", type=Path, default=Path("docs/intent/stop-timing.md"))
    ap.add_argument("--plot", type=Path, default=Path("docs/images/stop-timing.png"))
    args = ap.parse_args(argv)
    try:
        if args.walkers < 1:
            raise UserError(f"--walkers {args.walkers}: must be at least 1")
        real = [real_group(path) for path in args.real]
        simulated = [
            simulated_group(name, spec, args.walkers, step) for name, spec, step in SIMULATED
        ]
    except UserError as err:
        print(err, file=sys.stderr)
        return 1
    results = {}
    for settings in (Settings(), LOOSE):
        scenes = [stop_set(g, settings) for g in real]
        both = [pooled("both real scenes", scenes)] if len(scenes) > 1 else []
        results[settings] = (scenes, [*scenes, *both, *(stop_set(g, settings) for g in simulated)])
    settings = Settings()
    scenes, sets = results[settings]
    command = shlex.join(
        [".venv/bin/python", "-m", "studies.intent.stop_timing", *(argv or sys.argv[1:])]
    )
    for path in (args.plot, args.out):
        path.parent.mkdir(parents=True, exist_ok=True)
    link = os.path.relpath(args.plot.resolve(), args.out.resolve().parent)
    text = report_text(sets, settings, command, link, (LOOSE, results[LOOSE][1]))
    plot_stops([*scenes, *(st for st in sets if st.kind == "simulated")], settings, args.plot)
    write_text_atomically(args.out, text)
    print("\n".join(summary(sets, settings)))
    print(f"wrote {args.out} and {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
