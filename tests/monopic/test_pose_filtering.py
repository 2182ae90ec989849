"""Landmark smoothing across frames (monopic.pose.filtering), checked against a
line-by-line port of MediaPipe's one_euro_filter.cc / low_pass_filter.cc and on the
behaviours the pose graph relies on."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from monopic.pose.filtering import (
    AUX_FILTER,
    LANDMARK_FILTER,
    LandmarkFilter,
    LowPassFilter,
    OneEuroFilter,
    object_scale,
)
from monopic.pose.landmarks import Pose
from monopic.pose.region import Region

FPS = 30.0


class ScalarOneEuro:
    """The oracle: MediaPipe's OneEuroFilter for one value, as its C++ reads (timestamps
    in seconds, "no last time" as None rather than 0)."""

    def __init__(self, min_cutoff: float, beta: float, derivate_cutoff: float) -> None:
        self.frequency, self.min_cutoff, self.beta = 30.0, min_cutoff, beta
        self.derivate_cutoff = derivate_cutoff
        self.last_time: float | None = None
        self.x_init = self.dx_init = False
        self.x_raw = self.x_stored = self.dx_stored = 0.0

    def alpha(self, cutoff: float) -> float:
        te = 1.0 / self.frequency
        tau = 1.0 / (2 * math.pi * cutoff)
        return 1.0 / (1.0 + tau / te)

    def apply(self, t: float, value_scale: float, value: float) -> float:
        if self.last_time is not None:
            if self.last_time >= t:
                return value
            self.frequency = 1.0 / (t - self.last_time)
        self.last_time = t
        dvalue = (value - self.x_raw) * value_scale * self.frequency if self.x_init else 0.0
        a = self.alpha(self.derivate_cutoff)
        edvalue = a * dvalue + (1 - a) * self.dx_stored if self.dx_init else dvalue
        self.dx_init, self.dx_stored = True, edvalue
        cutoff = self.min_cutoff + self.beta * abs(edvalue)
        a = self.alpha(cutoff)
        result = a * value + (1 - a) * self.x_stored if self.x_init else value
        self.x_init, self.x_raw, self.x_stored = True, value, result
        return result


def run(f: OneEuroFilter, values, times=None, scale: float = 1.0) -> np.ndarray:
    times = np.arange(len(values)) / FPS if times is None else times
    return np.array(
        [f.apply(np.asarray(v, float), t, scale) for v, t in zip(values, times, strict=True)]
    )


def test_first_sample_passes_through():
    f = OneEuroFilter(**LANDMARK_FILTER)
    v = np.array([[3.0, -7.5, 0.25], [120.0, 80.0, -4.0]])
    np.testing.assert_array_equal(f.apply(v, 0.0, 0.01), v)
    lp = LowPassFilter(0.1)
    np.testing.assert_array_equal(lp.apply(np.array([0.3, 0.9])), [0.3, 0.9])


@given(st.floats(-1e4, 1e4), st.integers(2, 40))
def test_a_constant_input_stays_constant(value, n):
    out = run(OneEuroFilter(**LANDMARK_FILTER), [[value, -value]] * n, scale=0.02)
    np.testing.assert_allclose(out, [[value, -value]] * n, rtol=1e-12, atol=1e-9)


# Once the step's speed has faded the cutoff is back at min_cutoff: 0.01 Hz for the
# auxiliary filter, which then creeps (a still region stays put), so its tolerance is wider.
@pytest.mark.parametrize(("params", "tol"), [(LANDMARK_FILTER, 0.01), (AUX_FILTER, 0.1)])
def test_a_step_converges_monotonically_without_overshoot(params, tol):
    values = [0.0] * 5 + [10.0] * 60
    out = run(OneEuroFilter(**params), values, scale=1 / 100)
    after = out[5:]
    assert np.all(np.diff(after) >= 0)
    assert np.all(after <= 10.0)
    assert after[0] < 10.0  # it does filter: the step is not taken at once
    assert after[-1] == pytest.approx(10.0, abs=tol)
    np.testing.assert_array_equal(out[:5], 0.0)


def test_the_region_filter_is_the_slower_one():
    """Same step, same object: the auxiliary filter (min_cutoff 0.01, beta 10) lags
    more than the landmark filter (0.05, 80), as the region should be steadier."""
    values = [0.0] * 3 + [20.0] * 10
    lm = run(OneEuroFilter(**LANDMARK_FILTER), values, scale=1 / 100)
    aux = run(OneEuroFilter(**AUX_FILTER), values, scale=1 / 100)
    assert np.all(aux[3:] < lm[3:])


def test_a_fast_moving_point_lags_little():
    """MediaPipe tunes the landmark filter so that alpha is ~0.94 and up when a point
    moves fast: a point crossing 2 object sizes per second settles a small fraction of
    a frame's step behind."""
    object_px = 100.0
    step = 2 * object_px / FPS  # px per frame
    f = OneEuroFilter(**LANDMARK_FILTER)
    values = step * np.arange(60)
    out = run(f, values, scale=1 / object_px)
    lag = values - out
    assert np.all(lag[1:] > 0)  # behind, never ahead
    # Steady state of a ramp: lag = step (1 - alpha) / alpha.
    alpha = step / (step + lag[-1])
    assert alpha > 0.94
    assert lag[-1] < 0.07 * step
    # The same motion 100x slower (a jittery point that stays put) is smoothed hard.
    slow = run(OneEuroFilter(**LANDMARK_FILTER), values / 100, scale=1 / object_px)
    slow_alpha = (step / 100) / (step / 100 + (values[-1] - slow[-1]) / 100)
    assert slow_alpha < 0.5


def test_a_timestamp_not_after_the_last_returns_the_raw_value_and_keeps_the_state():
    f = OneEuroFilter(**LANDMARK_FILTER)
    g = OneEuroFilter(**LANDMARK_FILTER)
    for t, v in ((0.0, 0.0), (0.1, 1.0), (0.2, 2.0)):
        f.apply(np.array([v]), t, 0.01)
        g.apply(np.array([v]), t, 0.01)
    np.testing.assert_array_equal(f.apply(np.array([50.0]), 0.2, 0.01), [50.0])  # same time
    np.testing.assert_array_equal(f.apply(np.array([-9.0]), 0.1, 0.01), [-9.0])  # earlier
    # The skipped samples left no trace: f continues exactly as g.
    np.testing.assert_array_equal(
        f.apply(np.array([3.0]), 0.3, 0.01), g.apply(np.array([3.0]), 0.3, 0.01)
    )


def test_reset_forgets_everything():
    f = OneEuroFilter(**LANDMARK_FILTER)
    run(f, [[0.0], [5.0], [9.0]], times=[10.0, 10.2, 10.4], scale=0.05)
    f.reset()
    # A first sample again (and an earlier timestamp is accepted after the reset).
    np.testing.assert_array_equal(f.apply(np.array([42.0]), 0.0, 0.05), [42.0])
    fresh = OneEuroFilter(**LANDMARK_FILTER)
    fresh.apply(np.array([42.0]), 0.0, 0.05)
    np.testing.assert_array_equal(
        f.apply(np.array([40.0]), 1 / FPS, 0.05), fresh.apply(np.array([40.0]), 1 / FPS, 0.05)
    )
    lp = LowPassFilter(0.1)
    lp.apply(np.array([1.0]))
    lp.reset()
    np.testing.assert_array_equal(lp.apply(np.array([0.0])), [0.0])


def test_low_pass_weights_the_newest_sample_by_alpha():
    lp = LowPassFilter(0.1)
    lp.apply(np.array([1.0, 0.0]))
    np.testing.assert_allclose(lp.apply(np.array([0.0, 1.0])), [0.9, 0.1])
    np.testing.assert_allclose(lp.apply(np.array([0.0, 1.0])), [0.81, 0.19])


samples = st.lists(st.tuples(st.floats(0.001, 0.5), st.floats(-500, 500)), min_size=1, max_size=25)


@settings(max_examples=60, deadline=None)
@given(samples, st.floats(1.0, 1000.0), st.sampled_from([LANDMARK_FILTER, AUX_FILTER]))
def test_the_array_filter_matches_mediapipes_scalar_filter(steps, object_px, params):
    """Element by element, the vectorised filter is MediaPipe's, including repeated
    timestamps (dt of 0 is drawn as a 'not later' sample)."""
    times = np.cumsum([0.0] + [dt if dt > 0.002 else 0.0 for dt, _ in steps[1:]])
    values = np.array([[v, -0.5 * v, v * v / 500] for _, v in steps])
    f = OneEuroFilter(**params)
    oracles = [ScalarOneEuro(**params) for _ in range(3)]
    for t, row in zip(times, values, strict=True):
        got = f.apply(row, float(t), 1 / object_px)
        want = [
            o.apply(float(t), 1 / object_px, float(x)) for o, x in zip(oracles, row, strict=True)
        ]
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9)


def make_pose(shift: float = 0.0, vis: float = 0.8, size: float = 50.0) -> Pose:
    rng = np.random.default_rng(0)
    lm = rng.uniform(0, 100, (33, 3)) + [shift, 0.0, 0.0]
    aux = np.array([[50.0 + shift, 60.0], [50.0 + shift, 60.0 - size / 2]] + [[0.0, 0.0]] * 4)
    return Pose(
        landmarks=lm,
        visibility=np.full(33, vis),
        presence=np.full(33, 0.9),
        score=0.99,
        region=Region(50.0, 50.0, 100.0),
        aux=aux,
    )


def test_object_scale_is_the_side_of_the_unenlarged_alignment_square():
    assert object_scale(make_pose(size=50.0).aux) == pytest.approx(50.0)


def test_landmark_filter_smooths_landmarks_visibility_and_aux_and_forgets_on_reset():
    f = LandmarkFilter()
    first = make_pose()
    f.apply(make_pose(shift=-20.0), -1 / FPS)  # a track to forget
    f.reset()
    out0 = f.apply(first, 0.0)
    np.testing.assert_array_equal(out0.landmarks, first.landmarks)
    moved = make_pose(shift=3.0, vis=0.0)
    out1 = f.apply(moved, 1 / FPS)
    # Between the two frames, nearer the new one for landmarks (they follow motion).
    x0, x1, got = first.landmarks[:, 0], moved.landmarks[:, 0], out1.landmarks[:, 0]
    assert np.all((got > x0) & (got < x1))
    np.testing.assert_allclose(out1.visibility, 0.9 * 0.8)  # alpha 0.1 on visibility
    assert np.all(out1.aux[:2, 0] > first.aux[:2, 0]) and np.all(out1.aux[:2, 0] < 53.0)
    np.testing.assert_array_equal(out1.presence, moved.presence)  # not filtered
    assert out1.score == moved.score and out1.region == moved.region
    f.reset()
    again = f.apply(moved, 2 / FPS)
    np.testing.assert_array_equal(again.landmarks, moved.landmarks)
    np.testing.assert_array_equal(again.visibility, moved.visibility)
    np.testing.assert_array_equal(again.aux, moved.aux)


def test_with_smooth_landmarks_off_only_the_region_points_are_filtered():
    """As MediaPipe with smooth_landmarks=False: the auxiliary filter has no switch."""
    f = LandmarkFilter(smooth_landmarks=False)
    f.apply(make_pose(), 0.0)
    moved = make_pose(shift=3.0, vis=0.0)
    out = f.apply(moved, 1 / FPS)
    np.testing.assert_array_equal(out.landmarks, moved.landmarks)
    np.testing.assert_array_equal(out.visibility, moved.visibility)
    assert np.all(out.aux[:2, 0] < moved.aux[:2, 0])
    off = LandmarkFilter(smooth_landmarks=False, smooth_region=False)
    off.apply(make_pose(), 0.0)
    assert off.apply(moved, 1 / FPS) is moved


def test_a_degenerate_object_scale_passes_landmarks_through():
    f = LandmarkFilter()
    f.apply(make_pose(), 0.0)
    flat = make_pose(shift=3.0, size=0.0)
    out = f.apply(flat, 1 / FPS)
    np.testing.assert_array_equal(out.landmarks, flat.landmarks)
    np.testing.assert_array_equal(out.aux, flat.aux)
