"""Replay logs through our motion, classification and prediction stages and score them.

Which tree judges which file (never trained on the rows it judges, unless said so):
- a tree given by the caller judges every file (files in its training data are flagged
  in-sample);
- with no tree and two or more files, leave one file out: file k is judged by a tree
  trained on the other files with the given options;
- with no tree and one file, the default tree shipped in the package judges it (flagged
  in-sample if that file was part of its training data).
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from monopic.cases import Case
from monopic.features.record import Features
from monopic.predict.base import Prediction, Predictor
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from monopic.predict.rules import RulePredictor
from monopic.replay.dataset import PreparedLog
from monopic.replay.metrics import (
    PAPER_RADIUS_PX,
    SHARE_RADIUS_PX,
    ErrorSummary,
    horizon_errors,
    paper_metric,
)
from monopic.replay.training import TrainOptions, train_on_logs, trained_on
from monopic.tree.model import Placement, TreeModel, TreePredictor
from monopic.tree.opcount import prediction_ops
from monopic.tree.serialise import load_default_model

TREE_LEAF = "tree, leaf displacement"
TREE_CASE = "tree, case extrapolation"
AUTHORS = "authors' predictions"
CONSTANT_VELOCITY = "constant velocity"
RULES = "rule cascade"
STILL = "standing still"
METHODS = (TREE_LEAF, TREE_CASE, AUTHORS, CONSTANT_VELOCITY, RULES, STILL)


@dataclass(frozen=True)
class MethodRows:
    """One method's prediction for every row of a log (case None when it has none)."""

    name: str
    predicted: np.ndarray  # (n, 2) centre at the horizon
    cases: tuple[Case | None, ...]


@dataclass(frozen=True)
class FileResult:
    prepared: PreparedLog
    model: TreeModel
    tree_note: str
    in_sample: bool
    methods: tuple[MethodRows, ...]
    ops_per_prediction: tuple[float, int, int]  # mean, min, max over all rows

    def method(self, name: str) -> MethodRows:
        for m in self.methods:
            if m.name == name:
                return m
        raise KeyError(name)

    def center(self) -> np.ndarray:
        log = self.prepared.log
        return np.column_stack([log.center_x, log.center_y])

    def paper(self, name: str) -> float:
        return paper_metric(self.center(), self.method(name).predicted)

    def errors(self, name: str) -> np.ndarray:
        s = self.prepared.scored
        return horizon_errors(self.prepared.future_center[s], self.method(name).predicted[s])

    def case_hits(self, name: str) -> tuple[int, int] | None:
        """(correct, judged) against the next-second labels on scored rows."""
        cases = self.method(name).cases
        idx = np.flatnonzero(self.prepared.scored)
        if any(cases[i] is None for i in idx):
            return None
        correct = sum(cases[i] == self.prepared.labels[i] for i in idx)
        return int(correct), int(idx.size)


def _run_predictor(
    predictor: Predictor, features: Sequence[Features], horizon: float
) -> MethodRows:
    preds: list[Prediction] = [predictor.predict(f, horizon) for f in features]
    return MethodRows(
        predictor.name,
        np.array([p.center for p in preds], dtype=float),
        tuple(p.case for p in preds),
    )


def judge(prepared: PreparedLog, model: TreeModel, note: str) -> FileResult:
    """Run every method on one log with the given tree."""
    feats = prepared.features
    h = prepared.horizon
    leaf = TreePredictor(model, Placement.LEAF, name=TREE_LEAF)
    methods = [
        _run_predictor(leaf, feats, h),
        _run_predictor(TreePredictor(model, Placement.CASE, name=TREE_CASE), feats, h),
        MethodRows(
            AUTHORS,
            np.column_stack([prepared.log.predicted_x, prepared.log.predicted_y]),
            tuple(None for _ in feats),
        ),
        _run_predictor(ConstantVelocityPredictor(name=CONSTANT_VELOCITY), feats, h),
        _run_predictor(RulePredictor(name=RULES), feats, h),
        MethodRows(
            STILL,
            np.array([f.center for f in feats], dtype=float),
            tuple(Case.STILL for _ in feats),
        ),
    ]
    totals = [prediction_ops(leaf, f, h).total.total for f in feats]
    ops = (float(np.mean(totals)), int(min(totals)), int(max(totals)))
    in_sample = trained_on(model, prepared.log.sha256)
    return FileResult(prepared, model, note, in_sample, tuple(methods), ops)


def replay(
    prepared: Sequence[PreparedLog], tree: TreeModel | None, options: TrainOptions
) -> list[FileResult]:
    """Judge every log; see the module docstring for which tree judges which file."""
    if not prepared:
        raise ValueError("no logs to replay")
    results = []
    for k, p in enumerate(prepared):
        if tree is not None:
            model, note = tree, "given tree"
        elif len(prepared) >= 2:
            others = [q for j, q in enumerate(prepared) if j != k]
            model = train_on_logs(others, options)
            names = ", ".join(q.log.name for q in others)
            note = (
                f"leave-one-file-out: trained on {names} ({model.provenance['training_rows']} rows)"
            )
        else:
            model, note = load_default_model(), "default tree shipped in the package"
        results.append(judge(p, model, note))
    return results


def _pct(x: float) -> str:
    return "   -  " if not np.isfinite(x) else f"{100 * x:5.1f}%"


def _px(x: float) -> str:
    return "     -" if not np.isfinite(x) else f"{x:6.1f}"


def _table(
    rows: Sequence[tuple[str, float, ErrorSummary, tuple[int, int] | None]],
) -> list[str]:
    head = (
        f"  {'method':<26} {'paper@' + format(PAPER_RADIUS_PX, 'g') + 'px':>11} "
        f"{'median px':>9} {'mean px':>8} {'<' + format(SHARE_RADIUS_PX, 'g') + 'px':>7} "
        f"{'case acc':>8}"
    )
    lines = [head]
    for name, paper, summary, hits in rows:
        acc = "      -" if hits is None or hits[1] == 0 else _pct(hits[0] / hits[1])
        lines.append(
            f"  {name:<26} {paper:11.4f} {_px(summary.median):>9} {_px(summary.mean):>8} "
            f"{_pct(summary.share_within):>7} {acc:>8}"
        )
    return lines


def format_report(results: Sequence[FileResult]) -> str:
    """Per-file and overall tables as plain text."""
    first = results[0].prepared
    out = [
        f"Replay at a {first.horizon:g} s horizon.",
        f"Paper metric: every row j >= 1, |centre(j) - predicted(j-1)| < {PAPER_RADIUS_PX:g} px.",
        f"Horizon metric (error at {first.horizon:g} s, px) and case accuracy: rows after "
        f"the first {first.warm_up:g} s (warm-up) whose t + {first.horizon:g} s lies within "
        "the log;",
        "case accuracy is against the static-camera image labels of the next second.",
        "",
    ]
    for r in results:
        p = r.prepared
        flag = "  ** IN-SAMPLE: this file is in the tree's training data **" if r.in_sample else ""
        out.append(f"{p.log.name}: {len(p.log)} rows, {int(p.scored.sum())} scored")
        out.append(f"  tree: {r.tree_note}{flag}")
        mean, lo, hi = r.ops_per_prediction
        out.append(f"  tree operations per prediction: mean {mean:.1f}, min {lo}, max {hi}")
        out.extend(
            _table([(m, r.paper(m), ErrorSummary.of(r.errors(m)), r.case_hits(m)) for m in METHODS])
        )
        out.append("")
    if len(results) > 1:
        n_scored = sum(int(r.prepared.scored.sum()) for r in results)
        out.append(
            f"overall: {len(results)} files, {n_scored} scored rows pooled "
            "(paper metric: mean of the per-file values, as in the paper)"
        )
        rows = []
        for m in METHODS:
            paper = float(np.mean([r.paper(m) for r in results]))
            errs = np.concatenate([r.errors(m) for r in results])
            hits = [r.case_hits(m) for r in results]
            pooled = (
                None
                if any(h is None for h in hits)
                else (sum(h[0] for h in hits if h), sum(h[1] for h in hits if h))
            )
            rows.append((m, paper, ErrorSummary.of(errs), pooled))
        out.extend(_table(rows))
        out.append("")
    return "\n".join(out)


CSV_HEADER = (
    "file",
    "row",
    "time",
    "horizon_s",
    "predicted_x",
    "predicted_y",
    "case",
    "case_label",
)


def predictions_csv(results: Sequence[FileResult]) -> str:
    """Our tree's prediction (leaf displacement) for every input row, as CSV text.

    `row` is the 1-based data row of the log; `case` uses the paper's numbering.
    """
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(CSV_HEADER)
    for r in results:
        m = r.method(TREE_LEAF)
        log = r.prepared.log
        for i in range(len(log)):
            case = m.cases[i]
            assert case is not None
            w.writerow(
                [
                    log.name,
                    i + 1,
                    repr(float(log.time[i])),
                    repr(r.prepared.horizon),
                    repr(float(m.predicted[i, 0])),
                    repr(float(m.predicted[i, 1])),
                    int(case),
                    case.label,
                ]
            )
    return buf.getvalue()
