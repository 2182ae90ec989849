"""The closed loop: the robot brakes when the pipeline warns, late by the pipeline's own latency.

Each run is the one run loop (sim.runs.loop) with a brake controller, ending as the
gymnasium environment `monopic/PedestrianCrossing-v0` ends an episode (contact, the
pedestrian behind the robot, or the scenario's duration) and seeded as it seeds the
world, so a run equals that environment's episode. A policy turns each frame into a
brake decision:

- "none": never brakes (the baseline the contacts are counted against);
- "truth": brakes when the ground truth says the footprints meet within the horizon (an
  oracle: what a perfect warning with the same horizon and brake would achieve);
- "<predictor>/<mode>", e.g. "rules/image" or "rules/ground": brakes on that predictor's
  collision warning; the pipeline sees only the camera frame, its timestamp and the
  robot's own state.

Latency: a frame captured at step k whose processing took L seconds (the pipeline's own
measured `stage_ms["total"]`, a fixed figure, or the latency recorded for that frame in an
earlier run: sim.runs.latency) is known at t_k + L, and its command acts
from the first frame boundary at or after that, i.e. on the step leaving frame
k + ceil(L / dt). Commands are latched: once the brake acts the robot brakes at its
maximum deceleration (RobotSpec.max_deceleration) until it stands, and stays standing
(an emergency stop, as AEB systems do; a false alarm therefore costs the rest of the run).
The pipeline processes every frame even when L > dt (a real robot would drop frames).

Per run: contact (footprints meet, sim.world.ground_truth), the robot's speed at contact
(impact speed), the smallest gap between the footprints, when the first warning came and
when the brake acted, and whom the car braked for: at the frame whose warning made the
brake act (the warning that acted first, LatencyBrake), the warned person's track matched
to the truth's people (sim.world.warned_for): their name or "nobody" (a phantom), and
whether they were on a collision course then. The pipeline follows one pedestrian or
everyone in view (`tracker`, sim.runs.run_spec.TRACKERS); with everyone, the warning the
brake acts on is the worst person's (monopic.pipeline.worst_for). A brake for nobody or
for someone not on a collision course is braking for the wrong person, counted apart from
right braking (a needless stop that braked for a bystander is the wrong person's).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from contextlib import nullcontext
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from monopic.pipeline import Pipeline
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor, predictor_names
from sim.recording.sim_recording import SimRecording
from sim.runs.latency import AppliedLatency
from sim.runs.loop import Listener, LoopEnd, LoopFrame, OnBoard, Progress, run_loop
from sim.runs.run_spec import ONE
from sim.scenario.spec import Scenario
from sim.world.ground_truth import footprint_gap, pedestrian_passed
from sim.world.render import RenderContext
from sim.world.warned_for import (
    WarnedFor,
    braked_wrong,
    oracle_warned_for,
    warned_for,
)
from sim.world.world import World, WorldStep

NO_BRAKE = "none"
ORACLE = "truth"


@dataclass(frozen=True)
class LoopOutcome:
    """One closed-loop run."""

    scenario: str
    policy: str
    seed: int
    frames: int
    contact: bool
    contact_time: float | None
    impact_speed: float | None  # robot speed at contact, m/s
    min_gap: float  # m between the footprints (0: contact)
    first_warning_time: float | None  # s, capture time of the first warned frame
    brake_time: float | None  # s, when the brake started to act
    warned_frames: int
    start_speed: float
    final_speed: float
    # The pipeline's measured latency of every processed frame, ms (what a replay of a
    # run made with the measured latency passes back as `latencies_ms`).
    latencies_ms: tuple[float, ...] = field(repr=False, default=())
    delays: tuple[int, ...] = field(repr=False, default=())  # frames, per warned frame
    # Whom the brake acted for (sim.world.warned_for), None when it did not brake or the
    # line predates it; written only for the people tracker or several people (OPTIONAL).
    braked_for: str | None = None  # the truth's name, or NOBODY (a phantom)
    braked_for_track: int | None = None  # the pipeline's person id (None: the oracle)
    braked_for_on_course: bool | None = None  # on a collision course at that frame
    people: int = 1  # people in the scenario
    braked_for_ttc: float | None = None  # s, that person's true time to collision then

    @property
    def braked(self) -> bool:
        return self.brake_time is not None

    @property
    def wrong_person(self) -> bool:
        """Braked for nobody or for someone not on a collision course (known only where
        the run names whom it braked for)."""
        return braked_wrong(self.braked_for, self.braked_for_on_course)

    def braked_for_said(self) -> str | None:
        """'braked for adult (track 3, not on a collision course)', None if unnamed."""
        if self.braked_for is None:
            return None
        ttc = self.braked_for_ttc if self.braked_for_on_course else None
        if self.braked_for_on_course and ttc is None:  # a line without the time
            ttc = math.nan
        return f"braked for {WarnedFor(self.braked_for_track, self.braked_for, ttc).said()}"


# The outcome's fields a run writes only with the people tracker or several people, so a
# one-tracker run of one person writes the line it always wrote (sim.runs.result's rule).
OPTIONAL = ("braked_for", "braked_for_track", "braked_for_on_course", "people", "braked_for_ttc")


def outcome_json(outcome: LoopOutcome | Any, tracker: str) -> dict[str, Any]:
    """A closed-loop or AEB outcome as its result line holds it (OPTIONAL's rule)."""
    data = asdict(outcome)
    if tracker == ONE and outcome.people <= 1:
        for key in OPTIONAL:
            data.pop(key, None)
    return data


class LatencyBrake:
    """Warnings in, acceleration commands out, each late by the latency of its frame.

    `observe(k, warned, latency_s)` after processing frame k; `action(k)` is the
    acceleration for the step leaving frame k. Pure bookkeeping, so it is tested alone.
    """

    def __init__(self, dt: float, deceleration: float) -> None:
        if not (dt > 0 and deceleration > 0):
            raise ValueError(f"dt and deceleration must be positive, got {dt}, {deceleration}")
        self.dt = dt
        self.deceleration = deceleration
        self.brake_from: int | None = None  # first step the brake acts on
        self.first_warning: int | None = None
        self.delays: list[int] = []

    def delay_frames(self, latency_s: float) -> int:
        """Frame boundaries until a command computed in `latency_s` can act."""
        if not (math.isfinite(latency_s) and latency_s >= 0):
            raise ValueError(f"latency must be a finite number >= 0 s, got {latency_s}")
        return max(0, math.ceil(latency_s / self.dt - 1e-9))

    def observe(self, index: int, warned: bool, latency_s: float) -> None:
        if not warned:
            return
        delay = self.delay_frames(latency_s)
        self.delays.append(delay)
        if self.first_warning is None:
            self.first_warning = index
        acts = index + delay
        if self.brake_from is None or acts < self.brake_from:
            self.brake_from = acts

    def braking(self, index: int) -> bool:
        return self.brake_from is not None and index >= self.brake_from

    def action(self, index: int) -> float:
        """m/s^2 for the step leaving frame `index`."""
        return -self.deceleration if self.braking(index) else 0.0


POLICY = "policy"  # the on-board pipeline's name in the loop


def policy_choices() -> str:
    """The policies there are, as the error and --help say them."""
    names = "|".join(predictor_names())
    modes = "|".join(m.value for m in Mode)
    return f"{NO_BRAKE}, {ORACLE} or PREDICTOR/MODE ({names})/({modes})"


def check_policy(policy: str) -> None:
    """ValueError naming the policies there are unless `policy` is one of them.

    Policies are the keys results and reports use ("rules/image"), predictors by their
    registry names; checked before any run, not when the first run of it starts."""
    if policy in (NO_BRAKE, ORACLE):
        return
    name, slash, mode = policy.partition("/")
    if not slash or name not in predictor_names() or mode not in {m.value for m in Mode}:
        raise ValueError(f"{policy!r} is not a policy: use {policy_choices()}")


def policy_pipeline(scenario: Scenario, policy: str, tracker: str = ONE) -> Pipeline:
    """A pipeline whose primary (only) predictor is the policy's, e.g. 'rules/ground',
    following one pedestrian or everyone (`tracker`, sim.runs.run_spec.TRACKERS)."""
    from sim.runs.pipelines import scenario_pipeline

    check_policy(policy)
    name, _, mode = policy.partition("/")
    return scenario_pipeline(scenario, [make_predictor(name, Mode(mode))], follows=tracker)


def frame_warned_for(frame: LoopFrame, policy: str) -> WarnedFor | None:
    """Whom the policy's warning on this frame was for (None: it names no one)."""
    result = frame.results.get(POLICY)
    if result is not None:
        return warned_for(result, frame.truth)
    return oracle_warned_for(frame.truth) if policy == ORACLE else None


def world_seed(seed: int) -> int:
    """The world's seed for a closed-loop seed, drawn as the gymnasium environment draws it
    on reset(seed=seed), so a closed-loop run and that environment episode are the same."""
    rng, _ = gymnasium.utils.seeding.np_random(seed)
    return int(rng.integers(2**31 - 1))


@dataclass
class BrakeController:
    """The policy's warning on each frame, turned into the brake command (LatencyBrake)."""

    policy: str
    brake: LatencyBrake
    latency: AppliedLatency
    warned_frames: int = 0
    first_warning_time: float | None = None
    acted: WarnedFor | None = None  # whom the warning the brake acts on was for

    def action(self, frame: LoopFrame) -> float:
        truth = frame.truth
        result = frame.results.get(POLICY)
        if result is not None:
            warned = bool(result.warning is not None and result.warning.collision)
            latency = self.latency.next_ms(result.stage_ms["total"]) / 1e3
        elif self.policy == ORACLE:
            warned = truth.pedestrian.collision
            fixed = self.latency.latency_ms
            latency = 0.0 if fixed is None else fixed / 1e3
        else:
            warned, latency = False, 0.0
        self.warned_frames += int(warned)
        if warned and self.first_warning_time is None:
            self.first_warning_time = truth.time
        before = self.brake.brake_from
        self.brake.observe(frame.index, warned, latency)
        if self.brake.brake_from != before:  # this frame's warning is now the one acting
            self.acted = frame_warned_for(frame, self.policy)
        return self.brake.action(frame.index)


@dataclass
class LoopLog(Listener):
    """What a closed-loop run amounts to: gaps, contact, when the brake acted (and the .rrd)."""

    footprint: float
    policy: str
    recording: SimRecording | None = None
    # Whom the brake acts for, asked when it first acts (the controller's `acted`).
    acted: Callable[[], WarnedFor | None] | None = None
    min_gap: float = math.inf
    contact_time: float | None = None
    impact_speed: float | None = None
    brake_time: float | None = None
    start_speed: float | None = None
    final_speed: float = 0.0
    frames: int = 0
    people: int = 1

    def frame(self, frame: LoopFrame) -> None:
        truth = frame.truth
        if self.start_speed is None:
            self.start_speed = truth.robot.speed
            self.people = len(truth.people)
        self.min_gap = min(self.min_gap, footprint_gap(truth, self.footprint))
        if truth.pedestrian.contact and self.contact_time is None:
            self.contact_time, self.impact_speed = truth.time, truth.robot.speed
        if self.recording is not None:
            self.recording.log_step(frame.step, frame.results.get(POLICY))
            self.recording.log_series("brake/command", frame.action)
            if frame.action and self.brake_time is None:
                who = self.acted() if self.acted is not None else None
                said = f", braking for {who.said()}" if who is not None else ""
                self.recording.log_event(
                    f"BRAKE at {-frame.action:g} m/s^2 from this frame ({self.policy}{said})",
                    "WARN",
                )
        if frame.action and self.brake_time is None:
            self.brake_time = truth.time

    def end(self, end: LoopEnd) -> None:
        # The run ends on contact, or at the first state after which nothing can happen
        # (the pedestrian behind the robot, or time up): that state's gap counts too.
        if end.reason == "until":
            self.min_gap = min(self.min_gap, footprint_gap(end.final.truth, self.footprint))
        self.frames = end.frames + (end.reason == "until")
        self.final_speed = end.final.truth.robot.speed


def run_closed_loop(
    scenario: Scenario,
    policy: str,
    *,
    seed: int = 0,
    latency_ms: float | None = None,
    rrd: Path | None = None,
    on_frame: Callable[[int], None] | None = None,
    latencies_ms: Sequence[float] | None = None,
    render_context: RenderContext | None = None,
    tracker: str = ONE,
) -> LoopOutcome:
    """One run of `scenario` under `policy` (see the module docstring), its pipeline
    following one pedestrian or everyone (`tracker`).

    `latency_ms` None applies the pipeline's measured latency per frame (the oracle has
    none); a number applies that fixed latency instead. `latencies_ms` replays an earlier
    run made with the measured latency: its outcome's `latencies_ms`, one per processed
    frame (a replay that processes another number of frames raises ValueError). `rrd`
    records the run. `render_context`: a worker's kept GL context (sim.world.render).
    """
    latency = AppliedLatency(latency_ms, latencies_ms)
    onboard = []
    if policy not in (NO_BRAKE, ORACLE):
        onboard.append(OnBoard(POLICY, policy_pipeline(scenario, policy, tracker)))
    controller = BrakeController(
        policy, LatencyBrake(scenario.dt, scenario.robot.max_deceleration), latency
    )
    robot, footprint = scenario.robot, scenario.pedestrian.footprint

    def over(step: WorldStep) -> bool:  # as the gymnasium environment ends an episode
        if step.truth.pedestrian.contact:
            return False  # a contact frame is processed, then the loop stops
        passed = pedestrian_passed(step.truth, robot.length, footprint)
        return passed or step.index >= scenario.frames

    with World(scenario, render=True, render_context=render_context) as world:
        recording = SimRecording(rrd, world) if rrd is not None else None
        with recording if recording is not None else nullcontext():
            log = LoopLog(footprint, policy, recording, lambda: controller.acted)
            listeners: list[Listener] = [log]
            if on_frame is not None:
                listeners.append(Progress(on_frame))
            run_loop(
                world,
                onboard,
                listeners,
                controller=controller,
                until=over,
                seed=world_seed(seed),
            )
    latency.check_used()
    return LoopOutcome(
        scenario=scenario.name,
        policy=policy,
        seed=seed,
        frames=log.frames,
        contact=log.contact_time is not None,
        contact_time=log.contact_time,
        impact_speed=log.impact_speed,
        min_gap=log.min_gap,
        first_warning_time=controller.first_warning_time,
        brake_time=log.brake_time,
        warned_frames=controller.warned_frames,
        start_speed=log.start_speed if log.start_speed is not None else robot.speed,
        final_speed=log.final_speed,
        latencies_ms=tuple(latency.measured),
        delays=tuple(controller.brake.delays),
        **braked_for_fields(controller.acted if log.brake_time is not None else None),
        people=log.people,
    )


def braked_for_fields(acted: WarnedFor | None) -> dict[str, Any]:
    """An outcome's braked_for fields from whom the acting warning was for."""
    if acted is None:
        return {}
    return {
        "braked_for": acted.name,
        "braked_for_track": acted.track,
        "braked_for_on_course": acted.on_course,
        "braked_for_ttc": acted.ttc,
    }


# -- the comparison table ---------------------------------------------------------------


@dataclass(frozen=True)
class PolicyRow:
    """One policy over the same scenarios."""

    policy: str
    runs: int
    contacts: int
    avoided: int | None  # baseline contacts this policy avoided (None for the baseline)
    baseline_contacts: int
    impact_mean: float | None
    impact_max: float | None
    gap_mean: float
    gap_min: float
    braked: int
    needless_stops: int | None  # braked in runs the baseline finished without contact
    latency_ms_median: float | None
    delay_frames_median: float | None
    # Braked for nobody or someone not on a collision course (None: no run of the policy
    # names whom it braked for, e.g. one-tracker runs of one person).
    wrong_person: int | None = None


def summarise(outcomes: Sequence[LoopOutcome]) -> list[PolicyRow]:
    """Per policy, over the scenarios every policy ran (baseline first)."""
    by_policy: dict[str, dict[tuple[str, int], LoopOutcome]] = {}
    for o in outcomes:
        by_policy.setdefault(o.policy, {})[(o.scenario, o.seed)] = o
    baseline = by_policy.get(NO_BRAKE, {})
    rows = []
    order = sorted(by_policy, key=lambda p: (p != NO_BRAKE, p != ORACLE, p))
    for policy in order:
        runs = by_policy[policy]
        hit = [o for o in runs.values() if o.contact]
        speeds = [o.impact_speed for o in hit if o.impact_speed is not None]
        gaps = [o.min_gap for o in runs.values()]
        base_hits = {key for key, o in baseline.items() if o.contact and key in runs}
        avoided = needless = None
        if policy != NO_BRAKE and baseline:
            avoided = sum(1 for key in base_hits if not runs[key].contact)
            clear = [key for key, o in baseline.items() if not o.contact and key in runs]
            needless = sum(runs[key].braked for key in clear)
        lat = [v for o in runs.values() for v in o.latencies_ms]
        delays = [d for o in runs.values() for d in o.delays]
        named = [o for o in runs.values() if o.braked_for is not None]
        rows.append(
            PolicyRow(
                policy=policy,
                runs=len(runs),
                contacts=len(hit),
                avoided=avoided,
                baseline_contacts=len(base_hits),
                impact_mean=float(np.mean(speeds)) if speeds else None,
                impact_max=float(np.max(speeds)) if speeds else None,
                gap_mean=float(np.mean(gaps)),
                gap_min=float(np.min(gaps)),
                braked=sum(o.braked for o in runs.values()),
                needless_stops=needless,
                latency_ms_median=float(np.median(lat)) if lat else None,
                delay_frames_median=float(np.median(delays)) if delays else None,
                wrong_person=sum(o.wrong_person for o in named) if named else None,
            )
        )
    return rows


CONTACT, NEEDLESS = "with contact", "braked without need"
WRONG_PERSON = "braked for the wrong person"
# Also the order of the runs to look at: the worst first.
WENT_WRONG = (CONTACT, WRONG_PERSON, NEEDLESS)


def went_wrong(outcomes: Sequence[LoopOutcome]) -> list[str | None]:
    """Per outcome, CONTACT, WRONG_PERSON or NEEDLESS for a braking policy's run that went
    wrong as the table counts it, else None: contact although the policy brakes, braked
    for nobody or someone not on a collision course (LoopOutcome.wrong_person; the
    outcome's `braked_for_said` names them), or braked in a run the baseline (same
    scenario and seed) finished without contact. The baseline's own runs are the
    reference, never listed."""
    baseline = {(o.scenario, o.seed): o for o in outcomes if o.policy == NO_BRAKE}
    out: list[str | None] = []
    for o in outcomes:
        base = baseline.get((o.scenario, o.seed))
        if o.policy == NO_BRAKE:
            out.append(None)
        elif o.contact:
            out.append(CONTACT)
        elif o.braked and o.wrong_person:
            out.append(WRONG_PERSON)
        elif o.braked and base is not None and not base.contact:
            out.append(NEEDLESS)
        else:
            out.append(None)
    return out


def _f(x: float | None, fmt: str = ".2f") -> str:
    return "-" if x is None else format(x, fmt)


def format_table(rows: Sequence[PolicyRow]) -> str:
    """Markdown table of the comparison; a column of the brakes for the wrong person when a
    run names whom it braked for (the people tracker, several people)."""
    named = any(r.wrong_person is not None for r in rows)
    head = (
        "| policy | runs | contacts | contact rate | baseline contacts avoided | "
        "impact speed mean / max (m/s) | min gap mean / min (m) | braked | "
        + ("braked for the wrong person | " if named else "")
        + "braked without need | latency median (ms) | brake delay median (frames) |"
    )
    lines = [head, "|" + " --- |" * (11 + named)]
    for r in rows:
        wrong = ""
        if named:
            wrong = f"| {'-' if r.wrong_person is None else r.wrong_person} "
        avoided = (
            "-"
            if r.avoided is None
            else f"{r.avoided}/{r.baseline_contacts}"
            + (f" ({100 * r.avoided / r.baseline_contacts:.0f} %)" if r.baseline_contacts else "")
        )
        lines.append(
            f"| {r.policy} | {r.runs} | {r.contacts} | {100 * r.contacts / max(r.runs, 1):.0f} % "
            f"| {avoided} | {_f(r.impact_mean)} / {_f(r.impact_max)} "
            f"| {_f(r.gap_mean)} / {_f(r.gap_min)} | {r.braked} {wrong}"
            f"| {'-' if r.needless_stops is None else r.needless_stops} "
            f"| {_f(r.latency_ms_median, '.1f')} | {_f(r.delay_frames_median, '.0f')} |"
        )
    return "\n".join(lines)


def format_runs(outcomes: Sequence[LoopOutcome]) -> str:
    """Markdown table, one line per run; whom each braked for when a run names it."""
    named = any(o.braked_for is not None for o in outcomes)
    lines = [
        "| scenario | policy | contact | impact speed (m/s) | min gap (m) | first warning (s) "
        "| brake acts (s) | final speed (m/s) |" + (" braked for |" if named else ""),
        "|" + " --- |" * (8 + named),
    ]
    for o in outcomes:
        who = ""
        if named:
            said = o.braked_for_said()
            who = f" {said.removeprefix('braked for ') if said else '-'} |"
        lines.append(
            f"| {o.scenario} | {o.policy} | {'yes' if o.contact else 'no'} "
            f"| {_f(o.impact_speed)} | {o.min_gap:.2f} | {_f(o.first_warning_time)} "
            f"| {_f(o.brake_time)} | {o.final_speed:.2f} |{who}"
        )
    return "\n".join(lines)
