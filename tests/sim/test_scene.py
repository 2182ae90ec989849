"""The MuJoCo scene: camera agrees with monopic's CameraModel, mannequin and gait behave."""

from __future__ import annotations

import csv
import math

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import sim.world.render
from monopic.camera import CameraModel
from sim.dataset.clip import ClipSpec, clip_scene, truth_header, truth_row, walk
from sim.geometry.frames import Pose2D
from sim.scenario.spec import MannequinSpec, Occluder, RoadLayout, SceneSpec
from sim.world.body import PedestrianTruth
from sim.world.gait import JOINT_FIELDS, Gait, idle_pose, pose_vector
from sim.world.mannequin import geom_z_extent
from sim.world.render import GLUnavailableError, Marker, SceneRenderer
from sim.world.scene import Scene, SceneConfig
from sim.world.street import GRASS_REPEAT, GRASS_UNDER, build_street
from tests.paths import DATA

SMALL = CameraModel.from_fov(320, 180, vertical_fov_deg=65.0, mount_height=1.2, pitch_deg=5.0)
# A pose that is not the identity, so a mix-up of world and robot frames shows.
ROBOT = Pose2D(3.0, -2.0, 0.7)


def stand(scene: Scene, *args: object, **kw: object) -> None:
    """Stand the still scene's person (PedestrianBody.pose_at) and update the scene."""
    scene.pedestrians[0].pose_at(scene.model, scene.data, *args, **kw)  # type: ignore[arg-type]
    scene.update()


def seen(scene: Scene) -> PedestrianTruth:
    """The still scene's person as the camera sees them."""
    return scene.pedestrians[0].seen(scene.data, scene.camera, scene.robot_pose)


def small_scene(camera: CameraModel = SMALL, **kw: object) -> Scene:
    """A light scene (no buildings) with the pedestrian placed behind the camera."""
    spec = SceneSpec(road=RoadLayout(buildings=False), **kw)  # type: ignore[arg-type]
    config = SceneConfig(camera=camera, spec=spec)
    scene = Scene(config)
    scene.set_camera_pose(ROBOT.x, ROBOT.y, ROBOT.yaw)
    behind = ROBOT.to_world(np.array([-10.0, 0.0, 0.0]))
    stand(scene, behind[0], behind[1], 0.0)
    return scene


def marker_centroid(image: np.ndarray) -> np.ndarray:
    """Pixel centroid (u, v) of the pure-red marker, pixel centres at +0.5."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    mask = (r > 200) & (g < 60) & (b < 60)
    assert mask.sum() >= 12, "marker not visible"
    vs, us = np.nonzero(mask)
    return np.array([us.mean() + 0.5, vs.mean() + 0.5])


FORWARD_MOUNT = CameraModel.from_fov(
    320, 240, vertical_fov_deg=50.0, mount_height=0.8, pitch_deg=-3.0, mount_forward=0.4
)


@pytest.mark.parametrize(
    "camera",
    [SMALL, SceneConfig().camera, FORWARD_MOUNT],
    ids=["320x180", "768x432", "forward-mount-pitched-up"],
)
def test_marker_lands_on_camera_model_projection(camera: CameraModel) -> None:
    scene = small_scene(camera)
    points_robot = np.array([[4.0, 0.0, 0.5], [5.0, 1.8, 1.6], [3.5, -1.5, 0.15], [9.0, 2.5, 1.2]])
    with SceneRenderer(scene) as renderer:
        for p in points_robot:
            world = ROBOT.to_world(p)
            radius = 0.04 * p[0] * 180 / camera.height  # about 11 px across at any size
            image = renderer.render((Marker(tuple(world), radius=radius),))
            expected = camera.project(p)
            assert np.all((expected > 10) & (expected < [camera.width - 10, camera.height - 10]))
            found = marker_centroid(image)
            assert np.linalg.norm(found - expected) < 1.0, (p, found, expected)
            # The scene's own projection helper goes through the same model.
            assert np.allclose(scene.project(world), expected)


def test_right_in_the_world_is_right_in_the_image() -> None:
    scene = small_scene()
    with SceneRenderer(scene) as renderer:
        left = ROBOT.to_world(np.array([5.0, 1.0, 1.0]))  # robot frame: y is left
        right = ROBOT.to_world(np.array([5.0, -1.0, 1.0]))
        u_left = marker_centroid(renderer.render((Marker(tuple(left), radius=0.08),)))[0]
        u_right = marker_centroid(renderer.render((Marker(tuple(right), radius=0.08),)))[0]
    assert u_right > u_left + 20


def test_person_facing_the_camera_shows_their_left_on_the_image_right() -> None:
    scene = small_scene()
    ahead = ROBOT.to_world(np.array([4.0, 0.0, 0.0]))
    stand(scene, ahead[0], ahead[1], ROBOT.yaw + math.pi)  # facing the robot
    px = seen(scene).landmarks_px
    assert px[11, 0] > px[12, 0]  # left shoulder right of the right shoulder
    assert px[23, 0] > px[24, 0] and px[2, 0] > px[5, 0]
    stand(scene, ahead[0], ahead[1], ROBOT.yaw)  # back to the robot
    px = seen(scene).landmarks_px
    assert px[11, 0] < px[12, 0]


@pytest.mark.parametrize(
    "look, height", [(MannequinSpec.adult(), 1.8), (MannequinSpec.child(), 1.15)]
)
def test_mannequin_height_and_feet_on_the_ground(look: MannequinSpec, height: float) -> None:
    scene = Scene(SceneConfig(pedestrian=look, spec=SceneSpec(road=RoadLayout(buildings=False))))
    stand(scene, 1.0, 2.0, 0.3)  # idle stance
    truth = seen(scene)
    assert truth.top_z == pytest.approx(height, abs=0.01)
    shoes = scene.pedestrians[0].mannequin.shoe_geoms
    assert np.min(geom_z_extent(scene.model, scene.data, shoes)[0]) == pytest.approx(0.0, abs=1e-9)
    # Shoulders, hips and knees at human heights (fractions of stature).
    z = truth.landmarks_world[:, 2] / height
    assert 0.76 < z[11] < 0.84 and 0.48 < z[23] < 0.56 and 0.25 < z[25] < 0.31
    # While walking one foot always touches the ground.
    for phase in np.linspace(0, 1, 9):
        stand(scene, 1.0, 2.0, 0.3, gait_phase=phase, speed=1.2)
        low = np.min(geom_z_extent(scene.model, scene.data, shoes)[0])
        assert low == pytest.approx(0.0, abs=1e-9)


def test_gait_is_periodic_and_mirrored() -> None:
    gait = Gait()
    for phase in np.linspace(0, 1, 13):
        a = pose_vector(gait.pose(phase, 1.4))
        assert np.allclose(a, pose_vector(gait.pose(phase + 1.0, 1.4)))
        p, q = gait.pose(phase, 1.4), gait.pose(phase + 0.5, 1.4)
        for side in ("hip_flex", "knee", "ankle", "shoulder_flex", "elbow"):
            assert getattr(p, f"{side}_l") == pytest.approx(getattr(q, f"{side}_r"))
    assert gait.pose(0.3, 0.0) == idle_pose()
    assert len(JOINT_FIELDS) == 18


def test_cadence_follows_speed_and_size() -> None:
    adult, child = Gait(1.8), Gait(1.15)
    assert adult.cadence(1.4) == pytest.approx(1.8, abs=0.05)
    assert adult.cadence(0.8) < adult.cadence(1.4) < adult.cadence(2.0)
    assert adult.step_length(0.8) < adult.step_length(1.4) < adult.step_length(2.0)
    assert child.cadence(1.2) > adult.cadence(1.2)
    # One stride (two steps) per 1 / (cadence / 2) seconds brings the phase back.
    period = 2.0 / adult.cadence(1.4)
    assert adult.advance(0.25, 1.4, period) == pytest.approx(0.25)


def knee_angles(scene: Scene) -> np.ndarray:
    """Knee flexion (rad) of both legs from the hip, knee and ankle landmarks."""
    lm = seen(scene).landmarks_world
    out = []
    for hip, knee, ankle in ((23, 25, 27), (24, 26, 28)):
        thigh, shin = lm[knee] - lm[hip], lm[ankle] - lm[knee]
        cos = thigh @ shin / np.linalg.norm(thigh) / np.linalg.norm(shin)
        out.append(math.acos(np.clip(cos, -1, 1)))
    return np.array(out)


def test_knees_bend_when_walking_and_not_when_standing() -> None:
    scene = Scene(SceneConfig(spec=SceneSpec(road=RoadLayout(buildings=False))))
    flex = []
    for phase in np.linspace(0, 1, 20, endpoint=False):
        stand(scene, 0.0, 0.0, 0.0, gait_phase=phase, speed=1.4)
        flex.append(knee_angles(scene))
    flex_deg = np.degrees(np.array(flex))
    assert flex_deg.max() > 50 and flex_deg.min() < 10
    # The stance leg is straight while the swing knee bends: they alternate.
    assert np.corrcoef(flex_deg[:, 0], flex_deg[:, 1])[0, 1] < 0
    stand(scene, 0.0, 0.0, 0.0, speed=0.0)
    assert np.degrees(knee_angles(scene)).max() < 6


def test_foot_point_box_and_landmarks_agree() -> None:
    scene = small_scene()
    spot = ROBOT.to_world(np.array([4.0, 0.5, 0.0]))
    stand(scene, spot[0], spot[1], ROBOT.yaw + 2.0, gait_phase=0.3, speed=1.4)
    truth = seen(scene)
    u0, v0, u1, v1 = truth.box
    inside = truth.landmarks_px
    assert np.all((inside[:, 0] >= u0) & (inside[:, 0] <= u1))
    assert np.all((inside[:, 1] >= v0) & (inside[:, 1] <= v1))
    assert truth.in_frame and truth.box_height > 50
    assert truth.foot_world[2] == 0.0
    assert np.linalg.norm(truth.foot_world[:2] - spot[:2]) < 0.3
    assert np.allclose(SMALL.ground_point(truth.foot_px), truth.foot_robot[:2], atol=1e-6)


def test_mask_sees_the_pedestrian_and_an_occluder_hides_it() -> None:
    spot = np.array([6.0, 0.0, 0.0])
    car = ROBOT.to_world(np.array([4.0, 0.0, 0.0]))
    visible = []
    for occluders in ((), (Occluder.parked_car(car[0], car[1], ROBOT.yaw + math.pi / 2),)):
        scene = small_scene(occluders=occluders)
        world = ROBOT.to_world(spot)
        stand(scene, world[0], world[1], ROBOT.yaw + math.pi)
        with SceneRenderer(scene) as renderer:
            visible.append(int(renderer.mask(scene.geoms_of(scene.pedestrians[0])).sum()))
    assert visible[0] > 300
    assert visible[1] < 0.6 * visible[0]


def test_renders_are_deterministic() -> None:
    scene = small_scene()
    spot = ROBOT.to_world(np.array([4.0, 0.0, 0.0]))
    stand(scene, spot[0], spot[1], 1.0, gait_phase=0.4, speed=1.4)
    with SceneRenderer(scene) as renderer:
        a = renderer.render()
        b = renderer.render()
    assert a.shape == (180, 320, 3) and a.dtype == np.uint8
    assert np.array_equal(a, b)
    assert a.std() > 10  # not a blank frame


def test_missing_gl_gives_one_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_gl(width: int, height: int) -> None:
        raise ImportError("libEGL.so.1: cannot open shared object file")

    monkeypatch.setattr(sim.world.render, "_gl_context", no_gl)
    with pytest.raises(GLUnavailableError, match="libegl1 libgl1-mesa-dri libegl-mesa0"):
        SceneRenderer(small_scene())


def test_shipped_clip_truth_matches_the_scene() -> None:
    """tests/data/walk_clip_truth.csv is what sim.dataset.clip computes (no rendering needed)."""
    clip = ClipSpec()
    scene = clip_scene(clip)
    expected = [truth_row(k, t, seen(scene)) for k, t in walk(clip, scene)]
    with (DATA / "walk_clip_truth.csv").open() as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == truth_header()
    assert rows[1:] == expected
    heights = [(float(r[-1]) - float(r[-3])) / clip.height for r in rows[1:]]
    assert min(heights) >= 0.45 and max(heights) <= 0.7
    assert (DATA / "walk_clip.mp4").stat().st_size < 1.5e6


def _street_geoms(road: RoadLayout) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """name -> (centre, half size) of every box build_street adds, no GL needed."""
    spec = mujoco.MjSpec()
    build_street(spec, road)
    model = spec.compile()
    return {
        model.geom(g).name: (model.geom_pos[g].copy(), model.geom_size[g].copy())
        for g in range(model.ngeom)
    }


def _covered(
    boxes: list[tuple[np.ndarray, np.ndarray]], x: np.ndarray, y: np.ndarray
) -> np.ndarray:
    hit = np.zeros(x.shape, dtype=bool)
    for (cx, cy, _), (hx, hy, _) in boxes:
        hit |= (np.abs(x - cx) <= hx) & (np.abs(y - cy) <= hy)
    return hit


@settings(max_examples=25, deadline=None)
@given(
    center_y=st.floats(-20.0, 20.0),
    lanes=st.integers(1, 4),
    lane_width=st.floats(2.5, 4.0),
    pavement_width=st.floats(1.0, 6.0),
    length=st.floats(60.0, 400.0),
)
def test_grass_lies_only_off_the_street_and_tiles_as_one_box_would(
    center_y: float, lanes: int, lane_width: float, pavement_width: float, length: float
) -> None:
    road = RoadLayout(
        length=length, lanes=lanes, lane_width=lane_width, center_y=center_y,
        pavement_width=pavement_width, crosswalk_x=None,
    )  # fmt: skip
    geoms = _street_geoms(road)
    grass = [v for k, v in geoms.items() if k.startswith("ground")]
    street = [v for k, v in geoms.items() if k.startswith(("road", "kerb", "pavement"))]
    assert len(grass) == 4
    period = 2.0 / GRASS_REPEAT
    for (cx, cy, _), _ in grass:  # the texture's phase: whole periods from the centre line
        for offset in (cx, cy - center_y):
            assert abs(offset / period - round(offset / period)) < 1e-6
    rng = np.random.default_rng(0)
    extent = 1.5 * length
    x, y = rng.uniform(-extent, extent, 20000), center_y + rng.uniform(-extent, extent, 20000)
    assert np.all(_covered(grass, x, y) | _covered(street, x, y))  # no hole down to the sky
    y_right, y_left = road.edges
    on_road = (np.abs(x) < length / 2 - GRASS_UNDER) & (y > y_right) & (y < y_left)
    assert on_road.any() and not _covered(grass, x[on_road], y[on_road]).any()


def test_the_pedestrian_still_casts_its_shadow_on_the_road() -> None:
    """The ground's slabs are left out of the shadow map; the pedestrian is not."""
    scene = small_scene()
    with SceneRenderer(scene) as renderer:
        empty = renderer.render().astype(int)
        spot = ROBOT.to_world(np.array([3.0, 0.0, 0.0]))
        stand(scene, spot[0], spot[1], ROBOT.yaw + math.pi / 2)
        image = renderer.render().astype(int)
        body = renderer.mask(scene.geoms_of(scene.pedestrians[0]))
    darker = (image.sum(-1) < empty.sum(-1) - 30) & ~body
    assert darker.sum() > 40  # 62 pixels of shadow beside the 740 of the body
