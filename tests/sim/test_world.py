"""The simulated world: frame conversion, projection through World, collision truth, cases."""

from __future__ import annotations

import math
import multiprocessing
import os
from dataclasses import replace

import numpy as np
import pytest
from highway_env import utils
from highway_env.vehicle.kinematics import Vehicle
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.cases import Case
from monopic.features.orientation import facing_angle
from sim.geometry.frames import Pose2D, wrap_angle
from sim.geometry.highway_frame import highway_to_world, reflect, world_to_highway
from sim.scenario.cases import CasePlacement, case_heading_deg, default_crossing
from sim.scenario.plan import rail_track
from sim.scenario.spec import (
    CameraSpec,
    Leg,
    MannequinSpec,
    Occluder,
    PedestrianSpec,
    RoadLayout,
    RobotSpec,
    Scenario,
    SceneSpec,
)
from sim.world.ground_truth import contact_window
from sim.world.render import Marker, RenderContext
from sim.world.robot import Robot, highway_road
from sim.world.world import World

SMALL_CAMERA = CameraSpec(width=320, height=180)
LIGHT_SCENE = SceneSpec(road=RoadLayout(buildings=False))
DT = 1.0 / 15.0


def scenario(
    pedestrian: PedestrianSpec,
    robot_speed: float = 2.0,
    duration: float = 4.0,
    camera: CameraSpec = SMALL_CAMERA,
    scene: SceneSpec = LIGHT_SCENE,
    seed: int = 0,
) -> Scenario:
    return Scenario(
        name="test",
        pedestrian=pedestrian,
        robot=RobotSpec(speed=robot_speed, camera=camera),
        scene=scene,
        duration=duration,
        seed=seed,
    )


def marker_centroid(image: np.ndarray) -> np.ndarray:
    """Pixel centroid (u, v) of the pure-red marker, pixel centres at +0.5."""
    r, g, b = (image[..., k].astype(int) for k in range(3))
    mask = (r > 200) & (g < 60) & (b < 60)
    assert mask.sum() >= 12, "marker not visible"
    vs, us = np.nonzero(mask)
    return np.array([us.mean() + 0.5, vs.mean() + 0.5])


# -- highway-env <-> world -------------------------------------------------------------


def test_reflection_is_its_own_inverse_and_mirrors_y_and_heading() -> None:
    pose = Pose2D(3.0, -2.0, 0.7)
    position, heading = world_to_highway(pose)
    assert np.allclose(position, [3.0, 2.0]) and heading == pytest.approx(-0.7)
    back = highway_to_world(position, heading)
    assert (back.x, back.y, back.yaw) == pytest.approx((pose.x, pose.y, pose.yaw))
    twice = reflect(*reflect(np.array([1.5, 4.0]), 2.0))
    assert np.allclose(twice[0], [1.5, 4.0]) and twice[1] == pytest.approx(2.0)


def test_highway_env_kinematics_move_along_the_world_heading() -> None:
    """A highway-env vehicle driving from a world pose moves where the world yaw points."""
    start = Pose2D(1.0, 2.0, 0.6)  # heading north-east in the world
    position, heading = world_to_highway(start)
    vehicle = Vehicle(None, position, heading, speed=3.0)
    vehicle.step(1.0)
    end = highway_to_world(vehicle.position, vehicle.heading)
    assert end.x - start.x == pytest.approx(3.0 * math.cos(0.6))
    assert end.y - start.y == pytest.approx(3.0 * math.sin(0.6))
    assert end.yaw == pytest.approx(0.6)


def test_highway_env_lane_right_is_south_of_an_eastbound_robot() -> None:
    """highway-env numbers lanes left to right; its right lane must be the world's south one."""
    road = highway_road(RoadLayout(lanes=2, lane_width=3.5, center_y=0.0))
    lanes = road.network.graph["west"]["east"]
    centres = [highway_to_world(lane.position(0.0, 0.0), lane.heading).y for lane in lanes]
    assert centres == pytest.approx([1.75, -1.75])  # lane 0 north (left), lane 1 south (right)
    assert highway_to_world(lanes[0].position(0, 0), lanes[0].heading).yaw == pytest.approx(0.0)


@pytest.mark.parametrize("side, sign", [("right", 1.0), ("left", -1.0)])
def test_right_in_highway_env_is_right_in_the_image(side: str, sign: float) -> None:
    """A pedestrian placed on the robot's right in highway-env coordinates (+y for a robot
    heading along +x) shows right of the image centre, in the render and in the truth."""
    ahead_hw = np.array([6.0, sign * 1.5])  # robot at the origin heading along x
    place = highway_to_world(ahead_hw, 0.0)
    ped = PedestrianSpec(x=place.x, y=place.y, heading_deg=90.0, speed=0.0)
    with World(scenario(ped, robot_speed=0.0)) as world:
        step = world.reset()
        mask = world.pedestrian_mask()
    assert step.frame is not None
    cols = np.nonzero(mask)[1]
    assert cols.size > 200
    centre = SMALL_CAMERA.width / 2
    if sign > 0:
        assert cols.min() > centre and step.truth.pedestrian.centre_px[0] > centre
        assert step.truth.pedestrian.position_robot[1] < 0  # robot frame: y is left
    else:
        assert cols.max() < centre and step.truth.pedestrian.centre_px[0] < centre
        assert step.truth.pedestrian.position_robot[1] > 0


def test_marker_lands_on_the_camera_model_projection_with_a_moving_robot() -> None:
    """After highway-env has driven the robot, MuJoCo's camera is where the truth says."""
    ped = PedestrianSpec(x=-20.0, y=8.0, heading_deg=0.0, speed=0.0)  # out of view
    with World(scenario(ped, robot_speed=2.5)) as world:
        world.reset()
        for _ in range(20):
            step = world.step(action=0.5)
        robot = step.truth.robot
        assert robot.position[0] > 3.0 and robot.speed > 2.5  # it has moved and sped up
        camera = world.camera
        for p in np.array([[4.0, 0.0, 0.5], [5.0, 1.8, 1.6], [3.5, -1.5, 0.15], [9.0, 2.5, 1.2]]):
            world_point = robot.pose.to_world(p)
            radius = 0.04 * p[0] * 180 / camera.height
            image = world.render((Marker(tuple(world_point), radius=radius),))
            expected = camera.project(p)
            found = marker_centroid(image)
            assert np.linalg.norm(found - expected) < 1.0, (p, found, expected)


def test_a_borrowed_render_context_renders_as_a_fresh_one_and_outlives_its_worlds() -> None:
    """Worlds one after another on one RenderContext (as a sweep worker runs them) draw the
    same images as worlds with their own, and leave the context open for the next."""
    first = CasePlacement(Case.PERPENDICULAR_RIGHT, distance=8.0).scenario()
    second = CasePlacement(Case.OBLIQUE_LEFT_AWAY, distance=6.0).scenario()

    def frames(sc: Scenario, context: RenderContext | None) -> list[np.ndarray]:
        with World(sc, render_context=context) as world:
            steps = [world.reset()] + [world.step() for _ in range(3)]
        return [s.frame.image for s in steps]

    with RenderContext(768, 432) as shared:
        borrowed = frames(first, shared) + frames(second, shared)
        assert shared.fits(768, 432)
        shared.make_current()  # still open after both worlds closed
    own = frames(first, None) + frames(second, None)
    for a, b in zip(borrowed, own, strict=True):
        np.testing.assert_array_equal(a, b)
    with pytest.raises(RuntimeError, match="after close"):
        shared.make_current()
    with RenderContext(320, 240) as small, pytest.raises(ValueError, match="cannot hold"):
        frames(first, small)


# -- robot and pedestrian --------------------------------------------------------------


def test_robot_clips_acceleration_and_never_reverses() -> None:
    spec = RobotSpec(speed=1.0, max_acceleration=2.0, max_deceleration=5.0)
    robot = Robot(None, spec, Pose2D(0.0, 0.0, 0.0))
    robot.act(100.0)
    robot.step(0.1)
    assert robot.applied_acceleration == pytest.approx(2.0) and robot.speed == pytest.approx(1.2)
    xs = []
    for _ in range(20):
        robot.act(-100.0)
        robot.step(0.1)
        xs.append(robot.world_pose.x)
        assert robot.speed >= 0.0
    assert robot.speed == 0.0 and robot.applied_acceleration == pytest.approx(0.0)
    assert np.all(np.diff(xs) >= 0)  # braking to a stop, never backwards
    with pytest.raises(ValueError, match="robot speed"):
        Robot(None, RobotSpec(speed=-1.0), Pose2D(0.0, 0.0, 0.0))


def test_pedestrian_path_with_delay_stop_and_turn() -> None:
    spec = PedestrianSpec(
        x=1.0,
        y=2.0,
        heading_deg=0.0,
        speed=1.0,
        start_delay=1.0,
        legs=(Leg(at=3.0, speed=0.0), Leg(at=4.0, speed=2.0, turn_deg=90.0)),
    )
    path = rail_track(spec, acceleration_distance=0.0)  # the plan itself
    assert np.allclose(path.state(0.5).position, [1.0, 2.0]) and path.state(0.5).speed == 0.0
    assert np.allclose(path.state(2.0).position, [2.0, 2.0])
    assert np.allclose(path.state(3.5).position, [3.0, 2.0]) and path.state(3.5).speed == 0.0
    s = path.state(5.0)
    assert np.allclose(s.position, [3.0, 4.0]) and s.yaw == pytest.approx(math.pi / 2)
    assert np.allclose(s.velocity, [0.0, 2.0])
    assert path.breakpoints_between(0.0, 10.0) == [1.0, 3.0, 4.0]


# -- collision ground truth --------------------------------------------------------------


def run_truth(sc: Scenario) -> list:
    with World(sc, render=False) as world:
        return [step.truth for step in world.run()]


def test_head_on_time_to_collision_is_known() -> None:
    """Robot at 2 m/s, pedestrian walking at it at 1.5 m/s, 10 m between centres.

    Footprints: robot 0.8 long, pedestrian 0.5 square, so the gap is 10 - 0.4 - 0.25 =
    9.35 m, closing at 3.5 m/s: contact at 2.6714 s, frame 41 (t = 2.733) is the first in
    contact, and the 1 s horizon first sees it at frame 26 (t = 1.733).
    """
    ped = PedestrianSpec(x=10.0, y=0.0, heading_deg=180.0, speed=1.5)
    truths = run_truth(scenario(ped, robot_speed=2.0, duration=3.0))
    t_contact = 9.35 / 3.5
    assert truths[0].pedestrian.time_to_collision == pytest.approx(t_contact, abs=1e-9)
    for truth in truths:
        expected_ttc = max(t_contact - truth.time, 0.0)
        assert truth.pedestrian.time_to_collision == pytest.approx(expected_ttc, abs=1e-9)
        assert truth.pedestrian.contact == (truth.time >= t_contact)
        assert truth.pedestrian.collision == (truth.time >= t_contact - 1.0)
    assert [t.index for t in truths if t.pedestrian.contact][0] == 41
    assert [t.index for t in truths if t.pedestrian.collision][0] == 26


def test_highway_env_flags_the_same_contact() -> None:
    ped = PedestrianSpec(x=10.0, y=0.0, heading_deg=180.0, speed=1.5)
    with World(scenario(ped, duration=3.0), render=False) as world:
        world.reset()
        for _ in range(41):
            step = world.step()
            assert world.pedestrian is not None
            assert world.pedestrian.hit == step.truth.pedestrian.contact


@pytest.mark.parametrize("offset, meets", [(0.60, False), (0.50, True)])
def test_side_by_side_near_miss_and_graze(offset: float, meets: bool) -> None:
    """Walking at the robot 0.6 m off its centre line passes 5 cm clear (0.3 + 0.25 = 0.55);
    0.5 m off overlaps by 5 cm and meets at the head-on time."""
    ped = PedestrianSpec(x=10.0, y=offset, heading_deg=180.0, speed=1.5)
    truths = run_truth(scenario(ped, duration=4.0))
    if meets:
        assert truths[0].pedestrian.time_to_collision == pytest.approx(9.35 / 3.5, abs=1e-9)
        assert any(t.pedestrian.contact for t in truths)
    else:
        assert all(t.pedestrian.time_to_collision is None for t in truths)
        assert not any(t.pedestrian.contact or t.pedestrian.collision for t in truths)


def test_crossing_ahead_in_time_is_a_near_miss() -> None:
    """The pedestrian crosses 6 m ahead at t = 1.5 s; the robot's front is at 4.2 m at most
    while the pedestrian is within its width: no contact, no collision, no TTC."""
    sc = CasePlacement(
        Case.PERPENDICULAR_RIGHT, distance=6.0, robot_speed=2.0, meet_time=1.5
    ).scenario()
    truths = run_truth(replace(sc, scene=LIGHT_SCENE, duration=4.0))
    assert all(
        t.pedestrian.time_to_collision is None and not t.pedestrian.collision for t in truths
    )


def test_default_crossing_collides_unless_the_robot_brakes() -> None:
    truths = run_truth(default_crossing())
    assert any(t.pedestrian.contact for t in truths)
    with World(default_crossing(), render=False) as world:
        braked = list(world.run(policy=lambda step: -8.0))
    assert not any(s.truth.pedestrian.contact for s in braked)
    assert braked[-1].truth.robot.speed == 0.0


def test_the_true_path_with_a_turn_decides_the_collision() -> None:
    """Walking east beside a standing robot, then turning south into it at t = 1 s.

    Straight extrapolation would miss; the truth follows the turn: the pedestrian's
    south edge (y - 0.25) reaches the robot's north edge (0.3) at t = 1 + 2.45 s.
    """
    ped = PedestrianSpec(
        x=-1.0, y=3.0, heading_deg=0.0, speed=1.0, legs=(Leg(at=1.0, speed=1.0, turn_deg=-90.0),)
    )
    truths = run_truth(scenario(ped, robot_speed=0.0, duration=4.0))
    assert truths[0].pedestrian.time_to_collision == pytest.approx(3.45, abs=1e-9)
    assert truths[0].pedestrian.case is Case.AWAY  # the next second is still the walk east
    assert truths[30].pedestrian.case is Case.PERPENDICULAR_RIGHT  # t = 2 s, walking south


rect = st.tuples(
    st.floats(-3, 3), st.floats(-3, 3), st.floats(-math.pi, math.pi), st.floats(0.3, 2.0)
)
vel = st.tuples(st.floats(-3, 3), st.floats(-3, 3))


@settings(max_examples=60, deadline=None)
@given(rect, rect, vel, vel)
def test_contact_window_agrees_with_highway_env_at_every_time(
    a: tuple[float, float, float, float],
    b: tuple[float, float, float, float],
    va: tuple[float, float],
    vb: tuple[float, float],
) -> None:
    def polygon(x: float, y: float, h: float, size: float) -> np.ndarray:
        ghost = Vehicle(None, [x, y], h)
        ghost.LENGTH, ghost.WIDTH = size, 0.6 * size
        return ghost.polygon()

    pa, pb = polygon(*a), polygon(*b)
    va_, vb_ = np.array(va), np.array(vb)
    window = contact_window(pa, va_, pb, vb_, 2.0)
    for t in np.linspace(0.0, 2.0, 81):
        zero = np.zeros(2)
        meets = utils.are_polygons_intersecting(pa + t * va_, pb + t * vb_, zero, zero)[0]
        if window is None:
            assert not meets
        elif window[0] + 1e-6 < t < window[1] - 1e-6:
            assert meets
        elif t < window[0] - 1e-6 or t > window[1] + 1e-6:
            assert not meets


# -- cases, facing, visibility -------------------------------------------------------------

PLACEMENTS = [
    {},
    {"robot_speed": 0.0},
    {"angle_deg": 30.0, "lateral_offset": 2.0, "distance": 12.0},
    {"angle_deg": 60.0, "lateral_offset": -1.5, "robot_speed": 5.0, "pedestrian_speed": 0.8},
]


@pytest.mark.parametrize("params", PLACEMENTS, ids=lambda p: ",".join(p) or "defaults")
@pytest.mark.parametrize("case", list(Case), ids=lambda c: c.name.lower())
def test_every_placed_case_is_labelled_as_that_case(case: Case, params: dict) -> None:
    sc = replace(CasePlacement(case, **params).scenario(), scene=LIGHT_SCENE)
    truths = run_truth(sc)
    assert len(truths) == sc.frames
    assert {t.pedestrian.case for t in truths} == {case}
    # In the middle of the run the pedestrian is where the placement put it.
    mid = truths[sc.frames // 2]
    robot_x = mid.robot.position[0]
    distance = params.get("distance", 8.0)
    assert mid.pedestrian.position_world[0] == pytest.approx(distance, abs=0.01)
    assert mid.pedestrian.position_robot[0] == pytest.approx(distance - robot_x, abs=0.01)


def test_oblique_angles_outside_their_sector_are_refused() -> None:
    with pytest.raises(ValueError, match="angle_deg"):
        CasePlacement(Case.OBLIQUE_LEFT_AWAY, angle_deg=15.0).scenario()
    with pytest.raises(ValueError, match=r"pedestrian_speed = 0.1: must be >= 0.3 m/s"):
        CasePlacement(Case.TOWARD, pedestrian_speed=0.1).scenario()
    assert case_heading_deg(Case.OBLIQUE_RIGHT_TOWARD, 40.0) == pytest.approx(-140.0)


@pytest.mark.parametrize("facing_deg", [180.0, 150.0, 100.0, 60.0, 0.0, -45.0, -120.0])
def test_true_phi_matches_the_pipeline_formula_on_true_shoulders(facing_deg: float) -> None:
    """The phi in the truth equals what monopic's orientation gives for the true shoulders."""
    sc = CasePlacement(Case.STILL, distance=5.0, robot_speed=0.0, facing_deg=facing_deg).scenario()
    with World(replace(sc, scene=LIGHT_SCENE), render=False) as world:
        truth = world.reset().truth
        camera = world.camera
    lm = camera.to_camera(truth.pedestrian.body.landmarks_robot[[11, 12]])
    # In the pipeline, z comes in the x scale: optical-frame metres keep that isotropy.
    phi_landmarks = facing_angle(lm[0], lm[1])
    assert truth.pedestrian.phi == pytest.approx(phi_landmarks, abs=6.0)
    assert wrap_angle(truth.pedestrian.facing_yaw - math.radians(facing_deg)) == pytest.approx(
        0.0, abs=1e-9
    )


def test_a_parked_car_occludes_a_child_behind_it() -> None:
    child = PedestrianSpec(x=8.0, y=0.0, heading_deg=90.0, speed=0.0, looks=MannequinSpec.child())
    hidden = SceneSpec(road=RoadLayout(buildings=False), occluders=(Occluder.parked_car(5.0, 0.0),))
    aside = SceneSpec(road=RoadLayout(buildings=False), occluders=(Occluder.parked_car(5.0, 6.0),))
    truth_hidden = run_truth(replace(scenario(child, robot_speed=0.0, scene=hidden), duration=0.2))[
        0
    ]
    truth_clear = run_truth(replace(scenario(child, robot_speed=0.0, scene=aside), duration=0.2))[0]
    assert truth_hidden.pedestrian.occluded and truth_hidden.pedestrian.visible_fraction < 0.2
    assert not truth_clear.pedestrian.occluded and truth_clear.pedestrian.visible_fraction == 1.0
    assert truth_hidden.pedestrian.in_frame and truth_clear.pedestrian.in_frame


# -- determinism ------------------------------------------------------------------------------


def test_same_seed_same_frames_and_truth() -> None:
    sc = replace(
        CasePlacement(Case.OBLIQUE_LEFT_TOWARD, distance=6.0).scenario(), scene=LIGHT_SCENE
    )
    sc = replace(sc, robot=replace(sc.robot, camera=CameraSpec(width=160, height=90)))

    def frames(seed: int) -> list:
        with World(replace(sc, seed=seed)) as world:
            steps = [world.reset()]
            steps += [world.step(action=0.3) for _ in range(4)]
        return steps

    a, b, c = frames(3), frames(3), frames(4)
    for sa, sb in zip(a, b, strict=True):
        assert sa.frame is not None and sb.frame is not None
        assert np.array_equal(sa.frame.image, sb.frame.image)
        assert sa.truth.to_dict() == sb.truth.to_dict()
    assert a[-1].frame is not None and a[-1].frame.image.std() > 10
    # Another seed starts the gait elsewhere: the body differs, the path does not.
    assert not np.allclose(
        a[0].truth.pedestrian.body.landmarks_world, c[0].truth.pedestrian.body.landmarks_world
    )
    assert np.allclose(a[-1].truth.pedestrian.position_world, c[-1].truth.pedestrian.position_world)


# -- processes -----------------------------------------------------------------------------


def _first_frame_in_worker(sc: Scenario) -> tuple[tuple[int, ...], float, int]:
    with World(sc) as world:
        step = world.reset()
    assert step.frame is not None
    return step.frame.image.shape, float(step.frame.image.std()), os.getpid()


def test_the_renderer_is_made_lazily_and_a_spawned_worker_renders_its_own_world() -> None:
    sc = scenario(
        PedestrianSpec(x=6.0, y=0.0, heading_deg=180.0, speed=0.0), camera=CameraSpec(160, 90)
    )
    world = World(sc)
    assert world._renderer is None  # nothing GL-bound until the first frame
    world.close()
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        shape, std, pid = pool.apply(_first_frame_in_worker, (sc,))
    assert shape == (90, 160, 3) and std > 10 and pid != os.getpid()


def test_the_case_placement_checks_the_same_range_at_every_entry_point(tmp_path, capsys) -> None:
    from monopic.cli.main import main

    with pytest.raises(ValueError, match=r"distance = -3.0: must be >= 0 m"):
        CasePlacement(Case.PERPENDICULAR_LEFT, distance=-3.0)
    assert main(["record", "5", "--distance", "-3", "--out", str(tmp_path / "x.rrd")]) == 2
    assert "--distance -3: must be >= 0 m" in capsys.readouterr().err
    scenario = tmp_path / "case.toml"
    scenario.write_text('name = "c"\n[path]\nkind = "case"\ncase = 5\ndistance = -3.0\n')
    from sim.scenario.files import ScenarioFileError, load

    with pytest.raises(ScenarioFileError, match=r"case.toml: path.distance = -3.0: must be >= 0"):
        load(scenario)
    assert not (tmp_path / "x.rrd").exists()


def test_two_worlds_drawing_in_turns_in_one_context_draw_what_each_draws_alone() -> None:
    """Each renderer binds its own offscreen buffer before it draws (sim.world.render)."""
    from monopic.cases import Case
    from sim.scenario.cases import CasePlacement
    from sim.world.render import RenderContext

    a = CasePlacement(Case(5), duration=0.2, seed=1).scenario()
    b = CasePlacement(Case(3), duration=0.2, seed=2).scenario()
    alone = {}
    for name, s in (("a", a), ("b", b)):
        with World(s) as w:
            alone[name] = [step.frame.image for step in w.run()]
    context = RenderContext(768, 432)
    try:
        with World(a, render_context=context) as wa, World(b, render_context=context) as wb:
            for k, (sa, sb) in enumerate(zip(wa.run(), wb.run(), strict=True)):
                assert np.array_equal(sa.frame.image, alone["a"][k])
                assert np.array_equal(sb.frame.image, alone["b"][k])
    finally:
        context.close()
