"""Where everyone is: every person of a scenario and their Track in a run.

The one answer to "where is everyone" that the world's bodies, `monopic tracks` and the
analyses share: the planned people walk their own walkers' Tracks (sim.scenario.path, each
with their own seed, person_seed), and a crowd's members the Tracks its model works out for
them together, making way for the planned people (sim.scenario.crowd_motion).
"""

from __future__ import annotations

from sim.scenario.crowd_motion import crowd_tracks
from sim.scenario.path import pedestrian_path, person_seed
from sim.scenario.spec import Scenario, person_name
from sim.scenario.track import Track


def people_tracks(scenario: Scenario, seed: int, t_end: float) -> dict[str, Track]:
    """Every person of the scenario by name, in the order of scenario.people (the
    scripted person first, the crowd last), and their Track up to at least t_end in a run
    of `seed`: the motion the world renders and the truth reports."""
    names = [person_name(p, k) for k, p in enumerate(scenario.people)]
    planned = [
        pedestrian_path(person, t_end, person_seed(seed, names[k], k == 0))
        for k, person in enumerate(scenario.planned)
    ]
    crowd = scenario.crowd
    together = crowd_tracks(scenario, planned, seed, t_end) if crowd and crowd.count else []
    return dict(zip(names, [*planned, *together], strict=True))
