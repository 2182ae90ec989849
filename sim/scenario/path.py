"""The pedestrian's motion: where a PedestrianSpec puts the person at any time, exactly.

The motion is a Track (sim.scenario.track): a polyline in time that the body, highway-env
and the ground truth all read. The plan (sim.scenario.plan) is walked by the spec's
walker (sim.scenario.walkers: the Euro NCAP rail target, the human walker, ...), and a
spec's anchor (a point at a time the placement solved for) is then met exactly, whatever
the walker. person_seed gives each person of a run their own seed (the world's bodies and
sim.scenario.motion.people_tracks, where is everyone, use it).
"""

from __future__ import annotations

import zlib

import numpy as np

from sim.scenario.plan import anchored_plan
from sim.scenario.spec import PedestrianSpec
from sim.scenario.track import Track


def pedestrian_path(spec: PedestrianSpec, t_end: float, seed: int = 0) -> Track:
    """The pedestrian's Track up to at least t_end (it goes on straight after), per walker.

    `seed` draws what varies between runs (a human walker's wander: the scenario's seed,
    the same run, the same walk). The anchor belongs to the approach (the plan without its
    legs): a walker that stops at the kerb or turns away walks the same approach as the
    one that walks on, and is shifted as that one is to pass the anchor (which it then
    never reaches).
    """
    walker = spec.behaviour
    track = walker.track(spec, t_end, seed)
    anchor = spec.anchor
    if anchor is not None:  # pass the placement's point at its time, exactly
        reference = anchored_plan(spec, walker.start_distance)
        walked = track if reference is spec else walker.track(reference, t_end, seed)
        miss = np.array([anchor.x, anchor.y]) - walked.state(anchor.time).position
        track = track.translated(miss)
    return track


def person_seed(seed: int, name: str, scripted: bool) -> int:
    """A person's own seed in a run of `seed`: the scripted person's is the run's (as with
    one person), each other person's the run's and their name, so no two wander alike."""
    return seed if scripted else (seed + zlib.crc32(name.encode())) % 2**31
