"""Camera projection, regions of interest, orientation and zones: pure geometry."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.features.orientation import _cross, facing_angle, look_at, quaternion
from monopic.pose.anchors import ssd_anchor_centres
from monopic.pose.detector import Detection, letterbox, weighted_nms
from monopic.pose.region import Region
from monopic.pose.search import Window, tile_windows
from monopic.variants.zone import (
    RobotGeometry,
    meets_swept_footprint,
    point_in_polygon,
    points_in_polygon,
)

CAM = CameraModel.from_fov(768, 432, 70, 1.1, pitch_deg=8, mount_forward=0.3)


@given(st.floats(1.0, 40.0), st.floats(-10, 10))
def test_ground_point_inverts_projection(x, y):
    px = CAM.project(np.array([x, y, 0.0]))
    g = CAM.ground_point(px)
    assert np.allclose(g, [x, y], atol=1e-6 * max(1.0, x))


def test_left_is_left_and_far_is_higher():
    left = CAM.project(np.array([5.0, 1.0, 0.0]))
    right = CAM.project(np.array([5.0, -1.0, 0.0]))
    far = CAM.project(np.array([20.0, 0.0, 0.0]))
    near = CAM.project(np.array([3.0, 0.0, 0.0]))
    assert left[0] < CAM.cx < right[0]
    assert far[1] < near[1]
    assert far[1] > CAM.horizon_v()


def test_points_above_horizon_have_no_ground_point():
    assert np.all(np.isnan(CAM.ground_point(np.array([384.0, CAM.horizon_v() - 5]))))


def test_behind_camera_projects_to_nan():
    assert np.all(np.isnan(CAM.project(np.array([-1.0, 0.0, 1.0]))))


@given(st.floats(50, 700), st.floats(50, 400), st.floats(20, 400), st.floats(-math.pi, math.pi))
def test_region_crop_and_back_are_inverse(cx, cy, side, rot):
    r = Region(cx, cy, side, rot)
    crop_pts = np.array([[0, 0], [256, 0], [128, 128], [10, 200]], dtype=float)
    img = r.to_image(crop_pts, 256)
    m = r.crop_to_image(256)
    back = np.linalg.solve(m[:, :2], (img - m[:, 2]).T).T
    assert np.allclose(back, crop_pts, atol=1e-6)
    assert np.allclose(img[2], [cx, cy])


def test_region_from_upright_keypoints_has_no_rotation():
    r = Region.from_keypoints((100, 300), (100, 200), scale=1.25)
    assert r.rotation == pytest.approx(0.0)
    assert r.side == pytest.approx(2 * 100 * 1.25)
    lying = Region.from_keypoints((100, 300), (200, 300))
    assert lying.rotation == pytest.approx(math.pi / 2)


def test_region_crop_samples_the_right_pixels():
    img = np.zeros((200, 300, 3), np.uint8)
    img[90:110, 140:160] = 255  # a white square centred at (150, 100)
    crop = Region(150, 100, 40).crop(img, 40)
    assert crop[20, 20].tolist() == [255, 255, 255]
    assert crop[2, 2].tolist() == [0, 0, 0]


def test_anchor_count_and_layout():
    a = ssd_anchor_centres()
    assert a.shape == (2254, 2)
    assert np.allclose(a[0], [0.5 / 28, 0.5 / 28]) and np.allclose(a[1], a[0])
    assert np.allclose(a[-1], [6.5 / 7, 6.5 / 7])


def test_letterbox_maps_back_to_frame():
    img = np.zeros((432, 768, 3), np.uint8)
    tensor, to_frame = letterbox(img, Window(0, 0, 768, 432), 224)
    assert tensor.shape == (224, 224, 3) and tensor.min() >= -1 and tensor.max() <= 1
    # The centre of the tensor is the centre of the frame; its top-left is above the frame.
    assert np.allclose(to_frame(np.array([[0.5, 0.5]])), [[384, 216]])
    assert np.allclose(to_frame(np.array([[0.0, 0.0]])), [[0, -168]])


def test_tiles_cover_the_frame():
    tiles = tile_windows(768, 432, 216)
    xs = sorted({t.x for t in tiles})
    assert xs[0] == 0 and xs[-1] + 216 == 768
    assert all(b - a <= 216 * 0.75 + 1e-9 for a, b in zip(xs, xs[1:], strict=False))
    assert tile_windows(768, 432, 800) == [Window(0, 0, 768, 432)]


def test_weighted_nms_merges_overlaps_and_keeps_separate_people():
    k = np.zeros((4, 2))
    a = Detection(0.9, (0, 0, 10, 10), k)
    b = Detection(0.6, (1, 0, 11, 10), k + 3)
    c = Detection(0.8, (50, 50, 60, 60), k)
    out = weighted_nms([b, c, a], 0.3)
    assert [d.score for d in out] == [0.9, 0.8]
    assert out[0].box[0] == pytest.approx(0.6 / 1.5)
    assert np.allclose(out[0].keypoints, 3 * 0.6 / 1.5)


def test_look_at_is_a_rotation():
    r = look_at(np.array([0, 0, 0.0]), np.array([3, 1, 2.0]))
    assert np.allclose(r @ r.T, np.eye(3)) and np.linalg.det(r) == pytest.approx(1.0)


@given(st.lists(st.floats(-1e6, 1e6), min_size=6, max_size=6))
def test_look_at_cross_product_is_numpys_bit_for_bit(xs):
    a, b = np.array(xs[:3]), np.array(xs[3:])
    assert np.array_equal(_cross(a, b), np.cross(a, b))


@given(st.floats(-89.0, 89.0))
def test_phi_is_twice_the_shoulder_yaw(beta):
    b = math.radians(beta)
    phi = facing_angle(np.zeros(3), np.array([math.cos(b), 0.0, math.sin(b)]) * 50)
    assert phi == pytest.approx(2 * beta, abs=1e-6)


def test_phi_edges_of_the_published_mapping():
    assert facing_angle(np.zeros(3), np.array([100.0, 0, 0])) == pytest.approx(0.0)
    assert facing_angle(np.zeros(3), np.array([0, 0, 100.0])) == pytest.approx(180.0)
    assert math.isnan(facing_angle(np.ones(3), np.ones(3)))
    a, *_ = quaternion(look_at(np.zeros(3), np.array([0, 0, 1.0])))
    assert a == 0.0


def test_point_in_polygon():
    sq = np.array([[0, 0], [10, 0], [10, 10], [0, 10]], dtype=float)
    assert point_in_polygon((5, 5), sq)
    assert not point_in_polygon((15, 5), sq)
    assert not point_in_polygon((float("nan"), 5), sq)


coord = st.floats(-50, 850, allow_nan=False)


@given(st.lists(st.tuples(coord, coord), min_size=1, max_size=30))
def test_points_in_polygon_agrees_with_half_planes_on_the_image_zone(points):
    """The even-odd rule against an independent test: inside all edges of a convex polygon."""
    zone = np.array([[268.8, 237.6], [499.2, 237.6], [652.8, 432.0], [115.2, 432.0]])
    pts = np.array(points)
    edge = np.roll(zone, -1, axis=0) - zone
    rel = pts[:, None, :] - zone[None, :, :]
    cross = edge[None, :, 0] * rel[..., 1] - edge[None, :, 1] * rel[..., 0]
    strictly = np.all(cross > 1e-6, axis=1)  # clockwise on screen: interior on the left
    outside = np.any(cross < -1e-6, axis=1)
    got = points_in_polygon(pts, zone)
    assert np.all(got[strictly]) and not np.any(got[outside])
    assert [point_in_polygon(tuple(p), zone) for p in pts] == got.tolist()


def test_swept_footprint_meets_a_crossing_pedestrian():
    robot = RobotGeometry(width=0.6, length=0.8, front=0.4, margin=0.0)
    # Robot at 2 m/s; pedestrian 2 m ahead walking from 2 m left to the centre line in 1 s:
    # the front (0.4 + 2t) reaches 1.9 m at t = 0.75, when the pedestrian is 0.5 m left,
    # and they touch at t = 0.8 (front at 2.0 m, pedestrian 0.4 m = half width + radius).
    t = meets_swept_footprint((2.0, 2.0), (2.0, 0.0), robot, 2.0, 0.0, 1.0, radius=0.1)
    assert t == pytest.approx(0.8)
    # Same pedestrian 4 m further away: the robot does not get there in time.
    assert meets_swept_footprint((6.0, 2.0), (6.0, 0.0), robot, 2.0, 0.0, 1.0, 0.1) is None
    # Standing robot, pedestrian walking past 2 m ahead: no contact.
    assert meets_swept_footprint((2.0, 1.0), (2.0, -1.0), robot, 0.0, 0.0, 1.0, 0.1) is None
