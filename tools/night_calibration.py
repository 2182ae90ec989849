"""How the night's render compares with its photometry: docs/night/calibration.md.

    python -m tools.night_calibration [--out DIR]

Three measurements, all through the real renderer (headless, MUJOCO_GL=egl) with the
car-scale camera (sim.scenario.families CAR) under the `night` lighting preset:

1. A matte grey board (reflectance 0.5, 1 m x 1 m, facing the car, standing on the road)
   straight ahead at 5, 10, 20 and 40 m from the car's front, lit by the 1 lux ambient
   alone, by the low beam (sim.scenario.lamps LOW_BEAM at the front centre, 0.65 m high)
   and by one street lamp beside it. Each pixel of the board gets the illuminance
   lamps.py's formulas predict (I/d^2 times the cosine of incidence) and the value the
   renderer draws; the table compares them, says what the render stands for in lux and
   what the imx273 camera model makes of it at its auto-exposure's settled settings.
   MuJoCo's classic renderer lights per vertex (Gouraud shading), so the board is built
   of 5 cm tiles, each with its own corners, to measure the photometry; a second table
   shows the same board as one box, the way every other geom of the scene is built, and
   the road under a street lamp at the scenes' tessellation and at a fine one.
2. The low beam against UN R112's test points (sim.scenario.lamps.regulation_table).
3. The light budget: MuJoCo lights at most 8 lights; StreetLamps (sim.world.entities
   .street_lamps) lights the lamps that matter each frame. Along a night road with the
   Euro NCAP lamp layout, the budget's image is compared with the exact one, the scene
   drawn in passes of at most 7 lights with the ambient in one of them and summed (the
   renderer is linear below white).

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
from sim.scenario.lamps import LOW_BEAM, Headlamps, StreetLamp, regulation_table
from sim.scenario.lighting import NIGHT_AMBIENT_LUX, NIGHT_FULL_SCALE_LUX, PRESETS
from sim.scenario.spec import MannequinSpec, SceneSpec
from sim.sensor.readout import linear_light, srgb_decode
from sim.sensor.sensor import Sensor
from sim.sensor.spec import IMX273
from sim.world.entities.base import Entity, Moment
from sim.world.entities.pedestrian import PedestrianBody
from sim.world.entities.robot import RobotBody
from sim.world.entities.street_lamps import MAX_LIGHTS, StreetLamps
from sim.world.lighting import lights
from sim.world.render import SceneRenderer
from sim.world.scene import Scene, SceneConfig

OUT = Path("docs/night")
NIGHT = PRESETS["night"]
REFLECTANCE = 0.5  # the board's grey
BOARD_SIZE = 1.0  # m, square
BOARD_TILES = 20  # tiles a side: per-vertex lighting sampled every 5 cm
DISTANCES = (5.0, 10.0, 20.0, 40.0)  # m from the car's front (the headlamps) to the board
FRONT = CAR.robot.length / 2  # the headlamps, ahead of the car's reference point
# The street lamp beside the board: 2 m nearer the car and 2 m to its right, so that its
# light meets the board's face at a known slant (the same for every distance).
LAMP_BEFORE, LAMP_RIGHT = 2.0, 2.0
FINE_QUADS = 50  # quads a box face is drawn with to sample per-vertex lighting finely
ERODE_PX = 2  # the board's interior: its mask less this many pixels at the edges
SENSOR_FPS = 15.0  # the car's camera rate (sim.scenario.presets FPS)
# The Euro NCAP night roads' lamps, in x from the impact point and y (m).
NCAP_LAMPS = (
    *((dx, -6.1) for dx in (-62.5, -37.5, -12.5, 12.5, 37.5)),
    (-12.5, 8.1),
    (12.5, 8.1),
)
IMPACT_X = 0.0
CAR_BEFORE_IMPACT = (60.0, 45.0, 30.0, 20.0, 10.0)  # m from the car's front to the impact
PEDESTRIAN = (IMPACT_X, -3.0)  # at the nearside of the road, about to cross


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


def board_scene(
    distance: float, source: Source, tiles: int = BOARD_TILES, box_quads: int = 1
) -> tuple[Scene, Board]:
    """The still night scene: the car at the origin heading east, the board `distance`
    metres ahead of its front, lit by `source`."""
    cam = car_camera()
    face_x = FRONT + distance
    lamps = (lamp_beside(face_x, source.lamp_on),) if source.lamp else ()
    board = Board(face_x, tiles)
    entities = [*lights(NIGHT, lamps, cam, source.beam, FRONT), RobotBody(cam), board]
    spec = SceneSpec(lighting=NIGHT, road=CAR.road, lamps=lamps)
    return Scene(SceneConfig(camera=cam, spec=spec, box_quads=box_quads), entities), board


def pixel_rays(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The camera's centre and a ray (world frame) through every pixel's centre."""
    cam, data, cid = scene.camera, scene.data, scene.robot.camera_id
    u, v = np.meshgrid(np.arange(cam.width) + 0.5, np.arange(cam.height) + 0.5)
    local = np.stack([(u - cam.cx) / cam.fx, -(v - cam.cy) / cam.fy, -np.ones_like(u)], -1)
    return data.cam_xpos[cid].copy(), local @ data.cam_xmat[cid].reshape(3, 3).T


def predicted_lux(scene: Scene, face_x: float, source: Source) -> np.ndarray:
    """The illuminance on the board's plane seen through every pixel (lux), from lamps.py's
    photometry: the ambient, plus I/d^2 times the cosine of incidence of the source."""
    origin, rays = pixel_rays(scene)
    t = (face_x - origin[0]) / rays[..., 0]
    points = origin + t[..., None] * rays
    lux = np.full(points.shape[:2], NIGHT_AMBIENT_LUX)
    normal = np.array([-1.0, 0.0, 0.0])
    if source.beam is not None:
        lamp = np.array([FRONT, 0.0, source.beam.height])
        d = points - lamp
        r = np.linalg.norm(d, axis=-1)
        down = np.degrees(np.arctan2(-d[..., 2], np.hypot(d[..., 0], d[..., 1])))
        right = np.degrees(np.arctan2(-d[..., 1], d[..., 0]))
        intensity = np.vectorize(source.beam.intensity)(down, right)
        lux += intensity * np.maximum(-(d @ normal), 0.0) / r**3
    if source.lamp and source.lamp_on:
        street = lamp_beside(face_x)
        d = points - np.array([street.x, street.y, street.height])
        r = np.linalg.norm(d, axis=-1)
        inside = -d[..., 2] / r >= math.cos(math.radians(street.cutoff_deg))
        lux += np.where(inside, street.intensity_cd * np.maximum(-(d @ normal), 0.0) / r**3, 0)
    return lux


def interior(mask: np.ndarray) -> np.ndarray:
    kernel = np.ones((2 * ERODE_PX + 1, 2 * ERODE_PX + 1), np.uint8)
    return cv2.erode(mask.astype(np.uint8), kernel).astype(bool)


def steps(lux: np.ndarray | float) -> np.ndarray | float:
    """The 8-bit value the photometric render should draw on the board under `lux`."""
    return np.clip(REFLECTANCE * np.asarray(lux) / NIGHT_FULL_SCALE_LUX, 0.0, 1.0) * 255.0


@dataclass(frozen=True)
class CameraRead:
    """What the imx273 model made of a frame: its settings and the board's pixels."""

    exposure_ms: float
    gain: float
    mean: float  # the board's sRGB 8-bit mean (red channel)
    noise: float  # std of the noisy frame less the noiseless one on the board


def imx273_read(image: np.ndarray, board: np.ndarray, seed: int = 0) -> CameraRead:
    """The frame through the imx273 model, its auto-exposure settled on it."""
    light = linear_light(image)
    dt = 1.0 / SENSOR_FPS
    noisy = Sensor(IMX273, NIGHT.illuminance_lux, dt, seed)
    noisy.meter(light)
    state = noisy.settings()
    quiet = Sensor(replace(IMX273, exposure_ms=1000 * state.exposure_s, gain=state.gain,
                           noise=False), NIGHT.illuminance_lux, dt, seed)  # fmt: skip
    frame, _ = noisy.read(light, state)
    clean, _ = quiet.read(light, quiet.settings())
    red, red_clean = frame[..., 0][board].astype(float), clean[..., 0][board].astype(float)
    return CameraRead(
        1000 * state.exposure_s, state.gain, float(red.mean()), float(np.std(red - red_clean))
    )


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
    sensor_lux: float  # what the sensor model's linear light stands for (sRGB-decoded)
    camera: CameraRead

    @property
    def rendered_lux(self) -> float:
        return self.rendered / 255.0 / REFLECTANCE * NIGHT_FULL_SCALE_LUX


def measure_board(distance: float, source: Source) -> BoardRow:
    scene, board = board_scene(distance, source)
    with SceneRenderer(scene) as renderer:
        image = renderer.render()
        inside = interior(renderer.mask(scene.geoms_of(board)))
    lux = predicted_lux(scene, board.x, source)[inside]
    want = steps(lux)
    red = image[..., 0][inside].astype(float)
    decoded = srgb_decode(red / 255.0)
    return BoardRow(
        source=source.name,
        distance=distance,
        pixels=int(inside.sum()),
        predicted_lux=float(lux.mean()),
        predicted=float(np.mean(want)),
        rendered=float(red.mean()),
        error=float(np.mean(np.abs(red - want))),
        clipped=float(np.mean(red >= 255)),
        sensor_lux=float(decoded.mean() / REFLECTANCE * NIGHT_FULL_SCALE_LUX),
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


@dataclass(frozen=True)
class RoadRow:
    """The road around a street lamp's foot, drawn with the scenes' box tessellation and a
    fine one."""

    quads: int
    rendered: float  # 8-bit mean, red channel, road pixels within ROAD_RADIUS of the foot
    dark: float  # the same pixels with the lamp off


ROAD_DISTANCE = 15.0  # m from the car's front to the lamp's foot
ROAD_RADIUS = 3.0  # m around the foot


def measure_road(quads: int) -> RoadRow:
    cam = car_camera()
    values = []
    for on in (True, False):
        lamp = StreetLamp(FRONT + ROAD_DISTANCE, -2.0, on=on)
        entities = [*lights(NIGHT, (lamp,), cam), RobotBody(cam)]
        spec = SceneSpec(lighting=NIGHT, road=CAR.road, lamps=(lamp,))
        scene = Scene(SceneConfig(camera=cam, spec=spec, box_quads=quads), entities)
        with SceneRenderer(scene) as renderer:
            image = renderer.render()
        origin, rays = pixel_rays(scene)
        down = rays[..., 2] < -1e-6
        t = np.where(down, -origin[2] / np.where(down, rays[..., 2], -1.0), np.inf)
        ground = origin + t[..., None] * rays
        near = down & (np.hypot(ground[..., 0] - lamp.x, ground[..., 1] - lamp.y) < ROAD_RADIUS)
        values.append(float(image[..., 0][near].mean()))
    return RoadRow(quads, values[0], values[1])


# -- the light budget -------------------------------------------------------------------


def ncap_lamps() -> tuple[StreetLamp, ...]:
    return tuple(StreetLamp(IMPACT_X + dx, y) for dx, y in NCAP_LAMPS)


def ncap_scene(box_quads: int = 1) -> tuple[Scene, StreetLamps, PedestrianBody]:
    """A night road with the Euro NCAP lamp layout, the car's low beam and a pedestrian."""
    cam = car_camera()
    lamps = ncap_lamps()
    pedestrian = PedestrianBody(MannequinSpec())
    entities = [*lights(NIGHT, lamps, cam, LOW_BEAM, FRONT), RobotBody(cam), pedestrian]
    spec = SceneSpec(lighting=NIGHT, road=CAR.road, lamps=lamps)
    scene = Scene(SceneConfig(camera=cam, spec=spec, box_quads=box_quads), entities)
    (street,) = [e for e in entities if isinstance(e, StreetLamps)]
    return scene, street, pedestrian


def active_lights(model: mujoco.MjModel) -> int:
    """The lights the renderer is asked for: the active scene lights and its headlight
    (whose `active` flag is any non-zero value: MuJoCo's default is 2)."""
    return int(np.sum(model.light_active)) + (1 if model.vis.headlight.active else 0)


def exact_render(
    scene: Scene, renderer: SceneRenderer, only_active: bool = False, per_pass: int = MAX_LIGHTS - 1
) -> np.ndarray:
    """The image with every light: passes of at most 7 scene lights beside the headlight,
    the ambient (the headlight's) in the first only, summed in 8-bit steps. Each pass also
    draws what glows by itself (the lamps' heads), so a pass with no scene light is taken
    off for every pass after the first. The headlight stays on with its ambient zeroed
    rather than off: with no light at all MuJoCo lights the scene by a default of its own
    (a probe: a mean of 29 steps over the night road). Float, unclipped.

    `only_active`: sum only the lights active now (to check the sum against one render);
    `per_pass`: at most this many scene lights a pass."""
    model = scene.model
    head = model.vis.headlight
    kept_active, kept_ambient = model.light_active.copy(), head.ambient.copy()
    every = [
        i
        for i in range(model.nlight)
        if model.light_active[i] or (_is_lamp(model, i) and not only_active)
    ]
    groups = [every[k : k + per_pass] for k in range(0, len(every), per_pass)] or [[]]
    try:
        total = np.zeros((renderer.height, renderer.width, 3))
        for k, group in enumerate(groups):
            model.light_active[:] = 0
            model.light_active[group] = 1
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


def _is_lamp(model: mujoco.MjModel, light: int) -> bool:
    return model.light(light).name.endswith("/light")


@dataclass(frozen=True)
class BudgetRow:
    before_impact: float
    quads: int  # SceneConfig.box_quads the scene was drawn with
    shining: int  # street lamps the budget lit
    seen: int  # street lamps with a score (some of their light in view)
    mean: float  # mean |budget - exact| over the image, 8-bit steps
    p99: float
    box_mean: float  # the same over the pedestrian's box (nan when out of view)
    box_p99: float
    floor: float  # mean |one render - the same lights summed in passes of 3|: the method's


def _stats(diff: np.ndarray, box: tuple[slice, slice] | None) -> tuple[float, ...]:
    inside = diff[box] if box is not None else np.array([np.nan])
    return (float(diff.mean()), float(np.percentile(diff, 99)), float(np.mean(inside)),
            float(np.percentile(inside, 99)))  # fmt: skip


def measure_budget(
    scene: Scene, street: StreetLamps, pedestrian: PedestrianBody, renderer: SceneRenderer,
    before_impact: float,
) -> BudgetRow:  # fmt: skip
    scene.set_camera_pose(IMPACT_X - before_impact - FRONT, 0.0, 0.0)
    pedestrian.pose_at(scene.model, scene.data, *PEDESTRIAN, math.pi / 2)
    scene.update()
    budget = renderer.render().astype(float)
    exact = np.minimum(exact_render(scene, renderer), 255.0)
    split = np.minimum(exact_render(scene, renderer, only_active=True, per_pass=3), 255.0)
    mask = renderer.mask(scene.geoms_of(pedestrian))
    box = None
    if mask.any():
        rows, cols = np.flatnonzero(mask.any(1)), np.flatnonzero(mask.any(0))
        box = (slice(rows[0], rows[-1] + 1), slice(cols[0], cols[-1] + 1))
    seen = int(np.sum(street.score(_moment(scene)) > 0))
    return BudgetRow(before_impact, scene.config.box_quads, len(street.shining), seen,
                     *_stats(np.abs(budget - exact), box),
                     float(np.abs(budget - split).mean()))  # fmt: skip


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


def render_markdown(
    boards: Sequence[BoardRow],
    vertex: Sequence[VertexRow],
    roads: Sequence[RoadRow],
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
        f"stands for {NIGHT_FULL_SCALE_LUX:g} lux, the ambient {NIGHT_AMBIENT_LUX:g} lux).",
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
        "the 8-bit value that is (0.5 x lux / 50 x 255, clipped at white); *drawn* the "
        "render's mean (red channel: the lamps' colours are 1 there); *|err|* the mean "
        "per-pixel difference in 8-bit steps; *clip* the share of pixels at 255; "
        "*stands for* what the drawn value means (value / 0.5 x 50 lux); *sensor reads* "
        "what the camera model's input stands for (it decodes the render as sRGB: "
        "sim.sensor.readout.linear_light); then the imx273 model, its auto-exposure "
        "settled on the whole frame (Sensor.meter), its sRGB 8-bit mean on the board and "
        "the noise's std (the noisy frame less the noiseless one at the same settings).",
        "",
    ]
    head = ["light", "d (m)", "px", "lux", "asks", "drawn", "|err|", "clip", "stands for (lux)",
            "sensor reads (lux)", "imx273 ms / gain", "imx273 mean", "noise std"]  # fmt: skip
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
            _f(b.sensor_lux, 2),
            f"{b.camera.exposure_ms:.0f} / {b.camera.gain:.1f}",
            _f(b.camera.mean),
            _f(b.camera.noise),
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
        f"The road within {ROAD_RADIUS:g} m of a street lamp's foot, {ROAD_DISTANCE:g} m "
        "ahead of the car and 2 m right of its centre line, the lamp on and off "
        "(8-bit mean, red channel), with box faces drawn as the scenes draw them "
        "(SceneConfig.box_quads) and finely:",
        "",
    ]
    lines += _table(
        ["box quads", "lamp on", "lamp off", "the lamp adds"],
        [[str(r.quads), _f(r.rendered), _f(r.dark), _f(r.rendered - r.dark)] for r in roads],
    )
    lines += [
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
        "included; the budget image lights the lamps StreetLamps chose, the exact image "
        "is the sum of passes. Absolute differences in 8-bit steps, over the whole image "
        "and over the pedestrian's box. *Box quads*: the scenes draw each box face as one "
        f"quad (SceneConfig.box_quads = 1), so the road is lit at its far corners only "
        f"(section 1b); at {FINE_QUADS} the road takes the lamps' light and the budget's "
        "cost shows. *Method's floor*: the budget's own lights drawn in one render and "
        "summed from passes of 3, the error the summing alone makes.",
        "",
    ]
    lines += _table(
        ["box quads", "before impact (m)", "lamps in view", "lamps lit", "image mean",
         "image p99", "pedestrian mean", "pedestrian p99", "method's floor"],
        [[str(b.quads), f"{b.before_impact:g}", str(b.seen), str(b.shining), _f(b.mean, 2),
          _f(b.p99), _f(b.box_mean, 2), _f(b.box_p99), _f(b.floor, 2)] for b in budget],
    )  # fmt: skip
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
    progress("road under a lamp")
    roads = [measure_road(q) for q in (1, FINE_QUADS)]
    budget = []
    for quads in (1, FINE_QUADS):
        scene, street, pedestrian = ncap_scene(quads)
        with SceneRenderer(scene) as renderer:
            for before in CAR_BEFORE_IMPACT:
                progress(f"budget: {before:g} m before the impact point, box quads {quads}")
                budget.append(measure_budget(scene, street, pedestrian, renderer, before))
    return render_markdown(boards, vertex, roads, budget, COMMAND)


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
