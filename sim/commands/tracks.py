"""`monopic tracks SPEC --out DIR`: the true tracks of a sweep's pedestrians, ETH/UCY format."""

from __future__ import annotations

import argparse
from pathlib import Path

from tqdm import tqdm


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "tracks",
        help="write the true world-plane tracks of a sweep's pedestrians (ETH/UCY format)",
        description="Expand a sweep (or dataset) spec and write each run's pedestrian, as "
        "its behaviour walks it with the run's seed, sampled every 0.4 s over the run, in "
        "the ETH/UCY text format (`frame person x y`, frames 10 apart, metres on the "
        "ground plane): DIR/<family>.txt per family and DIR/index.csv (which id is which "
        "run). No rendering: seconds for a whole sweep.",
    )
    p.add_argument(
        "spec", type=Path, metavar="SPEC.toml", help="a sweep or dataset spec (scenarios/sweeps)"
    )
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="DIR",
        help="folder for the tracks (made as needed)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sim.analysis.tracks import sweep_tracks, write_tracks
    from sim.runs.sweep import expand_spec, load_spec

    runs = expand_spec(load_spec(args.spec))
    with tqdm(total=len(runs), unit="run", desc="tracks") as bar:
        tracks = sweep_tracks(runs, on_run=lambda _: bar.update(1))
    files = write_tracks(tracks, args.out)
    print(f"{len(tracks)} tracks in {len(files) - 1} family files: {args.out}")
    return 0
