"""Intent features: window fits of the foot point, phi rate, head yaw, swept-path offset."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.features.extractor import DEFAULT_ROBOT_WIDTH, FeatureExtractor
from monopic.features.ground import GroundMotion, Odometry
from monopic.features.head import (
    LEFT_EAR,
    LEFT_EYE,
    RIGHT_EAR,
    RIGHT_EYE,
    HeadTurnWindow,
    head_facing,
    head_yaw,
)
from monopic.features.swept_path import path_offset
from monopic.features.window import (
    GroundKinematics,
    KinematicsConfig,
    SlidingWindow,
    angle_rate,
    derivatives_at,
    line_slope,
)
from monopic.frame import EgoState
from monopic.pipeline import Pipeline, PipelineConfig
from monopic.pose.landmarks import Pose
from monopic.pose.region import Region
from monopic.pose.skeleton import INDEX, LEFT_SHOULDER, RIGHT_SHOULDER
from monopic.variants.warning import CollisionWarning
from monopic.variants.zone import RobotGeometry

CAM = CameraModel.from_fov(768, 432, 70, 1.0, pitch_deg=5)
R_SMALL = np.eye(2) * 0.01


# -- the window fit ---------------------------------------------------------------------


def test_quadratic_fit_reads_value_velocity_and_acceleration_where_asked() -> None:
    t = np.linspace(0.0, 0.8, 13)
    y = 2.0 + 1.5 * t - 0.4 * t**2  # at t = 0.8: 2.944, slope 0.86, curvature -0.8
    d = derivatives_at(t, y, 2, 0.8)
    assert d[:, 0] == pytest.approx([2.0 + 1.2 - 0.256, 1.5 - 0.64, -0.8])
    assert derivatives_at(t, y, 2, 0.4)[:, 0] == pytest.approx([2.536, 1.18, -0.8])
    with pytest.raises(ValueError):
        derivatives_at(t[:2], y[:2], 2, 0.8)


def _feed(k: GroundKinematics, positions, times) -> None:
    for t, p in zip(times, positions, strict=True):
        k.add(float(t), np.asarray(p), R_SMALL)


def test_constant_walk_has_its_speed_and_no_acceleration_or_turn() -> None:
    k = GroundKinematics()
    t = np.arange(15) / 15
    _feed(k, np.column_stack([3.0 + 0.0 * t, 2.0 - 1.4 * t]), t)
    got = k.estimate()
    assert got.speed == pytest.approx(1.4)
    assert got.acceleration == pytest.approx(0.0, abs=1e-9)
    assert got.heading_rate == pytest.approx(0.0, abs=1e-9)


def test_slowing_walker_has_negative_acceleration_along_the_walk() -> None:
    # 1.5 m/s slowing at 1 m/s^2, walking toward -y: the sign is along the walk, not an axis.
    k = GroundKinematics()
    t = np.arange(15) / 15
    s = 1.5 * t - 0.5 * t**2
    _feed(k, np.column_stack([5.0 + 0 * t, -s]), t)
    got = k.estimate()
    # Read at the window's centre (equal weights: its mean time), `age` before the newest.
    assert got.age == pytest.approx(t[-1] - t.mean())
    assert got.speed == pytest.approx(1.5 - t.mean())
    assert got.acceleration == pytest.approx(-1.0)


def test_turning_left_on_a_circle_gives_positive_heading_rate() -> None:
    # 1.2 m/s on a 2 m circle counter-clockwise: 0.6 rad/s = 34.4 deg/s; clockwise: negative.
    # Read at the window's centre, a quadratic's error from the arc's cubic term is small.
    t = np.arange(15) / 15
    w = 1.2 / 2.0
    for sign in (1, -1):
        k = GroundKinematics()
        pts = np.column_stack([2.0 * np.cos(sign * w * t), 2.0 * np.sin(sign * w * t)])
        _feed(k, pts, t)
        got = k.estimate()
        assert got.speed == pytest.approx(1.2, rel=0.01)
        assert got.heading_rate == pytest.approx(sign * math.degrees(w), rel=0.01)
        assert got.acceleration == pytest.approx(0.0, abs=0.01)


def test_standing_has_no_heading_and_a_fresh_window_says_nothing() -> None:
    k = GroundKinematics()
    t = np.arange(15) / 15
    _feed(k, np.tile([4.0, 1.0], (15, 1)), t)
    got = k.estimate()
    assert got.speed == pytest.approx(0.0, abs=1e-9)
    assert math.isnan(got.acceleration) and math.isnan(got.heading_rate)
    fresh = GroundKinematics()
    _feed(fresh, [[0.0, 0.0], [0.1, 0.0], [0.2, 0.0], [0.3, 0.0]], [0.0, 0.1, 0.2, 0.3])
    assert math.isnan(fresh.estimate().speed)  # 4 samples: below min_samples
    short = GroundKinematics(KinematicsConfig(min_samples=3))
    _feed(short, [[0.0, 0.0], [0.1, 0.0], [0.2, 0.0]], [0.0, 0.1, 0.2])
    assert math.isnan(short.estimate().speed)  # 0.2 s: below min_span


def test_the_window_forgets_what_is_older_than_it() -> None:
    # Standing for 2 s, then walking 1 m/s: once the walk fills the window the standing is gone.
    k = GroundKinematics()
    times = np.arange(50) / 15
    x = np.where(times < 2.0, 0.0, times - 2.0)
    _feed(k, np.column_stack([x, 0 * x]), times)
    assert k.estimate().speed == pytest.approx(1.0)
    assert k.estimate().acceleration == pytest.approx(0.0, abs=1e-9)


def test_far_noisy_points_count_for_less() -> None:
    # Two samples far off the line with a huge covariance barely move the fit.
    k = GroundKinematics()
    t = np.arange(13) / 15
    for i, ti in enumerate(t):
        bad = i in (4, 8)
        p = np.array([ti * 1.0 + (3.0 if bad else 0.0), 0.0])
        k.add(float(ti), p, np.eye(2) * (1e4 if bad else 0.01))
    assert k.estimate().speed == pytest.approx(1.0, abs=0.01)


# -- through GroundMotion: robot ego-motion removed -------------------------------------


def _seen(truth: Odometry, world: np.ndarray) -> tuple[float, float]:
    d = world - (truth.x, truth.y)
    c, s = math.cos(truth.yaw), math.sin(truth.yaw)
    rel = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], 0.0])
    u, v = CAM.project(rel)
    return float(u), float(v)


def test_slowing_pedestrian_seen_from_a_moving_turning_robot() -> None:
    ego = EgoState(CAM, speed=1.5, yaw_rate=0.15)
    motion, truth = GroundMotion(), Odometry()
    for i in range(30):
        t = i / 15
        truth.update(t, ego)
        walked = 1.4 * t - 0.3 * t**2  # slowing at 0.6 m/s^2 while crossing to the right
        world = np.array([9.0, 2.5 - walked])
        motion.observe_ego(t, ego)
        assert motion.update(t, ego, _seen(truth, world), 80.0) is not None
    got = motion.kinematics()
    assert 0.3 < got.age < 0.7  # read near the window's centre (weights vary with range)
    assert got.speed == pytest.approx(1.4 - 0.6 * (29 / 15 - got.age), abs=0.01)
    assert got.acceleration == pytest.approx(-0.6, abs=0.02)
    assert got.heading_rate == pytest.approx(0.0, abs=0.5)  # the robot's turn is not theirs


def test_a_track_restart_restarts_the_window() -> None:
    ego = EgoState(CAM, speed=0.0)
    motion = GroundMotion()
    for i in range(15):
        t = i / 15
        motion.observe_ego(t, ego)
        motion.update(t, ego, tuple(CAM.project(np.array([6.0, 1.0 - 1.2 * t, 0.0]))), 80.0)
    assert motion.kinematics().speed == pytest.approx(1.2, abs=0.01)
    # Someone else, 4 m further: rejected three times, then the track (and window) restart.
    for i in range(15, 18):
        t = i / 15
        motion.observe_ego(t, ego)
        motion.update(t, ego, tuple(CAM.project(np.array([10.0, 3.0, 0.0]))), 80.0)
    assert math.isnan(motion.kinematics().speed)


# -- phi rate -----------------------------------------------------------------------------


def test_angle_rate_is_the_slope_and_unwraps_at_the_profile() -> None:
    w = SlidingWindow(0.5)
    for i in range(8):
        w.add(i / 15, 30.0 + 40.0 * i / 15)
    assert angle_rate(w) == pytest.approx(40.0)
    wrap = SlidingWindow(0.5)
    for i in range(8):  # 170, 180, -170 (190), ... : +150 deg/s through +-180
        wrap.add(i / 15, (170.0 + 150.0 * i / 15 + 180.0) % 360.0 - 180.0)
    assert angle_rate(wrap) == pytest.approx(150.0)
    two = SlidingWindow(0.5)
    two.add(0.0, 1.0)
    two.add(0.3, 2.0)
    assert math.isnan(angle_rate(two))  # fewer than three samples


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.floats(0.02, 0.2), min_size=2, max_size=11),
    st.lists(st.floats(-180.0, 180.0), min_size=12, max_size=12),
    st.floats(0.0, 1e4),
)
def test_the_line_slope_is_the_least_squares_slope(steps, values, start) -> None:
    """line_slope's centred sums against the degree-1 lstsq fit it replaced."""
    t = (start + np.concatenate([[0.0], np.cumsum(steps)])).tolist()
    y = values[: len(t)]
    fit = float(derivatives_at(np.array(t), np.array(y), 1, t[-1])[1, 0])
    assert line_slope(t, y) == pytest.approx(fit, rel=1e-9, abs=1e-9)
    with pytest.raises(ValueError, match="two distinct times"):
        line_slope([1.0, 1.0], [0.0, 1.0])


def _pose(lm: np.ndarray, vis: np.ndarray | None = None) -> Pose:
    vis = np.ones(33) if vis is None else vis
    return Pose(lm, vis, np.ones(33), 0.99, Region(400.0, 250.0, 200.0), np.zeros((6, 2)))


def _body(facing_deg: float, head_deg: float, cx: float = 400.0, scale: float = 500.0):
    """Landmarks (33, 3) in pixels of a person whose front points `facing_deg` in the
    camera's (x, z) plane (-90: facing the camera) with the head turned `head_deg` to the
    person's left; orthographic, as BlazePose's z is in x's scale."""
    lm = np.zeros((33, 3))
    lm[:, 0] = cx
    lm[:, 1] = np.linspace(100.0, 400.0, 33)

    def place(i: int, forward: float, left: float, yaw_deg: float) -> None:
        a = math.radians(yaw_deg)
        f = np.array([math.cos(a), math.sin(a)])
        lft = np.array([-math.sin(a), math.cos(a)])
        x, z = forward * f + left * lft
        lm[i, 0], lm[i, 2] = cx + scale * x, scale * z

    place(LEFT_SHOULDER, 0.0, 0.2, facing_deg)
    place(RIGHT_SHOULDER, 0.0, -0.2, facing_deg)
    h = facing_deg + head_deg
    place(LEFT_EAR, 0.0, 0.075, h)
    place(RIGHT_EAR, 0.0, -0.075, h)
    place(LEFT_EYE, 0.08, 0.03, h)
    place(RIGHT_EYE, 0.08, -0.03, h)
    place(INDEX["nose"], 0.1, 0.0, h)
    return lm


def test_phi_rate_follows_the_turning_shoulders_and_restarts_after_a_gap() -> None:
    fx = FeatureExtractor()
    times, phis, rates = [], [], []
    for i in range(15):  # shoulders turning from square toward a profile, 60 deg/s
        f = fx.update(i / 15, _pose(_body(-90.0 + 60.0 * i / 15, 0.0)), 432)
        times.append(f.timestamp)
        phis.append(f.phi)
        rates.append(f.phi_rate)
    assert math.isnan(rates[0]) and math.isnan(rates[1])
    # The rate is the slope of the smoothed phi (not the raw one) over the last 0.5 s.
    last = [i for i, t in enumerate(times) if times[-1] - t <= 0.5 + 1e-9]
    slope = np.polyfit(np.array(times)[last], np.array(phis)[last], 1)[0]
    assert rates[-1] == pytest.approx(slope)
    assert abs(rates[-1]) > 60.0  # phi is twice the shoulder line's yaw: ~120 deg/s, lagged
    assert math.isnan(fx.update(3.0, _pose(_body(-90.0, 0.0)), 432).phi_rate)  # after a gap


# -- head yaw -------------------------------------------------------------------------------


@pytest.mark.parametrize("facing", [-90.0, -60.0, -120.0, 90.0, 45.0])
@pytest.mark.parametrize("head", [0.0, 40.0, -30.0, 75.0])
def test_head_yaw_reads_the_turn_from_any_view(facing: float, head: float) -> None:
    got = head_yaw(_body(facing, head), np.ones(33))
    assert got.yaw == pytest.approx(head, abs=1e-6)
    assert got.visibility == 1.0


def test_head_yaw_sign_left_is_positive_seen_from_the_front() -> None:
    # Facing the camera and looking to their left: the left ear moves away (z grows)
    # and the nose toward the image's right (the person's left).
    lm = _body(-90.0, 30.0)
    assert lm[LEFT_EAR, 2] > lm[RIGHT_EAR, 2]
    assert lm[INDEX["nose"], 0] > (lm[LEFT_EAR, 0] + lm[RIGHT_EAR, 0]) / 2
    assert head_yaw(lm, np.ones(33)).yaw > 0


def test_head_yaw_from_behind_uses_the_ears_alone() -> None:
    vis = np.ones(33)
    vis[[LEFT_EYE, RIGHT_EYE, INDEX["nose"]]] = 0.05  # back to the camera: no face
    lm = _body(90.0, -50.0)
    lm[LEFT_EYE, 0] += 80.0  # hidden landmarks are garbage: they must not count
    assert head_yaw(lm, vis).yaw == pytest.approx(-50.0, abs=1e-6)


def test_head_yaw_is_nan_when_an_ear_or_shoulder_is_not_visible() -> None:
    for hidden in (LEFT_EAR, RIGHT_SHOULDER):
        vis = np.ones(33)
        vis[hidden] = 0.2
        got = head_yaw(_body(-90.0, 20.0), vis)
        assert math.isnan(got.yaw)
        assert got.visibility == pytest.approx(0.2)
    coincide = _body(-90.0, 0.0)
    coincide[RIGHT_EAR] = coincide[LEFT_EAR]
    assert math.isnan(head_yaw(coincide, np.ones(33)).yaw)


def test_extractor_reports_head_yaw_and_its_visibility() -> None:
    f = FeatureExtractor().update(0.0, _pose(_body(-70.0, 35.0)), 432)
    assert f.head_yaw == pytest.approx(35.0, abs=1e-6)
    assert f.head_visibility == 1.0


# -- head facing from the camera and the turn toward it ---------------------------------------


@pytest.mark.parametrize("facing", [-90.0, -60.0, -120.0])
@pytest.mark.parametrize("head", [0.0, 40.0, -30.0, 60.0])
def test_head_facing_reads_the_head_from_the_camera_in_image_x_alone(
    facing: float, head: float
) -> None:
    lm = _body(facing, head)
    lm[:, 2] = 0.0  # no depth at all: the facing needs none
    # _body's -90 faces the camera; its eyes are 60 mm apart where the reading assumes 63.
    assert head_facing(lm, np.ones(33)) == pytest.approx(facing + head + 90.0, abs=2.0)


def test_head_facing_is_nan_when_the_face_is_not_seen() -> None:
    vis = np.ones(33)
    vis[RIGHT_EYE] = 0.1
    assert math.isnan(head_facing(_body(-90.0, 20.0), vis))


def test_a_head_check_toward_the_camera_reads_as_a_turn_toward_it() -> None:
    window = HeadTurnWindow()
    t = np.arange(0.0, 3.0, 1 / 15)
    # Walking across, the head 70 deg from the camera; from 2 s on it turns to 20 deg.
    facing = np.where(t < 2.0, -70.0, -20.0)
    out = [window.update(float(ti), float(f)) for ti, f in zip(t, facing, strict=True)]
    assert math.isnan(out[0]) and math.isnan(out[9])  # not 4 samples 0.5 s back yet
    steady = [o for ti, o in zip(t, out, strict=True) if 0.8 < ti < 2.0]
    assert steady and all(o == pytest.approx(0.0) for o in steady)
    after = [o for ti, o in zip(t, out, strict=True) if 2.15 < ti < 2.5]
    assert after and all(o == pytest.approx(50.0) for o in after)
    # Reset forgets all; a glance away reads negative; a frame with no face adds nothing.
    window.reset()
    assert math.isnan(window.update(3.1, -20.0))
    away = HeadTurnWindow()
    for k, ti in enumerate(np.arange(0.0, 1.6, 1 / 15)):
        facing = math.nan if k == 4 else -10.0 if ti < 1.3 else -60.0
        last = away.update(float(ti), facing)
    assert last == pytest.approx(-50.0)


def test_extractor_reports_head_facing_and_the_turn_and_restarts_with_the_track() -> None:
    fx = FeatureExtractor()
    for i in range(30):
        head = 0.0 if i < 25 else 50.0  # facing the camera body-wise, head turns left
        f = fx.update(i / 15, _pose(_body(-90.0, head)), 432)
    assert f.head_facing == pytest.approx(50.0, abs=2.0)
    assert f.head_toward == pytest.approx(-50.0, abs=2.0)  # turned away from the camera
    assert math.isnan(fx.update(5.0, _pose(_body(-90.0, 0.0)), 432).head_toward)


# -- the swept path ---------------------------------------------------------------------------


def test_path_offset_and_distance_from_the_band() -> None:
    def both(p: tuple[float, float]) -> tuple[float, float]:
        got = path_offset(p, 0.6)
        return got.offset, got.distance

    assert both((5.0, 0.2)) == pytest.approx((0.2, 0.0))  # inside the band
    assert both((5.0, 1.3)) == pytest.approx((1.3, 1.0))  # left of it
    assert both((5.0, -2.3)) == pytest.approx((-2.3, 2.0))  # right of it
    assert path_offset((5.0, 0.3), 0.6).distance == 0.0  # on the edge
    with pytest.raises(ValueError):
        path_offset((1.0, 0.0), 0.0)


def test_extractor_ground_features_need_the_ground_model() -> None:
    lm = _body(-90.0, 0.0)
    lm[:, 1] = np.linspace(200.0, 330.0, 33)
    fx = FeatureExtractor(robot_width=1.0)
    ego = EgoState(CAM, speed=0.0)
    f = fx.update(0.0, _pose(lm), 432, ego)
    assert f.ground is not None
    assert f.ground.path_offset == pytest.approx(f.ground.position[1])
    assert f.ground.path_distance == pytest.approx(max(0.0, abs(f.ground.position[1]) - 0.5))
    assert math.isnan(f.ground.speed)  # one sample: the window says nothing yet
    assert FeatureExtractor().update(0.0, _pose(lm), 432).ground is None


def test_the_pipeline_gives_the_features_its_robots_width() -> None:
    assert RobotGeometry().width == DEFAULT_ROBOT_WIDTH
    wide = PipelineConfig(warning=CollisionWarning(robot=RobotGeometry(width=1.8)))
    assert Pipeline(wide).features.robot_width == 1.8
