"""Turning continuous features (phi, vx, vy, ground velocity) into the bins ID3 splits on.

ID3 only handles categorical attributes, so every feature is binned first. The default is
the authors' own binning from their analysis notebook (dead zone 15):

- phi -> 4 if 75 < phi < 105, 3 if -15 < phi < 15, 2 if 0 < phi < 90,
  1 if 90 < phi < 180, else 5, tested in that order;
- vx, vy -> 3 if |v| < 15, 1 if v > 0, else 2.

The data-driven alternative places cut points where they best separate the labels: the
recursive minimum-description-length split of Fayyad and Irani (1993). A non-finite value
(e.g. the velocity before two frames exist) goes to bin MISSING, which no training row has
(training rows are finite), so the tree answers with the majority of the node it reached.
That is our addition: the authors' code would put NaN phi in bin 5 and NaN velocity in 2.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from monopic.cases import GROUND_DEAD_ZONE_MPS
from monopic.tree.ops import ComparisonCounter, Ops

MISSING = 0
AUTHORS_DEAD_ZONE = 15.0

IMAGE_ATTRIBUTES = ("phi", "vx", "vy")


class Binner(Protocol):
    """Bins one feature."""

    kind: str

    def bin_counted(self, value: float) -> tuple[int, Ops]:
        """The bin of `value` and the operations spent finding it."""
        ...

    def describe(self, b: int) -> str:
        """Human-readable condition of bin `b`, e.g. '75 < phi < 105'."""
        ...

    def probes(self) -> tuple[float, ...]:
        """Values that exercise every code path (for the worst-case operation count)."""
        ...

    def to_json(self) -> dict[str, Any]: ...


def _num(x: float) -> str:
    return f"{x:g}"


@dataclass(frozen=True)
class AuthorsPhiBins:
    """The authors' five phi bins, with their order of tests; `dead_zone` widens 4 and 3."""

    dead_zone: float = AUTHORS_DEAD_ZONE
    kind: str = "authors-phi"

    def bin_counted(self, value: float) -> tuple[int, Ops]:
        c = ComparisonCounter()
        dz = self.dead_zone
        if not c.finite(value):
            b = MISSING
        elif c.lt(90.0 - dz, value) and c.lt(value, 90.0 + dz):
            b = 4
        elif c.lt(-dz, value) and c.lt(value, dz):
            b = 3
        elif c.lt(0.0, value) and c.lt(value, 90.0):
            b = 2
        elif c.lt(90.0, value) and c.lt(value, 180.0):
            b = 1
        else:
            b = 5
        return b, c.ops

    def describe(self, b: int) -> str:
        dz = self.dead_zone
        lo4, hi4 = _num(90 - dz), _num(90 + dz)
        if 0 < dz <= 45:  # the bins do not overlap: say exactly what each one holds
            rest = {
                2: f"{_num(dz)} <= phi <= {lo4}",
                1: f"{hi4} <= phi < 180",
                5: f"phi <= {_num(-dz)} or phi >= 180",
            }
        else:
            rest = {2: "0 < phi < 90 (rest)", 1: "90 < phi < 180 (rest)", 5: "phi elsewhere"}
        names = {MISSING: "phi missing", 4: f"{lo4} < phi < {hi4}"}
        names[3] = f"{_num(-dz)} < phi < {_num(dz)}"
        return {**names, **rest}.get(b, f"phi bin {b}")

    def probes(self) -> tuple[float, ...]:
        dz = self.dead_zone
        edges = (-180.0, -dz, 0.0, dz, 90.0 - dz, 90.0, 90.0 + dz, 180.0)
        return (*edges, *(e + 1e-6 for e in edges), *(e - 1e-6 for e in edges), math.nan)

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "dead_zone": self.dead_zone}


@dataclass(frozen=True)
class DeadZoneSignBins:
    """3 if |v| < dead_zone, 1 if v > 0, else 2: the authors' velocity bins."""

    dead_zone: float = AUTHORS_DEAD_ZONE
    unit: str = "px/s"
    kind: str = "dead-zone-sign"

    def bin_counted(self, value: float) -> tuple[int, Ops]:
        c = ComparisonCounter()
        if not c.finite(value):
            b = MISSING
        elif c.lt(c.abs(value), self.dead_zone):
            b = 3
        elif c.lt(0.0, value):
            b = 1
        else:
            b = 2
        return b, c.ops

    def describe(self, b: int) -> str:
        dz = _num(self.dead_zone)
        return {
            MISSING: "missing",
            3: f"|v| < {dz} {self.unit}",
            1: f"v >= {dz} {self.unit}",
            2: f"v <= -{dz} {self.unit}",
        }.get(b, f"bin {b}")

    def probes(self) -> tuple[float, ...]:
        dz = self.dead_zone
        return (-2 * dz, -dz, 0.0, dz, 2 * dz, math.nan)

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "dead_zone": self.dead_zone, "unit": self.unit}


@dataclass(frozen=True)
class CutPointBins:
    """Bin i+1 for values in (cuts[i-1], cuts[i]]: found by binary search over the cuts."""

    cuts: tuple[float, ...]
    kind: str = "cut-points"

    def __post_init__(self) -> None:
        if any(not math.isfinite(c) for c in self.cuts) or list(self.cuts) != sorted(
            set(self.cuts)
        ):
            raise ValueError(f"cut points must be finite and strictly increasing: {self.cuts}")

    def bin_counted(self, value: float) -> tuple[int, Ops]:
        c = ComparisonCounter()
        if not c.finite(value):
            return MISSING, c.ops
        lo, hi = 0, len(self.cuts)
        while lo < hi:
            mid = (lo + hi) // 2
            if c.le(value, self.cuts[mid]):
                hi = mid
            else:
                lo = mid + 1
        return lo + 1, c.ops

    def describe(self, b: int) -> str:
        if b == MISSING:
            return "missing"
        lo = self.cuts[b - 2] if b >= 2 else None
        hi = self.cuts[b - 1] if b - 1 < len(self.cuts) else None
        if lo is None and hi is None:
            return "any"
        if lo is None:
            return f"<= {hi:.4g}"
        if hi is None:
            return f"> {lo:.4g}"
        return f"({lo:.4g}, {hi:.4g}]"

    def probes(self) -> tuple[float, ...]:
        ends = (self.cuts[0] - 1.0, self.cuts[-1] + 1.0) if self.cuts else (0.0,)
        return (*self.cuts, *(x + 1e-9 * (1 + abs(x)) for x in self.cuts), *ends, math.nan)

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "cuts": list(self.cuts)}


def binner_from_json(data: Mapping[str, Any]) -> Binner:
    """Inverse of `Binner.to_json`; ValueError on anything else."""
    kind = data.get("kind")
    if kind == "authors-phi":
        return AuthorsPhiBins(dead_zone=float(data["dead_zone"]))
    if kind == "dead-zone-sign":
        return DeadZoneSignBins(dead_zone=float(data["dead_zone"]), unit=str(data["unit"]))
    if kind == "cut-points":
        return CutPointBins(cuts=tuple(float(c) for c in data["cuts"]))
    raise ValueError(f"unknown binner kind {kind!r}")


@dataclass(frozen=True)
class Discretiser:
    """One binner per attribute, in the attribute order the tree uses for tie-breaking."""

    name: str
    binners: tuple[tuple[str, Binner], ...]

    @property
    def attributes(self) -> tuple[str, ...]:
        return tuple(a for a, _ in self.binners)

    def binner(self, attribute: str) -> Binner:
        for a, b in self.binners:
            if a == attribute:
                return b
        raise KeyError(attribute)

    def discretise_counted(self, values: Mapping[str, float]) -> tuple[dict[str, int], Ops]:
        """Bins of every attribute, and the operations spent."""
        out: dict[str, int] = {}
        total = Ops()
        for a, b in self.binners:
            out[a], ops = b.bin_counted(float(values[a]))
            total = total + ops
        return out, total

    def discretise(self, values: Mapping[str, float]) -> dict[str, int]:
        return self.discretise_counted(values)[0]

    def worst_case_ops(self) -> Ops:
        """The most operations any input can cost (each attribute at its worst)."""
        total = Ops()
        for _, b in self.binners:
            total = total + max((b.bin_counted(p)[1] for p in b.probes()), key=_ops_key)
        return total

    def to_json(self) -> dict[str, Any]:
        return {"name": self.name, "binners": [[a, b.to_json()] for a, b in self.binners]}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Discretiser:
        return cls(
            name=str(data["name"]),
            binners=tuple((str(a), binner_from_json(b)) for a, b in data["binners"]),
        )


def _ops_key(o: Ops) -> tuple[int, int, int]:
    return (o.total, o.comparisons, o.functions)


def authors_discretiser(dead_zone: float = AUTHORS_DEAD_ZONE) -> Discretiser:
    """The authors' notebook binning of (phi, vx, vy)."""
    return Discretiser(
        name="authors",
        binners=(
            ("phi", AuthorsPhiBins(dead_zone)),
            ("vx", DeadZoneSignBins(dead_zone, "px/s")),
            ("vy", DeadZoneSignBins(dead_zone, "px/s")),
        ),
    )


def ground_discretiser(dead_zone: float = GROUND_DEAD_ZONE_MPS) -> Discretiser:
    """The same sign-with-dead-zone bins on the own ground velocity (forward, left), m/s."""
    return Discretiser(
        name="ground",
        binners=(
            ("forward", DeadZoneSignBins(dead_zone, "m/s")),
            ("left", DeadZoneSignBins(dead_zone, "m/s")),
        ),
    )


def entropy_discretiser(
    columns: Mapping[str, Sequence[float]],
    labels: Sequence[int],
    attributes: Sequence[str] = IMAGE_ATTRIBUTES,
    name: str = "entropy",
) -> Discretiser:
    """Cut points per attribute by the Fayyad-Irani MDL criterion on the training labels."""
    y = np.asarray(labels)
    return Discretiser(
        name=name,
        binners=tuple(
            (a, CutPointBins(mdlp_cut_points(np.asarray(columns[a], dtype=float), y)))
            for a in attributes
        ),
    )


def _entropy_of_counts(counts: np.ndarray) -> np.ndarray:
    """Entropy (bits) of class-count rows; last axis holds the classes."""
    n = counts.sum(axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(n > 0, counts / np.where(n > 0, n, 1), 0.0)
        terms = np.where(p > 0, -p * np.log2(np.where(p > 0, p, 1.0)), 0.0)
    return terms.sum(axis=-1)


def mdlp_cut_points(values: np.ndarray, labels: np.ndarray) -> tuple[float, ...]:
    """Fayyad-Irani recursive entropy split with the MDL stopping criterion.

    At each interval the cut minimising the weighted class entropy is taken (ties: the
    lowest value) and kept only if its gain exceeds (log2(N-1) + delta) / N, with
    delta = log2(3^k - 2) - (k Ent(S) - k1 Ent(S1) - k2 Ent(S2)) and k, k1, k2 the numbers
    of classes present. Cuts sit halfway between adjacent distinct values. Non-finite
    values are ignored.
    """
    v = np.asarray(values, dtype=float)
    keep = np.isfinite(v)
    v, y = v[keep], np.asarray(labels)[keep]
    if v.size < 2:
        return ()
    order = np.argsort(v, kind="stable")
    x = v[order]
    classes, y_idx = np.unique(y[order], return_inverse=True)
    onehot = np.zeros((x.size, classes.size))
    onehot[np.arange(x.size), y_idx] = 1.0
    cum = np.vstack([np.zeros(classes.size), np.cumsum(onehot, axis=0)])
    cuts: list[float] = []

    def split(lo: int, hi: int) -> None:
        n = hi - lo
        if n < 2:
            return
        candidates = np.arange(lo + 1, hi)
        candidates = candidates[x[candidates - 1] < x[candidates]]
        if candidates.size == 0:
            return
        total = cum[hi] - cum[lo]
        left = cum[candidates] - cum[lo]
        right = total - left
        n_left = candidates - lo
        e_left, e_right = _entropy_of_counts(left), _entropy_of_counts(right)
        weighted = (n_left * e_left + (n - n_left) * e_right) / n
        best = int(np.argmin(weighted))
        i = int(candidates[best])
        e_all = float(_entropy_of_counts(total))
        gain = e_all - float(weighted[best])
        k = int(np.count_nonzero(total))
        k1, k2 = int(np.count_nonzero(left[best])), int(np.count_nonzero(right[best]))
        delta = math.log2(3**k - 2) - (k * e_all - k1 * e_left[best] - k2 * e_right[best])
        if gain <= (math.log2(n - 1) + delta) / n:
            return
        cuts.append(float((x[i - 1] + x[i]) / 2))
        split(lo, i)
        split(i, hi)

    split(0, x.size)
    return tuple(sorted(cuts))
