"""Human-readable views of a trained model: summary, gain table, text tree, DOT."""

from __future__ import annotations

from monopic.cases import Case
from monopic.predict.base import Mode
from monopic.tree.id3 import Node, Value, render_dot, render_text
from monopic.tree.intent import IntentTreeModel, LeafReading, worst_case_ops
from monopic.tree.model import LeafValue, Placement, TreeModel, TreePredictor
from monopic.tree.opcount import PAPER_CALCULATIONS_PER_PREDICTION, ops_report

# The paper's root information gains ("ID3 Classification"), image mode.
PAPER_ROOT_GAINS = {"vx": 0.022, "vy": 0.014, "phi": 0.004}


def gain_table(model: TreeModel | IntentTreeModel) -> str:
    """Root information gain per attribute, highest first, beside the paper's figures."""
    n = model.tree.root.n
    lines = [
        f"Information gain at the root ({n} training rows, label entropy "
        f"{model.root_entropy:.3f} bits):",
        f"  {'attribute':<10} {'ours':>7} {'paper':>7}",
    ]
    for a, g in sorted(model.root_gains, key=lambda ag: -ag[1]):
        image = isinstance(model, TreeModel) and model.mode is Mode.IMAGE
        paper = PAPER_ROOT_GAINS.get(a) if image else None
        lines.append(f"  {a:<10} {g:7.3f} {'-' if paper is None else f'{paper:.3f}':>7}")
    return "\n".join(lines)


def _value_text(model: TreeModel, attribute: str, value: Value) -> str:
    desc = model.discretiser.binner(attribute).describe(int(value))
    return f"{attribute} = {value} ({desc})"


def _node_text(model: TreeModel, node: Node) -> str:
    case = Case(node.label)
    text = f"case {int(case)} {case.label} (n={node.n}, {node.purity:.0%})"
    if node.mean is not None:
        text += f", {_leaf_text(model, node.mean)}"
    if not node.is_leaf:
        text += f"; split on {node.attribute} (gain {node.gain:.3f})"
    return text


def _leaf_text(model: TreeModel, mean: tuple[float, ...]) -> str:
    if model.leaf_value is LeafValue.VELOCITY_GAIN:
        return f"velocity gain ({mean[0]:.2f}, {mean[1]:.2f})"
    unit = "heights" if model.mode is Mode.IMAGE else "m"
    return f"moves ({mean[0]:+.2f}, {mean[1]:+.2f}) {unit}"


def tree_text(model: TreeModel) -> str:
    return render_text(
        model.tree,
        describe_value=lambda a, v: _value_text(model, a, v),
        describe_node=lambda node: _node_text(model, node),
    )


def tree_dot(model: TreeModel) -> str:
    def node_label(node: Node) -> str:
        case = Case(node.label)
        text = f"case {int(case)}: {case.label}\nn={node.n} ({node.purity:.0%})"
        if node.mean is not None:
            text += f"\n{_leaf_text(model, node.mean)}"
        return text

    return render_dot(
        model.tree,
        describe_value=lambda a, v: f"{v}: {model.discretiser.binner(a).describe(int(v))}",
        describe_node=node_label,
        name=f"monopic-{model.mode.value}-tree",
    )


def summary(model: TreeModel) -> str:
    """Everything `monopic tree show` prints."""
    data = model.provenance.get("data", [])
    trained = ", ".join(f"{d['name']} ({d['training_rows']} rows)" for d in data) or "unknown"
    unit = "apparent heights" if model.mode is Mode.IMAGE else "metres"
    leaves = f"leaf displacements in {unit}"
    if model.leaf_value is LeafValue.VELOCITY_GAIN:
        leaves = "leaves: gains on the measured velocity (x, y)"
    parts = [
        f"ID3 tree, {model.mode.value} mode, horizon {model.horizon:g} s, "
        f"discretiser {model.discretiser.name}, depth {model.tree.depth}, "
        f"{sum(1 for n in model.tree.nodes() if n.is_leaf)} leaves; {leaves}",
        f"Trained on: {trained}",
        "",
        gain_table(model),
        "",
        tree_text(model),
    ]
    if model.mode is Mode.IMAGE:
        parts += ["", ops_report(TreePredictor(model, Placement.LEAF))]
    return "\n".join(parts)


def _intent_node_text(node: Node) -> str:
    r = LeafReading.of(node)
    text = (
        f"case {int(r.case)} {r.case.label}, {r.intent} ({r.support:.0%} of n={r.rows}; "
        f"stop or turn away {r.hold_share:.0%}, start crossing {r.start_share:.0%}), "
        f"corrects constant velocity by ({r.correction[0]:+.2f}, {r.correction[1]:+.2f}) m"
    )
    if not node.is_leaf:
        text += f"; split on {node.attribute} (gain {node.gain:.3f})"
    return text


def intent_tree_text(model: IntentTreeModel) -> str:
    return render_text(
        model.tree,
        describe_value=lambda a, v: f"{a} {model.discretiser.binner(a).describe(int(v))}",
        describe_node=_intent_node_text,
    )


def intent_tree_dot(model: IntentTreeModel) -> str:
    def node_label(node: Node) -> str:
        r = LeafReading.of(node)
        return (
            f"case {int(r.case)}: {r.case.label}\n{r.intent} {r.support:.0%}, n={r.rows}\n"
            f"({r.correction[0]:+.2f}, {r.correction[1]:+.2f}) m"
        )

    return render_dot(
        model.tree,
        describe_value=lambda a, v: f"{v}: {model.discretiser.binner(a).describe(int(v))}",
        describe_node=node_label,
        name="monopic-ground-intent-tree",
    )


def intent_summary(model: IntentTreeModel) -> str:
    """Everything `monopic tree show` prints for a ground intent tree."""
    r = model.rules
    chosen = model.provenance.get("chosen", {})
    val = model.provenance.get("validation", {})
    split = model.provenance.get("split", {})
    worst = worst_case_ops(model)
    parts = [
        f"ID3 intent tree, ground mode, horizon {model.horizon:g} s, discretiser "
        f"{model.discretiser.name}, depth {model.tree.depth}, "
        f"{sum(1 for n in model.tree.nodes() if n.is_leaf)} leaves; labels case/intent, "
        "leaves correct constant velocity (m, forward/left)",
        f"Chosen on validation: {_chosen_text(chosen)}; trained on "
        f"{len(split.get('train', []))} runs, validated on {len(split.get('validation', []))}"
        f", excluded {len(split.get('excluded', []))}",
        _validation_text(val),
        f"Intent rules: hold back at a stop + turn-away share of {_support(r.hold_back_support)}"
        f", warn earlier at a start-crossing share of {_support(r.warn_support)}, start speed "
        f"{r.start_speed:g} m/s, read at the deepest node with at least {r.min_rows} rows",
        "",
        gain_table(model),
        "",
        intent_tree_text(model),
        "",
        f"Operations for one prediction (worst case over inputs): {worst.describe()}"
        f"   [paper: {PAPER_CALCULATIONS_PER_PREDICTION} calculations per prediction]",
    ]
    return "\n".join(parts)


def _support(value: float) -> str:
    return "off" if value > 1 else f"{value:g}"


def _validation_text(val: dict) -> str:
    if not val:
        return "Validation: unknown"
    return (
        f"Validation: median error {val['median_error_m']:.3f} m (constant velocity "
        f"{val['constant_velocity_median_error_m']:.3f} m); warnings {val['warnings']} "
        f"(constant velocity: {val['constant_velocity_warnings']})"
    )


def _chosen_text(chosen: dict) -> str:
    if not chosen:
        return "unknown"
    shrink = chosen.get("shrink_rows", 0.0)
    corrections = "corrections off" if shrink is None else f"corrections shrunk by {shrink:g} rows"
    return f"{chosen['binning']} bins, depth {chosen['max_depth']}, {corrections}"
