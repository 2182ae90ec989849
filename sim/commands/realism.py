"""`monopic realism SPEC... --real FILE... --out DIR`: simulated walkers beside real tracks."""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

from monopic.errors import UserError


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "realism",
        help="compare the walkers of sweep specs with real pedestrian tracks (report + plot)",
        description="Set the pedestrians of each sweep spec (their true tracks at 0.4 s steps, "
        "as `monopic tracks` writes them) beside real tracks in the ETH/UCY text format "
        "(`frame person x y`, frames 10 apart, 0.4 s) on the same statistics: speed, "
        "|acceleration| and turn rate where walking, and the constant-velocity error at "
        "0.4, 0.8 and 1.2 s (p50 and p90). Writes DIR/report.md and DIR/distributions.png; "
        "--judge names the sets whose every p50 and p90 is checked against the real scenes' "
        "span (min to max, widened by 20 %). With --crowds, a crowd section too: each real "
        "scene's density (people per m2 of the ground its people walk), nearest-person "
        "distance, group speed difference, speed spread and group share beside each crowd "
        "spec's (every run's people), each judged against the real scenes' span, and "
        "DIR/crowds.png.",
    )
    p.add_argument(
        "specs", nargs="*", type=Path, metavar="SPEC.toml", help="sweep specs whose walkers to set"
    )
    p.add_argument("--crowds", nargs="+", type=Path, default=[], metavar="SPEC.toml",
                   help="sweep specs whose runs are crowds, for the crowd section")  # fmt: skip
    p.add_argument("--real", nargs="+", type=Path, required=True, metavar="FILE",
                   help="real tracks, e.g. ../shared/data/eth-ucy-calibration/*.txt")  # fmt: skip
    p.add_argument(
        "--out",
        type=Path,
        required=True,
        metavar="DIR",
        help="folder for report.md and its plot (made as needed)",
    )
    p.add_argument("--judge", nargs="+", metavar="NAME",
                   help="the spec names to judge (default: the first spec's)")  # fmt: skip
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from monopic.output import write_text_atomically
    from sim.analysis.realism import (
        TrackSet,
        judge,
        plot_distributions,
        read_tracks,
        report_text,
        summarise,
    )
    from sim.analysis.tracks import sweep_tracks
    from sim.runs.sweep import expand_spec, load_spec

    if not args.specs and not args.crowds:
        raise UserError("realism: name a sweep spec (SPEC.toml) or --crowds SPEC.toml")
    for path in args.real:
        if not path.is_file():
            raise UserError(f"--real {path}: no such file")
    if args.out.exists() and not args.out.is_dir():
        raise UserError(f"--out {args.out}: exists and is not a folder")
    real = [summarise(read_tracks(path)) for path in args.real]
    simulated = []
    for path in args.specs:
        spec = load_spec(path)
        tracks = sweep_tracks(expand_spec(spec))
        simulated.append(summarise(TrackSet(spec.name, tuple(t.positions for t in tracks))))
    judged = args.judge or ([simulated[0].name] if simulated else [])
    for name in judged:
        if name not in {s.name for s in simulated}:
            names = ", ".join(s.name for s in simulated) or "none"
            raise UserError(f"--judge {name!r}: not one of the specs' names ({names})")
    crowd_text = _crowds(args) if args.crowds else ""
    args.out.mkdir(parents=True, exist_ok=True)
    command = "monopic realism " + " ".join(shlex.quote(a) for a in sys.argv[2:])
    plot_distributions(real, simulated, args.out / "distributions.png", "Walkers, 0.4 s steps")
    text = report_text(real, simulated, judged, command, "distributions.png")
    write_text_atomically(args.out / "report.md", text + crowd_text)
    for name in judged:
        verdicts = judge(real, next(s for s in simulated if s.name == name))
        inside = sum(v.inside for v in verdicts)
        print(f"{name}: {inside} of {len(verdicts)} statistics inside the real scenes' span")
        for v in verdicts:
            if not v.inside:
                print(
                    f"  outside: {v.stat} {v.quantile} = {v.value:.3g} "
                    f"(span {v.low:.3g}-{v.high:.3g})"
                )
    print(f"report: {args.out / 'report.md'}")
    return 0


def _crowds(args: argparse.Namespace) -> str:
    """The crowd section (and DIR/crowds.png), its figures printed as it goes."""
    from sim.analysis.crowd_stats import crowd_report_text, crowd_summary, judge_crowd, plot_crowds
    from sim.analysis.realism import (
        TrackSet,
        judge,
        read_rows,
        read_tracks,
        summarise,
        walkers_text,
    )
    from sim.analysis.tracks import run_rows, run_tracks
    from sim.runs.sweep import expand_spec, load_spec

    real = [crowd_summary(path.stem, [read_rows(path)]) for path in args.real]
    for s in real:
        v = s.values
        print(
            f"{s.name}: density {v['density']:.3g} people/m2 over {s.area:.0f} m2 walked, "
            f"nearest person p10 / p50 {v['nn_p10']:.3g} / {v['nn_p50']:.3g} m, group speed "
            f"difference {v['group_speed_difference']:.3g} m/s, speed spread "
            f"{v['speed_spread']:.3g} m/s, group share {v['group_share']:.2f}"
        )
    simulated, walkers = [], []
    real_walkers = [summarise(read_tracks(path)) for path in args.real]
    for path in args.crowds:
        spec = load_spec(path)
        runs = list(expand_spec(spec))
        s = crowd_summary(spec.name, [run_rows(run) for run in runs])
        simulated.append(s)
        verdicts = judge_crowd(real, s)
        inside = sum(v.inside for v in verdicts)
        print(
            f"{s.name} (crowd): density {s.values['density']:.3g} people/m2; "
            f"{inside} of {len(verdicts)} crowd statistics inside the real scenes' span"
        )
        for v in verdicts:
            if not v.inside:
                print(f"  outside: {v.stat} = {v.value:.3g} (span {v.low:.3g}-{v.high:.3g})")
        # Its walkers: everyone but each run's scripted person (the family's script, judged
        # with the walker specs), on the per-walker statistics.
        tracks = [t for run in runs for t in run_tracks(run)[1:]]
        walkers.append(summarise(TrackSet(spec.name, tuple(t.positions for t in tracks))))
        verdicts = judge(real_walkers, walkers[-1])
        inside = sum(v.inside for v in verdicts)
        print(f"{s.name} (its walkers): {inside} of {len(verdicts)} per-walker statistics inside")
        for v in verdicts:
            if not v.inside:
                print(f"  outside: {v.stat} {v.quantile} = {v.value:.3g} "
                      f"(span {v.low:.3g}-{v.high:.3g})")  # fmt: skip
    args.out.mkdir(parents=True, exist_ok=True)
    plot_crowds(real, simulated, args.out / "crowds.png", "Crowds, 0.4 s frames")
    return (
        "\n"
        + crowd_report_text(real, simulated, "crowds.png")
        + walkers_text(real_walkers, walkers)
    )
