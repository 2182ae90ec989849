"""Training an image-mode tree on authors' logs, with a record of exactly what it saw."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from monopic.cases import ImageTrackThresholds
from monopic.predict.base import Mode
from monopic.replay.dataset import PreparedLog
from monopic.tree.discretise import AUTHORS_DEAD_ZONE, authors_discretiser
from monopic.tree.id3 import ID3Params
from monopic.tree.model import LeafValue, TreeModel, fit_model

DISCRETISERS = ("authors", "entropy")
LEAF_VALUES = tuple(v.value for v in LeafValue)
# A node with fewer training rows than this is not split: with a few hundred rows, leaves
# of one or two rows would hand their single displacement to every future match.
DEFAULT_MIN_SAMPLES = 10


@dataclass(frozen=True)
class TrainOptions:
    """How to bin and grow the tree."""

    discretiser: str = "authors"
    dead_zone: float = AUTHORS_DEAD_ZONE
    min_samples: int = DEFAULT_MIN_SAMPLES
    max_depth: int | None = None
    leaf_value: str = LeafValue.DISPLACEMENT.value
    shrink: float = 0.0  # rows: velocity gains pulled toward 1 by n / (n + shrink)

    def __post_init__(self) -> None:
        if self.discretiser not in DISCRETISERS:
            raise ValueError(f"discretiser must be one of {DISCRETISERS}, got {self.discretiser!r}")
        if not self.dead_zone >= 0:
            raise ValueError(f"dead zone must be >= 0, got {self.dead_zone}")
        if self.leaf_value not in LEAF_VALUES:
            raise ValueError(f"leaf value must be one of {LEAF_VALUES}, got {self.leaf_value!r}")
        if not self.shrink >= 0:
            raise ValueError(f"shrink must be >= 0, got {self.shrink}")
        ID3Params(self.min_samples, self.max_depth)  # validates both

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "discretiser": self.discretiser,
            "dead_zone": self.dead_zone if self.discretiser == "authors" else None,
            "min_samples": self.min_samples,
            "max_depth": self.max_depth,
        }
        if self.leaf_value != LeafValue.DISPLACEMENT.value:  # older files lack these keys
            out["leaf_value"] = self.leaf_value
            out["shrink"] = self.shrink
        return out


def train_on_logs(logs: Sequence[PreparedLog], options: TrainOptions) -> TreeModel:
    """Fit a tree on the scored rows of `logs` (warm-up and unlabelled rows left out)."""
    if not logs:
        raise ValueError("no logs to train on")
    horizons = {p.horizon for p in logs}
    if len(horizons) != 1:
        raise ValueError(f"logs prepared with different horizons: {sorted(horizons)}")
    if len({p.velocity_note for p in logs}) != 1:
        raise ValueError("logs prepared with different velocity estimates")
    samples = []
    files = []
    for p in logs:
        s = p.training_samples()
        samples.extend(s)
        files.append(
            {
                "name": p.log.name,
                "sha256": p.log.sha256,
                "rows": len(p.log),
                "training_rows": len(s),
            }
        )
    if not samples:
        names = ", ".join(p.log.name for p in logs)
        raise ValueError(f"no training rows in {names} (too short for warm-up plus horizon?)")
    th = ImageTrackThresholds()
    provenance = {
        "data": files,
        "training_rows": len(samples),
        "options": options.to_json(),
        "warm_up_s": logs[0].warm_up,
        "labels": (
            "monopic.cases.case_from_image_track over [t, t + horizon], "
            f"thresholds lateral {th.lateral} and depth {th.depth} heights/s"
        ),
        "velocity": logs[0].velocity_note,
    }
    disc = authors_discretiser(options.dead_zone) if options.discretiser == "authors" else "entropy"
    return fit_model(
        samples,
        mode=Mode.IMAGE,
        discretiser=disc,
        params=ID3Params(options.min_samples, options.max_depth),
        horizon=next(iter(horizons)),
        provenance=provenance,
        leaf_value=LeafValue(options.leaf_value),
        shrink=options.shrink,
    )


def trained_on(model: TreeModel, sha256: str) -> bool:
    """Whether a log with this content was in the model's training data."""
    return any(d.get("sha256") == sha256 for d in model.provenance.get("data", []))
