"""The static street: road with markings, pavements, grass, buildings.

The road runs along world x (east), centred on y = `center_y`. Every walkable surface
has its top at z = 0 so that the ground plane of monopic's camera model is exact; paint
sits a few millimetres above the asphalt (as real paint does) so it never z-fights.
Surfaces are thin boxes with procedural textures (asphalt grain, paving slabs, grass),
markings are thin white boxes, all added to an MjSpec in code.

At night the flat surfaces are planes drawn as grids of `lit_grid`-metre quads instead:
MuJoCo's classic renderer lights per vertex, so a box face (one quad) is lit only at its
corners, and a 400 m road took no light from a lamp 5 m above it nor from the low beams
(tools/night_calibration.py). By day the sun, a directional light, lights a box face
evenly, so the boxes stay (a plane's grid cost software GL 16 ms of a 46 ms frame). The
facades stay boxes at night: they take the lamps' light at their corners only.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sim.geometry.frames import yaw_quat
from sim.scenario.spec import RGB, RoadLayout

KERB_WIDTH = 0.15  # m
PAINT_HEIGHT = 0.004  # m, top of the road markings above the asphalt
SLAB_DEPTH = 0.1  # m, thickness of the road and pavement boxes below z = 0
GROUND_DEPTH = 0.1  # m, thickness of the grass box whose top is 1 cm below the road
GRASS_REPEAT = 0.2  # grass texture repeats per m: one period is 2 / 0.2 = 10 m
GRASS_UNDER = 0.25  # m the grass reaches under the pavements' outer edges (no crack between)
# Geom group of the surfaces flat on the ground (road, kerbs, pavements, paint, grass).
# Drawn like group 0, but the renderer leaves them out of the sun's shadow map: a slab
# whose top is the ground casts no shadow anything could see (the 1 cm step from a
# pavement down to the grass at most), and on software GL drawing those large boxes into
# it cost 4-11 % of a frame's render (with _add_grass's change, 0.84 of the render time
# in all: `bench/render_ab.py`).
SURFACE_GROUP = 2
GRASS_GRID_X = 5.0  # the grass's grid at night, in the street's grid: seen far off, if at all


def _texture(spec: mujoco.MjSpec, name: str, **kw: object) -> None:
    spec.add_texture(name=name, type=mujoco.mjtTexture.mjTEXTURE_2D, width=512, height=512, **kw)


def add_material(
    spec: mujoco.MjSpec,
    name: str,
    rgba: tuple[float, float, float, float],
    texture: str | None = None,
    texrepeat: tuple[float, float] = (1.0, 1.0),
    specular: float = 0.05,
    shininess: float = 0.05,
) -> str:
    mat = spec.add_material(name=name)
    mat.rgba = list(rgba)
    mat.specular = specular
    mat.shininess = shininess
    mat.reflectance = 0.0
    if texture is not None:
        textures = [""] * int(mujoco.mjtTextureRole.mjNTEXROLE)
        textures[int(mujoco.mjtTextureRole.mjTEXROLE_RGB)] = texture
        mat.textures = textures
        mat.texuniform = True
        mat.texrepeat = list(texrepeat)
    return name


def add_box(
    spec: mujoco.MjSpec,
    name: str,
    centre: tuple[float, float, float],
    half: tuple[float, float, float],
    material: str,
    yaw: float = 0.0,
    group: int = 0,
) -> None:
    spec.worldbody.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=list(centre),
        size=list(half),
        quat=yaw_quat(yaw).tolist(),
        material=material,
        contype=0,
        conaffinity=0,
        group=group,
    )


def _surface(
    spec: mujoco.MjSpec,
    name: str,
    centre: tuple[float, float, float],
    half: tuple[float, float, float],
    material: str,
    grid: float | None = None,
) -> None:
    """A box lying flat on the ground (slab, paint, grass): drawn, but casts no shadow.
    With `grid` (m), a plane at the box's top drawn as a grid of that spacing instead."""
    if grid is None:
        add_box(spec, name, centre, half, material, group=SURFACE_GROUP)
        return
    spec.worldbody.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        pos=[centre[0], centre[1], centre[2] + half[2]],
        size=[half[0], half[1], grid],
        material=material,
        contype=0,
        conaffinity=0,
        group=SURFACE_GROUP,
    )


def _grid_centre(inner: float, outer: float, origin: float, period: float) -> float:
    """Centre of a piece that starts at `inner`, reaches at least `outer`, and sits a whole
    number of texture periods from `origin` (`inner` lies between `origin` and `outer`)."""
    mid = (inner + outer) / 2
    periods = math.ceil(abs(mid - origin) / period)
    return origin + math.copysign(periods * period, outer - inner)


def build_street(spec: mujoco.MjSpec, road: RoadLayout, lit_grid: float | None = None) -> None:
    """Add ground, road, markings, pavements and buildings to `spec` (parked cars are
    entities of their own: sim.world.entities.parked_car). `lit_grid` (m): the flat
    surfaces as planes of that grid, for lights that are not the sun (module docstring)."""
    _texture(
        spec,
        "asphalt",
        builtin=mujoco.mjtBuiltin.mjBUILTIN_FLAT,
        mark=mujoco.mjtMark.mjMARK_RANDOM,
        random=0.25,
        rgb1=[0.25, 0.25, 0.26],
        markrgb=[0.36, 0.36, 0.36],
    )
    _texture(
        spec,
        "slabs",
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        mark=mujoco.mjtMark.mjMARK_EDGE,
        rgb1=[0.66, 0.64, 0.6],
        rgb2=[0.6, 0.58, 0.55],
        markrgb=[0.45, 0.44, 0.42],
    )
    _texture(
        spec,
        "grass",
        builtin=mujoco.mjtBuiltin.mjBUILTIN_FLAT,
        mark=mujoco.mjtMark.mjMARK_RANDOM,
        random=0.4,
        rgb1=[0.27, 0.42, 0.2],
        markrgb=[0.35, 0.5, 0.25],
    )
    asphalt = add_material(spec, "asphalt", (1, 1, 1, 1), "asphalt", (0.5, 0.5))
    slabs = add_material(spec, "slabs", (1, 1, 1, 1), "slabs", (0.5, 0.5))
    grass = add_material(spec, "grass", (1, 1, 1, 1), "grass", (GRASS_REPEAT, GRASS_REPEAT))
    paint = add_material(spec, "paint", (0.92, 0.92, 0.9, 1), specular=0.1)
    kerb = add_material(spec, "kerb", (0.72, 0.71, 0.68, 1))

    _add_grass(spec, road, grass, None if lit_grid is None else GRASS_GRID_X * lit_grid)
    half_len = road.length / 2
    y_right, y_left = road.edges
    _surface(
        spec,
        "road",
        (0, road.center_y, -SLAB_DEPTH / 2),
        (half_len, road.half_width, SLAB_DEPTH / 2),
        asphalt,
        lit_grid,
    )
    for name, sign, edge in (("south", -1.0, y_right), ("north", 1.0, y_left)):
        _surface(
            spec,
            f"kerb_{name}",
            (0, edge + sign * KERB_WIDTH / 2, -SLAB_DEPTH / 2),
            (half_len, KERB_WIDTH / 2, SLAB_DEPTH / 2),
            kerb,
            lit_grid,
        )
        pav_centre = edge + sign * (KERB_WIDTH + road.pavement_width / 2)
        _surface(
            spec,
            f"pavement_{name}",
            (0, pav_centre, -SLAB_DEPTH / 2),
            (half_len, road.pavement_width / 2, SLAB_DEPTH / 2),
            slabs,
            lit_grid,
        )

    paint_half_h = PAINT_HEIGHT / 2
    lw = road.line_width / 2
    # Solid edge lines.
    for name, y in (("south", y_right + 0.25), ("north", y_left - 0.25)):
        _surface(
            spec,
            f"edge_line_{name}",
            (0, y, paint_half_h),
            (half_len, lw, paint_half_h),
            paint,
            lit_grid,
        )
    # Dashed separators between lanes, with a gap across the zebra crossing.
    period = road.dash_length + road.dash_gap
    starts = np.arange(-half_len, half_len - road.dash_length, period)
    for lane in range(1, road.lanes):
        y = y_right + lane * road.lane_width
        for k, x0 in enumerate(starts):
            xc = x0 + road.dash_length / 2
            if road.crosswalk_x is not None and abs(xc - road.crosswalk_x) < (
                road.crosswalk_length / 2 + road.dash_length
            ):
                continue
            _surface(
                spec,
                f"dash_{lane}_{k}",
                (xc, y, paint_half_h),
                (road.dash_length / 2, lw, paint_half_h),
                paint,
            )
    # Zebra crossing: bars parallel to the traffic, spaced across the road.
    if road.crosswalk_x is not None:
        n_bars = int((2 * road.half_width - 0.5) // (2 * road.stripe_width))
        span = n_bars * 2 * road.stripe_width - road.stripe_width
        y0 = road.center_y - span / 2 + road.stripe_width / 2
        for k in range(n_bars):
            _surface(
                spec,
                f"zebra_{k}",
                (road.crosswalk_x, y0 + 2 * k * road.stripe_width, paint_half_h),
                (road.crosswalk_length / 2, road.stripe_width / 2, paint_half_h),
                paint,
            )

    if road.buildings:
        _add_buildings(spec, road)


def _add_grass(
    spec: mujoco.MjSpec, road: RoadLayout, grass: str, grid: float | None = None
) -> None:
    """Grass everywhere off the street, 1 cm below it, out to 1.5 road lengths each way.

    Four boxes around the street rather than one under everything: software GL shaded
    the grass under every road and pavement pixel again in each pass (12 % of a frame's
    render: `bench/render_ab.py`). Each piece's centre sits a whole number of texture
    periods from the street's centre line, so the grass looks exactly as one box's did.
    A box, not a plane: MuJoCo draws a plane as a dense grid of quads, which cost
    software GL 16 ms of a 46 ms frame for the same image (`bench/simulator.py`).
    """
    extent = road.length * 1.5
    period = 2.0 / GRASS_REPEAT
    z, half_z = -0.01 - GROUND_DEPTH / 2, GROUND_DEPTH / 2
    y_right, y_left = road.edges
    reach = KERB_WIDTH + road.pavement_width - GRASS_UNDER  # from a road edge to the grass
    cy = road.center_y
    for name, inner, outer in (
        ("ground_south", y_right - reach, cy - extent),
        ("ground_north", y_left + reach, cy + extent),
    ):
        yc = _grid_centre(inner, outer, cy, period)
        _surface(spec, name, (0.0, yc, z), (extent, abs(yc - inner), half_z), grass, grid)
    half_street = max(y_left + reach - cy, cy - (y_right - reach)) + GRASS_UNDER
    for name, inner, outer in (
        ("ground_west", -road.length / 2 + GRASS_UNDER, -extent),
        ("ground_east", road.length / 2 - GRASS_UNDER, extent),
    ):
        xc = _grid_centre(inner, outer, 0.0, period)
        _surface(spec, name, (xc, cy, z), (abs(xc - inner), half_street, half_z), grass, grid)


def _facade_texture(spec: mujoco.MjSpec, name: str, wall: RGB) -> None:
    """One window bay (2.5 m wide, 3 m high) of a facade; the material tiles it."""
    size = 128
    img = np.empty((size, size, 3), dtype=np.uint8)
    img[:] = np.round(np.array(wall) * 255).astype(np.uint8)
    glass = np.array([58, 68, 88], dtype=np.uint8)
    frame = np.round(np.array(wall) * 255 * 0.8).astype(np.uint8)
    img[22:86, 30:98] = frame
    img[26:82, 34:94] = glass
    img[52:56, 34:94] = frame  # transom
    tex = spec.add_texture(
        name=name, type=mujoco.mjtTexture.mjTEXTURE_2D, width=size, height=size, nchannel=3
    )
    tex.data = img.tobytes()


def _add_buildings(spec: mujoco.MjSpec, road: RoadLayout) -> None:
    """Facades along both pavements: one textured box per building, deterministic sizes."""
    colours: list[RGB] = [
        (0.76, 0.7, 0.6),
        (0.62, 0.45, 0.38),
        (0.82, 0.8, 0.74),
        (0.55, 0.57, 0.6),
        (0.7, 0.6, 0.45),
    ]
    mats = []
    for i, c in enumerate(colours):
        _facade_texture(spec, f"facade_{i}", c)
        mats.append(add_material(spec, f"facade_{i}", (1, 1, 1, 1), f"facade_{i}", (0.4, 1 / 3)))
    y_right, y_left = road.edges
    setback = KERB_WIDTH + road.pavement_width + 1.0
    half_len = road.length / 2
    for side, sign, edge in (("south", -1.0, y_right), ("north", 1.0, y_left)):
        x = -half_len
        k = 0
        while x < half_len:
            width = 10.0 + 5.0 * ((k * 7 + (3 if sign > 0 else 0)) % 4)
            height = 6.0 + 3.0 * ((k * 5 + (1 if sign > 0 else 2)) % 5)
            depth = 8.0
            add_box(
                spec,
                f"building_{side}_{k}",
                (x + width / 2, edge + sign * (setback + depth / 2), height / 2),
                (width / 2 - 0.3, depth / 2, height / 2),
                mats[(k + (2 if sign > 0 else 0)) % len(mats)],
            )
            x += width
            k += 1
