"""From light to an 8-bit frame: electrons with shot noise, read noise, gain, the digitiser,
the tone curve and optional JPEG compression.

The renderer's 8-bit output is read as sRGB-encoded light (MuJoCo writes its colour buffer
without a transfer function, and the scene's colours were chosen to look right that way),
so decoding it with the sRGB curve gives the linear light. Each colour channel is treated
as a sensor pixel of its own (no Bayer mosaic, no demosaicing). Shot noise is Poisson,
drawn as a Gaussian of the same variance: the frame's pixels hold hundreds to thousands of
electrons, where the two differ by less than the digitiser's step; read noise is Gaussian.
"""

from __future__ import annotations

import cv2
import numpy as np

from sim.sensor.exposure import METER_STRIDE
from sim.sensor.spec import SensorSpec


def srgb_decode(v: np.ndarray) -> np.ndarray:
    """sRGB-encoded values in [0, 1] to linear light."""
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def srgb_encode(v: np.ndarray) -> np.ndarray:
    """Linear light in [0, 1] to sRGB-encoded values."""
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


LINEAR_OF_U8 = srgb_decode(np.arange(256) / 255.0).astype(np.float32)


def linear_light(image: np.ndarray) -> np.ndarray:
    """A rendered 8-bit frame as linear light (float32, same shape)."""
    return cv2.LUT(image, LINEAR_OF_U8)  # a few times faster than numpy's indexing


LINEAR_OF_LINEAR_U8 = (np.arange(256) / 255.0).astype(np.float32)


def photometric_light(image: np.ndarray) -> np.ndarray:
    """A photometric render (night: each light's value is its lux over the full scale, so
    the renderer's output is already linear in light) as linear light: no sRGB decoding."""
    return cv2.LUT(image, LINEAR_OF_LINEAR_U8)


POOL_SIZE = 1 << 22  # standard normal deviates a sensor draws once per run (16 MB)


class NoisePool:
    """Standard normal deviates for a run's frames: a pool drawn once from the run's
    stream, each frame a slice of it at a random offset.

    Drawing a million Gaussian deviates costs about 20 ms on one core (bench/simulator.py's
    camera rows), as much as the rest of the frame's readout; a slice costs nothing. Within
    a frame the deviates are independent; two frames share deviates only shifted by the
    difference of their offsets (a pixel's noise in one frame is another pixel's in the
    next), which no detector can use. A frame larger than the pool draws afresh.
    """

    def __init__(self, rng: np.random.Generator, size: int = POOL_SIZE) -> None:
        self.rng = rng
        self.pool = rng.standard_normal(size, dtype=np.float32)

    def draw(self, shape: tuple[int, ...]) -> np.ndarray:
        n = int(np.prod(shape))
        if n > self.pool.size:
            return self.rng.standard_normal(shape, dtype=np.float32)
        start = int(self.rng.integers(0, self.pool.size - n + 1))
        return self.pool[start : start + n].reshape(shape)


class Readout:
    """One sensor's image formation; stateless apart from its lookup table."""

    def __init__(self, spec: SensorSpec) -> None:
        self.spec = spec
        codes = np.arange(spec.levels + 1) / spec.levels
        toned = srgb_encode(codes) if spec.tone == "srgb" else codes
        self._tone = np.round(255.0 * toned).astype(np.uint8)  # code -> 8-bit output

    def read(
        self,
        light: np.ndarray,
        electrons_per_s: float,
        exposure_s: float,
        gain: float,
        normals: NoisePool,
    ) -> tuple[np.ndarray, float]:
        """The 8-bit frame and its mean linear signal (share of full scale, the meter's)
        for linear `light` (float32, H x W x 3) exposed `exposure_s` at `gain`."""
        spec = self.spec
        electrons = light * np.float32(electrons_per_s * exposure_s)
        if spec.noise:
            sigma = np.sqrt(electrons + np.float32(spec.read_noise_e**2))
            sigma *= normals.draw(light.shape)
            electrons += sigma
        np.clip(electrons, 0.0, spec.full_well_e, out=electrons)
        electrons *= np.float32(gain * spec.levels / spec.full_well_e)
        np.clip(electrons, 0.0, spec.levels, out=electrons)
        codes = np.rint(electrons).astype(np.uint16)
        signal = float(codes[::METER_STRIDE, ::METER_STRIDE].mean()) / spec.levels
        image = np.take(self._tone, codes)  # faster than indexing for 16-bit codes
        if spec.jpeg_quality:
            image = compress(image, spec.jpeg_quality)
        return image, signal


def compress(image: np.ndarray, quality: int) -> np.ndarray:
    """The frame through JPEG at `quality` and back (what an MJPEG camera stream delivers)."""
    ok, data = cv2.imencode(".jpg", image[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise RuntimeError("JPEG encoding failed")
    return np.ascontiguousarray(cv2.imdecode(data, cv2.IMREAD_COLOR)[..., ::-1])
