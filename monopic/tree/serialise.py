"""Versioned JSON for trained trees, and the default tree shipped with the package.

The file is plain JSON so anyone can read the tree without our code. Floats are written
with Python's shortest round-trip repr, so load(save(model)) == model exactly. A file
with another format name or version is refused with a clear message rather than guessed.

Version 1: leaves carry displacements. Version 2 adds "leaf_value" ("displacement" or
"velocity-gain"); a tree with displacement leaves is still written as version 1 (so the
shipped tree's file does not change), one with gain leaves as version 2, which a version-1
reader refuses instead of reading gains as displacements. Version 3 is the ground-mode
intent tree (monopic/tree/intent.py): "leaf_value" "cv-correction", labels "case/intent",
node means the correction to constant velocity in metres, and "intent_rules". Older
readers refuse it by its version; `load_model` (the `tree` predictor) refuses it by name,
`load_intent_model` reads only it. All three versions load.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path
from typing import Any

from monopic.cases import Case
from monopic.errors import UserError
from monopic.output import write_text_atomically
from monopic.predict.base import Mode
from monopic.tree.discretise import Discretiser
from monopic.tree.id3 import DecisionTree
from monopic.tree.intent import IntentRules, IntentTreeModel, IntentTreePredictor
from monopic.tree.model import LeafValue, TreeModel, TreePredictor

FORMAT = "monopic-id3-tree"
VERSION = 2
VERSIONS = (1, 2)
INTENT_VERSION = 3
INTENT_LEAF_VALUE = "cv-correction"
DEFAULT_TREE_NAME = "default_tree.json"
# The ground intent tree shipped for the small robot's 1.5 s horizon (GROUND_TREE.md).
GROUND_TREE_NAME = "ground_tree.json"


def model_to_json(model: TreeModel) -> dict[str, Any]:
    displacement = model.leaf_value is LeafValue.DISPLACEMENT
    extra = {} if displacement else {"leaf_value": model.leaf_value.value}
    return {
        "format": FORMAT,
        "version": 1 if displacement else VERSION,
        **extra,
        "mode": model.mode.value,
        "horizon_s": model.horizon,
        "displacement_unit": model.displacement_unit,
        **_learnt(model),
    }


def _learnt(model: TreeModel | IntentTreeModel) -> dict[str, Any]:
    """The fields every tree file ends with, in this order: how its inputs were binned,
    what the learner found at the root, what it was trained on, and the tree itself."""
    return {
        "discretiser": model.discretiser.to_json(),
        "root_entropy": model.root_entropy,
        "root_gains": [[a, g] for a, g in model.root_gains],
        "provenance": model.provenance,
        "tree": model.tree.to_json(),
    }


def model_from_json(data: Any) -> TreeModel:
    """Inverse of `model_to_json`; ValueError naming what is wrong."""
    _check_format(data)
    version = data.get("version")
    if version == INTENT_VERSION:
        raise ValueError(
            "this is a ground intent tree (version 3): use it with predictor 'intent-tree'"
        )
    if version not in VERSIONS:
        raise ValueError(f"version {version!r} is not supported (only {VERSIONS})")
    if version == 1 and "leaf_value" in data:
        raise ValueError("leaf_value is a version-2 field; this file says version 1")
    try:
        leaf_value = LeafValue(data.get("leaf_value", LeafValue.DISPLACEMENT.value))
    except ValueError:
        known = ", ".join(v.value for v in LeafValue)
        raise ValueError(f"leaf_value {data.get('leaf_value')!r} is not one of {known}") from None
    try:
        mode = Mode(data["mode"])
        model = TreeModel(
            leaf_value=leaf_value,
            mode=mode,
            horizon=float(data["horizon_s"]),
            discretiser=Discretiser.from_json(data["discretiser"]),
            tree=DecisionTree.from_json(data["tree"]),
            root_entropy=float(data["root_entropy"]),
            root_gains=tuple((str(a), float(g)) for a, g in data["root_gains"]),
            provenance=dict(data["provenance"]),
        )
    except (KeyError, TypeError) as err:
        raise ValueError(f"malformed tree: {type(err).__name__} {err}") from err
    if data.get("displacement_unit") != model.displacement_unit:
        raise ValueError(
            f"displacement_unit {data.get('displacement_unit')!r} does not match mode {mode.value}"
        )
    if set(model.tree.attributes) != set(model.discretiser.attributes):
        raise ValueError("the tree's attributes differ from the discretiser's")
    valid = {int(c) for c in Case}
    for node in model.tree.nodes():
        if node.label not in valid or any(lab not in valid for lab, _ in node.counts):
            raise ValueError(f"node label {node.label!r} is not a case number 1-9")
        if node.mean is not None and len(node.mean) != 2:
            raise ValueError(f"node displacement {node.mean!r} is not an (x, y) pair")
    return model


def _check_format(data: Any) -> None:
    if not isinstance(data, dict):
        raise ValueError("not a JSON object")
    if data.get("format") != FORMAT:
        raise ValueError(f"format is {data.get('format')!r}, expected {FORMAT!r}")


def intent_model_to_json(model: IntentTreeModel) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "version": INTENT_VERSION,
        "leaf_value": INTENT_LEAF_VALUE,
        "mode": Mode.GROUND.value,
        "horizon_s": model.horizon,
        "displacement_unit": "metre",
        "labels": "case/intent",
        "intent_rules": model.rules.to_json(),
        **_learnt(model),
    }


def intent_model_from_json(data: Any) -> IntentTreeModel:
    """Inverse of `intent_model_to_json`; ValueError naming what is wrong."""
    _check_format(data)
    version = data.get("version")
    if version != INTENT_VERSION:
        raise ValueError(
            f"version {version!r} is not a ground intent tree (version {INTENT_VERSION}): "
            "use it with predictor 'tree'"
        )
    for key, want in (
        ("leaf_value", INTENT_LEAF_VALUE),
        ("mode", Mode.GROUND.value),
        ("displacement_unit", "metre"),
        ("labels", "case/intent"),
    ):
        if data.get(key) != want:
            raise ValueError(f"{key} is {data.get(key)!r}, expected {want!r}")
    try:
        return IntentTreeModel(
            horizon=float(data["horizon_s"]),
            discretiser=Discretiser.from_json(data["discretiser"]),
            tree=DecisionTree.from_json(data["tree"]),
            rules=IntentRules.from_json(data["intent_rules"]),
            root_entropy=float(data["root_entropy"]),
            root_gains=tuple((str(a), float(g)) for a, g in data["root_gains"]),
            provenance=dict(data["provenance"]),
        )
    except (KeyError, TypeError) as err:
        raise ValueError(f"malformed tree: {type(err).__name__} {err}") from err


def dumps(model: TreeModel | IntentTreeModel) -> str:
    data = (
        intent_model_to_json(model) if isinstance(model, IntentTreeModel) else model_to_json(model)
    )
    return json.dumps(data, indent=1, allow_nan=False) + "\n"


def save_model(model: TreeModel | IntentTreeModel, path: Path) -> None:
    write_text_atomically(Path(path), dumps(model))


def _read(path: Path) -> str:
    try:
        return Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise UserError(f"{path}: cannot read tree file: {err.strerror or err}") from err


def load_intent_model(path: Path) -> IntentTreeModel:
    """Read a ground intent tree file; UserError (naming the file) otherwise."""
    text = _read(path)
    try:
        return intent_model_from_json(json.loads(text))
    except json.JSONDecodeError as err:
        raise UserError(f"{path}: line {err.lineno}: not valid JSON: {err.msg}") from err
    except ValueError as err:
        raise UserError(f"{path}: {err}") from err


def load_any_model(path: Path) -> TreeModel | IntentTreeModel:
    """Either kind of tree file, by its version (for `tree show`)."""
    text = _read(path)
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise UserError(f"{path}: line {err.lineno}: not valid JSON: {err.msg}") from err
    if isinstance(data, dict) and data.get("version") == INTENT_VERSION:
        return load_intent_model(path)
    return _parse(text, str(path))


def load_model(path: Path) -> TreeModel:
    """Read a tree file; UserError (naming the file) if it is unreadable or malformed."""
    return _parse(_read(path), str(path))


def _parse(text: str, where: str) -> TreeModel:
    try:
        return model_from_json(json.loads(text))
    except json.JSONDecodeError as err:
        raise UserError(f"{where}: line {err.lineno}: not valid JSON: {err.msg}") from err
    except ValueError as err:
        raise UserError(f"{where}: {err}") from err


def load_default_model() -> TreeModel:
    """The tree shipped inside the package (see monopic/tree/DEFAULT_TREE.md)."""
    ref = resources.files("monopic.tree").joinpath(DEFAULT_TREE_NAME)
    return _parse(ref.read_text(encoding="utf-8"), f"package data {DEFAULT_TREE_NAME}")


def tree_predictor(mode: Mode, model: Path | None = None) -> TreePredictor:
    """The `tree` entry of the predictor registry: a tree file, or the shipped tree."""
    tree = load_model(model) if model is not None else load_default_model()
    if tree.mode is not mode:
        where = model if model is not None else "the shipped default tree"
        raise UserError(f"{where}: tree was trained for {tree.mode} mode, not {mode} mode")
    return TreePredictor(tree)


def shipped_ground_tree() -> Path:
    """Path of the ground intent tree shipped inside the package (GROUND_TREE.md)."""
    return Path(str(resources.files("monopic.tree").joinpath(GROUND_TREE_NAME)))


def intent_tree_predictor(mode: Mode, model: Path | None = None) -> IntentTreePredictor:
    """The `intent-tree` entry of the predictor registry: the given ground intent tree
    file, or the shipped one (trained for the small robot's 1.5 s horizon)."""
    if mode is not Mode.GROUND:
        raise UserError(f"predictor 'intent-tree' predicts in ground mode only, not {mode} mode")
    return IntentTreePredictor(load_intent_model(model or shipped_ground_tree()))
