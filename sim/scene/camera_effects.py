"""The camera's flaws: motion blur while the body turns, exposure off by a gain, and
sensor noise, as the config's ``world`` section asks (``camera_exposure_time``,
``camera_exposure``, ``camera_noise``).

In the order light meets them: the shutter stays open ``exposure_time`` seconds, so while
the body turns at ``yaw_rate`` the scene sweeps ``|yaw_rate| * exposure_time * fx``
pixels along the image's x axis (a box blur of that length; nothing while the body stands
or drives straight, where the sweep is under a pixel); auto exposure misses by a gain drawn
once per episode (a multiple of the brightness); then each pixel gets Gaussian read noise
of ``noise * 255`` (per channel). The noise differs from frame to frame but is
reproducible: it is seeded by the episode's seed and what identifies the frame (its time
stamp, the camera's pose, the pixels rendered), not by the order frames were rendered in,
which worker threads may change. Drawing fresh Gaussian noise costs more than a third of
a 320x240 frame's render, so each episode draws one field of noise (``NOISE_TILE``
square, repeated for larger frames) and each frame takes a window of it at an offset
drawn from the frame's key: a different pattern per frame, for a fraction of the cost. Depth and
segmentation are left exact (the depth a robot's tree uses comes from a sensor this
module does not model).

With the clean preset (no noise, gain 1, no exposure time) a frame passes through
untouched: bit-identical to a frame without this module.
"""

from __future__ import annotations

import math
import zlib
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import cv2
import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.sim.world import SimWorld

MIN_BLUR_PX = 1.0  # a sweep shorter than a pixel does not show
NOISE_TILE = 512  # pixels: the noise field repeats this far apart (unseen at 2 % noise)


@dataclass(frozen=True)
class CameraEffects:
    """One episode's camera: ``noise`` (std, fraction of 255), exposure ``gain``,
    ``exposure_time`` (s) and the ``seed`` its noise is drawn from."""

    noise: float = 0.0
    gain: float = 1.0
    exposure_time: float = 0.0
    seed: int = 0
    _bank: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def of_world(cls, world: SimWorld) -> CameraEffects:
        """The camera ``world.scene`` asks for; the gain is drawn from ``world.rng("camera")``."""
        scene = world.scene
        lo, hi = scene.camera_exposure
        gain = float(lo) if lo == hi else float(world.rng("camera").uniform(lo, hi))
        return cls(float(scene.camera_noise), gain, float(scene.camera_exposure_time), world.seed)

    @property
    def identity(self) -> bool:
        """True when frames pass through untouched (the clean preset)."""
        return self.noise == 0.0 and self.gain == 1.0 and self.exposure_time == 0.0

    def blur_px(self, yaw_rate: float, fx: float) -> float:
        """Length (pixels) of the blur of a frame taken while turning at ``yaw_rate`` rad/s."""
        return abs(yaw_rate) * self.exposure_time * fx

    def margin_px(self, yaw_rate: float, fx: float) -> int:
        """Pixels a part of the image must be rendered wider on each side for its blur."""
        return int(math.ceil(self.blur_px(yaw_rate, fx) / 2.0)) + 1

    def apply(
        self, rgb: np.ndarray, *, yaw_rate: float, fx: float, key: tuple[float, ...]
    ) -> np.ndarray:
        """The frame ``rgb`` (uint8) as this camera takes it while turning at ``yaw_rate``
        (rad/s, camera with focal length ``fx`` pixels); ``key`` identifies the frame
        (stamp, pose, pixels) and seeds its noise."""
        if self.identity:
            return rgb
        img = rgb.astype(np.float32)
        length = self.blur_px(yaw_rate, fx)
        if length >= MIN_BLUR_PX:
            img = motion_blur(img, length)
        if self.gain != 1.0:
            img *= self.gain
        if self.noise > 0.0:
            img += self._noise(img.shape, key)
        img += 0.5
        return np.clip(img, 0.0, 255.0, out=img).astype(np.uint8)

    def _noise(self, shape: tuple[int, ...], key: tuple[float, ...]) -> np.ndarray:
        """Noise for one frame: a window of the episode's noise field (``NOISE_TILE``
        square, repeated as far as the frame needs) at an offset drawn from the key. The
        window's values depend on the seed and the key alone, not on earlier frames."""
        h, w, c = shape
        tiled = self._bank.get("tiled")
        if tiled is None or tiled.shape[0] < NOISE_TILE + h or tiled.shape[1] < NOISE_TILE + w:
            base = self._bank.get("base")
            if base is None:
                rng = np.random.default_rng([self.seed & 0xFFFFFFFF, NOISE_TILE])
                base = rng.standard_normal((NOISE_TILE, NOISE_TILE, c), dtype=np.float32)
                base *= np.float32(self.noise * 255.0)
                self._bank["base"] = base
            have = (0, 0) if tiled is None else tiled.shape[:2]
            reps = (
                -(-max(have[0], NOISE_TILE + h) // NOISE_TILE),
                -(-max(have[1], NOISE_TILE + w) // NOISE_TILE),
                1,
            )
            tiled = np.tile(base, reps)
            self._bank["tiled"] = tiled
        pick = np.random.default_rng([self.seed & 0xFFFFFFFF, _key_bits(key)])
        y, x = (int(v) for v in pick.integers(NOISE_TILE, size=2))
        return tiled[y : y + h, x : x + w]


def motion_blur(img: np.ndarray, length: float) -> np.ndarray:
    """A box blur ``length`` pixels long along x, centred (the sweep of a turning camera
    during the exposure): each tap weighs how much of its pixel the box covers."""
    r = length / 2.0
    half = int(math.ceil(r - 0.5))
    i = np.arange(-half, half + 1, dtype=np.float64)
    kernel = np.clip(np.minimum(i + 0.5, r) - np.maximum(i - 0.5, -r), 0.0, None)
    kernel = (kernel / kernel.sum()).astype(np.float32)
    return cv2.filter2D(img, -1, kernel[None, :], borderType=cv2.BORDER_REPLICATE)


def _key_bits(key: tuple[float, ...]) -> int:
    return zlib.crc32(np.asarray(key, np.float64).tobytes())
