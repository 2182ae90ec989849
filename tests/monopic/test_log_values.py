"""The authors' log reader (monopic replay, monopic tree train) refuses values no camera,
walker or clock produces, naming the file, the line and the column; the real logs pass."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest

from monopic.cli.main import main
from monopic.errors import UserError
from monopic.replay.logs import COLUMNS, read_log
from tests.paths import AUTHORS_LOGS, needs_authors_logs


def rows(n: int = 4) -> list[dict[str, float]]:
    """A plausible log: a walker drifting right across a 768x432 frame at 15 fps."""
    out = []
    for k in range(n):
        row = {c: 0.0 for c in COLUMNS}
        row.update(
            frameNumber=k, windowSize=4, XYError=10, timeToFuture=1, time=1657586728.5 + k / 15,
            fps=15.0, currentCenterX=300 + 5 * k, currentCenterY=240, leftShoulderX=320 + 5 * k,
            leftShoulderY=200, rightShoulderX=280 + 5 * k, rightShoulderY=200,
            angleOfApproach=90.0, XFrameSpeed=75.0, occupiedHeights=0.5,
            predictedX=375 + 5 * k, predictedY=240,
        )  # fmt: skip
        out.append(row)
    return out


def write(path: Path, table: list[dict[str, float]]) -> Path:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        w.writerows([r[c] for c in COLUMNS] for r in table)
    return path


def test_a_plausible_log_loads(tmp_path: Path) -> None:
    assert len(read_log(write(tmp_path / "ok.csv", rows()))) == 4
    first = rows()
    first[0]["fps"] = 0.0  # the authors' logs: no rate yet on the first row
    assert len(read_log(write(tmp_path / "first.csv", first))) == 4


@needs_authors_logs
def test_the_authors_logs_load() -> None:
    for k in range(4):
        read_log(AUTHORS_LOGS / f"data{k}.csv")


@pytest.mark.parametrize(
    ("row", "column", "value", "reason"),
    [
        (1, "currentCenterX", 2e5, "outside any image"),
        (2, "currentCenterY", -1.5e5, "outside any image"),
        (3, "leftShoulderX", 1e9, "outside any image"),
        (0, "rightShoulderY", -1e6, "outside any image"),
        (2, "predictedX", 3e5, "outside any image"),
        (1, "predictedY", -2e5, "outside any image"),
        (0, "windowSize", 0, "not a window"),
        (2, "windowSize", -4, "not a window"),
        (0, "fps", -15, "not a frame rate"),
        (2, "fps", 0, "not a frame rate"),
        (1, "timeToFuture", 0, "not a horizon"),
        (1, "timeToFuture", -1, "not a horizon"),
        (0, "time", -3.0, "beyond any clock"),
        (0, "time", 1.6e12, "beyond any clock"),  # milliseconds, not seconds
    ],
)
def test_impossible_values_are_refused_with_file_line_and_column(
    tmp_path: Path, row: int, column: str, value: float, reason: str
) -> None:
    table = rows()
    table[row][column] = value
    if column == "time":  # keep the times increasing so only the bound can object
        for k in range(len(table)):
            table[k]["time"] = value + k / 15
    path = write(tmp_path / "bad.csv", table)
    with pytest.raises(UserError) as info:
        read_log(path)
    message = str(info.value)
    assert message.startswith(f"{path}: line {row + 2}, column {column!r}: ")
    assert reason in message and "\n" not in message


def test_the_replay_command_says_so_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    table = rows()
    table[3]["currentCenterX"] = 1e6
    path = write(tmp_path / "far.csv", table)
    assert main(["replay", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"monopic replay: error: {path}: line 5, column 'currentCenterX': '1000000.0' is "
        "outside any image (beyond +-100000 px)"
    )


def _two_people(path: Path) -> Path:
    """Two people's rows interleaved, as monopic video writes them (personId column)."""
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*COLUMNS, "personId"])
        for a, b in zip(rows(), rows(), strict=True):
            w.writerow([*(a[c] for c in COLUMNS), 1])
            b["currentCenterX"] += 200
            w.writerow([*(b[c] for c in COLUMNS), 4])
    return path


def test_a_log_of_several_people_is_read_one_person_at_a_time(tmp_path: Path) -> None:
    path = _two_people(tmp_path / "two.csv")
    with pytest.raises(UserError, match=r"two.csv: rows of 2 people \(personId 1, 4\)"):
        read_log(path)
    first, second = read_log(path, 1), read_log(path, 4)
    assert len(first) == len(second) == 4
    assert (second.center_x - first.center_x == 200).all()
    with pytest.raises(UserError, match="no row of person 2"):
        read_log(path, 2)
    with pytest.raises(UserError, match="no 'personId' column"):
        read_log(write(tmp_path / "one.csv", rows()), 1)


def test_replay_refuses_a_mixed_log_in_one_line_and_reads_one_person(tmp_path, capsys):
    path = _two_people(tmp_path / "two.csv")
    assert main(["replay", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--person ID" in err[0]
    assert main(["replay", str(path), "--person", "4"]) == 0


def test_one_person_at_a_time_under_new_identities_is_one_track(tmp_path: Path) -> None:
    """The one-pedestrian tracker gives a person found again a new identity: one track."""
    path = tmp_path / "relay.csv"
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([*COLUMNS, "personId"])
        for k, row in enumerate(rows()):
            w.writerow([*(row[c] for c in COLUMNS), 1 if k < 2 else 2])
    assert len(read_log(path)) == 4
