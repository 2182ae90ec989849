"""Frames from an image sequence: a printf pattern (img1/%06d.jpg) or a MOTChallenge folder.

Tracking data sets ship their clips as numbered images, not videos, so the times come from
a frame rate rather than a container: frame i (counted from 0) is at i / fps. The rate is
the sequence's own where it declares one (a MOTChallenge folder's seqinfo.ini, also for a
pattern inside its image folder), else the caller's. The images must be numbered without a
gap: a missing one would shift every later frame's time, so it is refused, not skipped.
"""

from __future__ import annotations

import configparser
import math
import re
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from monopic.errors import UserError
from monopic.frame import EgoState, Frame

SEQINFO = "seqinfo.ini"
# One integer conversion in the file name: %d, %06d or %6d, as printf and OpenCV take it.
_PATTERN = re.compile(r"(?P<head>[^%]*)%(?P<width>0?\d*)d(?P<tail>[^%]*)")


@dataclass
class ImageSequenceSource:
    """Iterates RGB frames of consecutively numbered images, each at index / fps seconds.

    `first_number` is the number in the first file's name, so a frame's number in the
    sequence's own numbering (a MOTChallenge ground truth's) is `index + first_number`.
    Width and height are the first image's; an image of another size is refused.
    """

    name: str  # what the user gave (pattern or folder), for messages
    files: list[Path]
    first_number: int
    fps: float
    ego: EgoState | None = None
    width: int = field(init=False)
    height: int = field(init=False)

    def __post_init__(self) -> None:
        if not self.files:
            raise UserError(f"{self.name}: the sequence holds no image")
        if not (math.isfinite(self.fps) and self.fps > 0):
            raise UserError(f"{self.name}: the frame rate must be positive, got {self.fps}")
        self.height, self.width = _read(self.files[0]).shape[:2]

    @property
    def frame_count(self) -> int:
        return len(self.files)

    @classmethod
    def from_pattern(cls, pattern: str, fps: float | None) -> ImageSequenceSource:
        """The images a printf pattern names, from the lowest number found on: the folder
        is scanned (not probed from 0 upwards), so a sequence may start at any number."""
        path = Path(pattern)
        match = _PATTERN.fullmatch(path.name)
        if match is None:
            raise UserError(
                f"{pattern}: an image pattern needs one %d or %0Nd in the file name "
                "(such as img1/%06d.jpg)"
            )
        folder = path.parent
        found = re.compile(re.escape(match["head"]) + r"(\d+)" + re.escape(match["tail"]))
        numbered: dict[int, Path] = {}
        if folder.is_dir():
            for file in folder.iterdir():
                hit = found.fullmatch(file.name)
                # printf's own rendering must give the name back: %06d is not 1.jpg.
                if hit and path.name % int(hit[1]) == file.name and file.is_file():
                    numbered[int(hit[1])] = file
        if not numbered:
            raise UserError(f"{pattern}: the pattern matches no image")
        declared = _declared_rate(folder)
        return cls._numbered(pattern, numbered, _rate(pattern, declared, fps), path.name)

    @classmethod
    def from_folder(cls, folder: Path, fps: float | None) -> ImageSequenceSource:
        """A MOTChallenge sequence: seqinfo.ini's [Sequence] names the image folder
        (imDir), the images' extension (imExt) and the frame rate (frameRate), which
        is the sequence's: an `fps` that differs is refused."""
        info = folder / SEQINFO
        if not info.is_file():
            raise UserError(
                f"{folder}: a folder is read as a MOTChallenge sequence, which needs a "
                f"{SEQINFO}; for other images give a pattern such as {folder / '%06d.jpg'}"
            )
        section = _sequence_section(info)
        rate = _rate(str(folder), _frame_rate(info, section), fps)
        images = folder / _field(info, section, "imDir")
        ext = _field(info, section, "imExt")
        if not images.is_dir():
            raise UserError(f"{info}: [Sequence] imDir={section['imDir']}: no folder {images}")
        numbered = {
            int(file.stem): file
            for file in images.iterdir()
            if file.suffix == ext and file.stem.isdigit() and file.is_file()
        }
        if not numbered:
            raise UserError(f"{images}: no image named by its number with imExt={ext}")
        width = len(numbered[min(numbered)].stem)
        return cls._numbered(str(folder), numbered, rate, f"%0{width}d{ext}")

    @classmethod
    def _numbered(
        cls, name: str, numbered: dict[int, Path], fps: float, shown: str
    ) -> ImageSequenceSource:
        numbers = sorted(numbered)
        for number, after in zip(numbers, numbers[1:], strict=False):
            if after != number + 1:
                missing = numbered[number].with_name(shown % (number + 1))
                raise UserError(
                    f"{missing}: missing from the sequence {numbered[numbers[0]].name}.."
                    f"{numbered[numbers[-1]].name} (every later frame's time would be wrong)"
                )
        return cls(name, [numbered[n] for n in numbers], numbers[0], fps)

    def __iter__(self) -> Iterator[Frame]:
        for index, file in enumerate(self.files):
            bgr = _read(file)
            height, width = bgr.shape[:2]
            if (width, height) != (self.width, self.height):
                raise UserError(
                    f"{file}: {width}x{height}, but the sequence's first image "
                    f"{self.files[0].name} is {self.width}x{self.height}"
                )
            rgb = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
            yield Frame(rgb, index / self.fps, self.ego, index)


def _read(file: Path) -> np.ndarray:
    """A BGR image; decoded from the bytes so that OpenCV prints no warning of its own."""
    try:
        data = np.fromfile(file, dtype=np.uint8)
    except OSError as err:
        raise UserError(f"{file}: cannot be read ({err.strerror})") from None
    bgr = cv2.imdecode(data, cv2.IMREAD_COLOR) if data.size else None
    if bgr is None:
        raise UserError(f"{file}: cannot be decoded as an image")
    return bgr


def _rate(name: str, declared: float | None, fps: float | None) -> float:
    """The sequence's frame rate: its seqinfo.ini's, else `fps`; an `fps` that differs
    from the declared rate is refused (it would be ignored)."""
    if declared is not None:
        if fps is not None and fps != declared:
            raise UserError(
                f"--fps {fps:g}: {name} declares its own frame rate, {declared:g} fps (its "
                f"{SEQINFO}); --fps gives a rate only to images without one"
            )
        return declared
    if fps is None:
        raise UserError(
            f"{name}: an image sequence has no frame rate of its own: give --fps "
            f"(or a {SEQINFO} with frameRate beside its folder)"
        )
    return fps


def _declared_rate(folder: Path) -> float | None:
    """The frame rate of the MOTChallenge sequence whose image folder `folder` is."""
    info = folder.parent / SEQINFO
    if not info.is_file():
        return None
    section = _sequence_section(info)
    if (folder.parent / section.get("imDir", "")).resolve() != folder.resolve():
        return None
    return _frame_rate(info, section)


def _sequence_section(info: Path) -> configparser.SectionProxy:
    parser = configparser.ConfigParser(interpolation=None)
    parser.optionxform = str  # type: ignore[assignment,method-assign]  # keys keep their case
    try:
        parser.read_string(info.read_text(errors="replace"), str(info))
    except configparser.Error as err:
        first = str(err).splitlines()[0]
        raise UserError(f"{info}: not a readable ini file ({first})") from None
    if not parser.has_section("Sequence"):
        raise UserError(f"{info}: no [Sequence] section")
    return parser["Sequence"]


def _field(info: Path, section: configparser.SectionProxy, key: str) -> str:
    value = section.get(key, "").strip()
    if not value:
        raise UserError(f"{info}: [Sequence] has no {key}")
    return value


def _frame_rate(info: Path, section: configparser.SectionProxy) -> float:
    text = _field(info, section, "frameRate")
    try:
        rate = float(text)
    except ValueError:
        rate = math.nan
    if not (math.isfinite(rate) and rate > 0):
        raise UserError(f"{info}: [Sequence] frameRate must be a positive number, got {text!r}")
    return rate
