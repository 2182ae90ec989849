"""A scenario file's `[crowd]` table: the people a crowd model moves together.

The table sets how many walk along the pavements, cross the road and queue at the near
kerb, where, and how (groups, desired speeds, the cues of a human walker); the motion is
sim.scenario.crowd_motion's (JuPedSim). Members look different from one another: bodies and
clothing follow a fixed order by member (a share `children` of children), the same in every
run, so that a run's people are the same people whatever its seed. Keys, units and sources:
scenarios/README.md.
"""

from __future__ import annotations

from dataclasses import replace

from sim.scenario import presets
from sim.scenario.families import mannequin
from sim.scenario.spec import Crowd, MannequinSpec, RoadLayout
from sim.scenario.toml_table import TomlTable
from sim.scenario.walkers import HumanWalker

MAX_CROWD = 60  # people in one crowd at most (a street's worth in view; each one is rendered)
# The members' clothes in turn (a fixed order, so neighbours differ), and statures around
# the adult's: 1.6-1.9 m, in turn.
CLOTHES = ("default", "dark", "light", "bright", "checker", "dark", "light", "default")
HEIGHTS = (1.75, 1.62, 1.84, 1.70, 1.90, 1.66, 1.78)
CHILD_EVERY = 10  # one member in CHILD_EVERY is a child when `children` allows


def crowd_looks(count: int, children: float) -> tuple[MannequinSpec, ...]:
    """Member k's mannequin: clothes and stature in turn, a child every
    round(1 / children) members (none when `children` is 0)."""
    every = round(1 / children) if children > 0 else 0
    out = []
    for k in range(count):
        child = every > 0 and k % every == every - 1
        looks = mannequin("child" if child else "adult", CLOTHES[k % len(CLOTHES)])
        out.append(looks if child else replace(looks, height=HEIGHTS[k % len(HEIGHTS)]))
    return tuple(out)


def crowd_from_table(t: TomlTable, road: RoadLayout) -> Crowd | None:
    """The crowd of a file's [crowd] table; None when the file has none (or it is empty of
    people). Each value is checked here (one FieldError line); the street's room for
    the crowd is checked with the whole scenario (sim.scenario.files)."""
    if not t.data:
        return None
    base = Crowd()
    half = road.length / 2
    along = t.integer("along", 0, high=MAX_CROWD)
    across = t.integer("across", 0, high=MAX_CROWD)
    queue = t.integer("queue", 0, high=MAX_CROWD)
    total = along + across + queue
    if total > MAX_CROWD:
        raise t.error("along", along, f"a crowd of {total} people: at most {MAX_CROWD}")

    def span(key: str, default: tuple[float, float]) -> tuple[float, float]:
        value = t.numbers(key, list(default), low=-half, high=half, unit="m")
        if len(value) != 2 or not value[0] < value[1]:
            raise t.error(key, list(value), "must be [from, to] in m of world x, from < to")
        return value[0], value[1]

    crowd_x = road.crosswalk_x if road.crosswalk_x is not None else base.queue_x
    cross = (crowd_x - 4.0, crowd_x + 4.0)
    crowd = Crowd(
        along=along,
        across=across,
        queue=queue,
        region=span("region", base.region),
        cross_region=span("cross_region", cross),
        queue_x=t.number("queue_x", crowd_x, low=-half, high=half, unit="m"),
        release=t.number("release", base.release, low=0.0, high=presets.MAX_DURATION_S, unit="s"),
        groups=t.number("groups", base.groups, low=0.0, high=1.0),
        speed=t.number("speed", base.speed, low=0.3, high=2.5, unit="m/s"),
        speed_spread=t.number("speed_spread", base.speed_spread, low=0.0, high=1.0, unit="m/s"),
        looks=crowd_looks(total, t.number("children", 0.1, low=0.0, high=1.0)),
        cues=HumanWalker.from_table(t.table("cues")),
    )
    t.done()
    return crowd if crowd.count else None
