"""SSD anchors of the BlazePose detector (MediaPipe's SsdAnchorsCalculator options).

5 layers, strides 8/16/32/32/32, one aspect ratio plus the interpolated scale, fixed
anchor size: two anchors per cell per layer, layers of equal stride share one grid.
28x28x2 + 14x14x2 + 7x7x6 = 2254 anchors for the 224x224 input.
"""

from __future__ import annotations

import numpy as np

INPUT_SIZE = 224
STRIDES = (8, 16, 32, 32, 32)
ANCHORS_PER_LAYER = 2  # aspect ratio 1.0 and the interpolated-scale anchor


def ssd_anchor_centres(
    input_size: int = INPUT_SIZE, strides: tuple[int, ...] = STRIDES
) -> np.ndarray:
    """(N, 2) anchor centres in normalised [0, 1] coordinates, in the model's output order."""
    centres: list[tuple[float, float]] = []
    layer = 0
    while layer < len(strides):
        stride = strides[layer]
        last = layer
        while last < len(strides) and strides[last] == stride:
            last += 1
        per_cell = ANCHORS_PER_LAYER * (last - layer)
        cells = int(np.ceil(input_size / stride))
        for y in range(cells):
            for x in range(cells):
                centres.extend([((x + 0.5) / cells, (y + 0.5) / cells)] * per_cell)
        layer = last
    return np.asarray(centres, dtype=np.float32)
