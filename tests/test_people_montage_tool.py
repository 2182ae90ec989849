"""tools.people_montage without rendering: its rows build, labels do not cover each other,
and the PNG is written whole or not at all."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

from sim.scenario.files import load
from tests.paths import ETH_UCY
from tools import people_montage as montage


@pytest.mark.parametrize(
    "row", [*montage.ROWS, *montage.CROWD_ROWS], ids=lambda r: Path(r.file).stem
)
def test_each_row_is_a_draw_of_its_file_with_several_people(row: montage.Row) -> None:
    path = montage.SCENARIOS / row.file
    if "shared:" in path.read_text() and not ETH_UCY.is_dir():
        pytest.skip(f"{row.file} replays the shared data, absent here ({ETH_UCY})")
    f = load(path)
    scenario = f.scenario(row.params, name=f.name, seed=row.seed)
    assert len(scenario.people) >= 2
    assert 0.0 <= row.times[0] < row.times[1] < scenario.duration


def overlaps(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_labels_wanted_at_one_spot_are_stacked_apart() -> None:
    taken: list[tuple[int, int, int, int]] = []
    spots = [montage.free_spot(taken, 100, 60, (50, 10), 288) for _ in range(4)]
    assert len(set(spots)) == 4
    assert all(not overlaps(a, b) for i, a in enumerate(taken) for b in taken[i + 1 :])


def person(name: str, box: tuple[float, float, float, float], seen: float) -> SimpleNamespace:
    visibility = SimpleNamespace(visible=seen)
    return SimpleNamespace(name=name, box=box, in_frame=True, visibility=visibility)


def test_people_out_of_view_are_left_out_and_the_scripted_one_is_red() -> None:
    image = np.zeros((288, 512, 3), np.uint8)
    people = (
        person("ped", (100.0, 100.0, 140.0, 200.0), 1.0),
        person("gone", (float("nan"),) * 4, 0.0),
        person("other", (300.0, 120.0, 330.0, 190.0), 0.5),
    )
    montage.draw_people(image, people, 1.0)  # type: ignore[arg-type]
    assert tuple(image[150, 100]) == montage.SCRIPTED  # the left edge of its box
    assert tuple(image[150, 300]) == montage.OTHERS[1]  # the third person's colour


def test_the_png_is_written_whole_or_not_at_all(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    image = np.full((40, 60, 3), 200, np.uint8)
    out = tmp_path / "docs" / "montage.png"
    montage.write_png(out, image)
    assert cv2.imread(str(out)).shape == image.shape
    with pytest.raises(SystemExit, match="a PNG"):
        montage.write_png(tmp_path / "montage.jpg", image)
    monkeypatch.setattr(montage.cv2, "imwrite", lambda *a, **k: False)
    with pytest.raises(SystemExit, match="could not write"):
        montage.write_png(tmp_path / "failed.png", image)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["docs"]  # no file, no temporary
