"""Could any tree on the pipeline's own features read intent on a judged draw?

Five judged draws missed the intent stage's goal (docs/intent/verdict.md) the same way:
the hold-back that removes near misses also delays real crossers' warnings. Two
explanations were left standing: the judged roads lie outside the training ranges (the
tree reads priors that do not carry over), or the features do not tell a walker about to
stop or turn away from a crosser on the frames where the warning is decided, wherever the
tree is trained.

This separates the two. It replays a sweep's own foot points (studies.ground_replay, the
shipped ground track and the real warning) and rebuilds, frame by frame, the intent
features the tree may read from what the results file keeps of the pipeline: the ground
track and its window kinematics, the path offset and distance, phi (the file's smoothed
phi) and its rate. Head features are not in the results file and are left out (the trees
grown with them did not use them: docs/intent/ground-tree.md). The runs are split into
folds by run, every family in every fold; for each fold a tree is grown (the project's ID3
and quantile bins, as the trainer grows them) on the other folds' frames, labelled with
the truth's intent, and read on this fold's frames. The hold-back rule
(monopic.tree.intent.place, no release bound) is then replayed with each frame's
out-of-fold stop + turn-away share against a range of thresholds.

The trees are fitted on the very draw they are read on (other runs of it), so the figures
are optimistic for a tree trained elsewhere: the roads, speeds and cue settings are those
of the judged families. No threshold is chosen here and nothing is shipped; the table
shows the whole trade. If no threshold meets both goals, these features cannot, wherever
a tree is trained; if one does, the misses were the training ranges.

Other readings ask what would: `pipeline-recent` adds the measured foot point's own
velocity over the last 0.4 s (shorter lag, more noise); `pipeline-column` reads the
motion attributes from a second ground track whose foot column has its own, measured,
smaller pixel noise (GroundTrackConfig.column_pixel_noise: the hips' column is steadier
than the foot's row, so motion across the line of sight is believed sooner), the warning
still from the shipped track; `truth` reads every attribute
from the simulator's truth (a perfect reader, with the head's true yaw), `truth-motion`
its motion alone, and `@S` reads the truth S seconds late, as an estimator lagging by S.
`@-S` reads it S seconds early: a cue that shows the walker's motion S seconds before it
happens, perfectly read. How far ahead would a cue have to tell, for the goal to be in
reach? (The simulator's body cues add nothing to the truth's own motion, so this asks
what any cue, real or simulated, would need.)

    .venv/bin/python -m studies.intent.crossfit RESULTS.jsonl [MORE.jsonl ...]
        [--reading pipeline|pipeline-recent|pipeline-column|truth|truth-motion[@S|@-S] ...]
        [--folds 5] [--depth 4 6]
        [--min-rows 50] [--out docs/intent/crossfit.md] [--plot docs/images/crossfit.png]
"""

from __future__ import annotations

import argparse
import hashlib
import math
import sys
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from monopic.camera import CameraModel
from monopic.errors import UserError
from monopic.features.ground import GroundMotion, foot_on_ground
from monopic.features.ground_track import GroundTrackConfig
from monopic.features.record import GroundFeatures
from monopic.features.swept_path import path_offset
from monopic.features.window import Kinematics, SlidingWindow, angle_rate
from monopic.frame import EgoState
from monopic.output import atomic_path, write_text_atomically
from monopic.predict.base import Prediction, with_ground_point
from monopic.tree.discretise import CutPointBins, Discretiser
from monopic.tree.id3 import DecisionTree, ID3Params, fit_id3
from monopic.tree.intent import INTENT_ATTRIBUTES, IntentRules, LeafReading, place
from monopic.tree.intent_training import quantile_cuts
from sim.analysis.metrics import LEAD_GOAL, PairedRecall, RunOutcome, paired_recall
from sim.runs.result import MAIN, RunResult
from sim.runs.results_file import read_results
from studies.ground_replay import (
    PointRule,
    ReplayFrame,
    camera,
    judge_warnings,
    replay,
)

# The ground tree's attributes less the head's reading, which the results file does not keep.
ATTRIBUTES = tuple(a for a in INTENT_ATTRIBUTES if a not in ("head_yaw", "head_toward"))
# The truth's reading adds the head's true yaw from the shoulders (the pipeline's own
# reading of it is not in the results file, and reads a fifth of a turn: head-reading.md).
TRUTH_ATTRIBUTES = (*ATTRIBUTES, "head_yaw")
# s: the truth's acceleration, heading and facing rates, from the last frame this far back
# (`delayed`: 3 frames at 15 fps, compared with a tolerance: a plain float comparison
# takes 4 on 41 % of frames)
TRUTH_WINDOW = 0.2
RECENT_WINDOW = 0.4  # s: the `pipeline-recent` reading's line fit (about 0.2 s of lag)
# The `pipeline-column` reading's track: the column's pixel noise as measured on the
# development intent sweep (GroundTrackConfig's docstring), the row's as shipped.
COLUMN_TRACK = GroundTrackConfig(column_pixel_noise=0.3, column_pixel_noise_per_height=0.01)
PHI_RATE_WINDOW = 0.5  # s, as the feature extractor's phi rate (FeatureExtractor)
THRESHOLDS = (0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.8)
BASELINE = "constant velocity (replayed)"


@dataclass(frozen=True)
class FrameRow:
    """One replayed frame's features and the truth's intent label."""

    run: int
    k: int
    values: dict[str, float]
    intent: str | None


def deal_folds(rows: Sequence[RunResult], folds: int) -> list[int]:
    """Each run's fold: runs dealt in turn within each family, in an order fixed by a hash
    of the run's id, so every family is in every fold and a rerun deals the same."""
    order: dict[str, int] = {}
    by_family: dict[str, list[RunResult]] = {}
    for r in rows:
        by_family.setdefault(r.family, []).append(r)
    for members in by_family.values():
        members.sort(key=lambda r: hashlib.sha1(r.id.encode()).hexdigest())
        for j, r in enumerate(members):
            order[r.id] = j
    return [order[r.id] % folds for r in rows]


def collect_run(
    i: int, row: RunResult, reading: Reading, drop: Sequence[str] = ()
) -> list[FrameRow]:
    """One run's frames with a ground point: the attributes the reading gives, rebuilt by
    replay, less the reading's own leave-outs and `drop`.

    A `recent` reading adds the foot point's own velocity over the last RECENT_WINDOW
    seconds (a line through the measured ground points in the odometry frame, read at the
    newest): a shorter-lag, noisier reading than the track's.
    """
    leave_out = {*reading.without, *drop}
    out: list[FrameRow] = []
    motion = GroundMotion()
    own = column_motion(row) if reading.column else None
    cam = camera(row)
    measured = SlidingWindow(RECENT_WINDOW)
    phi = row.pipelines[MAIN].phi
    history = SlidingWindow(PHI_RATE_WINDOW)
    labels = row.truth.intent

    def record(f: ReplayFrame) -> Prediction | None:
        g = f.features.ground
        assert g is not None
        p = phi[f.k] if f.k < len(phi) else None
        if p is not None and math.isfinite(p):
            history.add(f.features.timestamp, p)
        if reading.truth:
            values = truth_values(row, shifted(row, f.k, reading.delay))
        else:
            kin = motion.kinematics()
            if own is not None:  # the motion from the second track, the warning not
                g, kin = own.get(f.k, (g, kin))
            values = {
                "forward": g.velocity[0],
                "left": g.velocity[1],
                "speed": kin.speed,
                "acceleration": kin.acceleration,
                "heading_rate": kin.heading_rate,
                "phi": math.nan if p is None else p,
                "phi_rate": angle_rate(history),
                "path_offset": g.path_offset,
                "path_distance": g.path_distance,
            }
            if reading.recent:
                values.update(recent_velocity(row, f, cam, motion, measured))
        values = {a: v for a, v in values.items() if a not in leave_out}
        intent = labels[f.k] if f.k < len(labels) else None
        out.append(FrameRow(i, f.k, values, intent))
        return None

    replay(row, motion, record)
    return out


def column_motion(row: RunResult) -> dict[int, tuple[GroundFeatures, Kinematics]]:
    """Per frame, the ground features and window kinematics of a second track fed the same
    foot points with COLUMN_TRACK's noise model (the `pipeline-column` reading): the run
    replayed through it as through the shipped track."""
    motion = GroundMotion(COLUMN_TRACK)
    out: dict[int, tuple[GroundFeatures, Kinematics]] = {}

    def record(f: ReplayFrame) -> None:
        assert f.features.ground is not None
        out[f.k] = (f.features.ground, motion.kinematics())

    replay(row, motion, record)
    return out


def recent_velocity(
    row: RunResult, f: ReplayFrame, cam: CameraModel, motion: GroundMotion, window: SlidingWindow
) -> dict[str, float]:
    """The measured foot point's velocity (robot axes) over the last window: a line fit."""
    speed = row.truth.robot_speed[f.k]
    got = foot_on_ground(EgoState(cam, speed or 0.0, 0.0), f.features.foot, 1.0, 0.0)
    if got is not None:
        g = got[0]
        window.add(f.features.timestamp, np.array(motion.odometry.to_fixed((g[0], g[1]))))
    nan = {"forward_recent": math.nan, "left_recent": math.nan}
    if len(window) < 4 or window.span < 0.5 * RECENT_WINDOW:
        return nan
    t, xy, _ = window.arrays()
    vx, vy = (float(np.polyfit(t - t[-1], xy[:, d], 1)[0]) for d in (0, 1))
    vf, vl = motion.odometry.rotate_to_robot((vx, vy))
    return {"forward_recent": vf, "left_recent": vl}


def delayed(row: RunResult, k: int, delay: float) -> int:
    """The last frame at least `delay` seconds before frame k (k itself for no delay)."""
    t = row.truth.t
    j = k
    while j > 0 and delay > 0 and (t[j] is None or t[k] - t[j] < delay - 1e-9):  # type: ignore[operator]
        j -= 1
    return j


def ahead(row: RunResult, k: int, lead: float) -> int:
    """The first frame at least `lead` seconds after frame k, or the run's last frame with
    a time (the truth ends at contact or with the run: a cue cannot tell beyond it)."""
    t = row.truth.t
    if t[k] is None or lead <= 0:
        return k
    last = k
    for j in range(k + 1, len(t)):
        if t[j] is None:
            continue
        last = j
        if t[j] - t[k] >= lead - 1e-9:  # type: ignore[operator]
            return j
    return last


def shifted(row: RunResult, k: int, delay: float) -> int:
    """The frame a reading `delay` seconds late reads at frame k (early for a negative one)."""
    return delayed(row, k, delay) if delay >= 0 else ahead(row, k, -delay)


def truth_values(row: RunResult, k: int, window: float = TRUTH_WINDOW) -> dict[str, float]:
    """The same attributes read from the simulator's truth, with no lag and no noise: the
    velocity and its change over the last `window` seconds, the true facing and its rate,
    and the true head yaw from the shoulders (a perfect reader of the body's cues)."""
    tr = row.truth
    nan = math.nan

    def at(j: int) -> tuple[float, float, float] | None:
        t, x, y, v = tr.t[j], tr.forward[j], tr.lateral[j], tr.robot_speed[j]
        return None if None in (t, x, y, v) else (t, x, y)  # type: ignore[return-value]

    def velocity(j: int) -> tuple[float, float] | None:
        if j < 1 or at(j) is None or at(j - 1) is None:
            return None
        (t0, x0, y0), (t1, x1, y1) = at(j - 1), at(j)  # type: ignore[misc]
        if not t1 > t0:
            return None
        return (x1 - x0) / (t1 - t0) + float(tr.robot_speed[j]), (y1 - y0) / (t1 - t0)  # type: ignore[arg-type]

    v1, here = velocity(k), at(k)
    back = delayed(row, k, window) if here is not None else k
    v0 = velocity(back) if back < k else None
    values = dict.fromkeys(TRUTH_ATTRIBUTES, nan)
    if v1 is None or here is None:
        return values
    side = path_offset((here[1], here[2]), row.scenario.robot_width)
    speed = math.hypot(*v1)
    values.update(forward=v1[0], left=v1[1], speed=speed, path_offset=side.offset,
                  path_distance=side.distance)  # fmt: skip
    if v0 is not None:
        dt = here[0] - tr.t[back]  # type: ignore[operator]
        if speed > 0.2:
            ux, uy = v1[0] / speed, v1[1] / speed
            values["acceleration"] = ((v1[0] - v0[0]) * ux + (v1[1] - v0[1]) * uy) / dt
        if speed > 0.2 and math.hypot(*v0) > 0.2:
            turn = math.atan2(v1[1], v1[0]) - math.atan2(v0[1], v0[0])
            values["heading_rate"] = math.degrees(math.atan2(math.sin(turn), math.cos(turn))) / dt
        p0, p1 = tr.phi[back], tr.phi[k]
        if p0 is not None and p1 is not None:
            values["phi_rate"] = ((p1 - p0 + 180.0) % 360.0 - 180.0) / dt
    values["phi"] = nan if tr.phi[k] is None else float(tr.phi[k])  # type: ignore[arg-type]
    h = tr.head_yaw[k] if k < len(tr.head_yaw) else None
    values["head_yaw"] = nan if h is None else float(h)
    return values


def grow(train: Sequence[FrameRow], depth: int, bins: int) -> tuple[Discretiser, DecisionTree]:
    """Quantile bins and an ID3 tree on the intent labels, as the trainer grows them."""
    attributes = tuple(train[0].values)
    disc = Discretiser(
        name=f"crossfit-q{bins}",
        binners=tuple(
            (a, CutPointBins(quantile_cuts([r.values[a] for r in train], bins))) for a in attributes
        ),
    )
    binned = [disc.discretise(r.values) for r in train]
    labels = [r.intent for r in train]  # only labelled frames are trained on
    tree = fit_id3(binned, labels, attributes, params=ID3Params(min_samples=2, max_depth=depth))
    return disc, tree


def hold_shares(
    frames: Sequence[FrameRow],
    fold_of: Sequence[int],
    folds: int,
    depth: int,
    bins: int,
    min_rows: int,
) -> dict[tuple[int, int], tuple[float, str]]:
    """Out-of-fold (stop + turn-away share, the commoner of the two) per (run, frame)."""
    shares: dict[tuple[int, int], tuple[float, str]] = {}
    for fold in range(folds):
        train = [r for r in frames if fold_of[r.run] != fold and r.intent is not None]
        disc, tree = grow(train, depth, bins)
        for r in frames:
            if fold_of[r.run] != fold:
                continue
            path = tree.path(disc.discretise(r.values))
            node = next((nd for nd in reversed(path) if nd.n >= min_rows), path[0])
            counts = Counter({str(lab): c for lab, c in node.counts})
            stop, turn = counts["stop"], counts["turn away"]
            shares[(r.run, r.k)] = ((stop + turn) / node.n, "stop" if stop >= turn else "turn away")
        print(f"  fold {fold + 1}/{folds}: {len(train)} training frames", file=sys.stderr)
    return shares


def hold_rule(
    row: RunResult, run: int, shares: dict[tuple[int, int], tuple[float, str]], threshold: float
) -> PointRule:
    """Constant velocity held back where the out-of-fold share reaches the threshold."""
    rules = IntentRules(hold_back_support=min(threshold, 1.01), min_rows=1)
    horizon = row.scenario.horizon

    def point(f: ReplayFrame) -> Prediction | None:
        share, which = shares.get((run, f.k), (0.0, "stop"))
        if share < threshold:
            return None
        reading = LeafReading(
            f.constant_velocity.case, which, 1.0, 1, (0.0, 0.0), hold_share=share,
            hold_intent=which,
        )  # fmt: skip
        g = f.features.ground
        assert g is not None
        at, _, _ = place(g.position, g.velocity, reading, rules, horizon, horizon, g.path_distance)
        return with_ground_point(f.features, f.constant_velocity.case, horizon, at)

    return point


def judge(
    rows: Sequence[RunResult], rule_of: Callable[[int, RunResult], PointRule | None], name: str
) -> list[RunOutcome]:
    """Every run replayed with its rule (None: constant velocity) and judged as `name`."""
    return [
        judge_warnings(row, replay(row, GroundMotion(), rule_of(i, row))[0], name)
        for i, row in enumerate(rows)
    ]


@dataclass(frozen=True)
class Trade:
    """One threshold's outcome against constant velocity: all families together, and the
    family whose paired recall difference has the lowest lower bound."""

    all: PairedRecall
    worst_low: float
    worst_family: str
    worst_lost: int = 0  # that family's collision runs warned 1 s ahead by constant velocity only
    worst_runs: int = 0  # and its collision runs


def trade(outs: list[RunOutcome], base: list[RunOutcome], families: list[str]) -> Trade:
    worst: tuple[float, str, PairedRecall | None] = (math.inf, "", None)
    for fam in families:
        pf = paired_recall(
            [o for o in outs if o.family == fam], [o for o in base if o.family == fam]
        )
        if pf.collision_runs and pf.low < worst[0]:
            worst = (pf.low, fam, pf)
    pw = worst[2]
    return Trade(
        paired_recall(outs, base),
        worst[0],
        worst[1],
        worst_lost=pw.only_second if pw else 0,
        worst_runs=pw.collision_runs if pw else 0,
    )


@dataclass(frozen=True)
class Reading:
    """Where the trees' attributes come from: the pipeline, or the truth (late by `delay`,
    early by -`delay` when it is negative)."""

    name: str
    truth: bool
    delay: float
    without: tuple[str, ...]
    recent: bool = False  # add the measured foot point's velocity over RECENT_WINDOW
    column: bool = False  # motion from a track with the column's own noise (COLUMN_TRACK)

    @classmethod
    def parse(cls, text: str) -> Reading:
        name, _, late = text.partition("@")
        if name not in READINGS:
            raise UserError(
                f"--reading: {text!r} is not one of {', '.join(READINGS)} (@S: late, @-S: early)"
            )
        try:
            delay = float(late) if late else 0.0
        except ValueError:
            raise UserError(f"--reading: {text!r}: the delay after @ is not seconds") from None
        if not math.isfinite(delay):
            raise UserError(f"--reading: {text!r}: the delay must be a finite number of seconds")
        if delay and name.startswith("pipeline"):
            raise UserError(
                f"--reading: {text!r}: only the truth's reading can be made late or early"
            )
        return cls(
            text,
            name.startswith("truth"),
            delay,
            READINGS[name],
            recent=name == "pipeline-recent",
            column=name == "pipeline-column",
        )


# Each reading's attributes beyond those the tool leaves out for all (--without).
READINGS: dict[str, tuple[str, ...]] = {
    "pipeline": (),
    "pipeline-recent": (),  # plus the foot point's velocity over the last RECENT_WINDOW
    "pipeline-column": (),  # motion from a track with the column's own noise
    "truth": (),
    "truth-motion": ("phi", "phi_rate", "head_yaw"),  # the walker's motion alone
}


def combined(paths: Sequence[Path]) -> list[RunResult]:
    """The runs with intent labels of every file; a later file's runs of a family replace
    an earlier file's runs of that family."""
    by_family: dict[str, list[RunResult]] = {}
    for path in paths:
        mine: dict[str, list[RunResult]] = {}
        for r in read_results(path):
            if any(r.truth.intent):
                mine.setdefault(r.family, []).append(r)
        by_family.update(mine)
    return [r for runs in by_family.values() for r in runs]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "results",
        type=Path,
        nargs="+",
        help="a sweep's results file (JSON lines); with several, a later file's runs of a "
        "family replace an earlier file's runs of that family (a redraw of some families "
        "beside a judged draw's others)",
    )
    ap.add_argument(
        "--reading",
        action="append",
        metavar="NAME[@S]",
        help="pipeline (default), pipeline-recent (plus the foot point's velocity over the "
        "last 0.4 s), pipeline-column (motion from a track with the column's own noise), "
        "truth (every attribute, a perfect reader) or truth-motion (its motion alone); @S "
        "reads the truth S seconds late, as an estimator that lags by S, @-S S seconds early, "
        "as a cue that tells the motion S seconds before it happens (repeatable: one table "
        "and one picture for all)",
    )
    ap.add_argument("--folds", type=int, default=5)
    ap.add_argument("--depth", type=int, nargs="+", default=[4, 6])
    ap.add_argument("--bins", type=int, default=4, help="quantile bins per attribute")
    ap.add_argument("--min-rows", type=int, default=50, help="rows of the node the rule reads")
    ap.add_argument(
        "--without",
        action="append",
        default=[],
        metavar="ATTRIBUTE",
        help="leave an attribute out of every reading's trees (repeatable)",
    )
    ap.add_argument("--out", type=Path, help="also write the table to this Markdown file")
    ap.add_argument("--plot", type=Path, help="draw the trade (near misses against recall)")
    args = ap.parse_args(argv)
    try:
        for path in args.results:
            if not path.is_file():
                raise UserError(f"{path}: no such results file (write one with `monopic sweep`)")
        readings = [Reading.parse(r) for r in args.reading or ["pipeline"]]
        if args.folds < 2:
            raise UserError(f"--folds: at least 2, got {args.folds}")
        unknown = set(args.without) - set(TRUTH_ATTRIBUTES)
        if unknown:
            raise UserError(f"--without: no attribute {sorted(unknown)[0]!r}")
        rows = combined(args.results)
        if not rows:
            raise UserError(f"{' '.join(map(str, args.results))}: no runs with intent labels")
    except UserError as err:
        print(err, file=sys.stderr)
        return 1
    fold_of = deal_folds(rows, args.folds)
    names = " + ".join(f"`{p}`" for p in args.results)
    counts = ", ".join(f"{f} {n}" for f, n in sorted(Counter(r.family for r in rows).items()))
    base = judge(rows, lambda i, row: None, BASELINE)
    families = sorted({o.family for o in base})
    lines = [
        f"{len(rows)} runs of {names} ({counts}), {args.folds} folds by run, every family in "
        f"every fold; trees on q{args.bins} bins, the rule reading the deepest node of at "
        f"least {args.min_rows} rows, hold-back without a release bound "
        "(studies/intent/crossfit.py). Recall: collision runs warned at least "
        f"{LEAD_GOAL:g} s before contact, paired against constant velocity on the same runs.",
        "",
    ]
    table = [
        "| reading | depth | hold at share >= | near-miss runs warned | constant velocity | "
        "recall@1s | difference, points [95 %] | runs lost / gained | worst family: lower "
        "bound (runs lost of) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    curves: dict[tuple[str, int], list[tuple[float, float, float]]] = {}
    for reading in readings:
        print(f"{reading.name}: replaying {len(rows)} runs", file=sys.stderr, flush=True)
        frames = [
            fr for i, row in enumerate(rows) for fr in collect_run(i, row, reading, args.without)
        ]
        lines.append(
            f"- `{reading.name}`: {len(frames)} frames with a ground point; attributes "
            f"{', '.join(frames[0].values)}."
        )
        for depth in args.depth:
            print(f"  depth {depth}: growing {args.folds} trees", file=sys.stderr, flush=True)
            shares = hold_shares(frames, fold_of, args.folds, depth, args.bins, args.min_rows)
            for th in THRESHOLDS:

                def rule(i: int, row: RunResult, th: float = th, sh: dict = shares) -> PointRule:
                    return hold_rule(row, i, sh, th)

                s = trade(judge(rows, rule, "crossfit"), base, families)
                p = s.all
                table.append(
                    f"| {reading.name} | {depth} | {th:g} | "
                    f"{p.near_miss_warned[0]}/{p.near_miss_runs} | {p.near_miss_warned[1]} | "
                    f"{p.warned_1s[0]}/{p.collision_runs} | "
                    f"{100 * p.difference:+.0f} [{100 * p.low:+.0f}, {100 * p.high:+.0f}] | "
                    f"{p.only_second} / {p.only_first} | "
                    f"{s.worst_family}: {100 * s.worst_low:+.0f} "
                    f"({s.worst_lost} of {s.worst_runs}) |"
                )
                print(table[-1], file=sys.stderr, flush=True)
                ratio = p.near_miss_warned[0] / max(p.near_miss_warned[1], 1)
                curves.setdefault((reading.name, depth), []).append(
                    (ratio, 100 * p.difference, 100 * s.worst_low)
                )
    text = "\n".join([*lines, "", *table]) + "\n"
    print(text)
    if args.out:
        write_text_atomically(args.out, text)
    if args.plot:
        draw(curves, args.plot, " + ".join(p.name for p in args.results))
    return 0


def draw(
    curves: dict[tuple[str, int], list[tuple[float, float, float]]], path: Path, title: str
) -> None:
    """Recall lost against near misses left, one line per reading and depth; filled where
    every family's paired lower bound is at least -3 points (the goal's own test)."""
    fig = Figure(figsize=(7.5, 5))
    ax = fig.add_subplot()
    names = list(dict.fromkeys(name for name, _ in curves))
    depths = list(dict.fromkeys(d for _, d in curves))
    styles = ["-", "--", ":", "-."]
    for (name, depth), pts in curves.items():
        colour = f"C{names.index(name)}"
        xs, ys, lows = zip(*pts, strict=True)
        ax.plot(xs, ys, styles[depths.index(depth) % 4], color=colour, lw=1.2,
                label=f"{name}, depth {depth}")  # fmt: skip
        ok = [low >= -3 for low in lows]
        ax.scatter([x for x, o in zip(xs, ok, strict=True) if o],
                   [y for y, o in zip(ys, ok, strict=True) if o], color=colour, s=22)  # fmt: skip
        ax.scatter([x for x, o in zip(xs, ok, strict=True) if not o],
                   [y for y, o in zip(ys, ok, strict=True) if not o], facecolors="none",
                   edgecolors=colour, s=22)  # fmt: skip
    ax.axvline(1 / 3, color="grey", lw=0.8)
    ax.axhline(-3, color="grey", lw=0.8)
    ax.fill_between(
        [0, 1 / 3], -3, 1, color="tab:green", alpha=0.12,
        label="a third of the near misses, recall within 3 points overall",
    )  # fmt: skip
    ax.set_xlim(0, 1.05)
    ax.set_xlabel("near-miss runs warned / constant velocity's")
    ax.set_ylabel("recall@1s - constant velocity's, points (all families)")
    ax.set_title(
        f"Hold-back trees fitted on {title} itself, out of fold\n"
        "filled: every family's paired lower bound >= -3 points",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="lower right")
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")


if __name__ == "__main__":
    raise SystemExit(main())
