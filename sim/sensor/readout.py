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
    return LINEAR_OF_U8[image]


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
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, float]:
        """The 8-bit frame and its mean linear signal (share of full scale, the meter's)
        for linear `light` (float32, H x W x 3) exposed `exposure_s` at `gain`."""
        spec = self.spec
        electrons = light * np.float32(electrons_per_s * exposure_s)
        if spec.noise:
            sigma = np.sqrt(electrons + np.float32(spec.read_noise_e**2))
            electrons += sigma * rng.standard_normal(light.shape, dtype=np.float32)
        np.clip(electrons, 0.0, spec.full_well_e, out=electrons)
        electrons *= np.float32(gain * spec.levels / spec.full_well_e)
        np.clip(electrons, 0.0, spec.levels, out=electrons)
        codes = np.rint(electrons).astype(np.uint16)
        signal = float(codes[::METER_STRIDE, ::METER_STRIDE].mean()) / spec.levels
        image = self._tone[codes]
        if spec.jpeg_quality:
            image = compress(image, spec.jpeg_quality)
        return image, signal


def compress(image: np.ndarray, quality: int) -> np.ndarray:
    """The frame through JPEG at `quality` and back (what an MJPEG camera stream delivers)."""
    ok, data = cv2.imencode(".jpg", image[..., ::-1], [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:
        raise RuntimeError("JPEG encoding failed")
    return np.ascontiguousarray(cv2.imdecode(data, cv2.IMREAD_COLOR)[..., ::-1])
