"""tools.night_calibration: the night's render keeps to its photometry where it can, the
night street takes a lamp's light where a one-box road took none, a lit colour is clamped
per vertex before the texture, the light budget never asks the renderer for more lights
than it has, a dark lamp is dark, and passes of lights add up to one render wherever the
clamp leaves the sum alone."""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from sim.world.render import SceneRenderer
from tools import night_calibration as nc

LAMP = nc.SOURCES[2]


def test_the_lamp_on_the_board_renders_what_the_photometry_predicts() -> None:
    # At 10 m the lamp puts about 22 lux on the board: 57 of 255 steps, far from both
    # white and the few steps where rounding dominates.
    row = nc.measure_board(10.0, LAMP)
    assert 15.0 < row.predicted_lux < 30.0
    assert row.clipped == 0.0
    assert abs(row.rendered_lux - row.predicted_lux) < 0.08 * row.predicted_lux
    assert row.error < 4.0  # mean per-pixel difference, 8-bit steps
    assert row.camera.exposure_ms <= nc.IMX273.max_exposure_ms


def test_a_lamp_that_is_off_gives_no_light() -> None:
    dark = nc.Source("street lamp, off", lamp=True, lamp_on=False)
    values = []
    for source in (dark, nc.SOURCES[0]):  # the dark lamp, then no lamp at all
        scene, board = nc.board_scene(10.0, source)
        with SceneRenderer(scene) as renderer:
            image = renderer.render()
            inside = nc.interior(renderer.mask(scene.geoms_of(board)))
        values.append(image[inside])
    assert np.array_equal(values[0], values[1])
    assert nc.predicted_lux(scene, board.x, dark).max() == nc.NIGHT_AMBIENT_LUX


def test_the_night_street_takes_a_lamps_pool_that_a_one_box_road_did_not() -> None:
    (_, box), (_, grid) = nc.ROAD_BUILDS[:2]
    old = nc.measure_road(nc.LAMP, "one box", box)
    new = nc.measure_road(nc.LAMP, "grid", grid)
    assert old.adds == 0.0  # a one-quad road is lit at its far corners only
    # The 1 m grid: within 10 % of the per-pixel photometry the renderer's clamp allows.
    assert abs(new.adds - new.clamped) < 0.1 * new.clamped
    assert new.clamped > 30.0  # a real pool, many steps above the rounding


def test_a_lit_colour_is_clamped_per_vertex_before_the_texture() -> None:
    rows = {r.lux: r for r in nc.measure_clamp()}
    full = nc.FULL
    # The textured road: linear up to the full scale, then no brighter (at its texture's
    # value, far below white); the untextured board (colour 0.5) goes on to white.
    assert abs(rows[full / 2].road - rows[full].road / 2) < 1.0
    assert rows[full].road < 200.0
    assert all(abs(rows[lux].road - rows[full].road) <= 1.0 for lux in rows if lux > full)
    assert rows[1.5 * full].board > rows[full].board + 30.0
    assert rows[2 * full].board == 255.0


def test_the_sensors_clip_level_is_where_its_output_clips() -> None:
    image = np.full((48, 64, 3), 60, np.uint8)
    sensor, _ = nc.imx273_settled(image)
    level = nc.clip_level(sensor)
    quiet = nc.Sensor(replace(nc.IMX273, noise=False), nc.NIGHT.illuminance_lux, 1 / 15, 0)
    quiet.meter(np.full(image.shape, 60 / 255, np.float32))
    assert nc.clip_level(quiet) == level
    state = quiet.settings()  # (a read moves the auto-exposure on: keep these settings)
    for share, clipped in ((0.97, False), (1.02, True)):
        light = np.full(image.shape, share * level, np.float32)
        frame, _ = quiet.read(light, state)
        assert bool((frame == 255).all()) is clipped


def test_the_budget_never_lights_more_than_the_renderer_has() -> None:
    scene, street, _ = nc.ncap_scene()
    for before in (80.0, *nc.CAR_BEFORE_IMPACT, 0.0):
        nc.place_car(scene, before)
        assert nc.active_lights(scene.model) <= nc.MAX_LIGHTS
        seen = int(np.sum(street.score(nc.Moment(0.0, scene.robot_pose)) > 0))
        assert len(street.shining) == min(seen, street.slots)  # every slot used when needed


def test_passes_add_up_to_one_render_where_no_vertex_saturates() -> None:
    # Fixed-function GL clamps each vertex's lit colour to [0, 1] before the texture
    # multiplies it: one render clamps the sum of every light at a vertex, summed passes
    # clamp each pass's share. With the low beam on the road near the car and the lamps'
    # pools above the full scale, the two differ there (the one render darker), so the
    # sum is the render's own image only on pixels whose quad's corners all take less
    # than the full scale (tools.night_calibration.street_saturation, from lamps.py's
    # photometry). There it must agree within the passes' rounding; the later passes'
    # light must be there too, or the comparison would pass with passes that do not add.
    scene, street, _ = nc.ncap_scene()
    beam_x = nc.place_car(scene, 20.0)
    with SceneRenderer(scene) as renderer:
        one = renderer.render().astype(float)
        groups = nc.own_passes(scene.model)
        summed = np.minimum(nc.summed_render(scene, renderer, groups), 255.0)
        first = nc.summed_render(scene, renderer, groups[:1])
        lit = [street.lamps[k] for k in street.shining]
        below, above = nc.street_saturation(scene, renderer, lit, beam_x)
        after = renderer.render()
    assert len(groups) > 1 and below.sum() > 10_000
    diff = one - summed
    assert np.abs(diff[below]).mean() < 0.5
    assert np.percentile(np.abs(diff[below]), 99) <= 2.0
    assert np.abs(one - first)[below].mean() > 5.0  # what the later passes add there
    # Where a corner may take more, the one render clamps the sum: never brighter than
    # the passes (beyond rounding), and darker by many steps somewhere.
    assert diff.max() <= 1.5
    assert diff[above].min() < -10.0
    assert np.array_equal(after, one)  # the lights are as the budget left them


@pytest.mark.slow
def test_the_table_is_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "argv", ["night_calibration", "--out", str(tmp_path)])
    nc.main()
    text = (tmp_path / "calibration.md").read_text()
    assert text.startswith("# The night's render")
    assert nc.COMMAND in text
    assert text.count("| low beam |") == 2 * len(nc.DISTANCES) + len(nc.ROAD_BUILDS)
    assert list(tmp_path.iterdir()) == [tmp_path / "calibration.md"]
