"""How the night's render compares with its photometry: docs/night/calibration.md.

    python -m tools.night_calibration [--out DIR]

Four measurements, all through the real renderer (headless, MUJOCO_GL=egl) with the
car-scale camera (sim.scenario.families CAR) under the `night` lighting preset:

1. A matte grey board (reflectance 0.5, 1 m x 1 m, facing the car, standing on the road)
   straight ahead at 5, 10, 20 and 40 m from the car's front, lit by the 1 lux ambient
   alone, by the low beam (sim.scenario.lamps LOW_BEAM at the front centre, 0.65 m high)
   and by one street lamp beside it. Each pixel of the board gets the illuminance
   lamps.py's formulas predict (I/d^2 times the cosine of incidence) and the value the
   renderer draws; the table compares them, says what the render stands for in lux and
   what the imx273 camera model makes of it at its auto-exposure's settled settings.
   MuJoCo's classic renderer lights per vertex (Gouraud shading), so the board is built
   of 5 cm tiles, each with its own corners, to measure the photometry.
1b. Per-vertex lighting: the same board as one box, and the road under a street lamp and
   under the low beam drawn three ways: as one box (the street before it was a grid at
   night), as the night street draws it (planes of a NIGHT_GRID = 1 m grid) and as a
   0.25 m grid, against the photometry per pixel.
1c. The per-vertex clamp: fixed-function GL clamps a vertex's lit colour (the light times
   the material's colour) to [0, 1] before the texture multiplies it, so a textured
   surface saturates at the full scale whatever its texture's reflectance; where the
   imx273 model saturates at the gains its auto-exposure chooses at night.
2. The low beam against UN R112's test points (sim.scenario.lamps.regulation_table).
3. The light budget: MuJoCo lights at most 8 lights; StreetLamps (sim.world.entities
   .street_lamps) lights the lamps that matter each frame. Along a night road with the
   Euro NCAP lamp layout, the light the budget leaves out is the lamps it did not light
   drawn in passes of their own; the same section measures what the clamp costs one
   render against its own lights summed from passes.

The Markdown is written whole or not at all.
"""

from __future__ import annotations

import argparse
import datetime
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import mujoco
import numpy as np

from monopic.camera import CameraModel
from monopic.output import atomic_path
from sim.runs.runner import machine
from sim.scenario.families import CAR
from sim.scenario.lamps import LOW_BEAM, UP, Headlamps, StreetLamp, regulation_table
from sim.scenario.lighting import NIGHT_AMBIENT_LUX, NIGHT_FULL_SCALE_LUX, PRESETS
from sim.scenario.spec import MannequinSpec, SceneSpec
from sim.sensor.readout import photometric_light
from sim.sensor.sensor import Sensor
from sim.sensor.spec import IMX273
from sim.world.entities.base import Entity, Moment
from sim.world.entities.pedestrian import PedestrianBody
from sim.world.entities.robot import RobotBody
from sim.world.entities.street_lamps import MAX_LIGHTS, StreetLamps
from sim.world.lighting import lights
from sim.world.render import SceneRenderer
from sim.world.scene import NIGHT_GRID, Scene, SceneConfig
from sim.world.street import GRASS_GRID_X

OUT = Path("docs/night")
NIGHT = PRESETS["night"]
FULL = NIGHT_FULL_SCALE_LUX
REFLECTANCE = 0.5  # the board's grey
BOARD_SIZE = 1.0  # m, square
BOARD_TILES = 20  # tiles a side: per-vertex lighting sampled every 5 cm
DISTANCES = (5.0, 10.0, 20.0, 40.0)  # m from the car's front (the headlamps) to the board
FRONT = CAR.robot.length / 2  # the headlamps, ahead of the car's reference point
# The street lamp beside the board: 2 m nearer the car and 2 m to its right, so that its
# light meets the board's face at a known slant (the same for every distance).
LAMP_BEFORE, LAMP_RIGHT = 2.0, 2.0
ERODE_PX = 2  # the board's interior: its mask less this many pixels at the edges
SENSOR_FPS = 15.0  # the car's camera rate (sim.scenario.presets FPS)
FINE_GRID = 0.25  # m, a finer grid than the night street's, for the road's reference
# A pixel's 1 m grid quad has its corners within sqrt(2) m of the point the pixel sees.
CORNER_REACH = 1.5  # m
RASTER_STEP = 0.25  # m, the ground illuminance raster the reach is taken over
CLAMP_LUX = (25.0, 50.0, 75.0, 100.0, 150.0)  # uniform light for the clamp's table
# The Euro NCAP night roads' lamps, in x from the impact point and y (m).
NCAP_LAMPS = (
    *((dx, -6.1) for dx in (-62.5, -37.5, -12.5, 12.5, 37.5)),
    (-12.5, 8.1),
    (12.5, 8.1),
)
IMPACT_X = 0.0
CAR_BEFORE_IMPACT = (60.0, 45.0, 30.0, 20.0, 10.0)  # m from the car's front to the impact
PEDESTRIAN = (IMPACT_X, -3.0)  # at the nearside of the road, about to cross
PASS_LIGHTS = 3  # scene lights a pass when a measurement sums passes


class Board(Entity):
    """A matte grey board standing on the road, its face towards -x (the car), built of
    tiles so that the renderer's per-vertex lighting samples it every few centimetres."""

    name = "board"

    def __init__(self, x: float, tiles: int = BOARD_TILES) -> None:
        self.x = x  # the face's x
        self.tiles = tiles

    def build(self, spec: mujoco.MjSpec) -> None:
        grey = [REFLECTANCE, REFLECTANCE, REFLECTANCE, 1.0]
        spec.add_material(
            name=self.prefix + "matte", rgba=grey, specular=0.0, shininess=0.0, reflectance=0.0
        )
        thick = 0.01
        body = spec.worldbody.add_body(name=self.name, pos=[self.x + thick, 0.0, BOARD_SIZE / 2])
        half = BOARD_SIZE / (2 * self.tiles)
        for i in range(self.tiles):
            for j in range(self.tiles):
                body.add_geom(
                    name=f"{self.prefix}{i}_{j}",
                    type=mujoco.mjtGeom.mjGEOM_BOX,
                    size=[thick, half, half],
                    pos=[
                        0.0,
                        -BOARD_SIZE / 2 + half * (2 * i + 1),
                        -BOARD_SIZE / 2 + half * (2 * j + 1),
                    ],
                    material=self.prefix + "matte",
                    contype=0,
                    conaffinity=0,
                )


@dataclass(frozen=True)
class Source:
    """What lights the board: the ambient alone, the low beam or a street lamp beside it."""

    name: str
    beam: Headlamps | None = None
    lamp: bool = False
    lamp_on: bool = True  # a lamp that stands dark (it must give no light)


SOURCES = (
    Source("ambient 1 lux"),
    Source("low beam", beam=LOW_BEAM),
    Source("street lamp", lamp=True),
)


def car_camera() -> CameraModel:
    return CAR.robot.camera.model()


def lamp_beside(face_x: float, on: bool = True) -> StreetLamp:
    return StreetLamp(face_x - LAMP_BEFORE, -LAMP_RIGHT, on=on)


def board_scene(distance: float, source: Source, tiles: int = BOARD_TILES) -> tuple[Scene, Board]:
    """The still night scene: the car at the origin heading east, the board `distance`
    metres ahead of its front, lit by `source`."""
    cam = car_camera()
    face_x = FRONT + distance
    lamps = (lamp_beside(face_x, source.lamp_on),) if source.lamp else ()
    board = Board(face_x, tiles)
    entities = [*lights(NIGHT, lamps, cam, source.beam, FRONT), RobotBody(cam), board]
    spec = SceneSpec(lighting=NIGHT, road=CAR.road, lamps=lamps)
    return Scene(SceneConfig(camera=cam, spec=spec), entities), board


def pixel_rays(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The camera's centre and a ray (world frame) through every pixel's centre."""
    cam, data, cid = scene.camera, scene.data, scene.robot.camera_id
    u, v = np.meshgrid(np.arange(cam.width) + 0.5, np.arange(cam.height) + 0.5)
    local = np.stack([(u - cam.cx) / cam.fx, -(v - cam.cy) / cam.fy, -np.ones_like(u)], -1)
    return data.cam_xpos[cid].copy(), local @ data.cam_xmat[cid].reshape(3, 3).T


def ground_points(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """Where each pixel's ray meets the ground (z = 0), and which rays do."""
    origin, rays = pixel_rays(scene)
    down = rays[..., 2] < -1e-6
    t = np.where(down, -origin[2] / np.where(down, rays[..., 2], -1.0), 0.0)
    return origin + t[..., None] * rays, down


def lux_from_beam(
    points: np.ndarray, normal: np.ndarray, beam: Headlamps, beam_x: float
) -> np.ndarray:
    """Lux the beam at (beam_x, 0, height), the car heading +x, puts on surfaces at
    `points` (..., 3) facing `normal`: I/d^2 times the cosine of incidence."""
    d = points - np.array([beam_x, 0.0, beam.height])
    r = np.linalg.norm(d, axis=-1)
    cos = np.maximum(-(d @ normal), 0.0) / r
    return beam.intensity_towards(d / r[..., None]) * cos / r**2


def predicted_lux(scene: Scene, face_x: float, source: Source) -> np.ndarray:
    """The illuminance on the board's plane seen through every pixel (lux), from lamps.py's
    photometry: the ambient, plus I/d^2 times the cosine of incidence of the source."""
    origin, rays = pixel_rays(scene)
    t = (face_x - origin[0]) / rays[..., 0]
    points = origin + t[..., None] * rays
    lux = np.full(points.shape[:2], NIGHT_AMBIENT_LUX)
    normal = np.array([-1.0, 0.0, 0.0])
    if source.beam is not None:
        lux += lux_from_beam(points, normal, source.beam, FRONT)
    if source.lamp:
        lux += lamp_beside(face_x, source.lamp_on).illuminance_on(points, normal)
    return lux


def interior(mask: np.ndarray) -> np.ndarray:
    kernel = np.ones((2 * ERODE_PX + 1, 2 * ERODE_PX + 1), np.uint8)
    return cv2.erode(mask.astype(np.uint8), kernel).astype(bool)


def steps(lux: np.ndarray | float) -> np.ndarray | float:
    """The 8-bit value the photometric render should draw on the board under `lux`."""
    return np.clip(REFLECTANCE * np.asarray(lux) / FULL, 0.0, 1.0) * 255.0


@dataclass(frozen=True)
class CameraRead:
    """What the imx273 model made of a frame: its settings and the board's pixels."""

    exposure_ms: float
    gain: float
    mean: float  # the board's sRGB 8-bit mean (red channel)
    noise: float  # std of the noisy frame less the noiseless one on the board
    clips_at: float  # the render's linear light (share of its white) the sensor clips at

    @property
    def clip_lux(self) -> float:
        """The illuminance on a white surface at which the sensor's output clips."""
        return self.clips_at * FULL


def imx273_settled(image: np.ndarray, seed: int = 0) -> tuple[Sensor, np.ndarray]:
    """The imx273 model, its auto-exposure settled on the frame (read as the sensor reads
    a night render: linear light, sim.sensor.readout.photometric_light), and the light."""
    light = photometric_light(image)
    sensor = Sensor(IMX273, NIGHT.illuminance_lux, 1.0 / SENSOR_FPS, seed)
    sensor.meter(light)
    return sensor, light


def clip_level(sensor: Sensor) -> float:
    """The linear light (share of the render's white) at which the sensor's output clips
    at its settings: its ADC's full scale, full_well / gain electrons (gain >= 1, so the
    ADC clips before the well does)."""
    state = sensor.settings()
    return IMX273.full_well_e / (sensor.rate * state.exposure_s * state.gain)


def imx273_read(image: np.ndarray, board: np.ndarray, seed: int = 0) -> CameraRead:
    """The frame through the imx273 model, its auto-exposure settled on it."""
    noisy, light = imx273_settled(image, seed)
    state = noisy.settings()
    quiet = Sensor(replace(IMX273, exposure_ms=1000 * state.exposure_s, gain=state.gain,
                           noise=False), NIGHT.illuminance_lux, 1.0 / SENSOR_FPS, seed)  # fmt: skip
    frame, _ = noisy.read(light, state)
    clean, _ = quiet.read(light, quiet.settings())
    red, red_clean = frame[..., 0][board].astype(float), clean[..., 0][board].astype(float)
    return CameraRead(1000 * state.exposure_s, state.gain, float(red.mean()),
                      float(np.std(red - red_clean)), clip_level(noisy))  # fmt: skip


@dataclass(frozen=True)
class BoardRow:
    source: str
    distance: float
    pixels: int
    predicted_lux: float  # mean over the board's interior
    predicted: float  # the 8-bit value the photometry asks for, clipped at white (mean)
    rendered: float  # the render's mean, red channel
    error: float  # mean |rendered - predicted| per pixel, 8-bit steps
    clipped: float  # share of the interior's pixels at 255
    camera: CameraRead

    @property
    def rendered_lux(self) -> float:
        return self.rendered / 255.0 / REFLECTANCE * FULL


def measure_board(distance: float, source: Source) -> BoardRow:
    scene, board = board_scene(distance, source)
    with SceneRenderer(scene) as renderer:
        image = renderer.render()
        inside = interior(renderer.mask(scene.geoms_of(board)))
    lux = predicted_lux(scene, board.x, source)[inside]
    want = steps(lux)
    red = image[..., 0][inside].astype(float)
    return BoardRow(
        source=source.name,
        distance=distance,
        pixels=int(inside.sum()),
        predicted_lux=float(lux.mean()),
        predicted=float(np.mean(want)),
        rendered=float(red.mean()),
        error=float(np.mean(np.abs(red - want))),
        clipped=float(np.mean(red >= 255)),
        camera=imx273_read(image, inside),
    )


@dataclass(frozen=True)
class VertexRow:
    """The same board as one box (each face lit at its four corners only) beside the tiled."""

    source: str
    distance: float
    tiled: float
    one_box: float
    predicted: float


def measure_one_box(distance: float, source: Source, tiled: BoardRow) -> VertexRow:
    scene, board = board_scene(distance, source, tiles=1)
    with SceneRenderer(scene) as renderer:
        image = renderer.render()
        inside = interior(renderer.mask(scene.geoms_of(board)))
    return VertexRow(source.name, distance, tiled.rendered,
                     float(image[..., 0][inside].mean()), tiled.predicted)  # fmt: skip


# -- the road, drawn three ways ---------------------------------------------------------

ROAD_DISTANCE = 15.0  # m from the car's front to the lamp's foot
ROAD_LAMP_Y = -2.0  # m, the lamp's foot on the road, right of the car's centre line
ROAD_RADIUS = 3.0  # m around the foot
BEAM_FROM, BEAM_TO = 5.0, 40.0  # m ahead of the car's front: the road the beam is read on
LAMP, BEAM = "street lamp", "low beam"
# How the road is drawn: the grid (m) of its plane, or None for the one box the street
# was drawn with before it was a grid at night.
ROAD_BUILDS: tuple[tuple[str, float | None], ...] = (
    ("one box (the street before)", None),
    (f"{NIGHT_GRID:g} m grid (the night street)", NIGHT_GRID),
    (f"{FINE_GRID:g} m grid", FINE_GRID),
)


def road_scene(light: str, on: bool, grid: float | None) -> Scene:
    """The car at the origin heading east on the night road drawn with `grid` (None: as
    one box, the street's daytime build under the same night light), `light` on or off."""
    cam = car_camera()
    lighting = NIGHT if grid is not None else replace(NIGHT, night=False)
    lamps = (StreetLamp(FRONT + ROAD_DISTANCE, ROAD_LAMP_Y, on=on),) if light == LAMP else ()
    beam = LOW_BEAM if light == BEAM and on else None
    entities = [*lights(lighting, lamps, cam, beam, FRONT), RobotBody(cam)]
    spec = SceneSpec(lighting=lighting, road=CAR.road, lamps=lamps)
    scene = Scene(SceneConfig(camera=cam, spec=spec), entities)
    if grid is not None:
        # The renderer builds a plane's grid when it is made: set before SceneRenderer.
        scene.model.geom_size[scene.model.geom("road").id, 2] = grid
    scene.set_camera_pose(0.0, 0.0, 0.0)
    return scene


def albedo(scene: Scene, renderer: SceneRenderer) -> np.ndarray:
    """Each pixel's reflectance as the renderer applies it (red channel, 0-1): the scene
    lit by a uniform light of the full scale alone (the headlight's ambient at 1), so a
    vertex's lit colour is the material's colour and the texture multiplies it."""
    model = scene.model
    head = model.vis.headlight
    kept_active, kept_ambient = model.light_active.copy(), head.ambient.copy()
    try:
        model.light_active[:] = 0
        head.ambient[:] = 1.0
        return renderer.render()[..., 0].astype(float) / 255.0
    finally:
        model.light_active[:] = kept_active
        head.ambient[:] = kept_ambient


@dataclass(frozen=True)
class RoadRow:
    """What a light adds to the road, drawn one way, against its photometry per pixel."""

    light: str
    build: str
    pixels: int
    adds: float  # 8-bit mean the light adds over the region, red channel
    clamped: float  # per-pixel photometry, clamped at the full scale as the render clamps
    photometry: float  # albedo x lux / full scale, clipped at white only (a camera's view)
    saturated: float  # share of the region's pixels at or above the full scale (lux)


def road_region(scene: Scene, renderer: SceneRenderer, light: str) -> tuple[np.ndarray, ...]:
    """The road pixels the measurement reads (no mast in front of them), and the lux the
    light puts on the ground each of them sees."""
    points, down = ground_points(scene)
    seen = down & renderer.mask(np.array([scene.model.geom("road").id]))
    if light == LAMP:
        foot = np.array([FRONT + ROAD_DISTANCE, ROAD_LAMP_Y])
        region = seen & (np.hypot(*(points[..., :2] - foot).transpose(2, 0, 1)) < ROAD_RADIUS)
        lux = StreetLamp(FRONT + ROAD_DISTANCE, ROAD_LAMP_Y).illuminance_on(points, UP)
    else:
        ahead = points[..., 0] - FRONT
        region = seen & (ahead > BEAM_FROM) & (ahead < BEAM_TO)
        lux = lux_from_beam(points, UP, LOW_BEAM, FRONT)
    return region, lux


def measure_road(light: str, build: str, grid: float | None) -> RoadRow:
    images = []
    for on in (True, False):
        scene = road_scene(light, on, grid)
        with SceneRenderer(scene) as renderer:
            images.append(renderer.render()[..., 0].astype(float))
            if on:
                reflect = albedo(scene, renderer)
                region, lux = road_region(scene, renderer, light)
    a, e = reflect[region], lux[region] + NIGHT_AMBIENT_LUX
    base = 255.0 * a * NIGHT_AMBIENT_LUX / FULL
    return RoadRow(
        light,
        build,
        int(region.sum()),
        float(np.mean(images[0][region] - images[1][region])),
        float(np.mean(255.0 * a * np.minimum(e / FULL, 1.0) - base)),
        float(np.mean(np.minimum(255.0 * a * e / FULL, 255.0) - base)),
        float(np.mean(e >= FULL)),
    )


# -- the per-vertex clamp ---------------------------------------------------------------


@dataclass(frozen=True)
class ClampRow:
    """A uniform light on the textured road and the untextured grey board."""

    lux: float
    road: float  # 8-bit mean, red channel
    road_photometry: float  # the road's albedo x lux / full scale, clipped at white
    board: float
    board_photometry: float


def measure_clamp() -> list[ClampRow]:
    """The scene lit by a uniform light (the headlight's ambient) of each illuminance in
    CLAMP_LUX: a vertex's light is the same everywhere, so interpolation plays no part."""
    scene, board = board_scene(10.0, SOURCES[0])
    model = scene.model
    head = model.vis.headlight
    kept = head.ambient.copy()
    rows = []
    with SceneRenderer(scene) as renderer:
        plate = interior(renderer.mask(scene.geoms_of(board)))
        road = interior(renderer.mask(np.array([model.geom("road").id])))
        reflect = albedo(scene, renderer)[road]
        try:
            for lux in CLAMP_LUX:
                head.ambient[:] = lux / FULL
                red = renderer.render()[..., 0].astype(float)
                rows.append(ClampRow(
                    lux, float(red[road].mean()),
                    float(np.minimum(255.0 * reflect * lux / FULL, 255.0).mean()),
                    float(red[plate].mean()), float(steps(lux)),
                ))  # fmt: skip
        finally:
            head.ambient[:] = kept
    return rows


@dataclass(frozen=True)
class SurfaceMaterial:
    name: str
    textured: bool
    colour: float  # the material's colour (red), inside the clamp


def street_materials(model: mujoco.MjModel) -> list[SurfaceMaterial]:
    """The materials of the street's grid surfaces (its planes), each once."""
    out: dict[str, SurfaceMaterial] = {}
    rgb = int(mujoco.mjtTextureRole.mjTEXROLE_RGB)
    for g in np.flatnonzero(model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE):
        mat = int(model.geom_matid[g])
        name = model.material(mat).name
        out[name] = SurfaceMaterial(
            name, bool(model.mat_texid[mat, rgb] >= 0), float(model.mat_rgba[mat, 0])
        )
    return list(out.values())


def street_saturation(
    scene: Scene, renderer: SceneRenderer, lamps: Sequence[StreetLamp], beam_x: float | None
) -> tuple[np.ndarray, np.ndarray]:
    """The pixels of the street's 1 m grid surfaces (road, kerbs, pavements, edge lines)
    whose quad's corners all take less than the full scale by lamps.py's photometry (the
    ambient, `lamps` and the low beam at `beam_x`), and those where a corner may take
    more: the ground illuminance's maximum within CORNER_REACH of the point each sees."""
    model = scene.model
    planes = np.flatnonzero(
        (model.geom_type == mujoco.mjtGeom.mjGEOM_PLANE) & (model.geom_size[:, 2] == NIGHT_GRID)
    )
    points, down = ground_points(scene)
    surface = down & renderer.mask(planes)
    x0 = float(scene.data.cam_xpos[scene.robot.camera_id][0]) - 5.0
    xs = np.arange(x0, x0 + 155.0, RASTER_STEP)
    ys = np.arange(-12.0, 12.0, RASTER_STEP)
    grid = np.stack([*np.meshgrid(xs, ys), np.zeros((len(ys), len(xs)))], -1)
    lux = np.full(grid.shape[:2], NIGHT_AMBIENT_LUX)
    for lamp in lamps:
        lux += lamp.illuminance_on(grid, UP)
    if beam_x is not None:
        lux += lux_from_beam(grid, UP, LOW_BEAM, beam_x)
    reach = round(CORNER_REACH / RASTER_STEP)
    disk = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1))
    most = cv2.dilate(lux.astype(np.float32), disk)
    ix = np.rint((points[..., 0] - xs[0]) / RASTER_STEP).astype(int)
    iy = np.rint((points[..., 1] - ys[0]) / RASTER_STEP).astype(int)
    inside = surface & (ix >= 0) & (ix < len(xs)) & (iy >= 0) & (iy < len(ys))
    peak = np.where(inside, most[np.clip(iy, 0, len(ys) - 1), np.clip(ix, 0, len(xs) - 1)], 0)
    return inside & (peak < FULL), inside & (peak >= FULL)


# -- the light budget -------------------------------------------------------------------


def ncap_lamps() -> tuple[StreetLamp, ...]:
    return tuple(StreetLamp(IMPACT_X + dx, y) for dx, y in NCAP_LAMPS)


def ncap_scene() -> tuple[Scene, StreetLamps, PedestrianBody]:
    """A night road with the Euro NCAP lamp layout, the car's low beam and a pedestrian."""
    cam = car_camera()
    lamps = ncap_lamps()
    pedestrian = PedestrianBody(MannequinSpec())
    entities = [*lights(NIGHT, lamps, cam, LOW_BEAM, FRONT), RobotBody(cam), pedestrian]
    spec = SceneSpec(lighting=NIGHT, road=CAR.road, lamps=lamps)
    scene = Scene(SceneConfig(camera=cam, spec=spec), entities)
    (street,) = [e for e in entities if isinstance(e, StreetLamps)]
    return scene, street, pedestrian


def place_car(scene: Scene, before_impact: float) -> float:
    """The car on the centre line, its front `before_impact` m before the impact point;
    returns the x of its front (the low beam's)."""
    scene.set_camera_pose(IMPACT_X - before_impact - FRONT, 0.0, 0.0)
    return IMPACT_X - before_impact


def active_lights(model: mujoco.MjModel) -> int:
    """The lights the renderer is asked for: the active scene lights and its headlight
    (whose `active` flag is any non-zero value: MuJoCo's default is 2)."""
    return int(np.sum(model.light_active)) + (1 if model.vis.headlight.active else 0)


def _is_lamp(model: mujoco.MjModel, light: int) -> bool:
    return model.light(light).name.endswith("/light")


def passes(lights_: Sequence[int], per_pass: int = PASS_LIGHTS) -> list[list[int]]:
    """`lights_` in groups of at most `per_pass`, one group a render pass."""
    return [list(lights_[k : k + per_pass]) for k in range(0, len(lights_), per_pass)]


def summed_render(
    scene: Scene, renderer: SceneRenderer, groups: Sequence[Sequence[int]]
) -> np.ndarray:
    """The scene drawn once per group of lights and summed, the ambient (the headlight's)
    in the first pass only. Each pass also draws what glows by itself (the lamps' heads),
    so a pass with no scene light is taken off for every pass after the first. The
    headlight stays on with its ambient zeroed rather than off: with no light at all
    MuJoCo lights the scene by a default of its own (a probe: a mean of 29 steps over the
    night road, the car 20 m before the impact point). Float, unclipped: the passes add
    the light each vertex takes, each pass clamped to white on its own (section 1c), the
    sum not."""
    model = scene.model
    head = model.vis.headlight
    kept_active, kept_ambient = model.light_active.copy(), head.ambient.copy()
    groups = list(groups) or [[]]
    try:
        total = np.zeros((renderer.height, renderer.width, 3))
        for k, group in enumerate(groups):
            model.light_active[:] = 0
            model.light_active[list(group)] = 1
            head.ambient[:] = kept_ambient if k == 0 else 0.0
            total += renderer.render()
        if len(groups) > 1:
            model.light_active[:] = 0
            head.ambient[:] = 0.0
            total -= (len(groups) - 1) * renderer.render().astype(float)
    finally:
        model.light_active[:] = kept_active
        head.ambient[:] = kept_ambient
    return total


def own_passes(model: mujoco.MjModel) -> list[list[int]]:
    """The lights active now (the low beam's cones and the lamps the budget lit), in
    passes of PASS_LIGHTS."""
    return passes(np.flatnonzero(model.light_active).tolist())


def left_out(model: mujoco.MjModel) -> list[int]:
    """The street lamps the budget left dark this frame."""
    return [i for i in range(model.nlight) if _is_lamp(model, i) and not model.light_active[i]]


@dataclass(frozen=True)
class BudgetRow:
    before_impact: float
    shining: int  # street lamps the budget lit
    seen: int  # street lamps with a score (some of their light in view)
    mean: float  # the light left out: mean over the image, 8-bit steps
    p99: float
    box_mean: float  # the same over the pedestrian's box (nan when out of view)
    box_p99: float
    clamp_mean: float  # mean |one render - its own lights summed from passes|, the image
    clamp_below: float  # the same on street pixels whose quad's corners stay below white
    clamp_above: float  # ... and on those where a corner may take more than the full scale
    above_share: float  # share of the image's pixels in the latter
    brighter: float  # max (one render - passes): the clamp only takes light away
    camera: CameraRead  # the imx273 model on the frame (the board fields: the image's)


def _stats(diff: np.ndarray, box: tuple[slice, slice] | None) -> tuple[float, ...]:
    inside = diff[box] if box is not None else np.array([np.nan])
    return (float(diff.mean()), float(np.percentile(diff, 99)), float(np.mean(inside)),
            float(np.percentile(inside, 99)))  # fmt: skip


def _mean_on(values: np.ndarray, mask: np.ndarray) -> float:
    return float(values[mask].mean()) if mask.any() else math.nan


def measure_budget(
    scene: Scene, street: StreetLamps, pedestrian: PedestrianBody, renderer: SceneRenderer,
    before_impact: float,
) -> BudgetRow:  # fmt: skip
    beam_x = place_car(scene, before_impact)
    pedestrian.pose_at(scene.model, scene.data, *PEDESTRIAN, math.pi / 2)
    scene.update()
    model = scene.model
    image = renderer.render()
    one = image.astype(float)
    own = own_passes(model)
    split = np.minimum(summed_render(scene, renderer, own), 255.0)
    extra = passes(left_out(model))
    exact = np.minimum(summed_render(scene, renderer, own + extra), 255.0)
    mask = renderer.mask(scene.geoms_of(pedestrian))
    box = None
    if mask.any():
        rows, cols = np.flatnonzero(mask.any(1)), np.flatnonzero(mask.any(0))
        box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
    seen = int(np.sum(street.score(_moment(scene)) > 0))
    lit = [street.lamps[k] for k in street.shining]
    below, above = street_saturation(scene, renderer, lit, beam_x)
    clamp = np.abs(one - split).mean(-1)
    everywhere = np.ones(one.shape[:2], bool)
    return BudgetRow(before_impact, len(street.shining), seen,
                     *_stats(np.abs(exact - split), box),
                     float(clamp.mean()), _mean_on(clamp, below), _mean_on(clamp, above),
                     float(above.mean()), float((one - split).max()),
                     imx273_read(image, everywhere))  # fmt: skip


def _moment(scene: Scene) -> Moment:
    return Moment(0.0, scene.robot_pose)


# -- the document -----------------------------------------------------------------------


def _table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> list[str]:
    return [
        "| " + " | ".join(head) + " |",
        "|" + "|".join("---" for _ in head) + "|",
        *("| " + " | ".join(r) + " |" for r in rows),
    ]


def _f(value: float, digits: int = 1) -> str:
    return "-" if math.isnan(value) else f"{value:.{digits}f}"


def _span(values: Sequence[float], digits: int = 1) -> str:
    lo, hi = min(values), max(values)
    return (
        _f(lo, digits)
        if f"{lo:.{digits}f}" == f"{hi:.{digits}f}"
        else f"{lo:.{digits}f}-{hi:.{digits}f}"
    )


def _saturates_at(rows: Sequence[ClampRow], drawn: Callable[[ClampRow], float]) -> str:
    """The first illuminance of the table at which the surface draws no brighter than at
    the one before (within a step), or that it brightens all the way."""
    for before, row in zip(rows, rows[1:], strict=False):
        if drawn(row) <= drawn(before) + 1.0:
            return f"stops brightening between {before.lux:g} and {row.lux:g} lux"
    return f"brightens up to {rows[-1].lux:g} lux"


def render_markdown(
    boards: Sequence[BoardRow],
    vertex: Sequence[VertexRow],
    roads: Sequence[RoadRow],
    clamp: Sequence[ClampRow],
    materials: Sequence[SurfaceMaterial],
    budget: Sequence[BudgetRow],
    command: str,
) -> str:
    m = machine()
    cam = car_camera()
    lines = [
        "# The night's render against its photometry",
        "",
        f"Written by `{command}` on {datetime.date.today().isoformat()}; "
        f"ran on {m.cpu}, {m.cores} cores, host {m.host}. MuJoCo {mujoco.__version__}, "
        f"the car's camera ({cam.width} x {cam.height} px), the `night` preset (white "
        f"stands for {FULL:g} lux, the ambient {NIGHT_AMBIENT_LUX:g} lux). At night the "
        f"street's flat surfaces (road, kerbs, pavements, edge lines) are planes drawn as a "
        f"grid of {NIGHT_GRID:g} m quads (the grass {GRASS_GRID_X * NIGHT_GRID:g} m) and the "
        "facades stay "
        "boxes: MuJoCo's classic renderer lights per vertex, so a facade takes a lamp's "
        "light at its corners only. The sensor model reads a night render as linear light "
        "(sim.sensor.readout.photometric_light).",
        "",
        "## 1. A grey board at known distances",
        "",
        f"A matte grey board (reflectance {REFLECTANCE}, {BOARD_SIZE:g} m square, standing "
        "on the road, facing the car) straight ahead; the distance is from the car's front, "
        f"where the low beam sits {LOW_BEAM.height} m high (the camera is "
        f"{FRONT - CAR.robot.camera.mount_forward:.2f} m behind it, 1.3 m high). The street "
        f"lamp stands {LAMP_BEFORE:g} m nearer the car than the board and {LAMP_RIGHT:g} m to "
        "its right, so its light is the same at every distance. The board is built of "
        f"{BOARD_TILES} x {BOARD_TILES} tiles: MuJoCo lights per vertex (section 1b). "
        "Over the board's interior: *lux* is the mean illuminance lamps.py's formulas "
        "predict (ambient plus I/d^2 times the cosine of incidence, per pixel); *asks* "
        f"the 8-bit value that is ({REFLECTANCE} x lux / {FULL:g} x 255, clipped at white); "
        "*drawn* the render's mean (red channel; the lights are white); *|err|* the mean "
        "per-pixel difference in 8-bit steps; *clip* the share of pixels at 255; "
        f"*stands for* what the drawn value means (value / 255 / {REFLECTANCE} x {FULL:g} "
        "lux), which is also what the sensor model receives; then the imx273 model, its "
        "auto-exposure settled on the whole frame (Sensor.meter), its sRGB 8-bit mean on "
        "the board, the noise's std (the noisy frame less the noiseless one at the same "
        "settings) and the illuminance on the board at which its output clips at those "
        "settings (section 1c).",
        "",
    ]
    head = ["light", "d (m)", "px", "lux", "asks", "drawn", r"\|err\|", "clip", "stands for (lux)",
            "imx273 ms / gain", "imx273 mean", "noise std", "imx273 clips at (lux)"]  # fmt: skip
    rows = [
        [
            b.source,
            f"{b.distance:g}",
            str(b.pixels),
            _f(b.predicted_lux, 2),
            _f(b.predicted),
            _f(b.rendered),
            _f(b.error),
            f"{100 * b.clipped:.0f} %",
            _f(b.rendered_lux, 2),
            f"{b.camera.exposure_ms:.0f} / {b.camera.gain:.1f}",
            _f(b.camera.mean),
            _f(b.camera.noise),
            _f(b.camera.clip_lux / REFLECTANCE, 2),
        ]  # fmt: skip
        for b in boards
    ]
    lines += _table(head, rows)
    lines += [
        "",
        "## 1b. Per-vertex lighting",
        "",
        "The same board as one box (its face lit at its four corners, the light "
        "interpolated between them) beside the tiled board; 8-bit means, red channel.",
        "",
    ]
    lines += _table(
        ["light", "d (m)", "asks", "tiled", "one box"],
        [[v.source, f"{v.distance:g}", _f(v.predicted), _f(v.tiled), _f(v.one_box)]
         for v in vertex],
    )  # fmt: skip
    lines += [
        "",
        f"The road under a street lamp (within {ROAD_RADIUS:g} m of its foot, "
        f"{ROAD_DISTANCE:g} m ahead of the car's front and {-ROAD_LAMP_Y:g} m right of its "
        f"centre line) and under the low beam ({BEAM_FROM:g}-{BEAM_TO:g} m ahead of the "
        "car's front), drawn as one box (how the street was drawn before it became a grid "
        f"at night), as the night street draws it and as a {FINE_GRID:g} m grid. *Adds*: the "
        "8-bit mean the light adds to the road's pixels (the render with it less the "
        "render without it; red channel). *Photometry*: what it should add, per pixel, "
        f"from lamps.py's illuminance on the ground and the road's albedo as drawn (the "
        f"road lit by a uniform {FULL:g} lux): *clamped* as the renderer clamps (the light "
        "at most the full scale, section 1c), *unclamped* as a camera would see it "
        "(clipped at white only). *At or above full scale*: the share of the region's "
        f"pixels whose illuminance is at least {FULL:g} lux.",
        "",
    ]
    lines += _table(
        ["light", "road drawn as", "px", "adds", "photometry, clamped", "photometry, unclamped",
         "at or above full scale"],
        [[r.light, r.build, str(r.pixels), _f(r.adds), _f(r.clamped), _f(r.photometry),
          f"{100 * r.saturated:.0f} %"] for r in roads],
    )  # fmt: skip
    road_sat = _saturates_at(clamp, lambda r: r.road)
    board_sat = _saturates_at(clamp, lambda r: r.board)
    clips = [b.camera.clip_lux for b in budget]
    gains = [b.camera.gain for b in budget]
    exposures = [b.camera.exposure_ms for b in budget]
    at_full = [c for c in clamp if c.lux == FULL]
    road_top = at_full[0].road / 255.0 if at_full else math.nan  # the road's albedo
    surfaces = "; ".join(
        f"{s.name} ({'textured' if s.textured else 'untextured'}, colour {s.colour:g}): "
        f"{FULL / s.colour:.0f} lux"
        for s in materials
    )
    lines += [
        "",
        "## 1c. The per-vertex clamp",
        "",
        "Fixed-function GL clamps each vertex's lit colour (the lights times the "
        "material's colour) to [0, 1] before the texture multiplies it. A textured "
        "material with a white colour, its reflectance in the texture, saturates at the "
        f"full scale, {FULL:g} lux, whatever its reflectance, and draws no brighter than "
        "its texture there; an untextured material's colour is inside the clamp, so it "
        "saturates at the full scale over its colour, where it reaches white. The "
        "street's grid surfaces and the illuminance at which each saturates in the "
        f"render: {surfaces}. The table lights the scene of section 1 (the board at 10 m, "
        "no lamp; the board's colour is "
        f"{REFLECTANCE}) by a uniform light of each illuminance (the headlight's ambient: "
        "every vertex takes the same, so interpolation plays no part); 8-bit means, red "
        f"channel, photometry as in 1b. The road {road_sat}; the board {board_sat}.",
        "",
    ]
    lines += _table(
        ["lux", "road drawn", "road photometry", "board drawn", "board photometry"],
        [[f"{c.lux:g}", _f(c.road), _f(c.road_photometry), _f(c.board),
          _f(c.board_photometry)] for c in clamp],
    )  # fmt: skip
    white = (
        "on white, and on an untextured surface of any colour, the sensor saturates before "
        "the render clips"
        if max(clips) < FULL
        else "the render can clip before the sensor saturates even on white"
    )
    road = (
        f"the road stops at its texture's value ({_f(road_top, 2)} of white) at {FULL:g} "
        "lux, below where the sensor clips: there the render's clamp, not the sensor, "
        "limits how bright it gets"
        if road_top < min(clips) / FULL
        else f"the road's texture ({_f(road_top, 2)} of white) reaches the sensor's clip"
    )
    lines += [
        "",
        "Through imx273: on the frames of section 3 its auto-exposure settles on "
        f"{_span(exposures, 0)} ms at gain {_span(gains)}, where its output clips at "
        f"{_span(clips, 1)} lux on a white surface ({_span([255 * c / FULL for c in clips], 0)} "
        f"of the render's 255 steps). So {white}; {road}. Section 1's board frames settle "
        f"on {_span([b.camera.exposure_ms for b in boards], 0)} ms at gain "
        f"{_span([b.camera.gain for b in boards])} (the darker the frame, the higher the "
        "gain and the lower the clip).",
        "",
        "## 2. The low beam against UN R112 (class B, the pair)",
        "",
        "Degrees down (negative: up) and right (negative: left); the requirement is the "
        "pair's (twice the per-lamp figure); ours is sim.scenario.lamps LOW_BEAM's "
        "intensity in that direction.",
        "",
    ]
    reg = []
    for name, down, right, need, ours in regulation_table():
        bound = float(need.split()[1].replace(",", ""))
        met = ours >= bound if need.startswith(">=") else ours <= bound
        reg.append(
            [name, f"{down:g}", f"{right:g}", need, f"{ours:,.0f}", "met" if met else "NOT met"]
        )
    lines += _table(["point", "down", "right", "requirement (cd)", "ours (cd)", ""], reg)
    lines += [
        "",
        "## 3. What the light budget leaves out",
        "",
        f"The Euro NCAP night road's lamps (5 m high, x from the impact point: y = -6.1 m at "
        "-62.5, -37.5, -12.5, +12.5, +37.5; y = +8.1 m at -12.5, +12.5), the car's low beam "
        f"and an adult standing at ({PEDESTRIAN[0]:g}, {PEDESTRIAN[1]:g}) m, facing across "
        "the road; the car on the centre line, its front the given distance before the "
        f"impact point. The renderer lights at most {MAX_LIGHTS} lights, the ambient's "
        "included, so StreetLamps lights the lamps that matter and leaves the others "
        "dark. *Left out*: the light of the lamps it left dark, drawn in passes of their "
        f"own ({PASS_LIGHTS} lights a pass) on top of the budget's lights in passes of "
        f"{PASS_LIGHTS}, against those alone: absolute differences in 8-bit steps over the "
        "whole image and over the pedestrian's box. *Clamp*: the frame as drawn (one "
        "render) against its own lights summed from those passes, mean absolute "
        "difference over the image, and over the street's grid surfaces where "
        "lamps.py's photometry keeps every corner of a pixel's quad below the full scale "
        f"(the ground illuminance's maximum within {CORNER_REACH:g} m) and where it does "
        "not; *share*: the image's pixels of the latter; *brightest*: the most the one "
        "render draws above the sum (the clamp only takes light away).",
        "",
    ]
    lines += _table(
        ["before impact (m)", "lamps in view", "lamps lit", "left out: image mean",
         "image p99", "pedestrian mean", "pedestrian p99", "clamp: image", "below full scale",
         "a corner above", "share", "brightest"],
        [[f"{b.before_impact:g}", str(b.seen), str(b.shining), _f(b.mean, 2), _f(b.p99),
          _f(b.box_mean, 2), _f(b.box_p99), _f(b.clamp_mean, 2), _f(b.clamp_below, 2),
          _f(b.clamp_above, 2), f"{100 * b.above_share:.0f} %", _f(b.brighter, 0)]
         for b in budget],
    )  # fmt: skip
    worst = max(budget, key=lambda b: -1.0 if math.isnan(b.box_mean) else b.box_mean)
    lines += [
        "",
        f"The most the budget leaves out on the pedestrian: a mean of {_f(worst.box_mean, 2)} "
        f"steps over its box ({_f(worst.box_p99)} at the 99th percentile) with the car "
        f"{worst.before_impact:g} m before the impact point, where {worst.seen} lamps are in "
        f"view and {worst.shining} lit. The clamp: below the full scale the one render and "
        f"the passes agree to {_span([b.clamp_below for b in budget], 2)} steps (the "
        "passes' rounding); where a corner takes more, the clamp lets them differ only "
        "where lights of more than one pass meet (a pass whose lights alone saturate a "
        "vertex clamps it as the one render does), and the one render never draws more than "
        f"{_f(max(b.brighter for b in budget), 0)} (8-bit steps) above the sum.",
    ]
    return "\n".join(lines) + "\n"


def measure(progress: Callable[[str], None] = print) -> str:
    """Every measurement and the document."""
    boards, vertex = [], []
    for source in SOURCES:
        for distance in DISTANCES:
            progress(f"board: {source.name} at {distance:g} m")
            row = measure_board(distance, source)
            boards.append(row)
            if source.beam is not None or source.lamp:
                vertex.append(measure_one_box(distance, source, row))
    roads = []
    for light in (LAMP, BEAM):
        for build, grid in ROAD_BUILDS:
            progress(f"road: {light}, {build}")
            roads.append(measure_road(light, build, grid))
    progress("the clamp")
    clamp = measure_clamp()
    budget = []
    scene, street, pedestrian = ncap_scene()
    materials = street_materials(scene.model)
    with SceneRenderer(scene) as renderer:
        for before in CAR_BEFORE_IMPACT:
            progress(f"budget: {before:g} m before the impact point")
            budget.append(measure_budget(scene, street, pedestrian, renderer, before))
    return render_markdown(boards, vertex, roads, clamp, materials, budget, COMMAND)


COMMAND = "python -m tools.night_calibration --out docs/night"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=OUT, help="folder to write calibration.md in")
    args = ap.parse_args()
    text = measure()
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "calibration.md"
    with atomic_path(path) as tmp:
        tmp.write_text(text)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
