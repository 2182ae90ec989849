"""The image-mode tree judged at the real 1 s horizon, leave one file out.

For each log k: a tree is trained on the other logs and judged on k; its depth, dead
zone and gain shrinkage are chosen by an inner leave-one-out inside those training logs
(train on all but one of them, validate on that one), never by looking at log k. The
tree is the paper's ID3 over the authors' (phi, vx, vy) bins, split on the case of the
next second; its leaves carry velocity gains (monopic.tree.model.LeafValue), so it
corrects constant velocity rather than replacing the measured speed by a bin average.

Every method is judged by |centre(t + 1 s) - predicted(t)| on the scored rows (after the
warm-up, with a full next second), the future centre interpolated from the log's own
timestamps. Constant velocity uses the same velocity as the retrained tree (the trailing
window's least-squares slope); the shipped tree is judged on the velocity it was trained
on (VelocityEstimator) and was trained on all four authors' logs, so it is in-sample.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from monopic.cases import Case
from monopic.predict.base import Predictor
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from monopic.replay.dataset import PreparedLog
from monopic.replay.metrics import horizon_errors
from monopic.replay.training import DEFAULT_MIN_SAMPLES, TrainOptions, train_on_logs, trained_on
from monopic.tree.model import LeafValue, Placement, TreeModel, TreePredictor

VELOCITY_WINDOW_S = 0.5
# The candidates the inner validation chooses from, most conservative first (ties go to
# the earlier one): shallow trees, strong shrinkage toward constant velocity.
DEPTHS = (1, 2, 3)
SHRINKS = (100.0, 10.0, 1.0)
DEAD_ZONES = (10.0, 15.0, 25.0, 40.0)
# A tree prediction "differs" from constant velocity's when they are this far apart (px).
DIFFER_PX = 1.0


def candidate_grid(
    depths: Sequence[int] = DEPTHS,
    shrinks: Sequence[float] = SHRINKS,
    dead_zones: Sequence[float] = DEAD_ZONES,
) -> tuple[TrainOptions, ...]:
    """Every (depth, shrink, dead zone) as training options for velocity-gain trees."""
    return tuple(
        TrainOptions(
            discretiser="authors",
            dead_zone=dz,
            min_samples=DEFAULT_MIN_SAMPLES,
            max_depth=depth,
            leaf_value=LeafValue.VELOCITY_GAIN.value,
            shrink=shrink,
        )
        for depth, shrink, dz in itertools.product(depths, shrinks, dead_zones)
    )


def leave_one_out(n: int) -> list[tuple[int, tuple[int, ...]]]:
    """(judged index, training indices) for each of `n` files; training never holds it."""
    if n < 2:
        raise ValueError(f"leave one file out needs at least 2 files, got {n}")
    return [(k, tuple(j for j in range(n) if j != k)) for k in range(n)]


def predict_centres(predictor: Predictor, log: PreparedLog) -> tuple[np.ndarray, tuple[Case, ...]]:
    """(n, 2) predicted centres and the cases, one per row of `log`, at its horizon."""
    preds = [predictor.predict(f, log.horizon) for f in log.features]
    return np.array([p.center for p in preds], dtype=float), tuple(p.case for p in preds)


def median_error(log: PreparedLog, predicted: np.ndarray) -> float:
    """Median horizon error (px) over the scored rows."""
    s = log.scored
    return float(np.median(horizon_errors(log.future_center[s], predicted[s])))


@dataclass(frozen=True)
class Selection:
    """The candidate the inner validation chose, and its score."""

    options: TrainOptions
    worst_ratio: float  # worst validation file's median error, tree / constant velocity
    mean_ratio: float
    candidates: int


def select_options(train: Sequence[PreparedLog], grid: Sequence[TrainOptions]) -> Selection:
    """Inner leave-one-out over `train`: the candidate whose worst validation file has the
    lowest median-error ratio to constant velocity (then the lowest mean ratio; then the
    earlier candidate). Matches the goal: at or below constant velocity on every log."""
    if len(train) < 2:
        raise ValueError("choosing the tree's options needs at least 2 training files")
    if not grid:
        raise ValueError("no candidate options to choose from")
    cv = ConstantVelocityPredictor()
    cv_median = [median_error(p, predict_centres(cv, p)[0]) for p in train]
    best: Selection | None = None
    for options in grid:
        ratios = []
        for j, inner in leave_one_out(len(train)):
            model = train_on_logs([train[i] for i in inner], options)
            pred = predict_centres(TreePredictor(model, Placement.LEAF), train[j])[0]
            ratios.append(median_error(train[j], pred) / max(cv_median[j], 1e-9))
        s = Selection(options, max(ratios), float(np.mean(ratios)), len(grid))
        if best is None or (s.worst_ratio, s.mean_ratio) < (best.worst_ratio, best.mean_ratio):
            best = s
    assert best is not None
    return best


@dataclass(frozen=True)
class ErrorStats:
    """Median and 90th percentile of horizon errors (px) over some rows."""

    n: int
    median: float
    p90: float

    @classmethod
    def of(cls, errors: np.ndarray) -> ErrorStats:
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            return cls(0, float("nan"), float("nan"))
        return cls(int(e.size), float(np.median(e)), float(np.percentile(e, 90)))


@dataclass(frozen=True)
class FoldResult:
    """One judged log: every method's predictions on its rows and what trained the tree."""

    judged: PreparedLog  # features with the window velocity
    shipped_view: PreparedLog  # the same log with the shipped tree's velocity
    model: TreeModel
    selection: Selection
    training: tuple[str, ...]
    tree: np.ndarray
    tree_cases: tuple[Case, ...]
    constant_velocity: np.ndarray
    cv_cases: tuple[Case, ...]
    shipped: np.ndarray
    shipped_cases: tuple[Case, ...]
    shipped_in_sample: bool

    def errors(self, predicted: np.ndarray) -> np.ndarray:
        s = self.judged.scored
        return horizon_errors(self.judged.future_center[s], predicted[s])

    def stats(self, predicted: np.ndarray) -> ErrorStats:
        return ErrorStats.of(self.errors(predicted))

    @property
    def differs(self) -> np.ndarray:
        """Scored rows where the tree's prediction is over DIFFER_PX from constant velocity's."""
        s = self.judged.scored
        gap = np.hypot(*(self.tree[s] - self.constant_velocity[s]).T)
        return gap > DIFFER_PX

    def displacement(self, predicted: np.ndarray) -> np.ndarray:
        """(m, 2) predicted move over the horizon on the scored rows, px."""
        s = self.judged.scored
        log = self.judged.log
        return predicted[s] - np.column_stack([log.center_x, log.center_y])[s]

    @property
    def actual_displacement(self) -> np.ndarray:
        """(m, 2) the centre's actual move over the horizon on the scored rows, px."""
        return self.displacement(self.judged.future_center)

    def case_accuracy(self, cases: Sequence[Case]) -> float:
        idx = np.flatnonzero(self.judged.scored)
        if idx.size == 0:
            return float("nan")
        return float(np.mean([cases[i] == self.judged.labels[i] for i in idx]))


def judge_leave_one_out(
    judged: Sequence[PreparedLog],
    shipped_views: Sequence[PreparedLog],
    shipped: TreeModel,
    grid: Sequence[TrainOptions],
) -> list[FoldResult]:
    """Train on all logs but one (options chosen inside them), judge on that one; for each."""
    if len(judged) != len(shipped_views):
        raise ValueError("every log needs both velocity views")
    if len(judged) < 3:
        raise ValueError(
            f"need at least 3 logs (train on the others, choose options by leave-one-out "
            f"inside them), got {len(judged)}"
        )
    cv = ConstantVelocityPredictor()
    shipped_predictor = TreePredictor(shipped, Placement.LEAF)
    results = []
    for k, train_idx in leave_one_out(len(judged)):
        train = [judged[i] for i in train_idx]
        selection = select_options(train, grid)
        model = train_on_logs(train, selection.options)
        if trained_on(model, judged[k].log.sha256):
            raise ValueError(f"{judged[k].log.name} is in its own training data (a duplicate?)")
        tree, tree_cases = predict_centres(TreePredictor(model, Placement.LEAF), judged[k])
        cvp, cv_cases = predict_centres(cv, judged[k])
        sp, sp_cases = predict_centres(shipped_predictor, shipped_views[k])
        results.append(
            FoldResult(
                judged=judged[k],
                shipped_view=shipped_views[k],
                model=model,
                selection=selection,
                training=tuple(p.log.name for p in train),
                tree=tree,
                tree_cases=tree_cases,
                constant_velocity=cvp,
                cv_cases=cv_cases,
                shipped=sp,
                shipped_cases=sp_cases,
                shipped_in_sample=trained_on(shipped, judged[k].log.sha256),
            )
        )
    return results


def _corr(a: np.ndarray, b: np.ndarray) -> float:
    """Pearson correlation, NaN when either side does not vary."""
    if a.size < 2 or np.std(a) == 0 or np.std(b) == 0:
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def _f(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{x:.1f}"


def _pct(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{100 * x:.0f} %"


def format_table(results: Sequence[FoldResult]) -> str:
    """The per-log table (Markdown) and the options each fold chose."""
    window = results[0].judged.velocity_window
    lines = [
        f"Horizon {results[0].judged.horizon:g} s, leave one file out; constant velocity and "
        f"the retrained tree from the trailing {window:g} s least-squares velocity; errors px.",
        "",
        "| log | rows | retrained tree median / p90 | constant velocity median / p90 "
        "| shipped tree median / p90 | tree differs from CV (> "
        f"{DIFFER_PX:g} px) | on those rows: tree / CV median | case acc: retrained / "
        "shipped / CV |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in results:
        t, c, s = r.stats(r.tree), r.stats(r.constant_velocity), r.stats(r.shipped)
        d = r.differs
        e_t, e_c = r.errors(r.tree)[d], r.errors(r.constant_velocity)[d]
        on = f"{_f(ErrorStats.of(e_t).median)} / {_f(ErrorStats.of(e_c).median)}"
        flag = " (in-sample)" if r.shipped_in_sample else ""
        acc = " / ".join(
            _pct(r.case_accuracy(x)) for x in (r.tree_cases, r.shipped_cases, r.cv_cases)
        )
        lines.append(
            f"| {r.judged.log.name} | {t.n} | {_f(t.median)} / {_f(t.p90)} "
            f"| {_f(c.median)} / {_f(c.p90)} | {_f(s.median)} / {_f(s.p90)}{flag} "
            f"| {_pct(float(d.mean()) if d.size else float('nan'))} | {on} | {acc} |"
        )
    lines += [
        "",
        "Chosen by inner leave-one-out on the training logs (worst / mean ratio of "
        "validation median error to constant velocity's):",
    ]
    for r in results:
        o = r.selection.options
        lines.append(
            f"- {r.judged.log.name}: trained on {', '.join(r.training)}; depth {o.max_depth}, "
            f"dead zone {o.dead_zone:g}, shrink {o.shrink:g} of {r.selection.candidates} "
            f"candidates (validation {r.selection.worst_ratio:.3f} / "
            f"{r.selection.mean_ratio:.3f}); tree depth {r.model.tree.depth}, "
            f"{sum(1 for n in r.model.tree.nodes() if n.is_leaf)} leaves"
        )
    lines += [
        "",
        "Moves over the horizon on the scored rows (px): median length of the actual move and "
        "of each method's predicted move; mean (x, y); correlation per axis of the actual move "
        "with constant velocity's.",
        "",
        "| log | actual: median / mean (x, y) | constant velocity | retrained tree "
        "| shipped tree | corr(actual, CV) x / y |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in results:
        actual = r.actual_displacement
        cells = []
        for d in (
            actual,
            r.displacement(r.constant_velocity),
            r.displacement(r.tree),
            r.displacement(r.shipped),
        ):
            mx, my = d.mean(axis=0) if d.size else (float("nan"), float("nan"))
            cells.append(f"{_f(float(np.median(np.hypot(*d.T))))} / ({_f(mx)}, {_f(my)})")
        cvd = r.displacement(r.constant_velocity)
        corr = " / ".join(
            "-" if not np.isfinite(c) else f"{c:+.2f}"
            for c in (_corr(actual[:, ax], cvd[:, ax]) for ax in range(2))
        )
        lines.append(f"| {r.judged.log.name} | {' | '.join(cells)} | {corr} |")
    verdict = [
        r.judged.log.name
        for r in results
        if r.stats(r.tree).median > r.stats(r.constant_velocity).median
    ]
    lines.append("")
    if verdict:
        lines.append(f"Retrained tree above constant velocity's median on: {', '.join(verdict)}.")
    else:
        lines.append("Retrained tree at or below constant velocity's median on every log.")
    return "\n".join(lines) + "\n"
