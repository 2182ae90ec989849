"""An AEB for the car: brakes on the pipeline's warning, late by latency and brake delay.

The pipeline's collision warning is the forward collision warning (FCW): the first
warned frame, known once the pipeline has processed it (capture time plus its measured
latency), is when the FCW is issued, and its time to collision then is the warning TTC
Euro NCAP judges (CPLA: timely at 1.7 s or more). The same warning asks the brakes for
an emergency stop: they start to build up `brake_delay` seconds after the warning is
issued (the brake system's dead time) and ramp at `jerk` m/s^3 up to the full
deceleration, then hold it until the car stands (latched, as AEB systems do: a false
alarm costs the rest of the run).

The world applies one constant acceleration per frame step; the brake gives each step
the mean of the continuous jerk-limited profile over it, so the car's speed at every
frame is exactly that of the continuous profile, whatever the frame rate.

`run_aeb` is one closed-loop run of a scenario under a policy ("rules/ground", ...) with
this brake, in the one run loop (sim.runs.loop) and seeded as the closed loop is, its
pipeline following one pedestrian or everyone (`tracker`); like the closed loop's, its
outcome names whom the car braked for (the person of the warning the brake acted on,
sim.world.warned_for).

Latency: a fixed figure (what a real-time implementation guarantees; `monopic ncap`
applies the car file's declared one by default, so that a rating is a property of the
pipeline and not of the host's load), the pipeline's own measured one per frame, or a
recorded sequence of per-frame latencies. The outcome keeps the measured latency of every
processed frame, so a run made with the measured latency is replayed exactly by passing
them back (the frames and decisions are the same: only the latency depended on the host).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sim.recording.sim_recording import SimRecording
from sim.runs.closed_loop import (
    POLICY,
    LoopLog,
    braked_for_fields,
    frame_warned_for,
    policy_pipeline,
    world_seed,
)
from sim.runs.latency import AppliedLatency
from sim.runs.loop import Listener, LoopFrame, OnBoard, Progress, run_loop
from sim.runs.run_spec import ONE
from sim.scenario.spec import Scenario
from sim.world.ground_truth import GroundTruth, pedestrian_passed
from sim.world.render import RenderContext
from sim.world.warned_for import WarnedFor, braked_wrong, target_found
from sim.world.world import World, WorldStep


@dataclass(frozen=True)
class AebParams:
    """The brake: dead time after the warning, build-up jerk, full deceleration.

    `latency_ms` None applies the pipeline's measured latency per frame; a number is a
    fixed latency instead (what a real-time implementation would guarantee).
    """

    brake_delay: float = 0.1  # s from the warning to the first brake pressure
    jerk: float = 30.0  # m/s^3 during the build-up
    deceleration: float = 9.0  # m/s^2, full braking
    latency_ms: float | None = None

    def __post_init__(self) -> None:
        if not (self.brake_delay >= 0 and self.jerk > 0 and self.deceleration > 0):
            raise ValueError("AEB needs brake_delay >= 0, jerk > 0 and deceleration > 0")
        if self.latency_ms is not None and not self.latency_ms >= 0:
            raise ValueError(f"latency must be >= 0 ms, got {self.latency_ms}")


class JerkLimitedBrake:
    """Warnings in, the mean deceleration of each frame step out (pure bookkeeping).

    `observe(t, warned, latency_s)` after processing the frame captured at time t;
    `action(t)` is the acceleration (m/s^2, negative) for the step from t to t + dt.
    """

    def __init__(self, dt: float, params: AebParams) -> None:
        if not dt > 0:
            raise ValueError(f"dt must be positive, got {dt}")
        self.dt = dt
        self.params = params
        self.warning_time: float | None = None  # s, when the first warning is issued
        self.brake_start: float | None = None  # s, when the brakes start to build up

    def observe(self, t: float, warned: bool, latency_s: float) -> None:
        if not warned:
            return
        if not (math.isfinite(latency_s) and latency_s >= 0):
            raise ValueError(f"latency must be a finite number >= 0 s, got {latency_s}")
        issued = t + latency_s
        if self.warning_time is None or issued < self.warning_time:
            self.warning_time = issued
            self.brake_start = issued + self.params.brake_delay

    def deceleration_at(self, t: float) -> float:
        """The continuous profile: 0 before the brakes start, then the jerk ramp, then full."""
        if self.brake_start is None or t <= self.brake_start:
            return 0.0
        return min(self.params.jerk * (t - self.brake_start), self.params.deceleration)

    def _integral(self, t: float) -> float:
        """Speed lost from the brake start up to t (m/s)."""
        if self.brake_start is None or t <= self.brake_start:
            return 0.0
        p = self.params
        tau = t - self.brake_start
        ramp = p.deceleration / p.jerk
        if tau <= ramp:
            return 0.5 * p.jerk * tau**2
        return 0.5 * p.deceleration * ramp + p.deceleration * (tau - ramp)

    def action(self, t: float) -> float:
        """m/s^2 for the step leaving the frame at time t: the profile's mean over it."""
        return -(self._integral(t + self.dt) - self._integral(t)) / self.dt


@dataclass
class AebController:
    """The policy's warning on each frame, issued as FCW and turned into the brake command."""

    brake: JerkLimitedBrake
    latency: AppliedLatency
    warned_frames: int = 0
    first_warning_frame: int | None = None
    warning_ttc: float | None = None  # s to collision when the FCW was issued
    policy: str = ""
    acted: WarnedFor | None = None  # whom the warning the brake acts on was for

    def action(self, frame: LoopFrame) -> float:
        result = frame.results.get(POLICY)
        warned, latency = False, 0.0
        if result is not None:
            warned = bool(result.warning is not None and result.warning.collision)
            latency = self.latency.next_ms(result.stage_ms["total"]) / 1e3
        if warned:
            self.warned_frames += 1
            if self.first_warning_frame is None:
                self.first_warning_frame = frame.index
                ttc = frame.truth.pedestrian.time_to_collision  # at constant speeds, as NCAP's TTC
                self.warning_ttc = None if ttc is None else max(0.0, float(ttc) - latency)
        before = self.brake.warning_time
        self.brake.observe(frame.truth.time, warned, latency)
        if self.brake.warning_time != before:  # this frame's warning is now the one acting
            self.acted = frame_warned_for(frame, self.policy)
        return self.brake.action(frame.truth.time)


@dataclass
class PitchLog(Listener):
    """The largest nose dip of the run (degrees), read from the world."""

    world: World
    max_deg: float = 0.0

    def frame(self, frame: LoopFrame) -> None:
        self.max_deg = max(self.max_deg, math.degrees(self.world.pitch))


SEEN = 0.5  # share of the target's landmarks in the image and unoccluded: in sight


def ahead_of_front(truth: GroundTruth, front: float) -> float:
    """m from the car's front (`front` m ahead of its reference point) to the target."""
    return max(0.0, float(np.hypot(*truth.pedestrian.position_robot)) - front)


@dataclass
class SightLog(Listener):
    """Per frame: whether the target was in sight, and found by the pipeline, and how far
    ahead of the car's front it stood (for detection by distance band, day against night)."""

    front: float  # m from the robot's reference point to its front
    found: list[int] = field(default_factory=list)  # 1 found, 0 missed, -1 not in sight
    range_m: list[float] = field(default_factory=list)

    def frame(self, frame: LoopFrame) -> None:
        person = frame.truth.pedestrian
        if person.visible_fraction < SEEN:
            self.found.append(-1)
        else:
            self.found.append(int(target_found(frame.results.get(POLICY), frame.truth)))
        self.range_m.append(round(ahead_of_front(frame.truth, self.front), 2))


@dataclass(frozen=True)
class AebOutcome:
    """One AEB run: what Euro NCAP measures and what the project adds."""

    scenario: str
    policy: str
    seed: int
    frames: int
    contact: bool
    start_speed: float  # m/s
    impact_speed: float | None  # the car's speed at contact, m/s
    relative_impact_speed: float | None  # closing speed along the car's axis, m/s
    speed_reduction: float  # m/s: start speed minus impact speed (or final speed)
    min_gap: float  # m between the footprints (0: contact)
    warning_time: float | None  # s, when the FCW was issued (capture + latency)
    warning_ttc: float | None  # s to collision then
    brake_time: float | None  # s, the first step with brake pressure
    final_speed: float
    max_pitch_deg: float
    warned_frames: int
    latency_ms_median: float | None  # of the pipeline's measured latencies
    # The pipeline's measured latency of every processed frame, ms (what a replay of a
    # run made with the measured latency passes back as `latencies_ms`).
    latencies_ms: tuple[float, ...] = field(repr=False, default=())
    # Whom the brake acted for, as the closed loop's LoopOutcome says it (written only
    # for the people tracker or several people: sim.runs.closed_loop.OPTIONAL).
    braked_for: str | None = None
    braked_for_track: int | None = None
    braked_for_on_course: bool | None = None
    people: int = 1
    braked_for_ttc: float | None = None
    # Per processed frame (SightLog): the target found (1), missed (0) or not in sight
    # (-1), and its distance ahead of the car's front in m.
    target_found: tuple[int, ...] = field(repr=False, default=())
    target_range_m: tuple[float, ...] = field(repr=False, default=())

    @property
    def braked(self) -> bool:
        return self.brake_time is not None

    @property
    def wrong_person(self) -> bool:
        """Braked for nobody or for someone not on a collision course."""
        return braked_wrong(self.braked_for, self.braked_for_on_course)


def run_aeb(
    scenario: Scenario,
    policy: str,
    params: AebParams,
    *,
    seed: int = 0,
    render_context: RenderContext | None = None,
    on_frame: Callable[[int], None] | None = None,
    latencies_ms: Sequence[float] | None = None,
    rrd: Path | None = None,
    tracker: str = ONE,
) -> AebOutcome:
    """One closed-loop run of `scenario` with the pipeline of `policy` and this AEB.

    `latencies_ms`: the per-frame latencies to apply instead of the measured ones (a
    replay: an earlier outcome's `latencies_ms`, with `params.latency_ms` None); a replay
    that processes another number of frames raises ValueError. `rrd` records the run (as
    the closed loop records one: sim.runs.closed_loop.LoopLog). `tracker`: whom the
    pipeline follows (sim.runs.run_spec.TRACKERS).
    """
    latency = AppliedLatency(params.latency_ms, latencies_ms)
    onboard = [OnBoard(POLICY, policy_pipeline(scenario, policy, tracker))]
    brake = JerkLimitedBrake(scenario.dt, params)
    controller = AebController(brake, latency, policy=policy)
    robot, footprint = scenario.robot, scenario.pedestrian.footprint

    def over(step: WorldStep) -> bool:
        if step.truth.pedestrian.contact:
            return False
        passed = pedestrian_passed(step.truth, robot.length, footprint)
        stopped = step.truth.robot.speed <= 0.0 and brake.brake_start is not None
        return passed or stopped or step.index >= scenario.frames

    with World(scenario, render=True, render_context=render_context) as world:
        recording = SimRecording(rrd, world) if rrd is not None else None
        with recording if recording is not None else nullcontext():
            log = LoopLog(footprint, policy, recording, lambda: controller.acted)
            pitch = PitchLog(world)
            sight = SightLog(robot.length / 2)
            listeners: list[Listener] = [log, pitch, sight]
            if on_frame is not None:
                listeners.append(Progress(on_frame))
            end = run_loop(
                world, onboard, listeners, controller=controller, until=over, seed=world_seed(seed)
            )
        ped_speed = float(end.final.truth.pedestrian.velocity_robot[0])
    latency.check_used()
    start = log.start_speed if log.start_speed is not None else robot.speed
    contact = log.contact_time is not None
    relative = None
    if contact and log.impact_speed is not None:
        relative = max(0.0, log.impact_speed - ped_speed)  # a walker ahead moves away
    reduction = start - (log.impact_speed if contact and log.impact_speed is not None else 0.0)
    if not contact:
        reduction = start - log.final_speed if log.brake_time is not None else 0.0
    lat = latency.measured
    return AebOutcome(
        scenario=scenario.name,
        policy=policy,
        seed=seed,
        frames=log.frames,
        contact=contact,
        start_speed=start,
        impact_speed=log.impact_speed,
        relative_impact_speed=relative,
        speed_reduction=reduction,
        min_gap=log.min_gap,
        warning_time=brake.warning_time,
        warning_ttc=controller.warning_ttc,
        brake_time=log.brake_time,
        final_speed=log.final_speed,
        max_pitch_deg=pitch.max_deg,
        warned_frames=controller.warned_frames,
        latency_ms_median=float(np.median(lat)) if lat else None,
        latencies_ms=tuple(lat),
        **braked_for_fields(controller.acted if log.brake_time is not None else None),
        people=log.people,
        target_found=tuple(sight.found),
        target_range_m=tuple(sight.range_m),
    )
