"""Frame time with 1, 3, 5 and 10 people in view: everyone's tracker at 1 and 2 threads.

The question: what following everyone costs a frame as the crowd grows, and whether a
landmark budget keeps it within a camera's frame period. One `Pipeline.process` call is
timed per frame (perf_counter around it: pose, features, predictors and warning for
everyone), on frames decoded beforehand, so decoding is not frame time. Settings:

- `one-pedestrian`: `PipelineConfig(people=None)`, the tracker that follows the most
  confident person; on the 1-person frames only: the row the others are read against;
- `everyone`: `PipelineConfig(people=PeopleConfig())`, every person's landmarks every frame;
- `budget 3`: `PipelineConfig(people=PeopleConfig(budget=3))`, at most three landmark-model
  runs a frame, the most urgent people first;

each at 1 and 2 onnxruntime threads (`TrackerConfig.threads`), every other option the
default. The views, by people in view:

- 1: bench/frameset's frames (768x432, one walker each: the shipped clip and rendered
  World clips, 13 sequences);
- 3 and 5: PETS09-S2L1 (768x576, 7 fps): the runs of consecutive frames whose ground
  truth has exactly that many scored people, at least MIN_RUN frames long, longest first
  (on the shared 300 frames, 3: frames 1-16 and 214-223; 5: 154-206 and 22-40);
- 10: PETS09-S2L1 has at most 8 people a frame, so a frame here is two 5-person frames
  side by side (1536x576): the longest 5-person run cut in two, frame f of its first part
  left of frame f + shift of its second (154-180 beside 180-206: the same five people
  3.7 s apart), so each half moves as it really did;
- street: road_walkers_high_angle.mp4 (854x480, 24 fps, 1-6 people, no ground truth),
  STREET_SEGMENTS runs of consecutive frames spread evenly over the clip; its people
  count is what each tracker reported.

Shared data is read where it lies ($MONOPIC_SHARED_DATA, else ../shared/data beside the
checkout), never copied. Trackers need consecutive frames, so sequences are timed in
order: a new Pipeline for each sequence, its first `--warmup` frames untimed (the new
sessions' first runs; 3, the detector's period, keeps the share of detecting frames).
Before the first round every setting warms up on each view's first sequence. Rounds run
the settings of a view back to back, in turn A B C ... then ... C B A, so the host's drift
hits them alike; ratios are of p50s from the same rounds, with their range over rounds.

Figures per view and setting: p50 and p95 frame time; fps, frames over their summed
time (the rate kept up, detecting frames included); landmark-model runs, detector
windows and people reported per frame. The goal: 10 people, budget 3, 2 threads, at least
15 fps. Appends one line to bench/history.jsonl (bench/history.py) unless --no-append.

    .venv/bin/python -m bench.people [--rounds 2] [--warmup 3] [--views 1 3 5 10 street]
        [--street-frames 48] [--no-append]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bench.frameset import build, load
from bench.goals import PEOPLE_FPS_GOAL
from bench.recorder import Recorder
from monopic.evaluation.mot import read_mot
from monopic.frame import Frame
from monopic.image_sequence import ImageSequenceSource
from monopic.people.tracker import PeopleConfig
from monopic.pipeline import Pipeline, PipelineConfig
from monopic.pose.tracker import TrackerConfig
from monopic.video import VideoSource

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("MONOPIC_SHARED_DATA") or ROOT.parent / "shared" / "data")
PETS = SHARED_DATA / "mot-pets09-s2l1"
STREET = SHARED_DATA / "street-clips" / "road_walkers_high_angle.mp4"
TITLE = "Frame time with 1, 3, 5 and 10 people in view (everyone's tracker)"
# A run shorter than this is mostly warm-up: not timed.
MIN_RUN = 10
# Runs of a people count taken at most (the longest).
MAX_RUNS = 2
STREET_SEGMENTS = 3
VIEWS = ("1", "3", "5", "10", "street")
ONE, EVERYONE, BUDGET = "one-pedestrian", "everyone", "budget 3"
GOAL_VIEW, GOAL_TRACKER, GOAL_THREADS = "10", BUDGET, 2
Row = dict[str, Any]  # one row of a results table in the history line


@dataclass(frozen=True)
class FrameRun:
    """Frames FIRST to LAST of a sequence, both included, numbered as its ground truth."""

    first: int
    last: int

    @property
    def frames(self) -> int:
        return self.last - self.first + 1

    def __str__(self) -> str:
        return f"{self.first}-{self.last}"


def runs_with(counts: Mapping[int, int], people: int, min_frames: int = MIN_RUN) -> list[FrameRun]:
    """The runs of consecutive frame numbers whose count is exactly `people`, at least
    `min_frames` long, longest first (the earlier first on a tie). `counts` maps a frame
    number to its people; a number missing from it ends a run."""
    runs: list[FrameRun] = []
    start: int | None = None
    numbers = sorted(counts)
    for k, number in enumerate(numbers):
        hit = counts[number] == people
        if hit and start is None:
            start = number
        follows = k + 1 < len(numbers) and numbers[k + 1] == number + 1
        if start is not None and (not follows or counts[numbers[k + 1]] != people):
            runs.append(FrameRun(start, number))
            start = None
    kept = [r for r in runs if r.frames >= min_frames]
    return sorted(kept, key=lambda r: (-r.frames, r.first))


def half_pairs(run: FrameRun) -> list[tuple[int, int]]:
    """A run cut in two: (f, f + shift) for each frame f of its first part, shift half
    the run, so both members of a pair step on one frame at a time."""
    shift = run.frames // 2
    return [(f, f + shift) for f in range(run.first, run.last - shift + 1)]


def side_by_side(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """Two RGB frames of one height as one frame, `left` on the left."""
    if left.shape[0] != right.shape[0] or left.shape[2:] != right.shape[2:]:
        raise ValueError(f"frames of different heights or channels: {left.shape}, {right.shape}")
    return np.ascontiguousarray(np.concatenate((left, right), axis=1))


def segments(total: int, length: int, count: int) -> list[range]:
    """`count` runs of `length` frame indices spread evenly over 0..total-1, the first at
    the start and the last at the end (fewer when they would overlap)."""
    if length > total:
        return [range(total)]
    count = max(1, min(count, total // length))
    if count == 1:
        return [range(length)]
    starts = [round(k * (total - length) / (count - 1)) for k in range(count)]
    return [range(s, s + length) for s in starts]


def summarise(times_ms: Sequence[float]) -> dict[str, float]:
    """p50, p95 and mean frame time, and fps as frames over their summed time."""
    a = np.asarray(times_ms, dtype=float)
    if a.size == 0:
        nan = float("nan")
        return {"p50_ms": nan, "p95_ms": nan, "mean_ms": nan, "fps": nan}
    mean = float(a.mean())
    return {
        "p50_ms": float(np.percentile(a, 50)),
        "p95_ms": float(np.percentile(a, 95)),
        "mean_ms": mean,
        "fps": 1e3 / mean if mean > 0 else float("nan"),
    }


@dataclass(frozen=True)
class Clip:
    """Consecutive frames a tracker follows from a fresh start."""

    name: str
    frames: list[Frame]


@dataclass(frozen=True)
class View:
    """Frames with one number of people in view, as sequences to time."""

    name: str  # "1", "3", "5", "10", "street"
    what: str  # where the frames come from, for the table
    clips: list[Clip]

    @property
    def size(self) -> tuple[int, int]:
        h, w = self.clips[0].frames[0].image.shape[:2]
        return w, h


@dataclass(frozen=True)
class Setting:
    tracker: str  # ONE, EVERYONE or BUDGET
    threads: int

    def config(self) -> PipelineConfig:
        tracker = TrackerConfig(threads=self.threads)
        if self.tracker == ONE:
            return PipelineConfig(tracker=tracker)
        budget = 3 if self.tracker == BUDGET else None
        return PipelineConfig(tracker=tracker, people=PeopleConfig(budget=budget))

    @property
    def label(self) -> str:
        return f"{self.tracker}, {self.threads} thread{'s' if self.threads > 1 else ''}"


@dataclass
class Timed:
    """Per-frame figures of the timed frames of one setting on one view, by round."""

    ms: list[list[float]] = field(default_factory=list)  # one list per round
    landmark_runs: list[int] = field(default_factory=list)
    detector_runs: list[int] = field(default_factory=list)
    people: list[int] = field(default_factory=list)
    detect_ms: list[float] = field(default_factory=list)
    landmark_ms: list[float] = field(default_factory=list)

    def all_ms(self) -> list[float]:
        return [x for r in self.ms for x in r]


class CountedCalls:
    """Counts the calls of one object's method by shadowing it on the instance: the
    landmark model's runs a frame, which a FrameResult does not carry."""

    def __init__(self, owner: object, name: str) -> None:
        self.calls = 0
        method: Callable[..., Any] = getattr(owner, name)

        def counted(*args: Any, **kwargs: Any) -> Any:
            self.calls += 1
            return method(*args, **kwargs)

        setattr(owner, name, counted)


def time_clip(setting: Setting, clip: Clip, warmup: int, timed: Timed | None) -> None:
    """A fresh Pipeline over the clip; the frames after the first `warmup` into `timed`
    (None: a warm-up pass, nothing kept). The pipeline's construction is not timed."""
    pipeline = Pipeline(setting.config())
    tracker = pipeline.people if pipeline.people is not None else pipeline.tracker
    runs = CountedCalls(tracker.landmarks, "run")
    kept: list[float] = []
    for k, frame in enumerate(clip.frames):
        before = runs.calls
        t0 = time.perf_counter()
        result = pipeline.process(frame)
        ms = (time.perf_counter() - t0) * 1e3
        if timed is None or k < warmup:
            continue
        kept.append(ms)
        timed.landmark_runs.append(runs.calls - before)
        timed.detector_runs.append(result.pose.detector_runs)
        timed.people.append(len(result.people))
        timed.detect_ms.append(result.pose.detect_ms)
        timed.landmark_ms.append(result.pose.landmark_ms)
    if timed is not None:
        timed.ms[-1].extend(kept)
    del pipeline, tracker, runs
    gc.collect()  # the sessions' memory goes now, not in the next clip's timed frames


def pets_frames(numbers: Iterable[int], sequence: Path = PETS) -> dict[int, Frame]:
    """The sequence's frames with these numbers (as its ground truth counts them)."""
    wanted = set(numbers)
    source = ImageSequenceSource.from_folder(sequence, None)
    out: dict[int, Frame] = {}
    for frame in source:
        number = frame.index + source.first_number
        if number in wanted:
            out[number] = frame
        if len(out) == len(wanted):
            break
    return out


def pets_views(names: Sequence[str], sequence: Path = PETS) -> list[View]:
    """The 3-, 5- and 10-person views asked for, from PETS09-S2L1's ground-truth counts."""
    truth = read_mot(sequence / "gt" / "gt.txt", scored_only=True)
    info = ImageSequenceSource.from_folder(sequence, None)
    numbers = range(info.first_number, info.first_number + info.frame_count)
    counts = {n: len(truth.get(n, [])) for n in numbers}
    plan: dict[str, list[FrameRun]] = {}
    for name in ("3", "5"):
        if name in names or (name == "5" and "10" in names):
            plan[name] = runs_with(counts, int(name))[:MAX_RUNS]
            if not plan[name]:
                raise SystemExit(f"{sequence}: no run of {MIN_RUN}+ frames with {name} people")
    pairs = half_pairs(plan["5"][0]) if "10" in names else []
    needed = {f for runs in plan.values() for r in runs for f in range(r.first, r.last + 1)}
    frames = pets_frames(needed, sequence)
    views = []
    for name in ("3", "5"):
        if name not in names:
            continue
        clips = [
            Clip(f"PETS09-S2L1 {r}", [frames[f] for f in range(r.first, r.last + 1)])
            for r in plan[name]
        ]
        runs = ", ".join(f"{r} ({r.frames})" for r in plan[name])
        views.append(View(name, f"PETS09-S2L1 frames {runs}", clips))
    if pairs:
        composed = [
            Frame(side_by_side(frames[a].image, frames[b].image), frames[a].timestamp, None, k)
            for k, (a, b) in enumerate(pairs)
        ]
        (a0, b0), (a1, b1) = pairs[0], pairs[-1]
        name = f"PETS09-S2L1 {a0}-{a1} beside {b0}-{b1}"
        views.append(
            View("10", f"{name} ({len(pairs)}; two 5-person frames side by side)",
                 [Clip(name, composed)])
        )  # fmt: skip
    return views


def street_view(length: int, path: Path = STREET) -> View:
    """STREET_SEGMENTS runs of `length` consecutive frames spread over the street clip."""
    source = VideoSource(str(path))
    total = source.frame_count or 0
    chosen = segments(total, length, STREET_SEGMENTS)
    last = max(r.stop for r in chosen)
    frames: list[Frame] = []
    for frame in source:
        if frame.index >= last:
            break
        frames.append(frame)
    clips = [Clip(f"{path.name} {r.start}-{r.stop - 1}", frames[r.start : r.stop]) for r in chosen]
    spans = ", ".join(f"{r.start}-{r.stop - 1}" for r in chosen)
    return View("street", f"{path.name} frames {spans} (counted from 0)", clips)


def one_person_view() -> View:
    """bench/frameset's frames, one clip per sequence."""
    fs = load(*build())
    clips = []
    for k, name in enumerate(fs.sequences):
        idx = np.flatnonzero(fs.sequence == k)
        frames = [Frame(np.array(fs.images[i]), float(fs.timestamp[i]), None, int(i)) for i in idx]
        clips.append(Clip(name, frames))
    return View("1", f"bench/frameset ({len(fs)} frames, {len(clips)} sequences)", clips)


def settings_of(view: str, threads: Sequence[int]) -> list[Setting]:
    """Everyone's tracker with and without the budget, at each thread count; on one
    person, the one-pedestrian tracker too."""
    trackers = (ONE, EVERYONE, BUDGET) if view == "1" else (EVERYONE, BUDGET)
    return [Setting(tr, t) for t in threads for tr in trackers]


def ratio_cell(a: Timed, b: Timed) -> tuple[float, float, float]:
    """p50(a) / p50(b) over all rounds, and the lowest and highest per-round ratio."""
    whole = float(np.median(a.all_ms()) / np.median(b.all_ms()))
    per = [np.median(x) / np.median(y) for x, y in zip(a.ms, b.ms, strict=True) if x and y]
    return whole, float(min(per)), float(max(per))


def fmt_ratio(cell: tuple[float, float, float]) -> str:
    return f"{cell[0]:.2f} ({cell[1]:.2f}-{cell[2]:.2f})"


Cells = dict[tuple[str, Setting], Timed]


def frame_rows(views: list[View], plan: dict[str, list[Setting]], timed: Cells) -> list[Row]:
    """One row of figures per view and setting, by thread count, the reference row first."""
    rows = []
    for view in views:
        for setting in sorted(plan[view.name], key=lambda s: (s.threads, s.tracker != ONE)):
            cell = timed[(view.name, setting)]
            rows.append(
                {
                    "view": view.name,
                    "tracker": setting.tracker,
                    "budget": 3 if setting.tracker == BUDGET else None,
                    "threads": setting.threads,
                    "frames": len(cell.all_ms()),
                    **summarise(cell.all_ms()),
                    "round_p50_ms": [float(np.median(r)) for r in cell.ms if r],
                    "landmark_runs_per_frame": float(np.mean(cell.landmark_runs)),
                    "detector_runs_per_frame": float(np.mean(cell.detector_runs)),
                    "people_per_frame": float(np.mean(cell.people)),
                    "detect_ms_per_frame": float(np.mean(cell.detect_ms)),
                    "landmarks_ms_per_frame": float(np.mean(cell.landmark_ms)),
                }
            )
    return rows


def frame_table(rows: list[Row]) -> list[str]:
    lines = [
        "| people in view | tracker | threads | frames | p50 | p95 | fps | landmark runs "
        "/ frame | detector windows / frame | people reported / frame |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in rows:
        lines.append(
            f"| {r['view']} | {r['tracker']} | {r['threads']} | {r['frames']} "
            f"| {r['p50_ms']:.1f} ms | {r['p95_ms']:.1f} ms | {r['fps']:.1f} "
            f"| {r['landmark_runs_per_frame']:.2f} | {r['detector_runs_per_frame']:.2f} "
            f"| {r['people_per_frame']:.2f} |"
        )
    return lines


def ratio_row(view: str, label: str, threads: int | None, c: tuple[float, float, float]) -> Row:
    return {"view": view, "ratio": label, "threads": threads, "p50_ratio_x": c[0],
            "round_low_x": c[1], "round_high_x": c[2]}  # fmt: skip


def ratio_rows(views: list[View], threads: list[int], timed: Cells) -> tuple[list[Row], list[str]]:
    """p50 ratios from the same rounds: the budget against everyone; on one person, each
    of everyone's settings against the one-pedestrian tracker; the last thread count
    against the first. Rows for the history and the table's lines."""
    rows: list[Row] = []
    lines = [
        "| people in view | ratio of p50s (range over rounds) | "
        + " | ".join(f"{t} thread{'s' if t > 1 else ''}" for t in threads)
        + " |",
        "| --- | --- |" + " ---: |" * len(threads),
    ]
    for view in views:
        trackers = (ONE, EVERYONE, BUDGET) if view.name == "1" else (EVERYONE, BUDGET)
        pairs = [(EVERYONE, ONE), (BUDGET, ONE)] if view.name == "1" else []
        pairs.append((BUDGET, EVERYONE))
        for a, b in pairs:
            cells = []
            for t in threads:
                c = ratio_cell(timed[(view.name, Setting(a, t))], timed[(view.name, Setting(b, t))])
                rows.append(ratio_row(view.name, f"{a} / {b}", t, c))
                cells.append(fmt_ratio(c))
            lines.append(f"| {view.name} | {a} / {b} | {' | '.join(cells)} |")
        if len(threads) < 2:
            continue
        first, last = threads[0], threads[-1]
        for tr in trackers:
            c = ratio_cell(
                timed[(view.name, Setting(tr, last))], timed[(view.name, Setting(tr, first))]
            )
            label = f"{tr}: {last} threads / {first}"
            rows.append(ratio_row(view.name, label, None, c))
            lines.append(f"| {view.name} | {label} | {fmt_ratio(c)} |" + " |" * (len(threads) - 1))
    return rows, lines


def goal_of(rows: list[Row]) -> tuple[Row | None, str]:
    """The goal's standing (10 people, budget 3, 2 threads, fps) and its line."""
    text = f"Goal (10 people, budget 3, 2 threads, >= {PEOPLE_FPS_GOAL:g} fps)"
    for row in rows:
        if (row["view"], row["tracker"], row["threads"]) != (GOAL_VIEW, GOAL_TRACKER, GOAL_THREADS):
            continue
        met = bool(row["fps"] >= PEOPLE_FPS_GOAL)
        goal = {"view": GOAL_VIEW, "tracker": GOAL_TRACKER, "threads": GOAL_THREADS,
                "fps": row["fps"], "goal_fps": PEOPLE_FPS_GOAL, "met": met}  # fmt: skip
        return goal, (
            f"{text}: {row['fps']:.1f} fps (p50 {row['p50_ms']:.1f} ms, p95 "
            f"{row['p95_ms']:.1f} ms): {'met' if met else 'missed'}."
        )
    return None, f"{text}: not measured in this run."


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--warmup", type=int, default=3, help="untimed frames per sequence")
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--views", nargs="+", choices=VIEWS, default=list(VIEWS))
    ap.add_argument("--street-frames", type=int, default=48, help="frames per street segment")
    ap.add_argument("--no-append", action="store_true", help="do not write the history")
    args = ap.parse_args()
    recorder = Recorder("people", TITLE)
    start = time.perf_counter()
    views: list[View] = []
    if "1" in args.views:
        views.append(one_person_view())
    views += pets_views(args.views)
    if "street" in args.views:
        views.append(street_view(args.street_frames))
    views.sort(key=lambda v: VIEWS.index(v.name))
    plan = {v.name: settings_of(v.name, args.threads) for v in views}
    for view in views:  # warm-up: every setting once on each view's first clip
        for setting in plan[view.name]:
            time_clip(setting, view.clips[0], args.warmup, None)
    timed: Cells = {(v.name, s): Timed() for v in views for s in plan[v.name]}
    loads = []
    for rnd in range(args.rounds):
        for view in views:
            order = plan[view.name] if rnd % 2 == 0 else plan[view.name][::-1]
            for setting in order:
                loads.append(os.getloadavg()[0])
                cell = timed[(view.name, setting)]
                cell.ms.append([])
                for clip in view.clips:
                    time_clip(setting, clip, args.warmup, cell)
        print(f"round {rnd + 1} of {args.rounds} done", file=sys.stderr)
    loads.append(os.getloadavg()[0])

    rows = frame_rows(views, plan, timed)
    ratios, ratio_lines = ratio_rows(views, args.threads, timed)
    goal, goal_line = goal_of(rows)
    head = [
        f"Frame time of `Pipeline.process`, {args.rounds} rounds alternated (A B ..., then "
        f"... B A), a new Pipeline per sequence with its first {args.warmup} frames untimed; "
        f"load average during the runs {min(loads):.1f}-{max(loads):.1f} on "
        f"{os.cpu_count()} cores; {time.perf_counter() - start:.0f} s in all. Views:",
        "",
        *(f"- {v.name}: {v.what}, {v.size[0]}x{v.size[1]}" for v in views),
        "",
        "fps = frames over their summed time (detecting frames included). Trackers: "
        f"`{ONE}` people=None; `{EVERYONE}` PeopleConfig(); `{BUDGET}` "
        "PeopleConfig(budget=3); all else the defaults.",
        "",
    ]
    lines = [*head, *frame_table(rows), "", "Ratios (< 1: faster):", "", *ratio_lines]
    table = "\n".join([*lines, "", goal_line])
    print(table)
    results = {
        "rounds": args.rounds,
        "warmup_frames": args.warmup,
        "threads": args.threads,
        "views": [
            {
                "view": v.name,
                "source": v.what,
                "width_px": v.size[0],
                "height_px": v.size[1],
                "clips": [c.name for c in v.clips],
                "frames": sum(len(c.frames) for c in v.clips),
            }
            for v in views
        ],  # fmt: skip
        "load_min": min(loads),
        "load_max": max(loads),
        "rows": rows,
        "ratios": ratios,
        "goal": goal,
    }
    recorder.finish(results, table, write=not args.no_append)


if __name__ == "__main__":
    main()
