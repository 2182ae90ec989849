"""Replayed people in a scenario file: a person whose walker is `replay` (a recorded walk).

A replayed person has no placement: where they are at every time is the track file's
(sim.scenario.walkers.replay), so their `[path]` is empty and they take no `speed`. Their
PedestrianSpec still says where they stand at t = 0, which way they face and how fast they
walk on average over the run, for the records that read a plan (results, errors). The
street check names what a file's user can change: the file, the person's id in it and the
frame that leaves the street (sim.scenario.files runs it before its own street check).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from sim.scenario.families import PlacementError, street_bounds
from sim.scenario.spec import MannequinSpec, PedestrianSpec, Scenario
from sim.scenario.toml_table import FieldError, TomlTable
from sim.scenario.track_file import FRAME_TIME, read_track_file
from sim.scenario.walkers.replay import ReplayWalker, read_transform


def replay_person(
    t: TomlTable, path: TomlTable, walker: ReplayWalker, looks: MannequinSpec, footprint: float,
    duration: float,
) -> PedestrianSpec:  # fmt: skip
    """A replayed person from their table `t` (already read) and their `[path]` (which
    must be empty: the file is the path)."""
    if t.has("speed"):
        raise t.error("speed", t.data["speed"], "a replayed person walks at the file's speeds "
                      "(behaviour.model = 'replay'): remove speed")  # fmt: skip
    for key in path.data:
        raise path.error(key, path.data[key], "a replayed person's path is the track file's "
                         "(behaviour.model = 'replay'): remove the path table")  # fmt: skip
    track = walker.track(PedestrianSpec(0.0, 0.0, 0.0, 0.0, looks=looks), duration, 0)
    start = track.state(0.0)
    times = np.array([0.0, *track.breakpoints_between(0.0, duration), duration])
    walked = float(np.sum(np.hypot(*np.diff(track.positions_at(times), axis=0).T)))
    return PedestrianSpec(
        x=float(start.position[0]), y=float(start.position[1]),
        heading_deg=math.degrees(start.yaw), speed=walked / duration, looks=looks,
        footprint=footprint, behaviour=walker,
    )  # fmt: skip


def replay_street_problem(
    s: Scenario, tables: Sequence[str], labels: Sequence[str]
) -> PlacementError | None:
    """Why a replayed person leaves the street during the run (None: nobody does): the
    first sample of the run that lies off it, or the standing point at t = 0 or at the end.

    `tables` are each person's table as the file names it (`pedestrian`, `pedestrians.1`),
    `labels` each person as an error names them."""
    x0, x1, y0, y1 = street_bounds(s.scene.road)
    for k, person in enumerate(s.people):
        walker = person.behaviour
        if not isinstance(walker, ReplayWalker):
            continue
        samples = walker.samples()
        inside = (samples.times > 0) & (samples.times < s.duration)
        track = walker.track(person, s.duration, s.seed)
        times = np.array([0.0, *samples.times[inside], s.duration])
        xy = track.positions_at(times)
        frames = walker.start_frame + times / FRAME_TIME  # the file's frame numbers
        off = np.flatnonzero(~((x0 <= xy[:, 0]) & (xy[:, 0] <= x1) & (y0 <= xy[:, 1])
                               & (xy[:, 1] <= y1)))  # fmt: skip
        if len(off):
            i = int(off[0])
            x, y = float(xy[i, 0]), float(xy[i, 1])
            where = {
                "person": walker.person, "frame": round(float(frames[i]), 1),
                "t": round(float(times[i]), 3), "x": round(x, 2), "y": round(y, 2),
            }  # fmt: skip
            return PlacementError(
                f"{tables[k]}.behaviour", where,
                f"{labels[k]}: person {walker.person} of {walker.file} is off the street at "
                f"frame {where['frame']:g} (x in [{x0:g}, {x1:g}] m, y in [{y0:.2f}, "
                f"{y1:.2f}] m): change rotate_deg, offset or start_frame",
            )  # fmt: skip
    return None


# -- [replay]: many people of one file at once ----------------------------------------

REPLAY_KEY = "replay"
PERSON_KEY = "pedestrians"  # sim.scenario.files' [[pedestrians]]
TRANSFORM_KEYS = ("file", "rotate_deg", "offset", "start_frame")  # the walker's, shared


def expand_replay(
    path: Path, data: Mapping[str, Any], origins: Mapping[int, str], duration: float
) -> tuple[dict[str, Any], dict[int, str]]:
    """A file's data with its `[replay]` table turned into `[[pedestrians]]` entries, one
    replayed person each (appended after the file's own people, or first when `scripted`
    names person 0), and where each comes from. `duration` is the run's: `people = "all"`
    takes everyone with a sample in `window` (default [0, duration] s of the run).

    The keys the walker shares are read as the walker reads them (read_transform), so
    `[replay]` refuses what `[pedestrian.behaviour]` refuses."""
    out = dict(data)
    value = out.pop(REPLAY_KEY)
    if not isinstance(value, dict):
        raise FieldError(path, REPLAY_KEY, value, "must be a table ([replay])")
    t = TomlTable(path, REPLAY_KEY, value, "scenarios/README.md")
    first = read_transform(t)
    shared = {key: value[key] for key in TRANSFORM_KEYS if key in value}
    window = t.numbers("window", [0.0, duration], unit="s")
    if len(window) != 2 or not window[0] <= window[1]:
        raise t.error("window", list(window), "must be [t0, t1] with t0 <= t1 (s of the run)")
    tracks = read_track_file(first.file)
    chosen = t.raw("people", "all")
    if chosen == "all":
        ids = [
            person for person in sorted(tracks.people)
            if _present(replace(first, person=person).samples().times, window)
        ]  # fmt: skip
    elif (
        isinstance(chosen, list)
        and chosen
        and all(isinstance(v, int) and not isinstance(v, bool) for v in chosen)
    ):
        ids = list(dict.fromkeys(chosen))
        for person in ids:
            if person not in tracks.people:
                raise t.error("people", chosen, f"person {person}: no such person in {first.file}")
    else:
        raise t.error("people", chosen, 'must be "all" or a non-empty list of person ids')
    scripted = t.integer("scripted", None)
    footprint = t.number("footprint", None, positive=True, high=2.0, unit="m")
    t.done()
    entries = out.get(PERSON_KEY, [])
    if not isinstance(entries, list):
        return out, dict(origins)  # the file's own check names it
    if scripted is not None:
        if "pedestrian" in out or "path" in out or entries:
            raise t.error("scripted", scripted, "person 0 is the file's own already "
                          "([pedestrian] or the first [[pedestrians]] entry)")  # fmt: skip
        if scripted not in tracks.people:
            raise t.error("scripted", scripted, f"no such person in {first.file}")
        ids = [scripted, *(p for p in ids if p != scripted)]
    if not ids:
        raise t.error("window", list(window), f"nobody of {first.file} is there in this window "
                      f"(frames from start_frame = {first.start_frame:g})")  # fmt: skip
    # The index of the first one added: after the file's [pedestrian] (person 0) if it has
    # one, else its entries are persons 0, 1, ... (files.listed), the added ones next.
    index = len(entries) + (1 if "pedestrian" in out or "path" in out else 0)
    added, where = [], dict(origins)
    for j, person in enumerate(ids):
        entry: dict[str, Any] = {
            "name": f"p{person}",
            "clothing": CLOTHES[j % len(CLOTHES)],
            "behaviour": {"model": ReplayWalker.model, **shared, "person": person},
        }
        if footprint is not None:
            entry["footprint"] = footprint
        where[index + j] = f"person {person} of {first.file} ([replay])"
        added.append(entry)
    out[PERSON_KEY] = [*entries, *added]
    return out, where


# The replayed people's clothes, in turn, so that neighbours can be told apart.
CLOTHES = ("default", "dark", "bright", "light", "checker")


def _present(times: np.ndarray, window: Sequence[float]) -> bool:
    """Whether a person has a sample within the window (s of the run)."""
    return bool(np.any((times >= window[0]) & (times <= window[1])))
