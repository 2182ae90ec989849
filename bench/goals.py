"""The goals BENCHMARKS.md opens with, each read from the latest run of one benchmark.

The goals: the whole pipeline at most half the reference's per-frame time at the
same thread count (1 and 2), landmark error equal or better (judged by the paired 95 %
interval of bench/paired.py), and a scenario run on one core at least as fast as real
time at 15 fps (with the rail target and with a human walker); and at most half the
reference's process CPU-seconds per frame, at 1 and at 2 threads, on the same frames and
host (the energy a robot spends on the pipeline); and, following everyone in view, 10
people with a landmark budget of 3 at 2 threads at least PEOPLE_FPS_GOAL frames a second
(bench/people.py: a camera's rate kept up with in a crowd). A goal reads the structured results
of bench/history.jsonl, never the Markdown, so the goal table cannot drift from the
figures below it. A later goal is one more entry in GOALS.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

RATIO_GOAL = 0.5  # ours / reference, whole-frame p50 on frames both sides found
REALTIME_FPS = 15.0  # the camera's frame rate a scenario run must keep up with on one core
PEOPLE_FPS_GOAL = 15.0  # frames a second with 10 people in view, budget 3, 2 threads


@dataclass(frozen=True)
class Standing:
    """Where one goal stands in one run: the figure in words and whether it meets the goal."""

    measured: str
    met: bool


@dataclass(frozen=True)
class Goal:
    """A goal, the benchmark whose latest run measures it, and how to read that run."""

    text: str
    benchmark: str
    read: Callable[[dict[str, Any]], Standing | None]  # None: the run lacks the figure


def _latency(results: dict[str, Any], threads: int, side: str) -> dict[str, Any] | None:
    for row in results.get("latency", []):
        if (row["threads"], row["frames"], row["stage"], row["side"]) == (
            threads,
            "both found",
            "whole frame",
            side,
        ):
            return row
    return None


def _sides(results: dict[str, Any], threads: int) -> tuple[dict[str, Any], dict[str, Any]] | None:
    """Our and the reference's latency rows at `threads`, when both are there with a ratio."""
    ours, ref = _latency(results, threads, "ours"), _latency(results, threads, "reference")
    if ours is None or ref is None or ours.get("ratio_p50_x") is None:
        return None
    return ours, ref


def p50_ratio(results: dict[str, Any], threads: int) -> float | None:
    """Ours / reference, whole-frame p50 on frames both found, at `threads`, or None."""
    sides = _sides(results, threads)
    return None if sides is None else sides[0]["ratio_p50_x"]


def ratio_at(threads: int) -> Callable[[dict[str, Any]], Standing | None]:
    """Ours / reference, whole-frame p50 on frames both found, at `threads` threads."""

    def read(results: dict[str, Any]) -> Standing | None:
        sides = _sides(results, threads)
        if sides is None:
            return None
        ours, ref = sides
        ratio = ours["ratio_p50_x"]
        return Standing(
            f"{ratio:.2f} ({ours['p50_ms']:.2f} vs {ref['p50_ms']:.2f} ms){_runtime(results)}",
            ratio <= RATIO_GOAL,
        )

    return read


def _runtime(results: dict[str, Any]) -> str:
    """' on openvino' for a run whose pose models were not on the default runtime, ' with
    full-int8' for one whose landmark model was not the default full one, ' and the int8
    detector' (or ' with the int8 detector') for one whose detector was not the float one,
    ' and the int8 detector on zooms and tiles' for a window detector unlike that one,
    ', spinning threads' when our onnxruntime threads spin-waited within runs, and ',
    whole-frame search' when ours searched as the reference does (no tiles)."""
    runtime, model = results.get("runtime", "cpu"), results.get("model", "full")
    detector = results.get("detector", "float")
    text = ("" if runtime == "cpu" else f" on {runtime}") + (
        "" if model == "full" else f" with {model}"
    )
    if detector != "float":
        text += f" {'and' if model != 'full' else 'with'} the {detector} detector"
    window = results.get("window_detector")
    if window is not None and window != detector:
        text += f" {'and' if text else 'with'} the {window} detector on zooms and tiles"
    if results.get("spin"):
        text += ", spinning threads"
    if results.get("search", "tiles") != "tiles":
        text += ", whole-frame search"
    return text


def cpu_ratio(results: dict[str, Any], threads: int) -> float | None:
    """Ours / reference in process CPU-seconds per frame (the energy proxy), or None."""
    per = {
        r["side"]: r["cpu_ms_per_frame"] for r in results.get("cpu", []) if r["threads"] == threads
    }
    if per.get("ours") is None or not per.get("reference"):
        return None
    return per["ours"] / per["reference"]


def cpu_ratio_at(threads: int) -> Callable[[dict[str, Any]], Standing | None]:
    """Ours / reference in CPU-seconds per frame at `threads` threads, against RATIO_GOAL."""

    def read(results: dict[str, Any]) -> Standing | None:
        ratio = cpu_ratio(results, threads)
        if ratio is None:
            return None
        per = {r["side"]: r for r in results["cpu"] if r["threads"] == threads}
        # Judged on every frame, as the energy proxy is; the frames both sides found (the
        # same work, no search) are shown beside, for where the rest goes.
        same = [per[s].get("cpu_ms_per_both_found_frame") for s in ("ours", "reference")]
        beside = f"; {same[0] / same[1]:.2f} on frames both found" if all(same) else ""
        return Standing(
            f"{ratio:.2f} ({per['ours']['cpu_ms_per_frame']:.1f} vs "
            f"{per['reference']['cpu_ms_per_frame']:.1f} CPU-ms per frame{beside})"
            f"{_runtime(results)}",
            ratio <= RATIO_GOAL,
        )

    return read


def landmark_error(results: dict[str, Any]) -> Standing | None:
    """Equal or better in every group the paired interval can judge (and at least one)."""
    rows = results.get("landmark_error")
    if rows is None:
        return None
    judged = [r for r in rows if r.get("verdict") is not None]
    if not judged:
        return Standing("no group both sides found", False)
    count = {v: sum(r["verdict"] == v for r in judged) for v in ("better", "equal", "worse")}
    text = (
        f"{len(judged)} judged (group x landmarks): {count['better']} better, "
        f"{count['equal']} equal, {count['worse']} worse"
    )
    worse = [f"{r['group']} {r['landmarks']}" for r in judged if r["verdict"] == "worse"]
    if worse:
        text += f" (worse: {', '.join(worse)})"
    return Standing(text, not worse)


def scenario_fps_of(model: str) -> Callable[[dict[str, Any]], Standing | None]:
    """Median fps of a whole scenario run on one core, sun's shadows, no ablation, with the
    pedestrian's behaviour `model` (runs before behaviours existed were rail)."""

    def standing(results: dict[str, Any]) -> Standing | None:
        for row in results.get("scenario_runs", []):
            default = not row["ablation"] and row["shadows"] and row.get("runtime", "cpu") == "cpu"
            if default and row.get("behaviour", "rail") == model:
                return Standing(
                    f"{row['fps_median']:.1f} fps ({row['fps_min']:.1f}-{row['fps_max']:.1f} "
                    f"over {row['runs']} runs)",
                    row["fps_median"] >= REALTIME_FPS,
                )
        return None

    return standing


def people_fps(results: dict[str, Any]) -> Standing | None:
    """fps (frames over their summed time) with 10 people in view, budget 3, 2 threads."""
    goal = results.get("goal")
    if not goal:
        return None
    row = next(
        (r for r in results.get("rows", [])
         if (r["view"], r["tracker"], r["threads"]) == (goal["view"], goal["tracker"],
                                                        goal["threads"])),
        None,
    )  # fmt: skip
    if row is None or row.get("fps") is None:
        return None
    return Standing(
        f"{row['fps']:.1f} fps (p50 {row['p50_ms']:.1f} ms, p95 {row['p95_ms']:.1f} ms; "
        f"{row['landmark_runs_per_frame']:.1f} landmark runs and "
        f"{row['people_per_frame']:.1f} people reported a frame)",
        row["fps"] >= PEOPLE_FPS_GOAL,
    )


GOALS = (
    Goal(
        f"whole pipeline <= {RATIO_GOAL}x the reference per frame (p50, frames both found), "
        "1 thread",
        "compare_reference",
        ratio_at(1),
    ),
    Goal(
        f"whole pipeline <= {RATIO_GOAL}x the reference per frame (p50, frames both found), "
        "2 threads",
        "compare_reference",
        ratio_at(2),
    ),
    Goal(
        f"CPU-seconds per frame <= {RATIO_GOAL}x the reference's, 1 thread",
        "compare_reference",
        cpu_ratio_at(1),
    ),
    Goal(
        f"CPU-seconds per frame <= {RATIO_GOAL}x the reference's, 2 threads",
        "compare_reference",
        cpu_ratio_at(2),
    ),
    Goal(
        "landmark error equal or better than the reference (paired 95 % interval)",
        "compare_reference",
        landmark_error,
    ),
    Goal(
        f"a scenario run on one core at >= {REALTIME_FPS:g} fps (render + pipeline with 5 "
        "predictors + truth)",
        "simulator",
        scenario_fps_of("rail"),
    ),
    Goal(
        f"the same with a human walker at >= {REALTIME_FPS:g} fps",
        "simulator",
        scenario_fps_of("human"),
    ),
    Goal(
        f"10 people in view, landmark budget 3, 2 threads: >= {PEOPLE_FPS_GOAL:g} fps "
        "(two PETS09-S2L1 frames side by side)",
        "people",
        people_fps,
    ),
)
