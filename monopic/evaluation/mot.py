"""Multi-person tracks scored against MOTChallenge ground truth (`monopic track-eval`).

Both files are in the MOTChallenge text format, one box per person per frame:
`frame, id, bb_left, bb_top, bb_width, bb_height, conf, ...` with frames counted from 1.
The files are read here, strictly (a bad line is named with its file, line and field);
the CLEAR MOT and identity metrics are motmetrics' (MIT), fed frame by frame.

The ground truth follows the MOTChallenge conventions, as the official evaluation
(TrackEval) applies them:
- a row whose conf is 0 is not scored: it is neither a miss when no track covers it nor
  taken out of the tracks (on 2D MOT 2015 files, which have no class column, a track box
  on such a person is a false positive, as in the official evaluation);
- files with a class column (MOT16 and later: nine fields, `..., conf, class, visibility`)
  score pedestrians (class 1) only, and a track box that the best assignment puts on a
  distractor (person on a vehicle, static person, distractor, reflection) is taken out
  before scoring: it is neither right nor wrong.

HOTA is not computed: motmetrics 1.4.0, its latest release, has none (it was added to the
project's unreleased main branch), and the official HOTA code (trackeval) requires
opencv-python, which clashes with the pinned opencv-python-headless.
"""

from __future__ import annotations

import importlib.util
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from monopic.errors import UserError

PEDESTRIAN = 1
# MOT16/17 classes whose boxes are neither to be found nor to be penalised: person on a
# vehicle, static person, distractor, reflection (TrackEval's MOT17 list).
DISTRACTORS = frozenset({2, 7, 8, 12})
# The fields every line has, in order; MOT16+ ground truth adds class and visibility,
# results and 2D MOT 2015 files add the world x, y, z.
FIELDS = ("frame", "id", "bb_left", "bb_top", "bb_width", "bb_height", "conf")
_SEPARATOR = re.compile(r"\s*,\s*|\s+")


class Box(NamedTuple):
    """A box in pixels, as MOTChallenge writes it: top-left corner, width, height.

    A tuple so that a list of boxes is a numpy array in one call."""

    left: float
    top: float
    width: float
    height: float

    def contains(self, x: float, y: float) -> bool:
        """Whether the image point (x, y) lies inside the box (edges included)."""
        return self.left <= x <= self.left + self.width and self.top <= y <= self.top + self.height


@dataclass(frozen=True)
class MotRow:
    """One line of a MOTChallenge file."""

    frame: int
    identity: int
    box: Box
    conf: float  # a tracker's score; in ground truth 0 means "do not score this row"
    class_id: int | None  # MOT16+ ground truth only (nine fields)
    line: int

    @property
    def scored(self) -> bool:
        """Whether the evaluation counts this ground-truth row (a person to be found)."""
        return self.conf != 0 and self.class_id in (None, PEDESTRIAN)

    @property
    def distractor(self) -> bool:
        """A ground-truth row a track box may cover without being right or wrong."""
        return self.class_id in DISTRACTORS


@dataclass(frozen=True)
class FrameRange:
    """Frames FIRST to LAST, both included, counted from 1 as MOTChallenge counts."""

    first: int
    last: int

    def __contains__(self, frame: int) -> bool:
        return self.first <= frame <= self.last

    def __str__(self) -> str:
        return f"{self.first}-{self.last}"


def parse_frame_range(text: str) -> FrameRange:
    """'FIRST-LAST' (1 <= FIRST <= LAST) as given to --frames; ValueError saying why."""
    first_text, sep, last_text = text.strip().partition("-")
    try:
        if not sep:
            raise ValueError
        first, last = int(first_text), int(last_text)
    except ValueError:
        raise ValueError(f"expected FIRST-LAST (e.g. 1-300), got {text!r}") from None
    if not 1 <= first <= last:
        raise ValueError(f"expected 1 <= FIRST <= LAST (frames count from 1), got {text!r}")
    return FrameRange(first, last)


def _integer(path: Path, line: int, field: str, text: str, low: int) -> int:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value.is_integer() and value >= low):
        raise UserError(f"{path}:{line}: {field} {text!r} is not an integer >= {low}")
    return int(value)


def _number(path: Path, line: int, field: str, text: str, low: float = -math.inf) -> float:
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= low):
        bound = "" if low == -math.inf else f" >= {low:g}"
        raise UserError(f"{path}:{line}: {field} {text!r} is not a finite number{bound}")
    return value


def read_mot_rows(path: Path) -> list[MotRow]:
    """Every line of a MOTChallenge file, checked; UserError naming file, line and field.

    Blank lines are skipped. A line needs at least the six fields up to bb_height (conf
    is 1 when absent); frames count from 1; one id appears at most once a frame."""
    path = Path(path)
    if not path.exists():
        raise UserError(f"{path}: no such file")
    if path.is_dir():
        raise UserError(f"{path}: is a folder, not a MOTChallenge text file")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise UserError(f"{path}: not a text file (not UTF-8)") from None
    except OSError as err:
        raise UserError(f"{path}: cannot read: {err.strerror or err}") from None
    rows: list[MotRow] = []
    seen: dict[tuple[int, int], int] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip():
            continue
        values = _SEPARATOR.split(raw.strip())
        if len(values) < 6:
            raise UserError(
                f"{path}:{number}: {len(values)} field(s), expected at least 6 "
                f"({', '.join(FIELDS[:6])})"
            )
        frame = _integer(path, number, "frame", values[0], 1)
        identity = _integer(path, number, "id", values[1], 0)
        left = _number(path, number, "bb_left", values[2])
        top = _number(path, number, "bb_top", values[3])
        width = _number(path, number, "bb_width", values[4], 0)
        height = _number(path, number, "bb_height", values[5], 0)
        conf = _number(path, number, "conf", values[6]) if len(values) > 6 else 1.0
        class_id = _integer(path, number, "class", values[7], -1) if len(values) == 9 else None
        first = seen.setdefault((frame, identity), number)
        if first != number:
            raise UserError(
                f"{path}:{number}: id {identity} twice in frame {frame} (lines {first} "
                f"and {number})"
            )
        rows.append(MotRow(frame, identity, Box(left, top, width, height), conf, class_id, number))
    return rows


def read_mot(path: Path, *, scored_only: bool = False) -> dict[int, list[tuple[int, Box]]]:
    """A MOTChallenge file as {frame: [(id, box), ...]}, frames ascending.

    With `scored_only`, ground-truth rows the evaluation does not count (conf 0, a class
    other than pedestrian) are left out; without it every person box is there."""
    out: dict[int, list[tuple[int, Box]]] = {}
    for row in sorted(read_mot_rows(path), key=lambda r: r.frame):
        if scored_only and not row.scored:
            continue
        out.setdefault(row.frame, []).append((row.identity, row.box))
    return out


def ground_truth_file(path: Path) -> Path:
    """The ground-truth file itself, or a MOTChallenge sequence folder's gt/gt.txt."""
    path = Path(path)
    if path.is_dir():
        inside = path / "gt" / "gt.txt"
        if not inside.is_file():
            raise UserError(f"--gt {path}: a folder without gt/gt.txt (a MOT sequence has one)")
        return inside
    if not path.exists():
        raise UserError(f"--gt {path}: no such file or folder")
    return path


@dataclass(frozen=True)
class IdentityScore:
    """How well one ground-truth person was followed."""

    gt_id: int
    frames: int  # frames in which the person is scored
    matched: int  # of those, frames in which some track box matched the person
    track_ids: tuple[int, ...]  # the distinct tracks that matched the person, ascending

    @property
    def recall(self) -> float:
        return self.matched / self.frames if self.frames else math.nan


@dataclass(frozen=True)
class TrackScores:
    """The MOTChallenge figures of one tracks file against one ground truth."""

    frames: FrameRange
    min_iou: float
    mota: float
    motp: float  # mean IoU of the matched boxes (MOTChallenge's MOTP; higher is better)
    idf1: float
    idp: float
    idr: float
    recall: float
    precision: float
    switches: int
    fragmentations: int
    false_positives: int
    misses: int
    matches: int
    gt_boxes: int
    track_boxes: int  # scored track boxes (those on distractors taken out)
    distractor_boxes: int  # track boxes taken out as lying on a distractor
    # False positives lying on a person the ground truth does not score (conf 0): the
    # official evaluation counts them, so a tracker that follows such a person pays.
    false_positives_on_unscored: int
    gt_identities: int
    mostly_tracked: int
    partially_tracked: int
    mostly_lost: int
    identities: tuple[IdentityScore, ...]

    def to_json(self) -> dict[str, Any]:
        """Every figure as JSON values (an undefined ratio is null)."""

        def clean(value: float | int) -> float | int | None:
            return None if isinstance(value, float) and not math.isfinite(value) else value

        metrics = {
            f.name: clean(getattr(self, f.name))
            for f in fields(self)
            if f.name not in ("frames", "min_iou", "identities")
        }
        return {
            "frames": [self.frames.first, self.frames.last],
            "min_iou": self.min_iou,
            "hota": None,
            "metrics": metrics,
            "identities": [
                {
                    "gt_id": s.gt_id,
                    "frames": s.frames,
                    "matched": s.matched,
                    "recall": clean(s.recall),
                    "track_ids": list(s.track_ids),
                }
                for s in self.identities
            ],
        }


def has_motmetrics() -> bool:
    """Whether motmetrics (the [tracking] extra) is installed, without importing it: a
    report says how to install it rather than failing."""
    return importlib.util.find_spec("motmetrics") is not None


def _motmetrics() -> Any:
    """motmetrics, imported when scoring: it is the [tracking] extra, and it brings pandas
    and scipy, which every other `monopic` command would otherwise pay for at start."""
    try:
        import motmetrics
    except ImportError:
        raise UserError(
            "scoring tracks needs motmetrics (the [tracking] extra): "
            "pip install -c requirements.lock -e '.[tracking]', or make install"
        ) from None
    return motmetrics


def _boxes(rows: Sequence[MotRow]) -> np.ndarray:
    return np.array([r.box for r in rows], dtype=float).reshape(len(rows), 4)


def _distances(mm: Any, truth: Sequence[MotRow], tracks: Sequence[MotRow], min_iou: float):
    """1 - IoU for every (truth, track) pair, NaN (do not pair) below `min_iou`.

    motmetrics' own iou_matrix calls np.asfarray, which numpy 2 removed; its boxiou,
    the IoU itself, is what this wraps."""
    if not truth or not tracks:
        return np.empty((len(truth), len(tracks)))
    iou = mm.distances.boxiou(_boxes(truth)[:, None], _boxes(tracks)[None, :])
    dist = 1.0 - iou
    return np.where(iou >= min_iou, dist, np.nan)


def _without_distractor_boxes(
    mm: Any, truth: Sequence[MotRow], tracks: Sequence[MotRow], min_iou: float
) -> list[MotRow]:
    """The track boxes of one frame less those the best assignment to all ground truth
    puts on a distractor (MOT16+ preprocessing, as TrackEval and motmetrics do it)."""
    if not any(r.distractor for r in truth) or not tracks:
        return list(tracks)
    rows, cols = mm.lap.linear_sum_assignment(_distances(mm, truth, tracks, min_iou))
    dropped = {int(c) for r, c in zip(rows, cols, strict=True) if truth[r].distractor}
    return [t for i, t in enumerate(tracks) if i not in dropped]


def _by_frame(rows: Iterable[MotRow], frames: FrameRange) -> dict[int, list[MotRow]]:
    out: dict[int, list[MotRow]] = {}
    for row in rows:
        if row.frame in frames:
            out.setdefault(row.frame, []).append(row)
    return out


@dataclass
class _Accumulated:
    """One sequence fed to motmetrics frame by frame, with what the accumulator does not
    keep: the scored track boxes, those taken out as distractors', and the rows by frame."""

    acc: Any
    track_boxes: int
    distractor_boxes: int
    truth_frames: dict[int, list[MotRow]]
    track_frames: dict[int, list[MotRow]]


def _accumulate(
    mm: Any, tracks: Sequence[MotRow], truth: Sequence[MotRow], frames: FrameRange, min_iou: float
) -> _Accumulated:
    """One sequence's frames into a motmetrics accumulator, MOTChallenge's conventions
    applied (module docstring): unscored rows neither found nor missed, distractors' boxes
    taken out."""
    track_frames = _by_frame(tracks, frames)
    truth_frames = _by_frame(truth, frames)
    acc = mm.MOTAccumulator(auto_id=False)
    track_boxes = distractor_boxes = 0
    for frame in sorted(track_frames.keys() | truth_frames.keys()):
        everyone = truth_frames.get(frame, [])
        found = track_frames.get(frame, [])
        kept = _without_distractor_boxes(mm, everyone, found, min_iou)
        distractor_boxes += len(found) - len(kept)
        track_boxes += len(kept)
        scored = [r for r in everyone if r.scored]
        acc.update(
            [r.identity for r in scored],
            [t.identity for t in kept],
            _distances(mm, scored, kept, min_iou),
            frameid=frame,
        )
    return _Accumulated(acc, track_boxes, distractor_boxes, truth_frames, track_frames)


_METRICS = [
    "mota", "motp", "idf1", "idp", "idr", "recall", "precision", "num_switches",
    "num_fragmentations", "num_false_positives", "num_misses", "num_detections",
    "num_objects", "num_unique_objects", "mostly_tracked", "partially_tracked",
    "mostly_lost",
]  # fmt: skip


def score_tracks(
    tracks: Sequence[MotRow],
    truth: Sequence[MotRow],
    frames: FrameRange,
    min_iou: float = 0.5,
) -> TrackScores:
    """Score `tracks` against the ground truth `truth` over `frames` (CLEAR MOT, IDF1).

    A track box and a ground-truth box can match when their IoU is at least `min_iou`."""
    mm = _motmetrics()
    seq = _accumulate(mm, tracks, truth, frames, min_iou)
    m = mm.metrics.create().compute(seq.acc, metrics=_METRICS, return_dataframe=False)
    return TrackScores(
        frames=frames,
        min_iou=min_iou,
        **_clear_scores(m),
        idp=float(m["idp"]),
        idr=float(m["idr"]),
        track_boxes=seq.track_boxes,
        distractor_boxes=seq.distractor_boxes,
        false_positives_on_unscored=_false_positives_on_unscored(
            mm, seq.acc.mot_events, seq.truth_frames, seq.track_frames, min_iou
        ),
        gt_identities=int(m["num_unique_objects"]),
        mostly_tracked=int(m["mostly_tracked"]),
        partially_tracked=int(m["partially_tracked"]),
        mostly_lost=int(m["mostly_lost"]),
        identities=_identity_scores(seq.acc.mot_events, seq.truth_frames),
    )


@dataclass(frozen=True)
class MotSequence:
    """One sequence to score among several: its tracks, its ground truth, its frames."""

    tracks: Sequence[MotRow]
    truth: Sequence[MotRow]
    frames: FrameRange


@dataclass(frozen=True)
class PooledScores:
    """The figures of several sequences scored together, as MOTChallenge's benchmark sums
    a tracker over its sequences (motmetrics' overall): counts summed, MOTA and IDF1 of
    the sums, so a long sequence weighs more than a short one. Identities are per
    sequence: one person in two sequences counts twice."""

    sequences: int
    min_iou: float
    mota: float
    motp: float  # mean IoU of the matched boxes
    idf1: float
    recall: float
    precision: float
    switches: int
    fragmentations: int
    false_positives: int
    misses: int
    matches: int
    gt_boxes: int
    gt_identities: int

    @property
    def switches_per_100(self) -> float:
        """Identity switches per 100 ground-truth boxes (person-frames)."""
        return 100.0 * self.switches / self.gt_boxes if self.gt_boxes else math.nan


def score_sequences(sequences: Sequence[MotSequence], min_iou: float = 0.5) -> PooledScores:
    """Score several sequences together (each its own accumulator, then motmetrics'
    overall); ValueError when there is none."""
    if not sequences:
        raise ValueError("no sequence to score")
    mm = _motmetrics()
    accs = [_accumulate(mm, s.tracks, s.truth, s.frames, min_iou).acc for s in sequences]
    names = [str(i) for i in range(len(accs))]
    table = mm.metrics.create().compute_many(
        accs, names=names, metrics=_METRICS, generate_overall=True
    )
    m = table.loc["OVERALL"]
    return PooledScores(
        sequences=len(sequences),
        min_iou=min_iou,
        **_clear_scores(m),
        gt_identities=int(m["num_unique_objects"]),
    )


def _clear_scores(m) -> dict[str, float | int]:
    """The CLEAR MOT and identity figures one sequence and a pool of them both report."""
    return {
        "mota": float(m["mota"]),
        # motmetrics' MOTP is the mean distance (1 - IoU) of the matches.
        "motp": 1.0 - float(m["motp"]),
        "idf1": float(m["idf1"]),
        "recall": float(m["recall"]),
        "precision": float(m["precision"]),
        "switches": int(m["num_switches"]),
        "fragmentations": int(m["num_fragmentations"]),
        "false_positives": int(m["num_false_positives"]),
        "misses": int(m["num_misses"]),
        "matches": int(m["num_detections"]),
        "gt_boxes": int(m["num_objects"]),
    }


def _false_positives_on_unscored(
    mm: Any,
    events: Any,
    truth_frames: Mapping[int, Sequence[MotRow]],
    track_frames: Mapping[int, Sequence[MotRow]],
    min_iou: float,
) -> int:
    """How many false-positive track boxes overlap (IoU >= min_iou) an unscored person."""
    count = 0
    false_positives = events[events["Type"] == "FP"]
    for (frame, _), hid in zip(false_positives.index, false_positives["HId"], strict=True):
        unscored = [r for r in truth_frames.get(frame, []) if not r.scored]
        box = [t for t in track_frames[frame] if t.identity == int(hid)]
        if unscored and np.isfinite(_distances(mm, unscored, box, min_iou)).any():
            count += 1
    return count


def _identity_scores(
    events: Any, truth_frames: Mapping[int, Sequence[MotRow]]
) -> tuple[IdentityScore, ...]:
    """Per ground-truth person: frames scored, frames matched, the tracks that matched."""
    present: dict[int, int] = {}
    for rows in truth_frames.values():
        for row in rows:
            if row.scored:
                present[row.identity] = present.get(row.identity, 0) + 1
    matched = events[events["Type"].isin(["MATCH", "SWITCH"])]
    counts = matched.groupby("OId").size()
    tracks = matched.groupby("OId")["HId"].agg(lambda ids: tuple(sorted({int(i) for i in ids})))
    return tuple(
        IdentityScore(
            gt_id=gt_id,
            frames=n,
            matched=int(counts.get(gt_id, 0)),
            track_ids=tracks.get(gt_id, ()),
        )
        for gt_id, n in sorted(present.items())
    )


def evaluate_files(
    tracks_path: Path,
    gt_path: Path,
    frames: FrameRange | None = None,
    min_iou: float = 0.5,
) -> TrackScores:
    """Read and check both files, then score the tracks over `frames` (default: every
    frame either file has). UserError when there is nothing to score."""
    gt_file = ground_truth_file(gt_path)
    truth = read_mot_rows(gt_file)
    tracks = read_mot_rows(tracks_path)
    if frames is None:
        present = [r.frame for r in (*truth, *tracks)]
        if not present:
            raise UserError(f"{tracks_path} and {gt_file}: both files are empty")
        frames = FrameRange(min(present), max(present))
    where = "" if not tracks else f" in frames {frames}"
    if not any(r.frame in frames for r in tracks):
        raise UserError(f"{tracks_path}: no track line{where}")
    if not any(r.scored and r.frame in frames for r in truth):
        raise UserError(f"{gt_file}: no scored ground-truth line in frames {frames}")
    return score_tracks(tracks, truth, frames, min_iou)
