"""tools.camera_montage: its four cameras differ where they should, and the picture is
written whole."""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import pytest

from sim.scenario.ncap import draw_for, load_car, load_protocol, scenario_for
from sim.sensor.spec import IMX273
from tools import camera_montage as montage


def test_the_panels_are_one_run_under_four_cameras() -> None:
    protocol, car = load_protocol(), load_car()
    point = montage.POINT
    base = scenario_for(protocol, car, point, draw_for(protocol.tolerances, point.id, 0))
    panels = montage.panel_scenarios(base)
    assert [s.robot.camera.sensor for _, s in panels] == [None, IMX273, IMX273, IMX273]
    lux = [s.scene.lighting.illuminance_lux for _, s in panels[1:]]
    assert lux[0] > lux[1] > lux[2]  # sun, overcast, dusk
    assert {s.pedestrian for _, s in panels} == {base.pedestrian}  # the same moment


@pytest.mark.slow
def test_the_montage_is_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "camera.png"
    monkeypatch.setattr(sys, "argv", ["camera_montage", "--out", str(out)])
    montage.main()
    image = cv2.imread(str(out))
    assert image.shape == (2 * montage.CROP[1], 2 * montage.CROP[0], 3)
    assert list(tmp_path.iterdir()) == [out]  # no temporary left behind
