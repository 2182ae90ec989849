"""Small checks of the intent features and labels on a few simulated runs (docs/intent).

    .venv/bin/python -m studies.intent.check labels [FAMILY ...]
    .venv/bin/python -m studies.intent.check features [--case 6] [--robot-speed 0]

`labels`: the intent label sequence of shipped small-robot family files, rail target and
human walker, from the truth alone (no rendering: a second or two per run).
`features`: one rendered 4 s run of a placed case with a human walker making a head
check every second (probability 1), through the pipeline: the head yaw BlazePose gives
against the true head yaw from the shoulders, and the window-fit ground speed, its
acceleration and heading rate against the true speed, beside the Kalman track's speed.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from monopic.cases import Case
from monopic.predict.base import Mode
from monopic.predict.constant_velocity import ConstantVelocityPredictor
from sim.runs.pipelines import scenario_pipeline
from sim.scenario.cases import CasePlacement
from sim.scenario.files import load
from sim.scenario.walkers import WALKERS, HumanWalker
from sim.world.world import World

ROOT = Path(__file__).resolve().parents[2]
FAMILIES = ROOT / "scenarios" / "families" / "small"
DEFAULT_FAMILIES = (
    "cpna25", "nearmiss_kerb_stop", "nearmiss_turn_away", "wait_then_cross",
    "hesitate_then_cross", "along_then_turn", "look_no_cross",
)  # fmt: skip


def labels(families: list[str]) -> None:
    """Print when each family's label changes, for both walkers."""
    for name in families:
        for model in ("rail", "human"):
            sc = load(FAMILIES / f"{name}.toml").scenario({}, name)
            if sc.pedestrian.behaviour.model != model:  # the family's plan, the other walker
                sc = replace(sc, pedestrian=replace(sc.pedestrian, behaviour=WALKERS[model]()))
            changes, previous = [], None
            with World(sc, render=False) as world:
                for step in world.run():
                    person = step.truth.pedestrian
                    if person.intent != previous:
                        changes.append(
                            f"{step.time:.2f} s {person.intent.value} "
                            f"(case now {int(person.case_now)}, {person.speed:.2f} m/s)"
                        )
                        previous = person.intent
            print(f"{name} [{model}]: " + " -> ".join(changes))


def features(case: Case, robot_speed: float) -> None:
    """Print the head yaw and ground kinematics errors of one rendered run."""
    behaviour = HumanWalker(head_check_probability=1.0, head_check_interval=1.0)
    placement = CasePlacement(case, distance=8.0, duration=4.0, robot_speed=robot_speed)
    sc = placement.scenario(behaviour=behaviour)
    pipe = scenario_pipeline(sc, [ConstantVelocityPredictor(mode=Mode.GROUND)])
    rows = []
    with World(sc) as world:
        for step in world.run():
            assert step.frame is not None
            f = pipe.process(step.frame).features
            g = f.ground if f is not None else None
            nan = math.nan
            rows.append(
                (
                    step.time,
                    math.degrees(step.truth.pedestrian.head_yaw_shoulders),
                    f.head_yaw if f is not None else nan,
                    step.truth.pedestrian.speed,
                    g.speed if g is not None else nan,
                    math.hypot(*g.velocity) if g is not None else nan,
                    g.acceleration if g is not None else nan,
                    g.heading_rate if g is not None else nan,
                )
            )
    a = np.array(rows)
    head = np.isfinite(a[:, 2])
    ground = np.isfinite(a[:, 4]) & np.isfinite(a[:, 5])
    print(f"case {int(case)}, robot {robot_speed:g} m/s, {len(a)} frames")
    print(
        f"head yaw: known on {head.sum()} frames; truth from {a[:, 1].min():.0f} to "
        f"{a[:, 1].max():.0f} deg; median |error| {np.median(np.abs(a[head, 2] - a[head, 1])):.1f}"
        f" deg; correlation {np.corrcoef(a[head, 1], a[head, 2])[0, 1]:.2f}"
    )
    print(
        f"ground speed: median |error| window {np.median(np.abs(a[ground, 4] - a[ground, 3])):.2f}"
        f" m/s, Kalman track {np.median(np.abs(a[ground, 5] - a[ground, 3])):.2f} m/s; "
        f"median |acceleration| {np.nanmedian(np.abs(a[ground, 6])):.2f} m/s^2, "
        f"|heading rate| {np.nanmedian(np.abs(a[ground, 7])):.0f} deg/s"
    )
    print("time  head truth/est (deg)  speed truth/window/track (m/s)  accel  heading rate")
    for r in a[::5]:
        print(
            f"{r[0]:4.2f}  {r[1]:6.1f} {r[2]:6.1f}   {r[3]:5.2f} {r[4]:5.2f} {r[5]:5.2f}   "
            f"{r[6]:6.2f} {r[7]:6.0f}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="what", required=True)
    lab = sub.add_parser("labels", help="intent label sequences of family files (truth only)")
    lab.add_argument("families", nargs="*", default=list(DEFAULT_FAMILIES))
    feat = sub.add_parser("features", help="head yaw and ground kinematics on one rendered run")
    feat.add_argument("--case", type=int, default=6, choices=range(1, 10))
    feat.add_argument("--robot-speed", type=float, default=0.0)
    args = parser.parse_args()
    if args.what == "labels":
        labels(args.families)
    else:
        features(Case(args.case), args.robot_speed)


if __name__ == "__main__":
    main()
