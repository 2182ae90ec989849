"""studies.intent.head_reading: its image reading on hand-made heads, its agreement, its errors."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from studies.intent import head_reading
from tests.paths import ROOT

TOOL = [sys.executable, "-m", "studies.intent.head_reading"]

PX_PER_M = 300.0


def rotated(yaw_deg: float, forward: float, left: float) -> tuple[float, float]:
    """A point `forward` ahead and `left` of a head facing `yaw_deg` from the camera.

    Camera frame: x right in the image, z away from the camera. Facing the camera (yaw 0)
    is facing -z, with the person's left on image right; + yaw turns to the person's left.
    """
    a = math.radians(yaw_deg)
    # facing direction and left direction in (x, z)
    fx, fz = math.sin(a), -math.cos(a)
    lx, lz = math.cos(a), math.sin(a)
    return forward * fx + left * lx, forward * fz + left * lz


def still(head_facing_deg: float, body_facing_deg: float) -> object:
    """Landmarks of a head facing `head_facing_deg` on shoulders facing `body_facing_deg`."""
    lm = np.zeros((33, 3))
    points = {
        0: (head_facing_deg, 0.10, 0.0),  # nose tip
        2: (head_facing_deg, 0.08, 0.0315),  # left eye
        5: (head_facing_deg, 0.08, -0.0315),  # right eye
        7: (head_facing_deg, 0.0, 0.075),  # left ear
        8: (head_facing_deg, 0.0, -0.075),  # right ear
        11: (body_facing_deg, 0.0, 0.19),  # left shoulder
        12: (body_facing_deg, 0.0, -0.19),  # right shoulder
    }
    for i, (yaw, forward, left) in points.items():
        x, z = rotated(yaw, forward, left)
        lm[i] = (400 + PX_PER_M * x, 200.0, PX_PER_M * z)
    return head_reading.Still(3.0, 0.0, 0.0, 0.0, lm, np.ones(33))


@given(st.floats(-80, 80))
def test_the_image_facing_reads_a_hand_made_head_from_image_x_alone(facing: float) -> None:
    s = still(facing, 0.0)
    assert head_reading.image_facing(s) == pytest.approx(facing, abs=1.0)
    s.landmarks[:, 2] = 0.0  # no depth at all: the facing needs none
    assert head_reading.image_facing(s) == pytest.approx(facing, abs=1.0)


@given(st.floats(-60, 60), st.floats(-170, 170))
def test_the_image_reading_is_the_head_from_the_shoulders(head: float, body: float) -> None:
    facing = head_reading.wrap_deg(body + head)
    if abs(facing) > 80:  # the eye line's sign says front from back only within 90 deg
        return
    s = still(facing, body)
    assert head_reading.image_reading(s) == pytest.approx(head, abs=1.5)


def test_agreement_of_a_full_reading_a_blind_one_and_a_fifth() -> None:
    truth = [float(h) for h in range(-60, 61, 10)]
    full = head_reading.agreement(truth, truth)
    assert full.slope == pytest.approx(1.0) and full.median_error_deg == pytest.approx(0.0)
    assert full.big_turns_read == 1.0 and full.n == len(truth)
    blind = head_reading.agreement(truth, [0.0] * len(truth))
    assert blind.slope == pytest.approx(0.0) and blind.big_turns_read == 0.0
    fifth = head_reading.agreement(truth, [t / 5 for t in truth])
    assert fifth.slope == pytest.approx(0.2) and fifth.big_turns_read == 0.0
    unseen = head_reading.agreement(truth, [math.nan] * len(truth))
    assert math.isnan(unseen.slope) and unseen.n == 0


def test_a_missing_output_directory_is_one_line(tmp_path) -> None:
    r = subprocess.run(
        [*TOOL, "--out", str(tmp_path / "nowhere")],
        capture_output=True, text=True, timeout=120, cwd=ROOT,
    )  # fmt: skip
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.strip() == f"head_reading: --out {tmp_path / 'nowhere'}: no such directory"
