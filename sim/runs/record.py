"""`monopic record`'s run: one scenario through the pipeline, every frame recorded to .rrd."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from monopic.pipeline import Pipeline
from sim.recording.sim_recording import DEFAULT_TOPDOWN_EVERY, RecordSummary, SimRecording
from sim.runs.pipelines import make_pipeline
from sim.scenario.spec import Scenario
from sim.world.world import World


def record_run(
    scenario: Scenario,
    path: Path,
    *,
    pipeline: Pipeline | None = None,
    topdown_every: int = DEFAULT_TOPDOWN_EVERY,
    stop_at_contact: bool = True,
    on_frame: Callable[[int], None] | None = None,
) -> RecordSummary:
    """Run one scenario through the pipeline, frame by frame, and record it to `path`."""
    pipeline = pipeline or make_pipeline(scenario)
    with World(scenario, render=True) as world:
        recording = SimRecording(path, world, topdown_every=topdown_every)
        with recording:
            step = world.reset()
            for k in range(scenario.frames):
                if k > 0:
                    step = world.step()
                assert step.frame is not None
                recording.log_step(step, pipeline.process(step.frame))
                if on_frame is not None:
                    on_frame(k)
                if stop_at_contact and step.truth.contact:
                    break
        return recording.summary()
