"""Metrics over sweep results: collision-warning quality, cases, phi, positions, pose, latency.

Definitions (the report states them too):

- Frame level: a frame is positive when the ground truth shows contact within the
  horizon (the robot keeping its course); a warning on a negative frame is a false alarm.
  Recall = TP / (TP + FN), precision = TP / (TP + FP), false-alarm rate = FP / (FP + TN).
  A predictor that made no decision on a frame (no pose, or no ground point) did not warn.
- Run level: a collision run has at least one positive frame. Its warning onset is the
  first warning while the ground truth is on a collision course (a contact ahead within
  the truth's lookahead); lead time = contact time - onset. Recall = warned collision
  runs / collision runs, with its 95 % Wilson lower bound; recall@1s counts only onsets
  at least 1 s before contact, "timely" at least 1.7 s (Euro NCAP's forward collision
  warning bar, for car-scale families). A non-collision run is warned when any frame
  warns; near-miss runs are the non-collision runs of near-miss families.
- Nuisance warnings: warning onsets (a warned frame after an unwarned one) while the
  truth has no contact ahead at all (no collision course within its lookahead), per
  hour of such frames with the pedestrian in view: what a driver is bothered with.
- Flicker: warning episodes that begin within FLICKER_S of the end of the previous one
  (on, off, on again within a second), as a share of episodes.
- Latency applied: the pipeline runs in real time on one core: it takes a frame only when
  it is idle, and a frame's warning exists from capture time + that frame's measured
  latency (pose + features + this predictor's share of predict and warning). Frames that
  arrive while it is busy are skipped. Decisions are those of the full-rate run (the
  features' velocity windows assume every frame), which favours the pipeline slightly.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from monopic.cases import Case
from sim.runs.code_version import UNKNOWN
from sim.runs.result import ABLATION, MAIN, DecisionColumns, RunResult

Z95 = 1.959963984540054
TIMELY_TTC = 1.7  # s, Euro NCAP's timely forward collision warning
LEAD_GOAL = 1.0  # s, the warning's goal: at least this long before contact (recall@1s)
RANGE_BINS = (0.0, 5.0, 10.0, 15.0, 20.0, 30.0, 50.0, 1e9)  # m
HEIGHT_BINS = (0.0, 30.0, 60.0, 120.0, 240.0, 1e9)  # px
RADII = tuple(range(0, 301, 5))  # px, for accuracy against error radius
FLICKER_S = 1.0  # s: a warning that comes back this soon after it ended flickers


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval (low, high) of a binomial proportion; (nan, nan) when n = 0."""
    if n == 0:
        return math.nan, math.nan
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    return max(0.0, centre - half), min(1.0, centre + half)


def paired_difference(
    both: int, only_first: int, only_second: int, neither: int, z: float = Z95
) -> tuple[float, float, float]:
    """Difference of two paired proportions (first - second) with its 95 % interval.

    Newcombe's hybrid score interval for paired data (method 10 of R. G. Newcombe,
    "Improved confidence intervals for the difference between binomial proportions based
    on paired data", Statistics in Medicine 17 (1998) 2635-2650): the two Wilson
    intervals combined with the correlation of the pairs. Why paired: both methods see
    the same runs, so a run hard for one is mostly hard for the other.
    Returns (difference, low, high); nan when there are no pairs.
    """
    n = both + only_first + only_second + neither
    if n == 0:
        return math.nan, math.nan, math.nan
    p1, p2 = (both + only_first) / n, (both + only_second) / n
    l1, u1 = wilson(both + only_first, n, z)
    l2, u2 = wilson(both + only_second, n, z)
    margins = (both + only_first) * (only_second + neither) * (both + only_second)
    margins *= only_first + neither
    # The correlation of the pairs, with Newcombe's continuity correction of a positive one.
    cross = both * neither - only_first * only_second
    cross = cross - n / 2 if cross > n / 2 else (cross if cross < 0 else 0.0)
    phi = cross / math.sqrt(margins) if margins else 0.0
    low = math.sqrt(max(0.0, (p1 - l1) ** 2 - 2 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) ** 2))
    high = math.sqrt(max(0.0, (u1 - p1) ** 2 - 2 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) ** 2))
    return p1 - p2, p1 - p2 - low, p1 - p2 + high


def ratio(num: float, den: float) -> float:
    return num / den if den else math.nan


def method_name(pipeline: str, key: str) -> str:
    """'rules/image' for the real pipeline, 'gtcrop:rules/image' for the ablation."""
    return key if pipeline == MAIN else f"{pipeline}:{key}"


def split_method(method: str) -> tuple[str, str]:
    if ":" in method:
        pipeline, key = method.split(":", 1)
        return pipeline, key
    return MAIN, method


def methods(rows: Iterable[RunResult]) -> list[str]:
    """Every (pipeline, predictor) pair present, main pipeline first, in a stable order."""
    found: dict[str, None] = {}
    for row in rows:
        for pipeline in (MAIN, ABLATION):
            columns = row.pipelines.get(pipeline)
            for key in columns.decisions if columns else ():
                found[method_name(pipeline, key)] = None
    return sorted(found, key=_method_order)


_ORDER = {
    "image": 0,
    "ground": 1,
    "rules": 0,
    "tree": 1,
    "constant-velocity": 2,
    "intent-tree": 3,
}


def _method_order(method: str) -> tuple[int, int, int, str]:
    """Main pipeline first; image mode, then ground; rules, tree, constant velocity."""
    pipeline, key = split_method(method)
    name, _, mode = key.partition("/")
    return (pipeline != MAIN, _ORDER.get(mode, 9), _ORDER.get(name, 9), key)


def dedupe(rows: Iterable[RunResult]) -> list[RunResult]:
    """One row per run id (the first), so a file appended twice counts each run once."""
    seen: set[str] = set()
    out = []
    for row in rows:
        if row.id not in seen:
            seen.add(row.id)
            out.append(row)
    return out


# -- per run ----------------------------------------------------------------------------


@dataclass(frozen=True)
class FrameCounts:
    tp: int = 0
    fp: int = 0
    fn: int = 0
    tn: int = 0

    def __add__(self, other: FrameCounts) -> FrameCounts:
        return FrameCounts(
            self.tp + other.tp, self.fp + other.fp, self.fn + other.fn, self.tn + other.tn
        )

    @property
    def recall(self) -> float:
        return ratio(self.tp, self.tp + self.fn)

    @property
    def precision(self) -> float:
        return ratio(self.tp, self.tp + self.fp)

    @property
    def false_alarm_rate(self) -> float:
        return ratio(self.fp, self.fp + self.tn)


@dataclass(frozen=True)
class RunOutcome:
    """One run judged for one method (pipeline + predictor)."""

    id: str
    family: str
    kind: str
    scale: str
    case: int
    robot_speed: float
    horizon: float
    collision_run: bool
    contact_time: float | None  # when the footprints first meet (truth), None if never
    warned: bool  # any warning frame
    onset: float | None  # first warning while on a collision course
    onset_latency: float | None  # the same with the measured latency applied
    frames: FrameCounts
    behaviour: str = "rail"  # the pedestrian's walker model
    cues: bool = False  # whether it showed intent cues
    lighting: str = ""  # the lighting preset (sim.scenario.lighting)
    nuisance_onsets: int = 0  # warning onsets while no contact is ahead at all
    clear_seconds: float = 0.0  # s in view with no contact ahead (the nuisance exposure)
    episodes: int = 0  # warning episodes (runs of warned frames)
    flickers: int = 0  # episodes beginning within FLICKER_S of the previous one's end

    @property
    def lead(self) -> float | None:
        if self.onset is None or self.contact_time is None:
            return None
        return self.contact_time - self.onset

    @property
    def lead_latency(self) -> float | None:
        if self.onset_latency is None or self.contact_time is None:
            return None
        lead = self.contact_time - self.onset_latency
        return lead if lead >= 0 else None

    @property
    def near_miss(self) -> bool:
        return self.kind == "near-miss" and not self.collision_run


def _decisions(row: RunResult, method: str) -> DecisionColumns | None:
    pipeline, key = split_method(method)
    columns = row.pipelines.get(pipeline)
    return columns.decisions.get(key) if columns else None


def run_case(row: RunResult) -> int:
    """The run's case: the one the scenario was built for, else the most common true case."""
    case = row.scenario.case
    if case is not None:
        return int(case)
    return Counter(row.truth.case).most_common(1)[0][0]


def contact_time(row: RunResult) -> float | None:
    """First contact by the truth: where frames on a collision course say it will happen."""
    return earliest_contact(row.truth.t, row.truth.ttc)


def earliest_contact(times: Sequence[float | None], ttcs: Sequence[float | None]) -> float | None:
    """The earliest frame time plus its time to collision (None: no frame has one)."""
    ends = [float(t) + float(c) for t, c in zip(times, ttcs, strict=True)
            if c is not None and t is not None]  # fmt: skip
    return min(ends) if ends else None


def frame_latency_ms(row: RunResult, pipeline: str, k: int) -> float | None:
    """Measured latency of frame k for one predictor: shared stages + its share of the rest."""
    ms = row.timing.ms.get(pipeline)
    if not ms:
        return None
    pose, feats = ms["pose"][k], ms["features"][k]
    if pose is None:
        return None
    decisions = row.pipelines[pipeline].decisions
    n = sum(1 for cols in decisions.values() if cols.warn[k] is not None)
    shared = (ms["predict"][k] or 0.0) + (ms["warning"][k] or 0.0)
    return pose + (feats or 0.0) + (shared / n if n else 0.0)


def available_times(row: RunResult, pipeline: str) -> list[float | None]:
    """When each frame's outputs exist on a real-time single-core pipeline (None: skipped)."""
    times = row.truth.t
    out: list[float | None] = []
    busy_until = -math.inf
    for k, t in enumerate(times):
        latency = frame_latency_ms(row, pipeline, k)
        if latency is None:
            out.append(None)
            continue
        if t + 1e-9 < busy_until:
            out.append(None)
            continue
        busy_until = t + latency / 1000.0
        out.append(busy_until)
    return out


def judge_run(row: RunResult, method: str) -> RunOutcome:
    truth = row.truth
    cols = _decisions(row, method)
    n = len(truth.t)
    warn = [bool(v) for v in cols.warn] if cols else [False] * n
    positive = [bool(v) for v in truth.collision]
    on_course = [c is not None for c in truth.ttc]
    counts = FrameCounts(
        tp=sum(w and p for w, p in zip(warn, positive, strict=True)),
        fp=sum(w and not p for w, p in zip(warn, positive, strict=True)),
        fn=sum(p and not w for w, p in zip(warn, positive, strict=True)),
        tn=sum(not w and not p for w, p in zip(warn, positive, strict=True)),
    )
    contact = contact_time(row)
    onset = next((truth.t[k] for k in range(n) if warn[k] and on_course[k]), None)
    pipeline, _ = split_method(method)
    avail = available_times(row, pipeline)
    onset_latency = next(
        (avail[k] for k in range(n) if warn[k] and on_course[k] and avail[k] is not None), None
    )
    scenario = row.scenario
    in_view = [bool(v) for v in truth.in_frame]
    clear = [not c and seen for c, seen in zip(on_course, in_view, strict=True)]
    onsets = [k for k in range(n) if warn[k] and (k == 0 or not warn[k - 1])]
    ends = [k for k in range(n) if warn[k] and (k == n - 1 or not warn[k + 1])]
    flickers = sum(
        1
        for previous_end, start in zip(ends[:-1], onsets[1:], strict=False)
        if truth.t[start] - truth.t[previous_end] <= FLICKER_S + 1e-9
    )
    return RunOutcome(
        id=row.id,
        family=row.family,
        kind=row.kind,
        scale=row.scale,
        case=run_case(row),
        robot_speed=float(scenario.robot_speed),
        horizon=float(scenario.horizon),
        collision_run=any(positive),
        contact_time=contact if any(positive) else None,
        warned=any(warn),
        onset=onset,
        onset_latency=onset_latency,
        frames=counts,
        behaviour=scenario.behaviour,
        cues=scenario.cues,
        lighting=scenario.lighting,
        nuisance_onsets=sum(clear[k] for k in onsets),
        clear_seconds=sum(clear) * scenario.dt,
        episodes=len(onsets),
        flickers=flickers,
    )


# -- warning summaries ------------------------------------------------------------------


@dataclass(frozen=True)
class WarningSummary:
    """Collision-warning quality of one method over a group of runs."""

    method: str
    runs: int
    collision_runs: int
    warned: int  # collision runs with a warning onset before contact
    warned_1s: int  # ... at least LEAD_GOAL before contact
    timely: int  # ... at least TIMELY_TTC before contact
    warned_latency: int
    warned_1s_latency: int
    near_miss_runs: int
    near_miss_warned: int
    other_runs: int  # non-collision runs that are not near-miss-family runs
    other_warned: int
    frames: FrameCounts
    leads: tuple[float, ...]
    nuisance_onsets: int = 0
    clear_seconds: float = 0.0
    episodes: int = 0
    flickers: int = 0

    @property
    def nuisance_per_hour(self) -> float:
        return ratio(self.nuisance_onsets, self.clear_seconds / 3600.0)

    @property
    def flicker_share(self) -> float:
        return ratio(self.flickers, self.episodes)

    @property
    def recall(self) -> float:
        return ratio(self.warned, self.collision_runs)

    @property
    def recall_low(self) -> float:
        return wilson(self.warned, self.collision_runs)[0]

    @property
    def recall_1s(self) -> float:
        return ratio(self.warned_1s, self.collision_runs)

    @property
    def recall_1s_low(self) -> float:
        return wilson(self.warned_1s, self.collision_runs)[0]

    @property
    def timely_share(self) -> float:
        return ratio(self.timely, self.collision_runs)

    @property
    def recall_latency(self) -> float:
        return ratio(self.warned_latency, self.collision_runs)

    @property
    def near_miss_warned_share(self) -> float:
        return ratio(self.near_miss_warned, self.near_miss_runs)

    @property
    def lead_p50(self) -> float:
        return float(np.median(self.leads)) if self.leads else math.nan

    @property
    def meets_goal(self) -> bool:
        """The warning's goal: recall@1s lower bound >= 0.95, <= 5 % of near misses warned."""
        nm_ok = self.near_miss_runs == 0 or self.near_miss_warned_share <= 0.05
        return self.collision_runs > 0 and self.recall_1s_low >= 0.95 and nm_ok


def summarise(method: str, outcomes: Sequence[RunOutcome]) -> WarningSummary:
    col = [o for o in outcomes if o.collision_run]
    leads = [o.lead for o in col if o.lead is not None]
    leads_lat = [o.lead_latency for o in col if o.lead_latency is not None]
    near = [o for o in outcomes if o.near_miss]
    other = [o for o in outcomes if not o.collision_run and not o.near_miss]
    frames = sum((o.frames for o in outcomes), FrameCounts())
    return WarningSummary(
        method=method,
        runs=len(outcomes),
        collision_runs=len(col),
        warned=len(leads),
        warned_1s=sum(lead >= LEAD_GOAL for lead in leads),
        timely=sum(lead >= TIMELY_TTC for lead in leads),
        warned_latency=len(leads_lat),
        warned_1s_latency=sum(lead >= LEAD_GOAL for lead in leads_lat),
        near_miss_runs=len(near),
        near_miss_warned=sum(o.warned for o in near),
        other_runs=len(other),
        other_warned=sum(o.warned for o in other),
        frames=frames,
        leads=tuple(leads),
        nuisance_onsets=sum(o.nuisance_onsets for o in outcomes),
        clear_seconds=sum(o.clear_seconds for o in outcomes),
        episodes=sum(o.episodes for o in outcomes),
        flickers=sum(o.flickers for o in outcomes),
    )


def group_by(
    outcomes: Sequence[RunOutcome], key: Callable[[RunOutcome], Any]
) -> dict[Any, list[RunOutcome]]:
    groups: dict[Any, list[RunOutcome]] = defaultdict(list)
    for o in outcomes:
        groups[key(o)].append(o)
    return dict(sorted(groups.items(), key=lambda kv: (str(type(kv[0])), kv[0])))


# -- cases, phi, positions, pose, latency -------------------------------------------


@dataclass(frozen=True)
class CaseSummary:
    method: str
    frames: int  # frames with a decision
    correct: int
    confusion: np.ndarray  # 9 x 9 counts, rows true case 1-9, columns predicted

    @property
    def accuracy(self) -> float:
        return ratio(self.correct, self.frames)

    @property
    def most_predicted(self) -> tuple[Case, float] | None:
        """The case this method says most often and its share of its decisions: a method
        that answers one case whatever the truth shows up here, not only as low accuracy."""
        said = self.confusion.sum(axis=0)
        if not said.sum():
            return None
        k = int(np.argmax(said))
        return Case(k + 1), float(said[k] / said.sum())


def case_summary(rows: Sequence[RunResult], method: str) -> CaseSummary:
    confusion = np.zeros((9, 9), dtype=int)
    for row in rows:
        cols = _decisions(row, method)
        if not cols:
            continue
        for truth_case, pred in zip(row.truth.case, cols.case, strict=True):
            if pred is not None:
                confusion[truth_case - 1, pred - 1] += 1
    return CaseSummary(method, int(confusion.sum()), int(np.trace(confusion)), confusion)


BEFORE_CHANGE_S = 1.5  # s: the window before each change of behaviour the intent is judged in


@dataclass(frozen=True)
class Accuracy:
    """Right answers over frames, on all frames and on those just before a change."""

    frames: int = 0
    correct: int = 0
    before_frames: int = 0
    before_correct: int = 0

    def __add__(self, other: Accuracy) -> Accuracy:
        return Accuracy(
            self.frames + other.frames,
            self.correct + other.correct,
            self.before_frames + other.before_frames,
            self.before_correct + other.before_correct,
        )

    @property
    def accuracy(self) -> float:
        return ratio(self.correct, self.frames)

    @property
    def before_accuracy(self) -> float:
        return ratio(self.before_correct, self.before_frames)


def before_change(times: Sequence[float | None], labels: Sequence[str | None]) -> list[bool]:
    """Frames within BEFORE_CHANGE_S before a frame whose true intent differs from the last."""
    changes = [
        t for k, t in enumerate(times)
        if k and t is not None and labels[k] is not None and labels[k - 1] is not None
        and labels[k] != labels[k - 1]
    ]  # fmt: skip
    return [t is not None and any(0 < c - t <= BEFORE_CHANGE_S for c in changes) for t in times]


def _accuracy(said: Sequence[Any], truth: Sequence[Any], near: Sequence[bool]) -> Accuracy:
    out = Accuracy()
    for s, t, b in zip(said, truth, near, strict=True):
        if s is None or t is None:
            continue
        hit = int(s == t)
        out = out + Accuracy(1, hit, int(b), hit * int(b))
    return out


@dataclass(frozen=True)
class IntentSummary:
    """Intent and case accuracy of a predictor that states an intent, beside the
    current-velocity baseline's case accuracy on the same frames."""

    method: str
    intent: Accuracy
    case: Accuracy
    baseline_case: Accuracy  # truth.case_now (the case of the velocity now) as the answer
    # Frames where its ground point and constant velocity's (same pipeline) are both known
    # against the truth, those where they differ by more than DIFFERS_M, and the median
    # error (m) of each on the differing frames.
    compared: int = 0
    differing: int = 0
    error_m: float = math.nan
    cv_error_m: float = math.nan

    @property
    def differing_share(self) -> float:
        return ratio(self.differing, self.compared)


DIFFERS_M = 0.05  # m: closer than this, the two points are the same prediction


def intent_summary(rows: Sequence[RunResult], method: str) -> IntentSummary | None:
    """None when the method states no intent or the lines carry no intent labels."""
    intent = case = baseline = Accuracy()
    seen = False
    pipeline, key = split_method(method)
    cv_method = method_name(pipeline, f"constant-velocity/{key.partition('/')[2]}")
    compared, errors, cv_errors = 0, [], []
    for row in rows:
        cols = _decisions(row, method)
        truth = row.truth
        if not cols or not cols.intent or not truth.intent:
            continue
        seen = True
        cv = _decisions(row, cv_method)
        for k, future in enumerate(truth.future if cv else ()):
            mine, theirs = cols.ground[k], cv.ground[k] if cv else None
            if mine is None or theirs is None or future is None:
                continue
            if None in mine + theirs + future:
                continue
            compared += 1
            if math.dist(mine, theirs) > DIFFERS_M:
                errors.append(math.dist(mine, future))
                cv_errors.append(math.dist(theirs, future))
        near = before_change(truth.t, truth.intent)
        decided = [w is not None for w in cols.warn]
        intent = intent + _accuracy(cols.intent, truth.intent, near)
        case = case + _accuracy(cols.case, truth.case, near)
        now = [c if d else None for c, d in zip(truth.case_now, decided, strict=True)]
        baseline = baseline + _accuracy(now, truth.case, near)
    if not seen:
        return None
    median = lambda v: float(np.median(v)) if v else math.nan  # noqa: E731
    return IntentSummary(
        method, intent, case, baseline, compared, len(errors), median(errors), median(cv_errors)
    )


@dataclass(frozen=True)
class PositionSummary:
    """Error of the predicted point at the real horizon (image px; ground m when predicted)."""

    method: str
    px: tuple[float, ...]
    m: tuple[float, ...]

    def px_percentile(self, q: float) -> float:
        return float(np.percentile(self.px, q)) if self.px else math.nan

    def m_percentile(self, q: float) -> float:
        return float(np.percentile(self.m, q)) if self.m else math.nan

    def accuracy_within(self, radii: Sequence[float] = RADII) -> np.ndarray:
        """Share of predictions within each error radius (px), the paper's accuracy curve."""
        errors = np.asarray(self.px)
        if errors.size == 0:
            return np.full(len(radii), math.nan)
        return np.array([(errors <= r).mean() for r in radii])


def position_summary(rows: Sequence[RunResult], method: str) -> PositionSummary:
    """Predicted foot point at frame k vs the true foot point at frame k + horizon / dt."""
    px_errors: list[float] = []
    m_errors: list[float] = []
    for row in rows:
        cols = _decisions(row, method)
        if not cols:
            continue
        truth = row.truth
        ahead = int(round(row.scenario.horizon / row.scenario.dt))
        n = len(truth.t)
        for k in range(n):
            pred = cols.foot[k]
            if pred is not None and k + ahead < n and truth.foot[k + ahead] is not None:
                true = truth.foot[k + ahead]
                if None not in pred and None not in true:
                    px_errors.append(math.dist(pred, true))
            ground, future = cols.ground[k], truth.future[k]
            if ground is not None and future is not None and None not in ground + future:
                m_errors.append(math.dist(ground, future))
    return PositionSummary(method, tuple(px_errors), tuple(m_errors))


@dataclass(frozen=True)
class PhiSummary:
    pipeline: str
    frames: int
    mae: float  # degrees
    correlation: float
    pairs: tuple[tuple[float, float], ...] = field(repr=False)  # (true, measured)


def phi_summary(rows: Sequence[RunResult], pipeline: str = MAIN) -> PhiSummary:
    pairs = []
    for row in rows:
        columns = row.pipelines.get(pipeline)
        if columns is None:
            continue
        for true, got in zip(row.truth.phi, columns.phi, strict=True):
            if true is not None and got is not None:
                pairs.append((float(true), float(got)))
    if not pairs:
        return PhiSummary(pipeline, 0, math.nan, math.nan, ())
    arr = np.array(pairs)
    corr = (
        float(np.corrcoef(arr.T)[0, 1]) if len(arr) > 2 and arr.std(axis=0).min() > 0 else math.nan
    )
    return PhiSummary(
        pipeline, len(arr), float(np.abs(arr[:, 0] - arr[:, 1]).mean()), corr, tuple(pairs)
    )


@dataclass(frozen=True)
class FoundShare:
    """Share of frames with a pose, over frames where the pedestrian is in view."""

    label: str
    edges: tuple[float, ...]
    seen: tuple[int, ...]
    found: tuple[int, ...]

    def shares(self) -> list[float]:
        return [ratio(f, s) for f, s in zip(self.found, self.seen, strict=True)]


def found_shares(
    rows: Sequence[RunResult], pipeline: str = MAIN, min_visible: float = 0.5
) -> tuple[FoundShare, FoundShare]:
    """Pose found share by distance (m) and by true apparent height (px)."""
    by_range = ([0] * (len(RANGE_BINS) - 1), [0] * (len(RANGE_BINS) - 1))
    by_height = ([0] * (len(HEIGHT_BINS) - 1), [0] * (len(HEIGHT_BINS) - 1))
    for row in rows:
        columns = row.pipelines.get(pipeline)
        if columns is None:
            continue
        truth = row.truth
        for k, hit in enumerate(columns.found):
            visible = truth.visible[k]
            if not truth.in_frame[k] or visible is None or visible < min_visible:
                continue
            for (seen, got), edges, value in (
                (by_range, RANGE_BINS, truth.range[k]),
                (by_height, HEIGHT_BINS, truth.height[k]),
            ):
                if value is None:
                    continue
                b = int(np.searchsorted(edges, value, side="right")) - 1
                b = min(max(b, 0), len(edges) - 2)
                seen[b] += 1
                got[b] += int(hit)
    return (
        FoundShare("distance (m)", RANGE_BINS, tuple(by_range[0]), tuple(by_range[1])),
        FoundShare("apparent height (px)", HEIGHT_BINS, tuple(by_height[0]), tuple(by_height[1])),
    )


def recall_by_range(
    rows: Sequence[RunResult], method: str
) -> tuple[tuple[float, ...], list[int], list[int]]:
    """Frame-level recall by true distance: (bin edges, positives, warned positives)."""
    pos = [0] * (len(RANGE_BINS) - 1)
    hit = [0] * (len(RANGE_BINS) - 1)
    for row in rows:
        cols = _decisions(row, method)
        truth = row.truth
        for k, positive in enumerate(truth.collision):
            distance = truth.range[k]
            if not positive or distance is None:
                continue
            b = min(int(np.searchsorted(RANGE_BINS, distance, side="right")) - 1, len(pos) - 1)
            pos[b] += 1
            hit[b] += int(bool(cols and cols.warn[k]))
    return RANGE_BINS, pos, hit


@dataclass(frozen=True)
class LatencySummary:
    pipeline: str
    frames: int
    p50: dict[str, float]
    p95: dict[str, float]


def latency_summary(rows: Sequence[RunResult], pipeline: str = MAIN) -> LatencySummary:
    values: dict[str, list[float]] = defaultdict(list)
    frames = 0
    for row in rows:
        ms = row.timing.ms.get(pipeline)
        if not ms:
            continue
        frames += len(ms["total"])
        for stage, column in ms.items():
            values[stage].extend(v for v in column if v is not None)
    p50 = {s: float(np.percentile(v, 50)) for s, v in values.items() if v}
    p95 = {s: float(np.percentile(v, 95)) for s, v in values.items() if v}
    return LatencySummary(pipeline, frames, p50, p95)


# -- everything -----------------------------------------------------------------------


@dataclass(frozen=True)
class SweepMetrics:
    """All metrics of a results file, per method and per grouping."""

    rows: int
    families: tuple[str, ...]
    methods: tuple[str, ...]
    outcomes: dict[str, list[RunOutcome]]  # per method
    overall: dict[str, WarningSummary]
    by_family: dict[str, dict[str, WarningSummary]]  # method -> family -> summary
    by_case: dict[str, dict[int, WarningSummary]]
    by_speed: dict[str, dict[float, WarningSummary]]
    by_scale: dict[str, dict[str, WarningSummary]]
    cases: dict[str, CaseSummary]
    positions: dict[str, PositionSummary]
    phi: dict[str, PhiSummary]
    found: dict[str, tuple[FoundShare, FoundShare]]
    latency: dict[str, LatencySummary]
    seeds: int
    frame_sizes: tuple[str, ...]
    machines: tuple[str, ...]
    codes: tuple[str, ...] = ()  # sim.runs.code_version of the runs ("unknown" before it existed)
    # method -> (walker model, "cues" or "no cues") -> summary
    by_behaviour: dict[str, dict[tuple[str, str], WarningSummary]] = field(default_factory=dict)
    by_lighting: dict[str, dict[str, WarningSummary]] = field(default_factory=dict)  # preset
    intents: dict[str, IntentSummary] = field(default_factory=dict)  # methods stating one


def _machine(row: RunResult) -> str:
    info = row.timing.machine
    return f"{info.cpu} ({info.cores if info.cores is not None else '?'} cores)"


def compute(rows: Sequence[RunResult]) -> SweepMetrics:
    rows = dedupe(rows)
    all_methods = methods(rows)
    outcomes = {m: [judge_run(row, m) for row in rows] for m in all_methods}

    def grouped(key: Callable[[RunOutcome], Any]) -> dict[str, dict[Any, WarningSummary]]:
        return {
            m: {g: summarise(m, os) for g, os in group_by(outcomes[m], key).items()}
            for m in all_methods
        }

    pipelines = [p for p in (MAIN, ABLATION) if any(p in r.pipelines for r in rows)]
    sizes = sorted({f"{r.scenario.camera.width}x{r.scenario.camera.height}" for r in rows})
    machines = sorted({_machine(r) for r in rows})
    return SweepMetrics(
        rows=len(rows),
        families=tuple(sorted({r.family for r in rows})),
        methods=tuple(all_methods),
        outcomes=outcomes,
        overall={m: summarise(m, outcomes[m]) for m in all_methods},
        by_family=grouped(lambda o: o.family),
        by_case=grouped(lambda o: o.case),
        by_speed=grouped(lambda o: round(o.robot_speed, 2)),
        by_scale=grouped(lambda o: o.scale),
        by_behaviour=grouped(lambda o: (o.behaviour, "cues" if o.cues else "no cues")),
        by_lighting=grouped(lambda o: o.lighting),
        cases={m: case_summary(rows, m) for m in all_methods},
        positions={m: position_summary(rows, m) for m in all_methods},
        phi={p: phi_summary(rows, p) for p in pipelines},
        found={p: found_shares(rows, p) for p in pipelines},
        latency={p: latency_summary(rows, p) for p in pipelines},
        seeds=len({r.seed for r in rows}),
        frame_sizes=tuple(sizes),
        machines=tuple(machines),
        codes=tuple(sorted({str(r.code or UNKNOWN) for r in rows})),
        intents={
            m: summary for m in all_methods if (summary := intent_summary(rows, m)) is not None
        },
    )


@dataclass(frozen=True)
class PairedRecall:
    """Two methods judged on the same runs: recall@1s of each on the collision runs, its
    paired difference with Newcombe's interval, and near-miss runs warned by each."""

    collision_runs: int
    warned_1s: tuple[int, int]
    difference: float
    low: float
    high: float
    near_miss_runs: int
    near_miss_warned: tuple[int, int]
    # Collision runs warned 1 s ahead by one method only: the discordant pairs the interval
    # rests on (with none lost in a family of n runs the lower bound is still about -3.3
    # points at n = 96, so these say what a bound cannot).
    only_first: int = 0
    only_second: int = 0


def paired_recall(first: Sequence[RunOutcome], second: Sequence[RunOutcome]) -> PairedRecall:
    """`first` and `second` hold the same runs in the same order (SweepMetrics.outcomes)."""
    if [o.id for o in first] != [o.id for o in second]:
        raise ValueError("paired outcomes must be of the same runs in the same order")
    cells = Counter()
    for a, b in zip(first, second, strict=True):
        if a.collision_run:
            cells[(_warned_1s(a), _warned_1s(b))] += 1
    diff, low, high = paired_difference(
        cells[(True, True)], cells[(True, False)], cells[(False, True)], cells[(False, False)]
    )
    near = [(a, b) for a, b in zip(first, second, strict=True) if a.near_miss]
    return PairedRecall(
        collision_runs=sum(cells.values()),
        warned_1s=(
            cells[(True, True)] + cells[(True, False)],
            cells[(True, True)] + cells[(False, True)],
        ),
        difference=diff,
        low=low,
        high=high,
        near_miss_runs=len(near),
        near_miss_warned=(sum(a.warned for a, _ in near), sum(b.warned for _, b in near)),
        only_first=cells[(True, False)],
        only_second=cells[(False, True)],
    )


def _warned_1s(o: RunOutcome) -> bool:
    return o.lead is not None and o.lead >= LEAD_GOAL


def paired_by_family(m: SweepMetrics, first: str, second: str) -> dict[str, PairedRecall]:
    """paired_recall per family and over all families ("all")."""
    a, b = m.outcomes[first], m.outcomes[second]
    out = {
        family: paired_recall(
            [o for o in a if o.family == family], [o for o in b if o.family == family]
        )
        for family in m.families
    }
    out["all"] = paired_recall(a, b)
    return out
