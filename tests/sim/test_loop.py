"""The one run loop: how it ends, what listeners see, what a controller does."""

from __future__ import annotations

from dataclasses import dataclass, field

import pytest

from monopic.cases import Case
from sim.runs.loop import Listener, LoopEnd, LoopFrame, OnBoard, StepTimes, run_loop
from sim.scenario.cases import CasePlacement
from sim.world.world import World


@dataclass
class Seen(Listener):
    calls: list[str] = field(default_factory=list)
    indices: list[int] = field(default_factory=list)
    speeds: list[float] = field(default_factory=list)
    ended: LoopEnd | None = None

    def start(self, world: World) -> None:
        self.calls.append("start")

    def frame(self, frame: LoopFrame) -> None:
        self.calls.append("frame")
        self.indices.append(frame.index)
        self.speeds.append(frame.truth.robot.speed)

    def end(self, end: LoopEnd) -> None:
        self.calls.append("end")
        self.ended = end


def crossing(duration: float = 4.0):
    """Case 5 on a collision course: contact about 2.7 s in (distance = speed x meet time)."""
    placement = CasePlacement(
        Case.PERPENDICULAR_RIGHT, distance=6.0, robot_speed=2.0, meet_time=3.0, duration=duration
    )
    return placement.scenario()


def test_frames_end_the_loop_and_listeners_see_each_frame_once_in_order():
    seen, times = Seen(), StepTimes()
    with World(CasePlacement(Case.AWAY, duration=1.0).scenario(), render=False) as world:
        end = run_loop(world, (), [seen, times], frames=5)
    assert seen.calls == ["start", *["frame"] * 5, "end"]
    assert seen.indices == [0, 1, 2, 3, 4]
    assert (end.frames, end.reason, end.final.index) == (5, "frames", 4)
    assert len(times.ms) == 5 and all(ms >= 0 for ms in times.ms)


def test_contact_ends_the_loop_after_its_frame_unless_told_to_go_on():
    scenario = crossing()
    with World(scenario, render=False) as world:
        end = run_loop(world, (), [], frames=scenario.frames)
        assert end.reason == "contact" and end.final.truth.pedestrian.contact
        assert end.contact_time == pytest.approx(end.final.time)
        assert end.frames == end.final.index + 1 < scenario.frames
        on = run_loop(world, (), [], frames=scenario.frames, stop_at_contact=False)
    assert on.reason == "frames" and on.frames == scenario.frames
    assert on.contact_time == pytest.approx(end.contact_time)  # the first contact


def test_until_ends_before_processing_the_state_it_names():
    seen = Seen()
    with World(CasePlacement(Case.AWAY, duration=2.0).scenario(), render=False) as world:
        end = run_loop(world, (), [seen], until=lambda step: step.index >= 3)
    assert seen.indices == [0, 1, 2]
    assert (end.reason, end.frames, end.final.index) == ("until", 3, 3)


@dataclass
class BrakeFrom:
    index: int

    def action(self, frame: LoopFrame) -> float:
        return -8.0 if frame.index >= self.index else 0.0


def test_the_controllers_action_drives_the_robot():
    seen = Seen()
    scenario = crossing()
    with World(scenario, render=False) as world:
        end = run_loop(world, (), [seen], controller=BrakeFrom(3), frames=scenario.frames)
    assert seen.speeds[:4] == pytest.approx([2.0] * 4)
    assert seen.speeds[4] == pytest.approx(2.0 - 8.0 * scenario.dt)
    assert seen.speeds[-1] == 0.0 and end.contact_time is None  # stopped short: no contact


def test_a_loop_without_an_end_or_a_pipeline_without_frames_is_refused():
    with World(CasePlacement(Case.AWAY, duration=1.0).scenario(), render=False) as world:
        with pytest.raises(ValueError, match="needs an end"):
            run_loop(world, (), [], stop_at_contact=False)
        board = OnBoard("main", pipeline=None)  # type: ignore[arg-type]
        with pytest.raises(ValueError, match="needs rendered frames"):
            run_loop(world, [board], [], frames=2)
