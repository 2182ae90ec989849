"""`--tracker one|everyone` of the commands that drive a robot on the pipeline's warning.

The names are sim.runs.run_spec.TRACKERS, written here too so the command line starts
without loading the scenario records (a test holds the two equal).
"""

from __future__ import annotations

import argparse

TRACKERS = ("one", "everyone")


def add_tracker_option(p: argparse.ArgumentParser, figures: str) -> None:
    """The option, its default the one-pedestrian tracker that made every earlier `figures`."""
    p.add_argument(
        "--tracker",
        choices=TRACKERS,
        default="one",
        help="whom the policy's pipeline follows: 'one' pedestrian (the one-pedestrian "
        f"tracker, the default: every earlier {figures} is made with it) or 'everyone' in "
        "view (the people tracker: the brake acts on the worst person's warning); each run "
        "names whom the car braked for",
    )
