"""The ground-plane Kalman track: noise carried from pixels, priors, gating."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.camera import CameraModel
from monopic.features.ground import GroundMotion, foot_on_ground
from monopic.features.ground_track import GroundTrack, GroundTrackConfig
from monopic.frame import EgoState

CAM = CameraModel.from_fov(768, 432, 65, 1.2, pitch_deg=5)
EGO = EgoState(CAM, speed=0.0)


def noisy_walk(
    motion: GroundMotion,
    start: tuple[float, float],
    velocity: tuple[float, float],
    seconds: float,
    pixel_sigma: float,
    seed: int = 0,
) -> list[tuple[float, float]]:
    """A pedestrian walking at constant velocity seen by a standing camera, foot pixels
    with Gaussian noise; returns the estimated velocity at each frame."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(int(seconds * 15)):
        t = i / 15
        p = np.array([start[0] + velocity[0] * t, start[1] + velocity[1] * t, 0.0])
        px = CAM.project(p) + rng.normal(0.0, pixel_sigma, 2)
        motion.observe_ego(t, EGO)
        got = motion.update(t, EGO, (float(px[0]), float(px[1])), 40.0)
        assert got is not None
        out.append(got[1])
    return out


def test_far_walker_velocity_stays_physical_under_pixel_noise() -> None:
    # 25 m away, 2 px of foot jitter is a metre on the ground: differencing it over a few
    # frames reads tens of m/s. The track never leaves walking speeds.
    vel = noisy_walk(GroundMotion(), (25.0, 3.0), (0.0, -1.4), 3.0, pixel_sigma=2.0)
    speeds = [math.hypot(*v) for v in vel]
    assert max(speeds) < 3.5
    assert np.mean(vel[-15:], axis=0) == pytest.approx((0.0, -1.4), abs=0.35)


def test_near_walker_velocity_converges_within_a_second() -> None:
    vel = noisy_walk(GroundMotion(), (6.0, 2.0), (0.0, -1.4), 2.0, pixel_sigma=1.0)
    assert vel[15] == pytest.approx((0.0, -1.4), abs=0.3)
    assert np.mean(vel[15:], axis=0) == pytest.approx((0.0, -1.4), abs=0.1)


def test_noise_stretches_along_the_line_of_sight_and_grows_with_range() -> None:
    near = foot_on_ground(EGO, tuple(CAM.project(np.array([5.0, 0.0, 0.0]))), 1.0)
    far = foot_on_ground(EGO, tuple(CAM.project(np.array([20.0, 0.0, 0.0]))), 1.0)
    assert near is not None and far is not None
    (gn, cn), (gf, cf) = near, far
    assert gn == pytest.approx((5.0, 0.0), abs=1e-6) and gf == pytest.approx((20.0, 0.0), abs=1e-6)
    # Straight ahead: forward variance dominates, and it grows about with range^4.
    assert cf[0, 0] > 20 * cf[1, 1]
    assert cf[0, 0] / cn[0, 0] > 100
    above = foot_on_ground(EGO, (384.0, 0.0), 1.0)  # above the horizon: no ground
    assert above is None


def test_a_quieter_column_narrows_only_the_across_sight_noise() -> None:
    # Straight ahead the column maps to the lateral axis, the row to the forward one.
    px = tuple(CAM.project(np.array([8.0, 0.0, 0.0])))
    same = foot_on_ground(EGO, px, 2.0, 0.0)
    quiet = foot_on_ground(EGO, px, 2.0, 0.0, column_noise=0.5)
    assert same is not None and quiet is not None
    assert quiet[1][0, 0] == pytest.approx(same[1][0, 0], rel=1e-9)
    assert quiet[1][1, 1] == pytest.approx(same[1][1, 1] / 16, rel=1e-6)
    assert foot_on_ground(EGO, px, 2.0, 0.0, column_noise=2.0)[1] == pytest.approx(same[1])


def test_the_column_noise_follows_the_apparent_height() -> None:
    motion = GroundMotion(
        GroundTrackConfig(column_pixel_noise=0.3, column_pixel_noise_per_height=0.01)
    )
    assert motion._pixel_noise(80.0) == pytest.approx((1.0 + 0.025 * 80, 0.3 + 0.8))
    assert GroundMotion()._pixel_noise(80.0) == (1.0 + 0.025 * 80, None)
    with pytest.raises(ValueError, match="column_pixel_noise"):
        GroundTrackConfig(column_pixel_noise=0.0)


def test_a_quieter_column_reads_a_stop_across_the_line_of_sight_sooner() -> None:
    # A walker crossing 8 m ahead stops dead; both tracks see the same noiseless pixels
    # (the hips' column as steady as measured). The one that believes its column reads
    # the lateral speed fall sooner.
    tracks = [GroundMotion(), GroundMotion(GroundTrackConfig(column_pixel_noise=0.5))]
    lateral = {0: [], 1: []}
    for i in range(45):
        t = i / 15
        y = 2.0 - 1.4 * min(t, 2.0)
        px = CAM.project(np.array([8.0, y, 0.0]))
        for j, m in enumerate(tracks):
            m.observe_ego(t, EGO)
            got = m.update(t, EGO, (float(px[0]), float(px[1])), 60.0)
            assert got is not None
            lateral[j].append(got[1][1])
    # 0.2 s after the stop (frame 33): the quiet column's track has shed more of the speed
    assert abs(lateral[1][33]) < abs(lateral[0][33]) - 0.1
    assert lateral[1][29] == pytest.approx(-1.4, abs=0.1)  # and it walked at pace before


def test_a_jump_is_not_believed_but_a_new_place_is_taken_after_three() -> None:
    track = GroundTrack()
    R = np.eye(2) * 0.01
    for i in range(10):
        track.update(i / 15, np.array([10.0, 0.0]), R)
    assert not track.update(10 / 15, np.array([20.0, 0.0]), R)  # one wild measurement
    assert track.position == pytest.approx((10.0, 0.0), abs=0.05)
    assert not track.update(11 / 15, np.array([20.0, 0.0]), R)
    assert track.update(12 / 15, np.array([20.0, 0.0]), R)  # the third: start again there
    assert track.position == pytest.approx((20.0, 0.0))
    assert track.velocity == pytest.approx((0.0, 0.0))


def test_track_refuses_time_going_back_and_empty_state() -> None:
    track = GroundTrack()
    with pytest.raises(ValueError, match="no state"):
        _ = track.position
    track.update(1.0, np.zeros(2), np.eye(2))
    with pytest.raises(ValueError, match="timestamps must increase"):
        track.update(1.0, np.zeros(2), np.eye(2))
    with pytest.raises(ValueError, match="acceleration"):
        GroundTrackConfig(acceleration=0.0)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0.01, 0.2),  # time step
            st.floats(-30, 30),
            st.floats(-30, 30),
            st.floats(0.001, 25.0),  # measurement variance
        ),
        min_size=1,
        max_size=30,
    )
)
def test_covariance_stays_symmetric_positive_definite(steps) -> None:
    track = GroundTrack()
    t = 0.0
    for dt, x, y, var in steps:
        t += dt
        track.update(t, np.array([x, y]), np.eye(2) * var)
        assert track.P is not None
        assert np.allclose(track.P, track.P.T, atol=1e-9)
        assert np.all(np.linalg.eigvalsh(track.P) > 0)
