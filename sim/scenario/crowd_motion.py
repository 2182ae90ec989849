"""The crowd's motion: JuPedSim moves a scenario's crowd together, around everyone else.

A crowd (sim.scenario.spec.Crowd) is walked by JuPedSim's anticipation velocity model
(Xu, Chraibi and Seyfried 2021, Transportation Research C 128, 103464: people perceive,
predict where their neighbours will be and choose a way round, which reproduces
bidirectional flows on a pavement; the collision-free speed model it extends jams there):
each person keeps a gap to the person ahead and turns away from neighbours and walls, so
nobody walks through anybody. The walkable area is the street's pavements, a strip of road
where people cross (`cross_region`) and a corridor along each planned person's path. The
planned people (the scripted person and the bystanders, whose walks are their own
walkers') are agents too, steered exactly along their Tracks (a direct steering stage,
with no repulsion or anticipation of their own): the crowd makes way for them, and they
keep their meeting with the robot.

The crowd does not see the robot: its people walk as they would beside a street (the run is
open-loop, as every walker's is). Everything drawn per run (start places, ways, groups,
desired speeds, cues) comes from the run's seed: the same run, the same crowd.

JuPedSim is the optional extra `crowd` (its package asks for a viewer, PySide6 and VTK, that
the simulation never uses: the Makefile installs it without them).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from monopic.errors import UserError
from sim.scenario.families import street_bounds
from sim.scenario.path import person_seed
from sim.scenario.spec import Crowd, Scenario
from sim.scenario.track import Track
from sim.scenario.walkers.human import intent_cues, sines, strides, wander_tables

DT = 0.01  # s, JuPedSim's step (its own examples' value)
SAMPLE = 5  # steps between the Track's vertices (0.05 s)
RADIUS = 0.2  # m, a person's radius to the model (JuPedSim's default: a body's half width)
PROXY_RADIUS = 0.2  # m, a planned person's: they never move for the crowd
SPACING = 0.8  # m, at least between two people's starts (JuPedSim refuses overlaps)
KERB_MARGIN = 0.3  # m kept from the pavement's edges at the start
SPEED_LIMITS = (0.6, 2.2)  # m/s, desired speeds drawn outside are clipped (Weidmann's span)
# The model's reach of neighbours' repulsion (JuPedSim's default), and a group's people's:
# at the default, two people walking side by side drift apart to about 0.85 m; a group keeps
# closer (dyads walk 0.6-0.8 m apart: Moussaid et al. 2010, PLoS ONE 5(4) e10047).
NEIGHBOUR_RANGE = 0.1  # m
GROUP_RANGE = 0.05  # m
GROUP_GAP = 0.7  # m between people of a group walking side by side (shoulder to shoulder)
GROUP_REACH = 1.5  # m: a group's people are within this of one another at the start
THIRD_IN_GROUP = 0.3  # share of groups of three (the rest pairs)
# Of the people walking along a pavement, the share on the right half of their way: people
# avoid to the right and form lanes by direction (Moussaid et al. 2009, Proc. R. Soc. B
# 276, 2755; right-hand traffic).
KEEP_RIGHT = 0.8
MARGIN = 30.0  # m of street beyond where anyone starts: nobody reaches its end in a run
# People per square metre of their start area at most, per part of the crowd: the walkers'
# starts are drawn GROUP_SPACING apart (room for a group beside each), which random draws
# fill at about 0.28 a square metre; the others' SPACING apart, about 1 a square metre.
CAPACITY = {"along": 0.2, "across": 0.5, "queue": 0.5}
GROUP_SPACING = 1.5  # m between the first people of the walkers' units
QUEUE_SPACING = 0.7  # m between places in the queue, along and away from the kerb
QUEUE_ROW = 3  # places per row at the kerb
SETTING_OFF = 0.3  # m/s: above it a person walks (a start or a stop for the cues)
SEED_TAG = 0x4352  # "CR": the crowd's own stream of the run's seed


@dataclass(frozen=True)
class Street:
    """The crowd's part of the street: pavements' y spans (near = south, far = north), the
    x span it may use, and the kerbs' y."""

    x0: float
    x1: float
    near: tuple[float, float]  # y span of the near (south) pavement
    far: tuple[float, float]  # y span of the far (north) pavement

    def pavement(self, side: str, x0: float, x1: float, margin: float = KERB_MARGIN):
        import shapely

        y0, y1 = self.near if side == "near" else self.far
        return shapely.box(x0, y0 + margin, x1, y1 - margin)


def street_of(s: Scenario, crowd: Crowd, planned: Sequence[Track], t_end: float) -> Street:
    x_min, x_max, y_min, y_max = street_bounds(s.scene.road)
    y_right, y_left = s.scene.road.edges
    starts = [float(t.state(0.0).position[0]) for t in planned]
    lo = min(crowd.region[0], crowd.cross_region[0], crowd.queue_x, *starts) - MARGIN
    hi = max(crowd.region[1], crowd.cross_region[1], crowd.queue_x, *starts) + MARGIN
    return Street(max(lo, x_min), min(hi, x_max), (y_min, y_right), (y_left, y_max))


def start_area(crowd: Crowd, street: Street, role: str):
    """Where the members of a role start (a shapely geometry)."""
    import shapely

    x0, x1 = crowd.region if role == "along" else crowd.cross_region
    if role == "queue":
        return queue_area(crowd, street)
    return shapely.union(street.pavement("near", x0, x1), street.pavement("far", x0, x1))


def start_room(crowd: Crowd, street: Street, role: str) -> float:
    """Square metres of a role's start area (as start_area draws it, without JuPedSim)."""

    def width(span: tuple[float, float]) -> float:
        return max(span[1] - span[0] - 2 * KERB_MARGIN, 0.0)

    if role == "queue":
        rows = math.ceil(crowd.queue / QUEUE_ROW)
        return (QUEUE_ROW * QUEUE_SPACING + 4.0 + rows) * width(street.near)
    x0, x1 = crowd.region if role == "along" else crowd.cross_region
    return (x1 - x0) * (width(street.near) + width(street.far))


def queue_places(crowd: Crowd, street: Street) -> list[tuple[float, float]]:
    """The queue's places at the near kerb, the head first: rows of QUEUE_ROW along the
    kerb, each row QUEUE_SPACING further back."""
    kerb = street.near[1]
    places = []
    for k in range(crowd.queue):
        row, col = divmod(k, QUEUE_ROW)
        places.append((crowd.queue_x + col * QUEUE_SPACING, kerb - 0.4 - row * QUEUE_SPACING))
    return places


def queue_area(crowd: Crowd, street: Street):
    """Where the queue's people start: the near pavement behind and beside the queue."""
    rows = math.ceil(crowd.queue / QUEUE_ROW)
    x0 = crowd.queue_x - 2.0
    x1 = crowd.queue_x + QUEUE_ROW * QUEUE_SPACING + 2.0 + rows
    return street.pavement("near", x0, x1)


def capacity_problem(crowd: Crowd, s: Scenario) -> tuple[str, int, str] | None:
    """(key, value, reason) when a part of the crowd is larger than its start area holds
    (CAPACITY people a square metre), None when it fits."""
    street = street_of(s, crowd, (), 0.0)
    for role in ("along", "across", "queue"):
        n = getattr(crowd, role)
        if n == 0:
            continue
        area = start_room(crowd, street, role)
        most = int(area * CAPACITY[role])
        if n > most:
            where = {"along": "region", "across": "cross_region", "queue": "queue_x"}[role]
            return role, n, (
                f"the street holds at most {most} people there ({area:.0f} m2 of pavement "
                f"at {CAPACITY[role]:g} a square metre, set by crowd.{where}): fewer people or a "
                "longer stretch"
            )  # fmt: skip
    return None


def crowd_tracks(s: Scenario, planned: Sequence[Track], seed: int, t_end: float) -> list[Track]:
    """The crowd's members' Tracks from 0 to t_end (standing after), making way for the
    planned people whose Tracks are `planned`."""
    try:
        import jupedsim as jps
        import shapely
    except ImportError:
        raise UserError(
            "a crowd needs JuPedSim: install the extra (`make install` does; by hand: "
            "pip install --no-deps jupedsim==1.4.2 shapely deprecated)"
        ) from None
    crowd = s.crowd
    assert crowd is not None
    rng = np.random.default_rng([int(seed), SEED_TAG])
    street = street_of(s, crowd, planned, t_end)
    area = walkable_area(s, crowd, street, planned, t_end, queue_crossing=False)
    try:
        model = jps.AnticipationVelocityModel(rng_seed=int(rng.integers(2**63)))
        sim = jps.Simulation(model=model, geometry=area, dt=DT)
    except RuntimeError as err:  # e.g. parked cars cutting a pavement in two
        raise UserError(
            f"scenario {s.name!r}: crowd: JuPedSim refuses its street ({err})"
        ) from None

    # The planned people: steered exactly along their Tracks.
    steer = sim.add_direct_steering_stage()
    steer_journey = sim.add_journey(jps.JourneyDescription([steer]))
    proxies = []
    for track in planned:
        x, y = track.state(0.0).position
        params = jps.AnticipationVelocityModelAgentParameters(
            position=(float(x), float(y)), journey_id=steer_journey, stage_id=steer,
            radius=PROXY_RADIUS, desired_speed=0.0, time_gap=0.1,
            strength_neighbor_repulsion=0.0, reaction_time=DT, anticipation_time=0.0,
            wall_buffer_distance=0.0,
        )  # fmt: skip
        proxies.append((sim.add_agent(params), track))

    # The crowd's starts, clear of the planned people's: a group side by side.
    taken = shapely.union_all(
        [shapely.Point(t.state(0.0).position).buffer(SPACING) for t in planned]
    )
    starts: list[tuple[float, float]] = []
    groups: list[list[int]] = []
    for role in ("along", "across", "queue"):
        n = getattr(crowd, role)
        if not n:
            continue
        free = start_area(crowd, street, role).difference(taken)
        sizes = group_sizes(n, crowd.groups, rng) if role == "along" else [1] * n
        placed, units = place_units(jps, free, sizes, int(rng.integers(2**31)), role, rng)
        groups += [[len(starts) + k for k in unit] for unit in units if len(unit) > 1]
        starts.extend(placed)
        taken = taken.union(shapely.MultiPoint(placed).buffer(SPACING / 2))
    speeds = np.clip(rng.normal(crowd.speed, crowd.speed_spread, crowd.count), *SPEED_LIMITS)
    ways = np.array([keep_right_way(street, y, rng) for _, y in starts])
    for group in groups:  # a group walks one way at one speed
        speeds[group] = speeds[group[0]]
        ways[group] = ways[group[0]]
    # Each person's own slow wander of speed (the human walker's: cues.speed_wander of it
    # over 3-12 s), so a group's people drift a little against one another, as people do.
    names = [m.name for m in crowd.members()]
    wander = [wander_tables(person_seed(seed, name, False))[0] for name in names]

    queue = None
    if crowd.queue:
        queue = sim.add_waiting_set_stage(queue_places(crowd, street))
    agents = []
    roles = [crowd.role(k) for k in range(crowd.count)]
    in_group = {k for group in groups for k in group}
    for k, (role, start) in enumerate(zip(roles, starts, strict=True)):
        stages = route(sim, crowd, street, role, start, ways[k], queue)
        journey = jps.JourneyDescription(stages)
        for a, b in zip(stages, stages[1:], strict=False):
            journey.set_transition_for_stage(a, jps.Transition.create_fixed_transition(b))
        params = jps.AnticipationVelocityModelAgentParameters(
            position=start, journey_id=sim.add_journey(journey), stage_id=stages[0],
            radius=RADIUS, desired_speed=float(speeds[k]),
            range_neighbor_repulsion=GROUP_RANGE if k in in_group else NEIGHBOUR_RANGE,
        )  # fmt: skip
        agents.append(sim.add_agent(params))

    n_steps = int(math.ceil(t_end / DT)) + SAMPLE
    positions = np.full((n_steps // SAMPLE + 1, crowd.count, 2), np.nan)
    headings = np.full((n_steps // SAMPLE + 1, crowd.count), np.nan)
    record(sim, agents, positions, headings, 0)
    for i in range(1, n_steps + 1):
        if i % SAMPLE == 1:
            t, walking = sim.elapsed_time(), alive(sim)
            for k, agent_id in enumerate(agents):
                if agent_id in walking:
                    factor = 1 + crowd.cues.speed_wander * float(sines(wander[k], t))
                    sim.agent(agent_id).model.desired_speed = float(speeds[k]) * factor
        for agent_id, track in proxies:
            steer_along(sim, agent_id, track, sim.elapsed_time() + DT)
        if queue is not None and abs(sim.elapsed_time() - crowd.release) < DT / 2:
            # The queue's way across opens when it is released: until then it keeps to
            # the pavement, as people waiting at a kerb do.
            sim.switch_geometry(walkable_area(s, crowd, street, planned, t_end))
            sim.get_stage(queue).state = jps.WaitingSetState.INACTIVE
        sim.iterate()
        if i % SAMPLE == 0:
            record(sim, agents, positions, headings, i // SAMPLE)
    times = np.arange(positions.shape[0]) * SAMPLE * DT
    return [
        member_track(
            crowd, k, times, positions[:, k], headings[:, k], person_seed(seed, name, False)
        )
        for k, name in enumerate(names)
    ]


def walkable_area(s: Scenario, crowd: Crowd, street: Street, planned: Sequence[Track],
                  t_end: float, queue_crossing: bool = True):  # fmt: skip
    """Pavements, the crossers' strip of road (which also joins the two pavements: JuPedSim
    needs one connected area), the queue's strip (once it may cross) and a corridor along
    each planned person's path over the run (joined to a pavement), less the parked cars."""
    import shapely

    pieces = [street.pavement(side, street.x0, street.x1, 0.0) for side in ("near", "far")]
    x0, x1 = crowd.cross_region
    pieces.append(shapely.box(x0, street.near[0], x1, street.far[1]))
    if crowd.queue and queue_crossing:
        x1 = crowd.queue_x + QUEUE_ROW * QUEUE_SPACING + 1.0
        pieces.append(shapely.box(crowd.queue_x - 1.0, street.near[0], x1, street.far[1]))
    times = np.arange(0.0, t_end + 2 * DT, 0.1)
    for track in planned:
        line = track.positions_at(times)
        pieces.append(shapely.LineString(line).buffer(0.6) if len(np.unique(line, axis=0)) > 1
                      else shapely.Point(line[0]).buffer(0.6))  # fmt: skip
        # Joined to the nearer pavement where it starts (someone standing on the road at
        # the start: the model's area must be one piece).
        x, y = line[0]
        edge = street.near[1] if y - street.near[1] < street.far[0] - y else street.far[0]
        pieces.append(shapely.box(x - 0.6, min(y, edge), x + 0.6, max(y, edge)))
    area = shapely.union_all(pieces)
    for car in s.scene.occluders:
        box = shapely.box(-car.length / 2, -car.width / 2, car.length / 2, car.width / 2)
        box = shapely.affinity.rotate(box, car.yaw, origin=(0, 0))
        area = area.difference(shapely.affinity.translate(box, car.x, car.y))
    return area


def distribute(jps, area, n: int, seed: int, role: str,
               spacing: float = SPACING) -> list[tuple[float, float]]:  # fmt: skip
    """n starts in `area`, `spacing` apart (JuPedSim's own sampler, over the area's parts by
    their size); a part of the crowd the area cannot hold is a UserError."""
    import shapely

    polygon = area if isinstance(area, shapely.Polygon) else max(area.geoms, key=lambda g: g.area)
    parts = list(area.geoms) if isinstance(area, shapely.MultiPolygon) else [polygon]
    weights = np.array([p.area for p in parts])
    counts = np.floor(n * weights / weights.sum()).astype(int)
    counts[np.argmax(weights)] += n - counts.sum()
    out: list[tuple[float, float]] = []
    for part, count in zip(parts, counts, strict=True):
        if count == 0:
            continue
        try:
            out.extend(jps.distribute_by_number(
                polygon=part, number_of_agents=int(count), distance_to_agents=spacing,
                distance_to_polygon=0.15, seed=seed, max_iterations=20_000,
            ))  # fmt: skip
        except Exception as err:  # JuPedSim's own errors: too many for the area
            raise UserError(
                f"crowd.{role} = {n}: cannot place {count} people {spacing:g} m apart in "
                f"{part.area:.0f} m2 ({err})"
            ) from None
    return [(float(x), float(y)) for x, y in out]


def group_sizes(n: int, share: float, rng: np.random.Generator) -> list[int]:
    """n people as units in a random order: groups of 2 (or 3, THIRD_IN_GROUP of them) until
    `share` of the people are in one, the rest alone."""
    want = round(share * n)
    sizes: list[int] = []
    while sum(sizes) < want and n - sum(sizes) >= 2:
        size = 3 if rng.uniform() < THIRD_IN_GROUP and n - sum(sizes) >= 3 else 2
        sizes.append(size)
    sizes += [1] * (n - sum(sizes))
    return [int(k) for k in rng.permutation(np.array(sizes))]


Starts = list[tuple[float, float]]


def place_units(jps, area, sizes: Sequence[int], seed: int, role: str,
                rng: np.random.Generator) -> tuple[Starts, list[list[int]]]:  # fmt: skip
    """Starts for units of people in `area`: each unit's first person by JuPedSim's sampler
    (the walkers' GROUP_SPACING apart, room for a group), the others of a group beside them
    (GROUP_GAP across the pavement, else behind or ahead); a mate with no room left walks
    alone from a place of their own. Returns the starts and each unit's indices."""
    import shapely

    spacing = GROUP_SPACING if role == "along" else SPACING
    firsts = distribute(jps, area, len(sizes), seed, role, spacing=spacing)
    starts: Starts = []
    units: list[list[int]] = []
    lonely = 0
    for (x, y), size in zip(firsts, sizes, strict=True):
        unit = [len(starts)]
        starts.append((x, y))
        side = 1.0 if rng.uniform() < 0.5 else -1.0
        offsets = [(0.0, side), (0.0, -side), (-1.0, 0.0), (1.0, 0.0), (-1.0, side)]
        for _ in range(size - 1):
            for dx, dy in offsets:
                p = (x + dx * GROUP_GAP, y + dy * GROUP_GAP)
                clear = all(math.dist(p, q) >= 2 * RADIUS + 0.05 for q in starts)
                if clear and area.contains(shapely.Point(p)):
                    unit.append(len(starts))
                    starts.append(p)
                    break
            else:
                lonely += 1
        units.append(unit)
    if lonely:  # places of their own, clear of everyone placed
        rest = area.difference(shapely.MultiPoint(starts).buffer(SPACING))
        for p in distribute(jps, rest, lonely, seed + 1, role):
            units.append([len(starts)])
            starts.append(p)
    return starts, units


def keep_right_way(street: Street, y: float, rng: np.random.Generator) -> float:
    """Which way (+1 east, -1 west) someone walks along the pavement from a start at `y`:
    most keep to the right of their way (KEEP_RIGHT of them), so a pavement's two flows
    use its two halves and meet side by side, not head on."""
    pavement = street.far if y > street.far[0] - 0.01 else street.near
    east_half = y < (pavement[0] + pavement[1]) / 2  # the right of an eastward walker
    keep = rng.uniform() < KEEP_RIGHT
    return 1.0 if east_half == keep else -1.0


def route(sim, crowd: Crowd, street: Street, role: str, start: tuple[float, float],
          way: float, queue: int | None) -> list[int]:  # fmt: skip
    """The stages a member walks: along their pavement to its end; across to the other
    pavement, then along it; to the queue, across when it is released, then along."""
    x, y = start
    far_side = y > street.far[0] - 0.01
    end_x = street.x1 - 1.0 if way > 0 else street.x0 + 1.0

    def along(at_y: float) -> list[int]:
        return [sim.add_waypoint_stage((end_x, at_y), 1.0), exit_at(sim, end_x, at_y)]

    if role == "along":
        return along(y)
    other = street.near if far_side else street.far
    if role == "queue":
        other = street.far
    middle = (other[0] + other[1]) / 2
    if role == "across":
        return [sim.add_waypoint_stage((x, middle), 0.5), *along(middle)]
    assert queue is not None
    return [queue, sim.add_waypoint_stage((crowd.queue_x + 0.7, middle), 0.5), *along(middle)]


def exit_at(sim, x: float, y: float) -> int:
    return sim.add_exit_stage([(x - 0.5, y - 0.5), (x + 0.5, y - 0.5), (x + 0.5, y + 0.5),
                               (x - 0.5, y + 0.5)])  # fmt: skip


def steer_along(sim, agent_id: int, track: Track, t: float) -> None:
    """Send a planned person's agent to where their Track is at t, at the speed that gets
    them there in one step (no repulsion of their own: exactly there)."""
    agent = sim.agent(agent_id)
    want = track.state(t).position
    here = np.asarray(agent.position)
    agent.target = (float(want[0]), float(want[1]))
    agent.model.desired_speed = float(np.hypot(*(want - here)) / DT)


def alive(sim) -> set[int]:
    """The ids of the agents still walking (an agent that reached its exit is gone)."""
    return {a.id for a in sim.agents()}


def record(sim, agents: Sequence[int], positions: np.ndarray, headings: np.ndarray,
           row: int) -> None:  # fmt: skip
    """Every member's position and heading now (a member who has left stays unrecorded:
    NaN, filled as standing where they were last)."""
    alive = {a.id: a for a in sim.agents()}
    for k, agent_id in enumerate(agents):
        agent = alive.get(agent_id)
        if agent is not None:
            positions[row, k] = agent.position
            ox, oy = agent.orientation
            headings[row, k] = math.atan2(oy, ox)


def member_track(crowd: Crowd, k: int, times: np.ndarray, xy: np.ndarray,
                 heading: np.ndarray, seed: int) -> Track:  # fmt: skip
    """Member k's Track: the model's positions with a human walker's stride (crowd.cues:
    the body surges and sways with each step, as a human walker's does), facing where
    they walk (held while they stand), with the human walker's cues at their starts, stops
    and every check interval."""
    keep = ~np.isnan(xy[:, 0])
    last = int(np.flatnonzero(keep)[-1])
    xy, heading = xy.copy(), heading.copy()
    xy[last + 1 :] = xy[last]
    heading[last + 1 :] = heading[last]
    steps = np.diff(xy, axis=0)
    arcs = np.concatenate([[0.0], np.cumsum(np.hypot(steps[:, 0], steps[:, 1]))])
    speeds, phases, surge, sway = strides(crowd.cues, times, arcs, crowd.looks[k].height, seed)
    walking = speeds > SETTING_OFF
    # Piece k's heading: its step's while walking, else the model's facing (held).
    speed = np.diff(arcs) / np.diff(times)
    ahead = np.arctan2(steps[:, 1], steps[:, 0])
    moving = np.concatenate([speed > SETTING_OFF, [False]])
    line = np.where(moving, np.concatenate([ahead, ahead[-1:]]), heading)
    forward = np.column_stack([np.cos(line), np.sin(line)])
    left = np.column_stack([-forward[:, 1], forward[:, 0]])
    points = xy + surge[:, None] * forward + sway[:, None] * left
    events: list[tuple[float, str]] = []
    for i in np.flatnonzero(np.diff(walking.astype(int))):
        events.append((float(times[i + 1]), "set-off" if walking[i + 1] else "stop"))
    head, torso = intent_cues(crowd.cues, times, line, speeds, events, seed)
    return Track.from_vertices(times, points, line, np.zeros(2), footprint_yaws=line,
                               phases=phases, head_yaws=head, torso_yaws=torso)  # fmt: skip
