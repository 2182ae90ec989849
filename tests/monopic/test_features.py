"""Smoothing, velocities from timestamps, ego-motion compensation, the feature extractor."""

import math

import numpy as np
import pytest

from monopic.camera import CameraModel
from monopic.features.extractor import FeatureExtractor, GroundColumn, foot_point
from monopic.features.ground import GroundMotion
from monopic.features.motion import VelocityEstimator
from monopic.features.smoothing import Kalman1D, MovingAverage
from monopic.frame import EgoState
from monopic.pose.landmarks import Pose
from monopic.pose.region import Region
from monopic.pose.skeleton import (
    FOOT_LANDMARKS,
    LEFT_HIP,
    LEFT_SHOULDER,
    RIGHT_HIP,
    RIGHT_SHOULDER,
)

CAM = CameraModel.from_fov(768, 432, 70, 1.0, pitch_deg=5)


def test_kalman_converges_and_skips_nan():
    k = Kalman1D(q=1.0, r=25.0)
    for _ in range(200):
        k.update(40.0)
    assert k.x == pytest.approx(40.0, abs=1e-3)
    assert k.update(float("nan")) == pytest.approx(40.0, abs=1e-3)
    first = Kalman1D()
    assert first.update(10.0) == 10.0


def test_moving_average_window():
    m = MovingAverage(3)
    assert [m.update(v) for v in (3, 6, 9, 12)] == [3, 4.5, 6, 9]
    with pytest.raises(ValueError):
        MovingAverage(0)


def test_velocity_uses_timestamps_not_frame_rate():
    v = VelocityEstimator(window=2, average=1)
    # Irregular frame times, a point moving at exactly 30 px/s right and 10 px/s up.
    times = [0.0, 0.05, 0.13, 0.2, 0.31]
    out = [v.update(t, 100 + 30 * t, 50 - 10 * t) for t in times]
    assert math.isnan(out[0][0])
    assert out[-1] == pytest.approx((30.0, -10.0))
    with pytest.raises(ValueError):
        v.update(0.31, 0, 0)


def test_standing_pedestrian_has_no_own_velocity_seen_from_a_moving_robot():
    ego = EgoState(CAM, speed=2.0, yaw_rate=0.0)
    motion = GroundMotion()
    for i in range(30):
        t = i / 15
        ped_in_robot = np.array([12.0 - 2.0 * t, 0.5, 0.0])  # world-fixed pedestrian
        motion.observe_ego(t, ego)
        pos, vel = motion.update(t, ego, tuple(CAM.project(ped_in_robot)), 60.0)
    assert pos == pytest.approx((12.0 - 2.0 * 29 / 15, 0.5), abs=1e-6)
    assert vel == pytest.approx((0.0, 0.0), abs=1e-6)


def test_crossing_pedestrian_velocity_under_ego_motion_and_turning():
    ego = EgoState(CAM, speed=1.5, yaw_rate=0.2)
    motion = GroundMotion()
    from monopic.features.ground import Odometry

    truth = Odometry()
    for i in range(45):
        t = i / 15
        truth.update(t, ego)
        world = np.array([8.0, 2.0]) + np.array([0.0, -1.2]) * t  # walking right at 1.2 m/s
        d = world - (truth.x, truth.y)
        c, s = math.cos(truth.yaw), math.sin(truth.yaw)
        rel = np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1], 0.0])
        motion.observe_ego(t, ego)
        pos, vel = motion.update(t, ego, tuple(CAM.project(rel)), 80.0)
    c, s = math.cos(truth.yaw), math.sin(truth.yaw)
    expected = (c * 0.0 + s * -1.2, -s * 0.0 + c * -1.2)
    # The filter starts from a standing prior and converges: within 5 cm/s after 3 s.
    assert vel == pytest.approx(expected, abs=0.05)
    assert pos == pytest.approx(tuple(rel[:2]), abs=0.02)


def _pose(cx=400.0, top=100.0, height=200.0, feet_visible=True):
    lm = np.zeros((33, 3))
    lm[:, 0] = cx
    lm[:, 1] = np.linspace(top, top + height, 33)
    lm[LEFT_SHOULDER] = (cx + 20, top + 40, 0)
    lm[RIGHT_SHOULDER] = (cx - 20, top + 40, 0)
    vis = np.ones(33)
    if not feet_visible:
        vis[list(FOOT_LANDMARKS)] = 0.1
    return Pose(lm, vis, np.ones(33), 0.99, Region(cx, top + height / 2, height), np.zeros((6, 2)))


def test_foot_point_from_feet_or_box_bottom():
    p = _pose()
    assert foot_point(p, 432)[1] == pytest.approx(300.0)
    q = _pose(feet_visible=False)
    assert foot_point(q, 432) == pytest.approx((400.0, 300.0))


def test_ground_column_from_hips_or_shoulders_row_from_the_feet():
    p = _pose()
    # A stride: one foot 30 px ahead, the other hidden; the hips and shoulders stay put.
    feet = list(FOOT_LANDMARKS)
    p.landmarks[feet[: len(feet) // 2], 0] = 430.0
    p.visibility[feet[len(feet) // 2 :]] = 0.1
    p.landmarks[[LEFT_HIP, RIGHT_HIP], 0] = (412.0, 392.0)  # midpoint 402
    row = p.landmarks[feet[: len(feet) // 2], 1].max()  # the lowest visible foot point
    assert foot_point(p, 432) == pytest.approx((430.0, row))
    assert foot_point(p, 432, GroundColumn.HIPS) == pytest.approx((402.0, row))
    assert foot_point(p, 432, GroundColumn.SHOULDERS)[0] == pytest.approx(400.0)
    # A hidden hip: back to the feet's column.
    p.visibility[LEFT_HIP] = 0.2
    assert foot_point(p, 432, GroundColumn.HIPS)[0] == pytest.approx(430.0)


def test_extractor_velocity_and_gap_reset():
    fx = FeatureExtractor(velocity_window=2, velocity_average=1, max_gap=0.5)
    for i in range(5):
        f = fx.update(i / 10, _pose(cx=300 + 50 * i / 10), 432)
    assert f.vx == pytest.approx(50.0)
    assert f.phi == pytest.approx(0.0)  # shoulders square to the camera
    assert fx.update(0.5, None, 432) is None
    f = fx.update(1.5, _pose(cx=900), 432)  # after a 1 s gap: history dropped
    assert math.isnan(f.vx)
