"""ID3 (Quinlan 1986): a multiway decision tree grown by information gain.

At each node the attribute with the highest information gain splits the rows into one
child per value seen there; growth stops when the node is pure, no attribute is left,
the node has fewer than `min_samples` rows, or it sits at `max_depth`. Every node keeps
its majority label, class counts and (optionally) the mean of a numeric target over its
rows, so any node can answer on its own.

Determinism, so the same data always gives the same tree:
- gain ties (within 1e-12, to be immune to summation order) go to the attribute listed
  first in `attributes`;
- majority ties go to the smallest label;
- children are stored in increasing value order.
Prediction never fails on a value the tree has not seen at a node: the walk stops there
and that node's majority (and mean target) answers.
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

Value = int | str
Label = int | str

GAIN_TIE_TOLERANCE = 1e-12


def _order_key(v: Hashable) -> tuple[str, Any]:
    """Sort key valid across mixed int/str values."""
    return (type(v).__name__, v)


def entropy(labels: Sequence[Label]) -> float:
    """Shannon entropy in bits of the label distribution."""
    n = len(labels)
    if n == 0:
        return 0.0
    return -sum((c / n) * math.log2(c / n) for c in Counter(labels).values())


def information_gain(
    rows: Sequence[Mapping[str, Value]], labels: Sequence[Label], attribute: str
) -> float:
    """Entropy(S) minus the weighted entropy of the subsets S_{A=v}."""
    if len(rows) != len(labels):
        raise ValueError(f"{len(rows)} rows but {len(labels)} labels")
    groups: dict[Value, list[Label]] = {}
    for row, label in zip(rows, labels, strict=True):
        groups.setdefault(row[attribute], []).append(label)
    n = len(labels)
    remainder = sum(len(g) / n * entropy(g) for g in groups.values())
    return entropy(labels) - remainder


def majority(labels: Sequence[Label]) -> Label:
    """Most frequent label; ties go to the smallest label."""
    counts = Counter(labels)
    best = max(counts.values())
    return min((lab for lab, c in counts.items() if c == best), key=_order_key)


@dataclass(frozen=True)
class Node:
    """A tree node: a leaf when `attribute` is None."""

    label: Label
    counts: tuple[tuple[Label, int], ...]
    mean: tuple[float, ...] | None = None
    attribute: str | None = None
    gain: float | None = None
    branches: tuple[tuple[Value, Node], ...] = ()

    @property
    def is_leaf(self) -> bool:
        return self.attribute is None

    @property
    def n(self) -> int:
        return sum(c for _, c in self.counts)

    @property
    def purity(self) -> float:
        """Share of this node's rows that carry its label."""
        return dict(self.counts)[self.label] / self.n

    def child(self, value: Value) -> Node | None:
        for v, node in self.branches:
            if v == value:
                return node
        return None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "label": self.label,
            "counts": [[lab, c] for lab, c in self.counts],
            "mean": None if self.mean is None else list(self.mean),
        }
        if self.attribute is not None:
            out["attribute"] = self.attribute
            out["gain"] = self.gain
            out["branches"] = [[v, child.to_json()] for v, child in self.branches]
        return out

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Node:
        mean = data.get("mean")
        return cls(
            label=_scalar(data["label"]),
            counts=tuple((_scalar(lab), int(c)) for lab, c in data["counts"]),
            mean=None if mean is None else tuple(float(x) for x in mean),
            attribute=data.get("attribute"),
            gain=None if data.get("gain") is None else float(data["gain"]),
            branches=tuple(
                (_scalar(v), cls.from_json(child)) for v, child in data.get("branches", [])
            ),
        )


def _scalar(v: Any) -> Value:
    if isinstance(v, bool) or not isinstance(v, int | str):
        raise ValueError(f"tree values and labels must be int or str, got {v!r}")
    return v


@dataclass(frozen=True)
class ID3Params:
    """Stopping rules beyond Quinlan's (pure node, no attribute left).

    A node with fewer than `min_samples` rows is not split; a node at depth `max_depth`
    (the root is depth 0) is not split. The defaults give the textbook algorithm.
    """

    min_samples: int = 2
    max_depth: int | None = None

    def __post_init__(self) -> None:
        if self.min_samples < 1:
            raise ValueError(f"min_samples must be >= 1, got {self.min_samples}")
        if self.max_depth is not None and self.max_depth < 0:
            raise ValueError(f"max_depth must be >= 0, got {self.max_depth}")


@dataclass(frozen=True)
class DecisionTree:
    """A fitted ID3 tree over categorical attributes."""

    attributes: tuple[str, ...]
    root: Node

    def path(self, row: Mapping[str, Value]) -> list[Node]:
        """Nodes visited for `row`; the last one answers (a leaf or an unseen value)."""
        node = self.root
        visited = [node]
        while not node.is_leaf:
            assert node.attribute is not None
            if node.attribute not in row:
                raise ValueError(f"row has no value for attribute {node.attribute!r}")
            nxt = node.child(row[node.attribute])
            if nxt is None:
                break
            node = nxt
            visited.append(node)
        return visited

    def answer(self, row: Mapping[str, Value]) -> Node:
        return self.path(row)[-1]

    def predict(self, row: Mapping[str, Value]) -> Label:
        return self.answer(row).label

    @property
    def depth(self) -> int:
        def d(node: Node) -> int:
            return 0 if node.is_leaf else 1 + max(d(c) for _, c in node.branches)

        return d(self.root)

    def nodes(self) -> list[Node]:
        out: list[Node] = []
        stack = [self.root]
        while stack:
            node = stack.pop()
            out.append(node)
            stack.extend(c for _, c in reversed(node.branches))
        return out

    def to_json(self) -> dict[str, Any]:
        return {"attributes": list(self.attributes), "root": self.root.to_json()}

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> DecisionTree:
        return cls(
            attributes=tuple(str(a) for a in data["attributes"]),
            root=Node.from_json(data["root"]),
        )


def fit_id3(
    rows: Sequence[Mapping[str, Value]],
    labels: Sequence[Label],
    attributes: Sequence[str],
    targets: np.ndarray | None = None,
    params: ID3Params | None = None,
) -> DecisionTree:
    """Grow an ID3 tree; `targets` (n, k) are averaged into every node's `mean`."""
    p = params or ID3Params()
    n = len(rows)
    if n == 0:
        raise ValueError("cannot fit a tree on zero rows")
    if len(labels) != n:
        raise ValueError(f"{n} rows but {len(labels)} labels")
    if len(set(attributes)) != len(attributes):
        raise ValueError(f"attributes repeat: {list(attributes)}")
    tgt = None if targets is None else np.asarray(targets, dtype=float).reshape(n, -1)
    for lab in labels:
        _scalar(lab)

    def grow(idx: list[int], remaining: tuple[str, ...], depth: int) -> Node:
        labs = [labels[i] for i in idx]
        counts = Counter(labs)
        node_counts = tuple(sorted(counts.items(), key=lambda kv: _order_key(kv[0])))
        mean = None if tgt is None else tuple(float(x) for x in tgt[idx].mean(axis=0))
        leaf = Node(label=majority(labs), counts=node_counts, mean=mean)
        if (
            len(counts) == 1
            or not remaining
            or len(idx) < p.min_samples
            or (p.max_depth is not None and depth >= p.max_depth)
        ):
            return leaf
        sub_rows = [rows[i] for i in idx]
        best_attr, best_gain = remaining[0], -math.inf
        for a in remaining:
            g = information_gain(sub_rows, labs, a)
            if g > best_gain + GAIN_TIE_TOLERANCE:
                best_attr, best_gain = a, g
        groups: dict[Value, list[int]] = {}
        for i in idx:
            groups.setdefault(_scalar(rows[i][best_attr]), []).append(i)
        rest = tuple(a for a in remaining if a != best_attr)
        branches = tuple(
            (v, grow(groups[v], rest, depth + 1)) for v in sorted(groups, key=_order_key)
        )
        return Node(
            label=leaf.label,
            counts=leaf.counts,
            mean=leaf.mean,
            attribute=best_attr,
            gain=best_gain,
            branches=branches,
        )

    return DecisionTree(tuple(attributes), grow(list(range(n)), tuple(attributes), 0))


def render_text(
    tree: DecisionTree,
    describe_value: Callable[[str, Value], str] | None = None,
    describe_node: Callable[[Node], str] | None = None,
) -> str:
    """Indented text: one line per branch, leaves marked with '->'."""
    dv = describe_value or (lambda a, v: f"{a} = {v}")
    dn = describe_node or _default_node_text
    lines = [f"root: {dn(tree.root)}"]

    def walk(node: Node, indent: str) -> None:
        for v, child in node.branches:
            assert node.attribute is not None
            arrow = "-> " if child.is_leaf else ""
            lines.append(f"{indent}{dv(node.attribute, v)}: {arrow}{dn(child)}")
            walk(child, indent + "|   ")

    walk(tree.root, "")
    return "\n".join(lines)


def _default_node_text(node: Node) -> str:
    split = f", split on {node.attribute} (gain {node.gain:.3f})" if not node.is_leaf else ""
    return f"{node.label} (n={node.n}, {node.purity:.0%}){split}"


def _dot_escape(s: str) -> str:
    return s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")


def render_dot(
    tree: DecisionTree,
    describe_value: Callable[[str, Value], str] | None = None,
    describe_node: Callable[[Node], str] | None = None,
    name: str = "id3",
) -> str:
    """Graphviz DOT: boxes for tests, ellipses for leaves, edges labelled by value."""
    dv = describe_value or (lambda a, v: str(v))
    dn = describe_node or (lambda node: f"{node.label}\nn={node.n}")
    lines = [f'digraph "{_dot_escape(name)}" {{', '  node [fontname="Helvetica"];']
    counter = 0

    def walk(node: Node) -> str:
        nonlocal counter
        ident = f"n{counter}"
        counter += 1
        if node.is_leaf:
            lines.append(f'  {ident} [shape=ellipse, label="{_dot_escape(dn(node))}"];')
            return ident
        head = f"{node.attribute}\n{dn(node)}"
        lines.append(f'  {ident} [shape=box, label="{_dot_escape(head)}"];')
        for v, child in node.branches:
            assert node.attribute is not None
            cid = walk(child)
            label = _dot_escape(dv(node.attribute, v))
            lines.append(f'  {ident} -> {cid} [label="{label}"];')
        return ident

    walk(tree.root)
    lines.append("}")
    return "\n".join(lines) + "\n"
