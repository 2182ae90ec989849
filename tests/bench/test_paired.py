"""The paired block bootstrap behind the landmark-error verdict of bench/compare_reference."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from bench.paired import blocks, paired_mean_difference, paired_median_difference


def errors(n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [rng.gamma(2.0, 1.5, size=2) for _ in range(n)]


@given(
    st.lists(st.integers(0, 3), min_size=1, max_size=60).map(sorted),
    st.integers(1, 10),
)
def test_blocks_cut_frames_into_short_runs_of_one_sequence(seq: list[int], size: int) -> None:
    sequence = np.array(seq)
    cut = blocks(sequence, size)
    assert np.array_equal(np.concatenate(cut), np.arange(len(seq)))
    for b in cut:
        assert 1 <= len(b) <= size
        assert len(set(sequence[b])) == 1


def test_identical_sides_are_equal() -> None:
    a = errors(60, 1)
    d = paired_median_difference(a, [x.copy() for x in a], np.zeros(60, int), resamples=300)
    assert d.difference == 0 and d.low == 0 and d.high == 0
    assert d.verdict == "equal"


@pytest.mark.parametrize(("shift", "verdict"), [(0.5, "worse"), (-0.5, "better")])
def test_a_shift_on_every_frame_is_detected(shift: float, verdict: str) -> None:
    b = errors(60, 2)
    a = [x + shift for x in b]
    d = paired_median_difference(a, b, np.repeat([0, 1], 30), resamples=300)
    assert d.difference == pytest.approx(shift)
    assert d.verdict == verdict


def test_noise_alone_is_not_called_a_difference() -> None:
    # Two independent draws from one distribution on 60 frames: not a real difference.
    d = paired_median_difference(errors(60, 3), errors(60, 4), np.zeros(60, int), resamples=500)
    assert d.low < 0 < d.high
    assert d.verdict == "equal"


def test_mismatched_frames_are_refused() -> None:
    with pytest.raises(ValueError, match="frame 0"):
        paired_median_difference([np.ones(2)], [np.ones(3)], np.zeros(1, int))
    with pytest.raises(ValueError, match="one error array per frame"):
        paired_median_difference([np.ones(2)], [], np.zeros(1, int))


def test_the_mean_difference_sees_a_few_large_errors_the_median_ignores() -> None:
    """Issue 21 bounds an int8 model by the mean: a model that is off by 5 px on one frame
    in six moves the mean by about 0.8 px while leaving the median where it was."""
    b = errors(60, 5)
    a = [x + (5.0 if k % 6 == 0 else 0.0) for k, x in enumerate(b)]
    seq = np.repeat([0, 1], 30)
    mean = paired_mean_difference(a, b, seq, resamples=500)
    assert mean.difference == pytest.approx(5.0 / 6, abs=1e-9)
    assert 0 < mean.low < mean.difference < mean.high
    assert mean.verdict == "worse"
    assert abs(paired_median_difference(a, b, seq, resamples=300).difference) < 0.5
