"""Choosing a predictor by name: the reference rules, the ID3 tree, constant velocity."""

from __future__ import annotations

from pathlib import Path

from monopic.errors import UserError
from monopic.predict.base import Mode, Predictor
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from monopic.predict.rules import RulePredictor
from monopic.tree.model import TreePredictor
from monopic.tree.serialise import load_default_model, load_model

PREDICTOR_NAMES = ("rules", "tree", "constant-velocity")


def make_predictor(name: str, mode: Mode, tree: Path | None = None) -> Predictor:
    """The named predictor for `mode`; `tree` is a tree file (default: the shipped tree)."""
    if name == "rules":
        return RulePredictor(mode=mode)
    if name == "constant-velocity":
        return ConstantVelocityPredictor(mode=mode)
    if name == "tree":
        model = load_model(tree) if tree is not None else load_default_model()
        if model.mode is not mode:
            where = tree if tree is not None else "the shipped default tree"
            raise UserError(f"{where}: tree was trained for {model.mode} mode, not {mode} mode")
        return TreePredictor(model)
    raise UserError(f"unknown predictor {name!r}: choose from {', '.join(PREDICTOR_NAMES)}")
