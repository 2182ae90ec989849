"""Predictors by name: the `monopic.predictors` entry-point group.

Each entry names a factory `(mode, model_file) -> Predictor`. This package lists the
authors' rule cascade, constant velocity and the ID3 tree (pyproject.toml); another
installed package adds its own predictor the same way, and every command that takes a
predictor name (video, sweeps, the closed loop) then knows it, without editing this one.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path

from monopic.errors import UserError
from monopic.predict.base import Mode, Predictor

PREDICTOR_GROUP = "monopic.predictors"
PredictorFactory = Callable[[Mode, Path | None], Predictor]


@cache
def _registered() -> dict[str, EntryPoint]:
    """Installed predictors (read once: installed metadata does not change in a run)."""
    return {ep.name: ep for ep in entry_points(group=PREDICTOR_GROUP)}


def predictor_names() -> tuple[str, ...]:
    """Every installed predictor's name, sorted."""
    return tuple(sorted(_registered()))


def check_predictor_name(name: str) -> None:
    """UserError (one line, the known names) unless `name` is an installed predictor."""
    if name not in _registered():
        known = ", ".join(predictor_names()) or "none installed: pip install -e ."
        raise UserError(f"unknown predictor {name!r}: choose from {known}")


def make_predictor(name: str, mode: Mode, model: Path | None = None) -> Predictor:
    """The named predictor for `mode`; `model` is its model file where it takes one.

    The predictor must call itself by its registry name: its decisions are stored and
    reported as "<name>/<mode>", and commands take that same key (closed-loop --policies),
    so there is one vocabulary from the command line to the report.
    """
    check_predictor_name(name)
    entry = _registered()[name]
    factory: PredictorFactory = entry.load()
    predictor = factory(mode, model)
    if predictor.name != name:
        raise UserError(
            f"predictor {name!r} ({entry.value}) calls itself {predictor.name!r}: its name "
            "attribute must be its entry-point name, which results and reports use"
        )
    return predictor


def no_model(name: str, model: Path | None) -> None:
    """For predictors without a model file: refuse one rather than ignore it."""
    if model is not None:
        raise UserError(f"{model}: predictor {name!r} takes no model file")
