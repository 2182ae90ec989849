"""`monopic video`: the pipeline on any video, with annotated video, CSV and rerun outputs."""

from __future__ import annotations

import argparse
import csv
import time
from contextlib import ExitStack
from pathlib import Path

import cv2
from tqdm import tqdm

from monopic.camera import CameraModel
from monopic.cli.args import (
    deprecated_alias,
    non_negative_float,
    non_negative_int,
    output_file,
    positive_float,
    positive_int,
    ranged,
)
from monopic.errors import UserError
from monopic.features.extractor import GroundColumn
from monopic.frame import EgoState
from monopic.framelog import FRAME_COLUMNS, authors_finite, frame_rows, mot_rows
from monopic.output import atomic_path
from monopic.overlay import draw
from monopic.people.tracker import PeopleConfig
from monopic.pipeline import Pipeline, PipelineConfig, Variant
from monopic.pose.sessions import (
    DEFAULT_DETECTOR_MODEL,
    DEFAULT_LANDMARK_MODEL,
    DEFAULT_RUNTIME,
    DETECTOR_MODELS,
    LANDMARK_MODELS,
    RUNTIMES,
    check_runtime,
    detector_file,
    landmark_file,
)
from monopic.pose.tracker import TrackerConfig
from monopic.predict.base import Mode
from monopic.predict.registry import make_predictor, predictor_names
from monopic.video import open_source


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "video",
        help="run the pipeline on a video file, a camera or an image sequence",
        description="Run the pipeline (pose, facing angle phi, image velocity, the motion case, "
        "the point a second ahead, the collision warning) on every frame of a video, a camera "
        "or an image sequence and write what you ask for: an annotated video (--out), one CSV "
        "row per person per frame (--csv), a MOTChallenge tracks file (--tracks) and/or a "
        "rerun recording (--rrd); at least one is needed. Everyone in view is followed with "
        "an identity, and the robot's warning is the worst person's; --max-people 1 is the "
        "one-pedestrian tracker (MediaPipe's wiring). Folders are made as needed; every "
        "output appears whole or not at all.",
    )
    p.add_argument(
        "input",
        help="video file OpenCV reads, a camera index such as 0, a MOTChallenge sequence "
        "folder (with its seqinfo.ini) or a printf pattern of numbered images such as "
        "img1/%%06d.jpg",
    )
    p.add_argument(
        "--fps",
        type=positive_float,
        help="frame rate of an image pattern, which needs it unless it lies in a "
        "MOTChallenge folder, or of a video file that declares none (> 0); refused where "
        "the input has its own (a seqinfo.ini frameRate or a file's rate that differs, a "
        "camera's wall clock)",
    )
    p.add_argument(
        "--variant",
        choices=[v.value for v in Variant],
        default="warning",
        help="what the annotated video shows: warning (the robot's zone coloured by risk, "
        "COLLISION IMMINENT), path (the zone and the predicted path with its conflict point) "
        "or direction (the case and its arrow) (default %(default)s)",
    )
    p.add_argument("--out", type=Path, metavar="VIDEO.mp4", help="annotated video to write")
    p.add_argument(
        "--csv", type=Path, metavar="FRAMES.csv", help="per-frame CSV (authors' columns plus ours)"
    )
    p.add_argument("--rrd", type=Path, metavar="RUN.rrd", help="rerun recording to write")
    p.add_argument(
        "--tracks",
        type=Path,
        metavar="TRACKS.txt",
        help="MOTChallenge results file: one line per person per frame (frame, id, box); "
        "score it with `monopic track-eval`",
    )
    people = p.add_argument_group("people (everyone in view)")
    people.add_argument(
        "--max-people",
        type=positive_int,
        default=None,
        help="follow at most this many people (>= 1; default: everyone found); 1 is the "
        "one-pedestrian tracker: the most confident person, followed until lost",
    )
    people.add_argument(
        "--budget",
        type=positive_int,
        default=None,
        help="landmark-model runs a frame (>= 1; default: everyone every frame), spent on "
        "the people nearest the robot's path and closing fastest; the others move by "
        "their boxes until their turn",
    )
    people.add_argument(
        "--detect-every",
        type=positive_int,
        default=None,
        help="frames between detector looks while everyone is followed (>= 1; default "
        f"{PeopleConfig.detect_every}): a person entering is found within about this many "
        "frames",
    )
    people.add_argument(
        "--search-budget",
        type=non_negative_int,
        default=TrackerConfig.search_budget,
        help="detector windows a look may spend: the whole frame, then the next tiles for "
        "small people (>= 0; 0: every tile each look, for offline runs; default %(default)d)",
    )
    p.add_argument(
        "--horizon",
        type=positive_float,
        default=PipelineConfig.horizon,
        help="seconds ahead (> 0; default %(default)g)",
    )
    p.add_argument(
        "--mode",
        choices=[m.value for m in Mode],
        default="image",
        help="image: the paper's method, motion measured on the image; ground: the foot "
        "point on the ground plane with the robot's own motion taken out (needs --fov and "
        "--camera-height) (default %(default)s)",
    )
    p.add_argument(
        "--predictor",
        choices=predictor_names(),
        default="rules",
        help="the decision stage, by its registry name (default %(default)s)",
    )
    p.add_argument(
        "--tree",
        type=Path,
        metavar="TREE.json",
        help="tree file for --predictor tree (default: the shipped tree)",
    )
    p.add_argument(
        "--threads",
        type=positive_int,
        default=1,
        help="onnxruntime threads (>= 1; default %(default)d)",
    )
    p.add_argument(
        "--spin",
        action="store_true",
        help="with --threads above 1, let onnxruntime's threads spin-wait within each model "
        "run: faster on cores the pipeline has to itself, much slower on busy ones",
    )
    p.add_argument(
        "--model",
        choices=list(LANDMARK_MODELS),
        default=DEFAULT_LANDMARK_MODEL,
        help="landmark model: lite, full or heavy (MediaPipe's model_complexity 0, 1, 2), or "
        "full-int8 (the full model quantised: faster at one thread on CPUs with VNNI, same "
        "landmark error); default %(default)s",
    )
    p.add_argument(
        "--detector",
        choices=list(DETECTOR_MODELS),
        default=DEFAULT_DETECTOR_MODEL,
        help="person detector: float (MediaPipe's) or int8 (quantised: cheaper passes while "
        "searching on CPUs with VNNI, the same tracking); default %(default)s",
    )
    p.add_argument(
        "--window-detector",
        choices=list(DETECTOR_MODELS),
        default=None,
        help="the detector on the search's zooms and tiles (far walkers) only; the whole "
        "frame keeps --detector's (default: --detector's everywhere)",
    )
    p.add_argument(
        "--runtime",
        choices=list(RUNTIMES),
        default=DEFAULT_RUNTIME,
        help="onnxruntime execution provider for the pose models: cpu (onnxruntime's own "
        "kernels) or openvino (Intel's, float32; the optional extra .[openvino]); "
        "default %(default)s",
    )
    p.add_argument(
        "--ground-column",
        choices=[c.value for c in GroundColumn],
        default=PipelineConfig.ground_column.value,
        help="which landmarks set the ground point's image column (its row is the feet's): "
        "the hips' midpoint, steady through the stride; the shoulders'; or the visible "
        "feet's mean (default %(default)s)",
    )
    g = p.add_argument_group("camera geometry (needed for ground mode and the projected zone)")
    g.add_argument("--fov", type=positive_float, help="vertical field of view, degrees (> 0)")
    g.add_argument("--camera-height", type=positive_float, help="metres above the ground (> 0)")
    g.add_argument(
        "--pitch",
        type=ranged(-90.0, 90.0),
        default=0.0,
        help="degrees, positive looks down ([-90, 90]; default %(default)g)",
    )
    speed = g.add_argument(
        "--robot-speed",
        type=non_negative_float,
        default=0.0,
        help="the camera-carrying robot's own speed, m/s (>= 0; default %(default)g)",
    )
    deprecated_alias(g, speed, "--speed")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    if args.variant not in {v.value for v in Variant}:
        raise UserError(f"unknown variant {args.variant!r}")
    if args.spin and args.threads < 2:
        raise UserError(f"--spin needs --threads 2 or more (got --threads {args.threads})")
    source = open_source(args.input, args.fps)
    ego = _ego(args, source.width, source.height)
    source.ego = ego
    mode = Mode(args.mode)
    if mode is Mode.GROUND and ego is None:
        raise UserError("--mode ground needs the camera geometry: --fov and --camera-height")
    if args.out is None and args.csv is None and args.rrd is None and args.tracks is None:
        raise UserError(
            "nothing to write: give --out VIDEO.mp4, --csv FRAMES.csv, --tracks TRACKS.txt "
            "and/or --rrd RUN.rrd (without them the run would only count the frames with a "
            "person)"
        )
    everyone = args.max_people != 1
    if not everyone:
        for option, value in (("--budget", args.budget), ("--detect-every", args.detect_every)):
            if value is not None:
                raise UserError(
                    f"{option} {value}: the one-pedestrian tracker (--max-people 1) runs "
                    "the landmark model on its one person every frame"
                )
    if args.budget is not None and args.max_people is not None and args.budget > args.max_people:
        raise UserError(
            f"--budget {args.budget}: more landmark runs than people (--max-people "
            f"{args.max_people})"
        )
    predictor = make_predictor(args.predictor, mode, args.tree)
    try:
        check_runtime(args.runtime)
    except ValueError as err:
        raise UserError(f"--runtime {args.runtime}: {err}") from None
    for option, value, check in (
        ("--model", args.model, landmark_file),
        ("--detector", args.detector, detector_file),
        ("--window-detector", args.window_detector, detector_file),
    ):
        try:
            if value is not None:
                check(value)
        except ValueError as err:
            raise UserError(f"{option} {value}: {err}") from None
    # Each output: its option, what the last lines call it, its path (None: not asked).
    outputs = (
        ("--out", "video", args.out),
        ("--csv", "csv", args.csv),
        ("--tracks", "tracks", args.tracks),
        ("--rrd", "recording", args.rrd),
    )
    for option, _, out in outputs:
        if out is not None:
            output_file(out, option)
    pipeline = Pipeline(
        PipelineConfig(
            horizon=args.horizon,
            mode=mode,
            tracker=TrackerConfig(
                threads=args.threads,
                spin=args.spin,
                model=args.model,
                detector=args.detector,
                window_detector=args.window_detector,
                runtime=args.runtime,
                search_budget=args.search_budget,
            ),
            ground_column=GroundColumn(args.ground_column),
            people=PeopleConfig(
                max_people=args.max_people,
                budget=args.budget,
                detect_every=args.detect_every or PeopleConfig.detect_every,
            )
            if everyone
            else None,
        ),
        predictor,
    )
    variant = Variant(args.variant)
    found = frames = 0
    identities: set[int] = set()
    most = 0
    with ExitStack() as stack:
        writer = csv_writer = recording = tracks = None
        if args.out is not None:
            tmp = stack.enter_context(atomic_path(args.out))
            fps = source.fps if source.fps > 0 else 15.0
            writer = cv2.VideoWriter(
                str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), fps, (source.width, source.height)
            )
            if not writer.isOpened():
                raise UserError(f"{args.out}: OpenCV cannot write a video there")
            stack.callback(writer.release)
        if args.csv is not None:
            tmp = stack.enter_context(atomic_path(args.csv))
            handle = stack.enter_context(open(tmp, "w", newline=""))
            csv_writer = csv.writer(handle)
            csv_writer.writerow(FRAME_COLUMNS)
        if args.tracks is not None:
            tmp = stack.enter_context(atomic_path(args.tracks))
            tracks = csv.writer(stack.enter_context(open(tmp, "w", newline="")))
        if args.rrd is not None:
            from monopic.recording import RunRecording

            recording = stack.enter_context(RunRecording(args.rrd))
        last = time.perf_counter()
        fps_now = 0.0
        bar = tqdm(source, total=source.frame_count, unit="frame", desc=Path(args.input).name)
        for frame in bar:
            result = pipeline.process(frame)
            frames += 1
            found += bool(result.people)
            identities.update(p.person_id for p in result.people)
            most = max(most, len(result.people))
            now = time.perf_counter()
            fps_now = 1.0 / max(now - last, 1e-6)
            last = now
            if writer is not None:
                annotated = draw(frame.image, result, variant, fps_now)
                writer.write(cv2.cvtColor(annotated, cv2.COLOR_RGB2BGR))
            if csv_writer is not None:
                for row in frame_rows(result, fps_now, args.horizon):
                    if authors_finite(row):
                        csv_writer.writerow(row)
            if tracks is not None:
                tracks.writerows(mot_rows(result, frame.index + source.first_number))
            if recording is not None:
                recording.log_frame(frame.image, result)
    share = f"{100 * found / max(frames, 1):.0f} %"
    if everyone:
        print(
            f"{frames} frames, people seen in {found} ({share}); {len(identities)} identities, "
            f"at most {most} at once"
        )
    else:
        print(f"{frames} frames, person found in {found} ({share})")
    for _, label, path in outputs:
        if path is not None:
            print(f"{label}: {path}")
    return 0


def _ego(args: argparse.Namespace, width: int, height: int) -> EgoState | None:
    if args.fov is None and args.camera_height is None:
        return None
    if args.fov is None or args.camera_height is None:
        raise UserError("camera geometry needs both --fov and --camera-height")
    camera = CameraModel.from_fov(width, height, args.fov, args.camera_height, args.pitch)
    return EgoState(camera=camera, speed=args.robot_speed)
