"""Real motion through the loop: the people tracker's 1 s ground prediction on replayed scenes.

The replay families (scenarios/families/small/crowd/replay_*.toml) put real recorded
walkers (ETH/UCY hotel and zara01, read from the shared data at run time) on the
simulated street. Each run renders the World and hands every frame to the pipeline in
everyone mode (monopic.people: detector, tracker, an identity per person) in ground mode,
with the robot's own state only, exactly as the run loop hands it any pipeline
(sim.runs.loop.OnBoard: `step.frame`, whose `ego` is the robot's speed, yaw rate and
camera). The pipeline is set up as sim.runs.pipelines.scenario_pipeline sets up the
sweep's (the scenario's robot footprint, one onnxruntime thread) with `people` added and
a 1 s horizon.

Scoring, per frame, in the world frame:
1. tracks are matched to the truth's people by box overlap: the track's box against each
   visible person's full body box (PersonTruth.box), IoU >= MIN_IOU, one to one by
   scipy's linear_sum_assignment on the IoU;
2. a matched track's fresh ground prediction (a foot point 1 s ahead in the robot's frame
   at this frame, what the pipeline outputs) is moved into the world with the robot's
   true pose at this frame (only for scoring: the pipeline never sees it) and compared
   with where that person's footprint centre really is 1 s later (the truth's
   future_position_world; the scenario's horizon is set to 1 s so that it is 1 s);
3. beside it, on the same person-frames, constant velocity fed the true positions: the
   person's true position now plus their true velocity over the last CV_LOOKBACK s times
   1 s (a person-frame without CV_LOOKBACK s of history is not scored).
Coverage is the share of person-frames in view (in the image, not occluded: the truth's
`in_frame` and not `occluded`) with a matched track.

    .venv/bin/python -m studies.crowd.replay_loop --out recordings/replay_loop

Each finished run appends one line to DIR/results.jsonl (its key, its settings and every
scored person-frame), so a crash loses nothing and a rerun skips what is there; the
report DIR/replay_loop.md is written from that file.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import asdict, dataclass, field, replace
from datetime import date
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment

from monopic.output import atomic_path
from monopic.people.box import Box
from monopic.people.tracker import PeopleConfig
from monopic.pipeline import FrameResult, Pipeline, PipelineConfig
from monopic.pose.detector import iou
from monopic.pose.tracker import TrackerConfig
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor
from monopic.variants.warning import CollisionWarning
from sim.geometry.frames import Pose2D
from sim.runs.loop import Listener, LoopFrame, OnBoard, run_loop
from sim.runs.runner import machine
from sim.scenario.files import load
from sim.scenario.spec import Scenario
from sim.world.world import World

# Real data is read where it is kept, never copied: $MONOPIC_SHARED_DATA, else
# ../shared/data beside the checkout (the families name it `shared:`).
ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = Path(os.environ.get("MONOPIC_SHARED_DATA") or ROOT.parent / "shared" / "data")
TRACKS = SHARED_DATA / "eth-ucy-calibration"
FAMILY_DIR = ROOT / "scenarios" / "families" / "small" / "crowd"
FAMILIES = {"hotel": FAMILY_DIR / "replay_hotel.toml", "zara": FAMILY_DIR / "replay_zara.toml"}
SPEEDS = (0.0, 1.0, 2.0)  # m/s: standing, half the families' own speed, their own 2 m/s

HORIZON = 1.0  # s: the prediction scored
MIN_IOU = 0.3  # a track is a person's when its box overlaps their body box this much
CV_LOOKBACK = 0.4  # s: the true velocity of the baseline, the recordings' own sample step
# The pipeline's ground predictors scored: the primary one (what `monopic video --mode
# ground` runs by default) and its constant velocity on the tracked foot point.
PREDICTORS = ("rules", "constant-velocity")
RESULTS = "results.jsonl"
REPORT = "replay_loop.md"


# -- scoring (pure: the tests hold these to known answers) -----------------------------


def match_boxes(
    tracks: Sequence[Box], people: Sequence[Box], min_iou: float = MIN_IOU
) -> list[tuple[int, int]]:
    """Pairs (track index, person index), one to one, maximising the summed IoU, each pair
    overlapping at least `min_iou`."""
    if not tracks or not people:
        return []
    overlap = np.array([[iou(t, p) for p in people] for t in tracks])
    rows, cols = linear_sum_assignment(overlap, maximize=True)
    return [(int(r), int(c)) for r, c in zip(rows, cols, strict=True) if overlap[r, c] >= min_iou]


def robot_to_world(point: Sequence[float], robot: Pose2D) -> np.ndarray:
    """A ground point in the robot's frame (x forward, y left, origin below its reference
    point) into the world, by the robot's pose."""
    return robot.to_world(np.array([point[0], point[1], 0.0]))[:2]


def constant_velocity(
    now: Sequence[float], before: Sequence[float], lookback: float, horizon: float
) -> np.ndarray:
    """Where constant velocity puts a person `horizon` s ahead, from their position now and
    `lookback` s before."""
    p, q = np.asarray(now, dtype=float), np.asarray(before, dtype=float)
    return p + (p - q) / lookback * horizon


def percentiles(errors: Iterable[float]) -> tuple[float, float]:
    """p50 and p90 (NaN for no values)."""
    values = np.asarray(list(errors), dtype=float)
    if values.size == 0:
        return float("nan"), float("nan")
    return float(np.percentile(values, 50)), float(np.percentile(values, 90))


@dataclass(frozen=True)
class Scored:
    """One person-frame whose prediction was scored (errors in m, world frame)."""

    person: str
    time: float
    track: int  # the pipeline's identity
    errors: dict[str, float]  # predictor key -> |predicted - true position 1 s later|
    cv_truth: float  # constant velocity fed the true positions
    located: float  # |the tracked foot point now - the true position now|: where it starts


@dataclass
class Scorer(Listener):
    """Per frame: match the pipeline's tracks to the truth's people and score their
    predictions (see the module docstring). The truth is read here, after the pipeline
    has decided, never handed to it."""

    board: str
    lookback_frames: int
    scored: list[Scored] = field(default_factory=list)
    in_view: dict[str, int] = field(default_factory=dict)  # person -> frames in view
    matched: dict[str, int] = field(default_factory=dict)  # ... of them with a track
    _history: dict[str, list[np.ndarray]] = field(default_factory=dict)

    def frame(self, frame: LoopFrame) -> None:
        truth = frame.truth
        for p in truth.people:
            self._history.setdefault(p.name, []).append(np.array(p.position_world, float))
        result: FrameResult | None = frame.results[self.board]
        sightings = result.people if result is not None else ()
        candidates = [
            p for p in truth.people
            if p.in_frame and np.all(np.isfinite(p.box))
            and (p.visibility is None or p.visibility.visible > 0)
        ]  # fmt: skip
        pairs = match_boxes([s.box for s in sightings], [p.box for p in candidates])
        matched = {candidates[j].name for _, j in pairs}
        for p in truth.people:
            if p.in_frame and not p.occluded:
                self.in_view[p.name] = self.in_view.get(p.name, 0) + 1
                self.matched[p.name] = self.matched.get(p.name, 0) + (p.name in matched)
        for i, j in pairs:
            track, person = sightings[i], candidates[j]
            history = self._history[person.name]
            if not track.fresh or len(history) <= self.lookback_frames:
                continue
            future = np.asarray(person.future_position_world, dtype=float)
            errors = {}
            for d in track.decisions:
                if d.mode is Mode.GROUND and d.prediction.ground is not None:
                    at = robot_to_world(d.prediction.ground, truth.robot.pose)
                    errors[d.predictor] = float(np.linalg.norm(at - future))
            if not errors:
                continue
            cv = constant_velocity(
                history[-1], history[-1 - self.lookback_frames], CV_LOOKBACK, HORIZON
            )
            assert track.features is not None and track.features.ground is not None
            now = robot_to_world(track.features.ground.position, truth.robot.pose)
            self.scored.append(
                Scored(person.name, round(truth.time, 4), track.person_id, errors,
                       float(np.linalg.norm(cv - future)),
                       float(np.linalg.norm(now - history[-1])))
            )  # fmt: skip


# -- runs ------------------------------------------------------------------------------


@dataclass(frozen=True)
class RunKey:
    """What makes a run: the family, the robot's speed and how many frames."""

    family: str
    speed: float
    frames: int | None  # None: the family's whole duration

    @property
    def text(self) -> str:
        return f"{self.family}/{self.speed:g}/{self.frames or 'all'}"


def scenario_for(key: RunKey) -> Scenario:
    """The family's base scenario at the key's robot speed, with a 1 s horizon (so the
    truth's future position is 1 s ahead)."""
    base = load(FAMILIES[key.family]).base
    return replace(base, horizon=HORIZON, robot=replace(base.robot, speed=key.speed))


def people_pipeline(scenario: Scenario, threads: int = 1) -> Pipeline:
    """The pipeline following everyone in ground mode, set up for the scenario as
    sim.runs.pipelines.scenario_pipeline sets up the sweep's, with `people` added."""
    config = PipelineConfig(
        horizon=scenario.horizon,
        mode=Mode.GROUND,
        tracker=TrackerConfig(threads=threads),
        warning=CollisionWarning(robot=scenario.robot.geometry()),
        people=PeopleConfig(),
    )
    return Pipeline(config, [make_predictor(name, Mode.GROUND) for name in PREDICTORS])


def run(key: RunKey, threads: int = 1) -> dict[str, object]:
    """One run: the World rendered frame by frame through the people pipeline; its line."""
    scenario = scenario_for(key)
    start = time.perf_counter()
    board = OnBoard("people", people_pipeline(scenario, threads))
    scorer = Scorer(board.name, round(CV_LOOKBACK / scenario.dt))
    frames = scenario.frames if key.frames is None else min(key.frames, scenario.frames)
    with World(scenario, render=True) as world:
        end = run_loop(world, [board], [scorer], frames=frames, stop_at_contact=False)
    return {
        "key": key.text,
        **asdict(key),
        "scenario": scenario.name,
        "people": len(scenario.people),
        "fps": round(1 / scenario.dt, 3),
        "frames_run": end.frames,
        "contact_time": end.contact_time,
        "wall_s": round(time.perf_counter() - start, 1),
        "in_view": scorer.in_view,
        "matched": scorer.matched,
        "scored": [asdict(s) for s in scorer.scored],
    }


def read_results(path: Path) -> list[dict[str, object]]:
    """The finished runs' lines (a last line cut short by a crash is left out: its run
    is run again)."""
    if not path.exists():
        return []
    lines = []
    for text in path.read_text().splitlines():
        try:
            lines.append(json.loads(text))
        except json.JSONDecodeError:
            continue
    return lines


def append_result(path: Path, line: Mapping[str, object]) -> None:
    with open(path, "a") as handle:
        handle.write(json.dumps(line) + "\n")
        handle.flush()
        os.fsync(handle.fileno())


# -- the report ------------------------------------------------------------------------


@dataclass
class Tally:
    """Scored person-frames and coverage counts pooled over runs."""

    errors: dict[str, list[float]] = field(default_factory=dict)
    cv: list[float] = field(default_factory=list)
    located: list[float] = field(default_factory=list)
    in_view: int = 0
    matched: int = 0

    def add_scored(self, s: Mapping[str, object]) -> None:
        for name, value in dict(s["errors"]).items():  # type: ignore[arg-type]
            self.errors.setdefault(name, []).append(float(value))
        self.cv.append(float(s["cv_truth"]))  # type: ignore[arg-type]
        self.located.append(float(s["located"]))  # type: ignore[arg-type]

    def row(self, label: str, keys: Sequence[str]) -> str:
        cells = [label, str(len(self.cv))]
        for k in keys:
            p50, p90 = percentiles(self.errors.get(k, []))
            cells.append(_pair(p50, p90))
        cells.append(_pair(*percentiles(self.cv)))
        cells.append(_pair(*percentiles(self.located)))
        share = f"{self.matched / self.in_view:.2f} ({self.matched}/{self.in_view})"
        cells.append(share if self.in_view else "-")
        return "| " + " | ".join(cells) + " |"


def _pair(p50: float, p90: float) -> str:
    return "-" if np.isnan(p50) else f"{p50:.2f} / {p90:.2f}"


def predictor_keys() -> list[str]:
    return [f"{name}/{Mode.GROUND}" for name in PREDICTORS]


def report(lines: Sequence[Mapping[str, object]], command: str) -> str:
    """The markdown report of the finished runs."""
    keys = predictor_keys()
    head = (
        "| {what} | scored | "
        + " | ".join(f"pipeline {k} p50 / p90 (m)" for k in keys)
        + " | CV on the true positions p50 / p90 (m) | pipeline position now p50 / p90 (m)"
        " | coverage |"
    )
    rule = "| " + " | ".join(["---"] * (len(keys) + 5)) + " |"
    scenes: dict[str, Tally] = {}
    families: dict[str, Tally] = {}
    persons: dict[tuple[str, str], Tally] = {}
    for line in lines:
        family = str(line["family"])
        scene = f"{family}, robot {float(line['speed']):g} m/s"  # type: ignore[arg-type]
        for tally in (scenes.setdefault(scene, Tally()), families.setdefault(family, Tally())):
            for s in line["scored"]:  # type: ignore[attr-defined]
                tally.add_scored(s)
            tally.in_view += sum(line["in_view"].values())  # type: ignore[attr-defined]
            tally.matched += sum(line["matched"].values())  # type: ignore[attr-defined]
        for s in line["scored"]:  # type: ignore[attr-defined]
            persons.setdefault((family, str(s["person"])), Tally()).add_scored(s)
        for name, n in line["in_view"].items():  # type: ignore[attr-defined]
            t = persons.setdefault((family, name), Tally())
            t.in_view += n
            t.matched += line["matched"].get(name, 0)  # type: ignore[attr-defined]
    m = machine()
    runs = ", ".join(
        f"{line['key']} ({line['frames_run']} frames, {line['people']} people, "
        f"{line['wall_s']:.0f} s)"
        for line in lines
    )
    out = [
        "# Real motion through the loop: the people tracker's 1 s ground prediction on "
        "replayed scenes",
        "",
        f"Measured {date.today().isoformat()} on {m.host} ({m.cpu}, {m.cores} cores) with",
        "",
        "```sh",
        command,
        "```",
        "",
        f"Runs (family/robot speed/frames): {runs}. The recordings are read from {TRACKS}.",
        "",
        "Each run renders a replay family (scenarios/families/small/crowd/replay_*.toml: "
        "real ETH/UCY walkers on the street) and feeds every frame, with the robot's own "
        "state only, to the pipeline following everyone (monopic.people) in ground mode "
        f"with a {HORIZON:g} s horizon. A track is matched to a person when its box "
        f"overlaps their true body box by IoU >= {MIN_IOU:g} (one to one, "
        "linear_sum_assignment); its fresh ground prediction (robot frame) is moved to the "
        "world with the robot's true pose and compared with where the person's footprint "
        f"centre is {HORIZON:g} s later. CV on the true positions: the person's true "
        f"position plus their true velocity over the last {CV_LOOKBACK:g} s, scored on "
        "the same person-frames. Coverage: person-frames in view (in the image, not "
        "occluded) with a matched track (a match on an occluded person is scored too, so a "
        "person's scored frames can outnumber their covered ones). Position now: the "
        "tracked foot point at the frame of the prediction against the true position "
        "then, where the prediction starts from. Errors are distances on the ground, metres.",
        "",
        "## Per scene",
        "",
        head.format(what="scene"),
        rule,
        *(scenes[k].row(k, keys) for k in scenes),
        *(families[k].row(f"{k}, all runs", keys) for k in families),
        "",
        "## Per person (all runs of the family pooled)",
        "",
        head.format(what="family, person"),
        rule,
        *(
            persons[k].row(f"{k[0]}, {k[1]}", keys)
            for k in sorted(persons, key=lambda k: (k[0], -len(persons[k].cv), k[1]))
        ),
        "",
    ]
    return "\n".join(out)


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="folder for results and report")
    parser.add_argument(
        "--families", nargs="+", choices=sorted(FAMILIES), default=sorted(FAMILIES),
        help="replay families to run (default: all)",
    )  # fmt: skip
    parser.add_argument(
        "--speeds", nargs="+", type=float, default=list(SPEEDS),
        help="robot speeds, m/s (each in [0, 5]; default %(default)s)",
    )  # fmt: skip
    parser.add_argument(
        "--frames", type=int, default=None,
        help="frames a run (>= 1; default: the family's whole duration)",
    )  # fmt: skip
    parser.add_argument(
        "--threads", type=int, default=1, help="onnxruntime threads (>= 1; default 1)"
    )
    args = parser.parse_args(argv)
    for speed in args.speeds:
        if not 0 <= speed <= 5:
            parser.error(f"--speeds {speed:g}: must lie in [0, 5] m/s")
    if args.frames is not None and args.frames < 1:
        parser.error(f"--frames {args.frames}: must be >= 1")
    if args.threads < 1:
        parser.error(f"--threads {args.threads}: must be >= 1")
    if not (TRACKS / "biwi_hotel.txt").is_file():
        parser.exit(2, f"the ETH/UCY tracks are not at {TRACKS} (set MONOPIC_SHARED_DATA)\n")
    args.out.mkdir(parents=True, exist_ok=True)
    results = args.out / RESULTS
    done = {str(line["key"]) for line in read_results(results)}
    for family in args.families:
        for speed in args.speeds:
            key = RunKey(family, speed, args.frames)
            if key.text in done:
                continue
            line = run(key, args.threads)
            append_result(results, line)
            print(f"{key.text}: {len(line['scored'])} scored, {line['wall_s']} s", flush=True)
    wanted = {RunKey(f, s, args.frames).text for f in args.families for s in args.speeds}
    lines = [line for line in read_results(results) if line["key"] in wanted]
    given = list(argv) if argv is not None else sys.argv[1:]
    shared = os.environ.get("MONOPIC_SHARED_DATA")
    where = [f"MONOPIC_SHARED_DATA={shared}"] if shared else []
    command = " ".join([*where, ".venv/bin/python -m studies.crowd.replay_loop", *given])
    text = report(lines, command)
    with atomic_path(args.out / REPORT) as tmp:
        tmp.write_text(text)
    print(text, end="")


if __name__ == "__main__":
    main()
