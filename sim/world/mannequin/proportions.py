"""A person's segment lengths and girths, from stature alone.

Proportions follow anthropometric tables (segment lengths as fractions of stature,
Drillis and Contini) with a head that is relatively larger for a child, so one `height`
parameter gives both the 1.8 m adult and the 1.15 m child. The builder places every part
from these, and the compiled mannequin reads the hip height to stand the pose up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Proportions:
    """Segment lengths and girths (m) derived from stature."""

    height: float
    head: float  # chin to crown
    body: float  # stature scale for everything below the chin (equals height for adults)

    @classmethod
    def of(cls, height: float) -> Proportions:
        # Head height is about 1/7.7 of an adult's stature and about 1/6 of a young
        # child's; the rest of the body scales so that chin height plus head = stature.
        head_fraction = float(np.interp(height, [1.10, 1.70], [0.165, 0.13]))
        head = head_fraction * height
        return cls(height=height, head=head, body=(height - head) / 0.87)

    # Heights above the ground, standing straight.
    @property
    def chin_z(self) -> float:
        return self.height - self.head

    @property
    def shoulder_z(self) -> float:
        return 0.80 * self.body

    @property
    def waist_z(self) -> float:
        return 0.60 * self.body

    @property
    def hip_z(self) -> float:
        return 0.53 * self.body

    @property
    def ankle_z(self) -> float:
        return 0.039 * self.body

    # Half widths and segment lengths.
    @property
    def shoulder_half(self) -> float:
        return 0.105 * self.body

    @property
    def hip_half(self) -> float:
        return 0.05 * self.body

    @property
    def upper_arm(self) -> float:
        return 0.186 * self.body

    @property
    def forearm(self) -> float:
        return 0.146 * self.body

    @property
    def hand(self) -> float:
        return 0.108 * self.body

    @property
    def thigh(self) -> float:
        return self.hip_z - 0.285 * self.body

    @property
    def shin(self) -> float:
        return 0.285 * self.body - self.ankle_z

    @property
    def foot(self) -> float:
        return 0.152 * self.body

    @property
    def heel_back(self) -> float:
        return 0.045 * self.body
