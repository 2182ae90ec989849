"""Runs recorded to .rrd: the loop's listener that logs frames, and `monopic record`'s run."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from monopic.pipeline import Pipeline
from sim.recording.sim_recording import DEFAULT_TOPDOWN_EVERY, RecordSummary, SimRecording
from sim.runs.loop import Listener, LoopFrame, OnBoard, Progress, run_loop
from sim.runs.pipelines import make_pipeline
from sim.runs.result import MAIN
from sim.scenario.spec import Scenario
from sim.world.world import World


@dataclass
class Recorder(Listener):
    """Logs every frame into a SimRecording: the truth, the world and one pipeline's result."""

    recording: SimRecording
    pipeline: str = MAIN

    def frame(self, frame: LoopFrame) -> None:
        self.recording.log_step(frame.step, frame.results.get(self.pipeline))


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
    onboard = OnBoard(MAIN, pipeline or make_pipeline(scenario))
    with World(scenario, render=True) as world:
        recording = SimRecording(path, world, topdown_every=topdown_every)
        with recording:
            listeners = [Recorder(recording)]
            if on_frame is not None:
                listeners.append(Progress(on_frame))
            run_loop(
                world,
                [onboard],
                listeners,
                frames=scenario.frames,
                stop_at_contact=stop_at_contact,
            )
        return recording.summary()
