"""Image sequences as `monopic video` input: a printf pattern or a MOTChallenge folder, read
in number order at index / fps, and every bad sequence refused in one line naming it."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from monopic.errors import UserError
from monopic.image_sequence import ImageSequenceSource
from monopic.video import VideoSource, open_source
from tests.clips import tiny_clip
from tests.paths import PETS09 as PETS


def write_images(folder: Path, names: list[str], size: tuple[int, int] = (8, 6)) -> None:
    """Tiny images whose blue channel is their position in `names` (written BGR)."""
    folder.mkdir(parents=True, exist_ok=True)
    width, height = size
    for value, name in enumerate(names):
        bgr = np.zeros((height, width, 3), np.uint8)
        bgr[..., 0] = 10 * value
        assert cv2.imwrite(str(folder / name), bgr)


def mot_folder(root: Path, ini: str, names=("000001.png", "000002.png", "000003.png")) -> Path:
    root.mkdir(parents=True, exist_ok=True)
    (root / "seqinfo.ini").write_text(ini)
    write_images(root / "img1", list(names))
    return root


GOOD_INI = "[Sequence]\nname=T\nimDir=img1\nframeRate=7\nseqLength=3\nimExt=.png\n"


def refusal(text: str, fps: float | None = None) -> str:
    with pytest.raises(UserError) as err:
        source = open_source(text, fps)
        list(source)
    message = str(err.value)
    assert "\n" not in message
    return message


def test_a_pattern_is_read_in_number_order_from_its_first_number(tmp_path):
    # 8..11 with %d: in name order 10 and 11 would come before 8 and 9.
    write_images(tmp_path, ["8.png", "9.png", "10.png", "11.png"])
    write_images(tmp_path / "other", ["x.png"])  # not matched: a folder and another name
    source = open_source(str(tmp_path / "%d.png"), 4.0)
    assert isinstance(source, ImageSequenceSource)
    assert (source.width, source.height, source.fps) == (8, 6, 4.0)
    assert (source.frame_count, source.first_number) == (4, 8)
    frames = list(source)
    assert [f.index for f in frames] == [0, 1, 2, 3]
    assert [f.timestamp for f in frames] == [0.0, 0.25, 0.5, 0.75]
    # Written blue = 10 * position; read back as RGB, so it is the last channel.
    assert [int(f.image[0, 0, 2]) for f in frames] == [0, 10, 20, 30]
    assert all(int(f.image[0, 0, 0]) == 0 for f in frames)


def test_a_zero_padded_pattern_takes_only_names_printf_gives(tmp_path):
    write_images(tmp_path, ["0000.png", "0001.png", "0002.png"])
    write_images(tmp_path, ["3.png", "00003.png"])  # %04d renders 3 as 0003: neither
    source = open_source(str(tmp_path / "%04d.png"), 10.0)
    assert [f.name for f in source.files] == ["0000.png", "0001.png", "0002.png"]
    assert source.first_number == 0


def test_a_mot_folder_has_its_own_rate_and_first_number(tmp_path):
    folder = mot_folder(tmp_path / "seq", GOOD_INI)
    for given in (None, 7.0):  # the folder's frameRate; --fps may only agree with it
        source = open_source(str(folder), given)
        assert (source.fps, source.first_number, source.frame_count) == (7.0, 1, 3)
        frames = list(source)
        assert [f.index for f in frames] == [0, 1, 2]
        assert [f.timestamp for f in frames] == [0.0, 1 / 7, 2 / 7]
        assert [int(f.image[0, 0, 2]) for f in frames] == [0, 10, 20]


def test_an_fps_the_sequence_would_ignore_is_refused(tmp_path):
    folder = mot_folder(tmp_path / "seq", GOOD_INI)
    for text in (str(folder), str(folder / "img1" / "%06d.png")):
        assert refusal(text, 30.0) == (
            f"--fps 30: {text} declares its own frame rate, 7 fps (its seqinfo.ini); "
            "--fps gives a rate only to images without one"
        )


def test_a_pattern_inside_a_mot_folder_takes_its_frame_rate(tmp_path):
    folder = mot_folder(tmp_path / "seq", GOOD_INI)
    source = open_source(str(folder / "img1" / "%06d.png"))
    assert (source.fps, source.first_number) == (7.0, 1)


def test_a_video_file_keeps_its_own_rate_and_refuses_another(tmp_path):
    clip = tiny_clip(tmp_path)
    for given in (None, 15.0):
        source = open_source(str(clip), given)
        assert isinstance(source, VideoSource) and source.fps == 15.0
        assert [round(f.timestamp * 15) for f in source] == [0, 1, 2]
    assert refusal(str(clip), 30.0) == (
        f"--fps 30: {clip} declares its own frame rate, 15 fps; --fps gives a rate only "
        "to inputs without one"
    )
    assert refusal("0", 30.0) == (
        "--fps 30: camera 0's frames carry the wall clock's time; --fps gives a rate only "
        "to inputs without one"
    )


class RatelessCapture:
    """A real capture of a real file, but reporting what a container without a frame rate
    or frame times does (FFmpeg assumes 25 fps for the rateless files OpenCV can write)."""

    opened = cv2.VideoCapture  # OpenCV's own, kept before the test puts this class in

    def __init__(self, source):
        self.capture = RatelessCapture.opened(source)

    def get(self, prop):
        if prop in (cv2.CAP_PROP_FPS, cv2.CAP_PROP_POS_MSEC):
            return 0.0
        return self.capture.get(prop)

    def __getattr__(self, name):
        return getattr(self.capture, name)


def test_a_video_without_a_rate_takes_fps_and_is_refused_without(tmp_path, monkeypatch):
    import monopic.video

    clip = tiny_clip(tmp_path)
    monkeypatch.setattr(monopic.video.cv2, "VideoCapture", RatelessCapture)
    source = open_source(str(clip), 4.0)
    assert source.fps == 4.0
    assert [f.timestamp for f in source] == [0.0, 0.25, 0.5]
    assert refusal(str(clip)) == f"{clip}: frames carry no timestamps"


def test_a_pattern_matching_no_image(tmp_path):
    write_images(tmp_path, ["a.png"])
    for pattern in (tmp_path / "%06d.png", tmp_path / "absent" / "%06d.png"):
        assert refusal(str(pattern), 7.0) == f"{pattern}: the pattern matches no image"


def test_a_pattern_without_a_number_conversion(tmp_path):
    message = refusal(str(tmp_path / "%s.png"), 7.0)
    assert message.startswith(f"{tmp_path / '%s.png'}: an image pattern needs one %d or %0Nd")


def test_a_pattern_without_fps_nor_seqinfo(tmp_path):
    write_images(tmp_path, ["1.png", "2.png"])
    message = refusal(str(tmp_path / "%d.png"))
    assert message.startswith(f"{tmp_path / '%d.png'}: an image sequence has no frame rate")
    assert "--fps" in message


@pytest.mark.parametrize(
    ("line", "shown"),
    [("", None), ("frameRate=\n", None), ("frameRate=0\n", "'0'"), ("frameRate=-7\n", "'-7'")]
    + [("frameRate=fast\n", "'fast'"), ("frameRate=nan\n", "'nan'")],
)
def test_seqinfo_without_a_usable_frame_rate(tmp_path, line, shown):
    ini = "[Sequence]\nimDir=img1\nimExt=.png\n" + line
    folder = mot_folder(tmp_path / "seq", ini)
    info = folder / "seqinfo.ini"
    if shown is None:
        expected = f"{info}: [Sequence] has no frameRate"
    else:
        expected = f"{info}: [Sequence] frameRate must be a positive number, got {shown}"
    assert refusal(str(folder), 7.0) == expected  # --fps does not mend the folder's file
    assert refusal(str(folder / "img1" / "%06d.png"), 7.0) == expected


def test_seqinfo_whose_image_folder_is_missing(tmp_path):
    folder = mot_folder(tmp_path / "seq", GOOD_INI.replace("imDir=img1", "imDir=images"))
    info = folder / "seqinfo.ini"
    assert refusal(str(folder)) == f"{info}: [Sequence] imDir=images: no folder {folder / 'images'}"


def test_seqinfo_that_is_not_an_ini_file_or_has_no_sequence(tmp_path):
    folder = mot_folder(tmp_path / "a", "frameRate=7\n")
    assert refusal(str(folder)).startswith(f"{folder / 'seqinfo.ini'}: not a readable ini file")
    folder = mot_folder(tmp_path / "b", "[Other]\nframeRate=7\n")
    assert refusal(str(folder)) == f"{folder / 'seqinfo.ini'}: no [Sequence] section"


def test_a_folder_without_seqinfo_points_to_a_pattern(tmp_path):
    write_images(tmp_path, ["000001.png"])
    message = refusal(str(tmp_path), 7.0)
    assert message.startswith(f"{tmp_path}: a folder is read as a MOTChallenge sequence")
    assert str(tmp_path / "%06d.jpg") in message


@pytest.mark.parametrize("position", [0, 2])
def test_an_image_that_cannot_be_decoded_is_named(tmp_path, position):
    write_images(tmp_path, ["1.png", "2.png", "3.png"])
    bad = tmp_path / f"{position + 1}.png"
    bad.write_bytes(b"not an image at all")
    assert refusal(str(tmp_path / "%d.png"), 7.0) == f"{bad}: cannot be decoded as an image"


def test_an_image_of_another_size_is_named(tmp_path):
    write_images(tmp_path, ["1.png", "2.png"])
    write_images(tmp_path, ["3.png"], size=(10, 6))
    assert refusal(str(tmp_path / "%d.png"), 7.0) == (
        f"{tmp_path / '3.png'}: 10x6, but the sequence's first image 1.png is 8x6"
    )


def test_a_gap_in_the_numbers_is_refused_not_skipped(tmp_path):
    folder = mot_folder(tmp_path / "seq", GOOD_INI, ("000001.png", "000002.png", "000004.png"))
    message = refusal(str(folder))
    assert message.startswith(f"{folder / 'img1' / '000003.png'}: missing from the sequence")
    write_images(tmp_path / "p", ["5.png", "7.png"])
    assert refusal(str(tmp_path / "p" / "%d.png"), 7.0).startswith(
        f"{tmp_path / 'p' / '6.png'}: missing from the sequence 5.png..7.png"
    )


@pytest.mark.skipif(not (PETS / "seqinfo.ini").is_file(), reason=f"no PETS09-S2L1 at {PETS}")
def test_the_real_pets09_sequence_reads_at_7_fps_768x576():
    source = open_source(str(PETS))
    assert (source.width, source.height, source.fps) == (768, 576, 7.0)
    assert (source.frame_count, source.first_number) == (300, 1)
    frames = []
    for frame in source:
        frames.append(frame)
        if len(frames) == 3:
            break
    assert [f.index for f in frames] == [0, 1, 2]
    assert [f.timestamp for f in frames] == [0.0, 1 / 7, 2 / 7]
    assert all(f.image.shape == (576, 768, 3) for f in frames)
    # The frames differ (people walk): the sequence is not one image read three times.
    assert not np.array_equal(frames[0].image, frames[2].image)


def cli_refusal(capsys, *args: str, progress: bool = False) -> str:
    """The one line `monopic video ARGS` ends with, exit status 2. With `progress`, the
    refusal came mid-run: the progress bar's line, closed, may stand above it."""
    from monopic.cli.main import main

    try:
        status = main(["video", *args])
    except SystemExit as stop:  # a value argparse refuses ends in a usage error
        status = stop.code
    assert status == 2
    lines = capsys.readouterr().err.strip().splitlines()
    if progress:
        assert [n for n, line in enumerate(lines) if "error" in line] == [len(lines) - 1]
        return lines[-1]
    (line,) = lines
    return line


def test_bad_sequences_through_the_command_are_one_line_and_write_nothing(tmp_path, capsys):
    write_images(tmp_path / "p", ["1.png", "2.png"])
    ini = "[Sequence]\nimDir=img1\nimExt=.png\n"
    folder = mot_folder(tmp_path / "seq", ini)
    out = tmp_path / "out" / "frames.csv"
    pattern = str(tmp_path / "p" / "%d.png")
    cases = [
        ((pattern,), f"{pattern}: an image sequence has no frame rate"),
        ((str(tmp_path / "p" / "%06d.png"), "--fps", "7"), "the pattern matches no image"),
        ((str(folder),), f"{folder / 'seqinfo.ini'}: [Sequence] has no frameRate"),
        ((pattern, "--fps", "0"), "--fps: "),
        ((pattern, "--fps", "-7"), "--fps: "),
    ]
    for args, expected in cases:
        line = cli_refusal(capsys, *args, "--csv", str(out))
        assert line.startswith("monopic video: ") and expected in line, (args, line)
    assert not (tmp_path / "out").exists()


def test_an_image_refused_mid_run_leaves_no_output(tmp_path, capsys):
    """The sizes are checked as the frames are read: the run stops at the odd one out and
    its outputs, already begun, are not left behind (whole or not at all)."""
    write_images(tmp_path, ["1.png", "2.png"], size=(64, 48))
    write_images(tmp_path, ["3.png"], size=(48, 64))
    out = tmp_path / "out"
    out.mkdir()
    line = cli_refusal(
        capsys, str(tmp_path / "%d.png"), "--fps", "7", "--csv", str(out / "f.csv"), progress=True
    )
    assert line.endswith(
        f"{tmp_path / '3.png'}: 48x64, but the sequence's first image 1.png is 64x48"
    )
    assert list(out.iterdir()) == []
