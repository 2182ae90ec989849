"""The pipelines a run compares, set up as the scenario's robot carries them.

The robot knows its camera, its footprint and the horizon; every predictor runs on one
pose (image and ground mode side by side).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from monopic.people.tracker import PeopleConfig
from monopic.pipeline import Pipeline, PipelineConfig
from monopic.pose.tracker import TrackerConfig
from monopic.predict.base import Mode, Predictor
from monopic.predict.registry import make_predictor
from monopic.variants.warning import CollisionWarning
from sim.runs.run_spec import EVERYONE, ONE, TRACKERS
from sim.scenario.spec import Scenario

# The predictors every run compares: the paper's image mode and the ground mode.
PREDICTORS: tuple[tuple[str, Mode], ...] = (
    ("rules", Mode.IMAGE),
    ("tree", Mode.IMAGE),
    ("constant-velocity", Mode.IMAGE),
    ("rules", Mode.GROUND),
    ("constant-velocity", Mode.GROUND),
)

INTENT_TREE = "intent-tree"  # the registry name of the ground intent tree (a spec names its file)


def scenario_pipeline(
    scenario: Scenario,
    predictors: Sequence[Predictor],
    tracker: TrackerConfig | None = None,
    follows: str = ONE,
) -> Pipeline:
    """A pipeline set up for the scenario: its horizon and the robot's own footprint;
    `follows` one pedestrian or everyone (TRACKERS).

    One onnxruntime thread by default, since workers run side by side.
    """
    if follows not in TRACKERS:
        raise ValueError(f"tracker must be one of {', '.join(TRACKERS)}, got {follows!r}")
    config = PipelineConfig(
        horizon=scenario.horizon,
        mode=predictors[0].mode,
        tracker=tracker or TrackerConfig(threads=1),
        warning=CollisionWarning(robot=scenario.robot.geometry()),
        people=PeopleConfig() if follows == EVERYONE else None,
    )
    return Pipeline(config, predictors)


def make_pipeline(
    scenario: Scenario,
    ablation: bool = False,
    intent_tree: Path | None = None,
    tracker: TrackerConfig | None = None,
    follows: str = ONE,
) -> Pipeline:
    """All predictors on one pose, the sweep's pipeline.

    With `intent_tree` (a sweep spec's `intent_tree` file) the ground intent tree runs
    too, last, so the primary predictor and the others' outputs are unchanged. `tracker`
    replaces the default one-thread tracker (the benchmarks time other runtimes with it).

    The ablation's tracker never detects (a threshold above any score, and no tiles nor
    zooms, so a failed crop costs one whole-frame pass): it only ever sees the true crop, so what it
    gets right or wrong is the pose from that crop; it follows the one person it is shown.
    `follows` sets the main pipeline's tracker (TRACKERS).
    """
    if ablation:
        tracker = replace(
            tracker or TrackerConfig(threads=1),
            min_detection_score=1.01,
            acquire_tiles=(),
            zoom_score=None,
        )
    predictors = [make_predictor(name, mode) for name, mode in PREDICTORS]
    if intent_tree is not None:
        predictors.append(make_predictor(INTENT_TREE, Mode.GROUND, intent_tree))
    return scenario_pipeline(scenario, predictors, tracker, ONE if ablation else follows)
