"""How a night scene is drawn: a street lit per vertex on a fine grid, a photometric render
read as light, and the lamps the renderer's lights go to."""

from __future__ import annotations

from dataclasses import replace

import mujoco
import numpy as np

from sim.scenario.lamps import LOW_BEAM, StreetLamp
from sim.scenario.lighting import DAY, NIGHT
from sim.scenario.spec import SceneSpec
from sim.sensor.readout import linear_light, photometric_light
from sim.world.entities.street_lamps import MAX_LIGHTS
from sim.world.scene import NIGHT_GRID, Scene, SceneConfig, scene_entities


def test_a_photometric_render_is_read_as_it_is_and_a_display_render_is_decoded() -> None:
    image = np.arange(256, dtype=np.uint8).reshape(16, 16, 1).repeat(3, axis=2)
    assert np.allclose(photometric_light(image), image / 255.0)
    decoded = linear_light(image)
    assert decoded[8, 0, 0] < image[8, 0, 0] / 255.0  # sRGB's mid-tones are darker in light


def _scene(spec: SceneSpec) -> Scene:
    return Scene(SceneConfig(spec=spec), scene_entities(SceneConfig(spec=spec)))


def test_the_night_street_is_a_fine_grid_and_the_day_street_keeps_its_boxes() -> None:
    day = _scene(SceneSpec(lighting=DAY)).model
    night = _scene(SceneSpec(lighting=NIGHT)).model
    assert day.geom("road").type == mujoco.mjtGeom.mjGEOM_BOX
    road = night.geom("road")
    assert road.type == mujoco.mjtGeom.mjGEOM_PLANE and road.size[2] == NIGHT_GRID
    # The plane lies where the box's top was: the ground at z = 0.
    assert night.geom_pos[road.id][2] == 0.0
    assert day.ngeom == night.ngeom


def test_a_night_scene_lights_no_more_lamps_than_the_renderer_has_lights() -> None:
    lamps = tuple(StreetLamp(x, -6.0) for x in range(5, 200, 20))
    scene = _scene(SceneSpec(lighting=NIGHT, lamps=lamps))
    model = scene.model
    street = next(e for e in scene.entities if e.name == "lamps")
    for x in (0.0, 50.0, 120.0):
        scene.set_camera_pose(x, 0.0, 0.0)
        active = int(np.sum(model.light_active)) + (1 if model.vis.headlight.active else 0)
        assert active <= MAX_LIGHTS
        assert 0 < len(street.shining) <= street.slots
        # The lamps that shine light ground the camera sees: none far behind it.
        assert all(lamps[k].x > x - 10.0 for k in street.shining)


def test_a_night_scene_has_no_sun_and_the_robots_beam_rides_with_it() -> None:
    from sim.world.lighting import lights

    camera = SceneConfig().camera
    assert [type(e).__name__ for e in lights(NIGHT, (), camera, LOW_BEAM, 2.25)] == [
        "HeadlampLights"
    ]
    assert [type(e).__name__ for e in lights(DAY)] == ["SunLight"]
    dark = replace(NIGHT.sun, diffuse=(0.1, 0.1, 0.1))
    assert dark.shines and not NIGHT.sun.shines
