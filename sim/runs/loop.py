"""The one run loop: a World stepped frame by frame, the robot's pipelines on every frame.

Every use of the simulator drives this loop: sweep runs (sim.runs.runner), recordings
(sim.runs.record), datasets (sim.dataset.build), the closed loop (sim.runs.closed_loop)
and the simulator benchmarks. What each use adds is a listener (dm_control style: built
once, hooks per frame): the results columns, a rerun recording, the dataset writer,
progress bars, benchmark timers. A controller turns each frame into the robot's next
action (the closed loop's brake); without one the robot keeps its course.

Per frame, in this order: the world's step (timed: `sim_ms`), each on-board pipeline on
the frame (what it may see: pixels, timestamp, the robot's own state; only an ablation's
crop is cut from the truth), the controller's action, then the listeners. The loop ends
after a frame with contact when `stop_at_contact`, after `frames` frames, or, before
processing, at a step that `until` says ends the run (its state is `LoopEnd.final`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from monopic.pipeline import FrameResult, Pipeline
from monopic.pose.region import Region
from sim.world.ground_truth import GroundTruth
from sim.world.world import World, WorldStep


@dataclass(frozen=True)
class OnBoard:
    """A pipeline the robot runs on every frame.

    `crop` (the ablation only) cuts the region the pipeline gets from the truth; a frame
    where it gives None is not processed (result None).
    """

    name: str
    pipeline: Pipeline
    crop: Callable[[GroundTruth], Region | None] | None = None

    def process(self, step: WorldStep) -> FrameResult | None:
        if step.frame is None:
            raise ValueError(f"pipeline {self.name!r} needs rendered frames (World render=True)")
        if self.crop is None:
            return self.pipeline.process(step.frame)
        region = self.crop(step.truth)
        return self.pipeline.process(step.frame, region) if region is not None else None


@dataclass
class LoopFrame:
    """One processed frame: the world's step, each pipeline's result, the action chosen."""

    step: WorldStep
    results: dict[str, FrameResult | None]
    sim_ms: float  # the world's step (or reset) and its render
    action: float = 0.0  # m/s^2 for the step leaving this frame

    @property
    def index(self) -> int:
        return self.step.index

    @property
    def truth(self) -> GroundTruth:
        return self.step.truth


@dataclass(frozen=True)
class LoopEnd:
    """How the loop ended."""

    frames: int  # frames processed
    contact_time: float | None  # first contact (s), None without one
    final: WorldStep  # the last state reached: the last frame, or the step `until` ended on
    reason: str  # "contact", "frames" or "until"


class Listener:
    """What a use adds to the loop; each hook does nothing unless overridden."""

    def start(self, world: World) -> None:
        """Before the first frame (the world is reset)."""

    def frame(self, frame: LoopFrame) -> None:
        """After each processed frame."""

    def end(self, end: LoopEnd) -> None:
        """After the last frame (not on an exception)."""


class Controller(Protocol):
    def action(self, frame: LoopFrame) -> float:
        """The robot's acceleration (m/s^2) for the step leaving this frame."""
        ...


@dataclass
class Progress(Listener):
    """Calls `on_frame(index)` after each frame (progress bars)."""

    on_frame: Callable[[int], None]

    def frame(self, frame: LoopFrame) -> None:
        self.on_frame(frame.index)


@dataclass
class StepTimes(Listener):
    """The world's time per frame (ms), for results and benchmarks."""

    ms: list[float] = field(default_factory=list)

    def frame(self, frame: LoopFrame) -> None:
        self.ms.append(frame.sim_ms)


def run_loop(
    world: World,
    onboard: Sequence[OnBoard] = (),
    listeners: Sequence[Listener] = (),
    *,
    controller: Controller | None = None,
    frames: int | None = None,
    stop_at_contact: bool = True,
    until: Callable[[WorldStep], bool] | None = None,
    seed: int | None = None,
) -> LoopEnd:
    """Reset `world` (seed: default the scenario's) and run it (see the module docstring).

    `frames` None runs until `until` or contact (give one of them, or the loop has no end).
    """
    if frames is None and until is None and not stop_at_contact:
        raise ValueError("the loop needs an end: frames, until or stop_at_contact")
    if frames is not None and frames < 1:
        raise ValueError(f"frames must be >= 1, got {frames}")
    t0 = time.perf_counter()
    step = world.reset(seed)
    sim_ms = (time.perf_counter() - t0) * 1e3
    for listener in listeners:
        listener.start(world)
    processed = 0
    contact_time = None
    while True:
        results = {board.name: board.process(step) for board in onboard}
        frame = LoopFrame(step, results, sim_ms)
        if controller is not None:
            frame.action = controller.action(frame)
        for listener in listeners:
            listener.frame(frame)
        processed += 1
        if step.truth.pedestrian.contact and contact_time is None:
            contact_time = step.truth.time
        reason = ""
        if step.truth.pedestrian.contact and stop_at_contact:
            reason = "contact"
        elif frames is not None and processed >= frames:
            reason = "frames"
        if not reason:
            t0 = time.perf_counter()
            nxt = world.step(action=frame.action)
            sim_ms = (time.perf_counter() - t0) * 1e3
            if until is not None and until(nxt):
                step, reason = nxt, "until"
            else:
                step = nxt
                continue
        end = LoopEnd(processed, contact_time, step, reason)
        for listener in listeners:
            listener.end(end)
        return end
