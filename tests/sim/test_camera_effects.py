"""The camera's flaws (sim/scene/camera_effects.py): motion blur only while turning and as
long as the sweep, exposure gain scales brightness, noise of the set size that differs per
frame but repeats per seed, and the reading view's crops taken by the same camera."""

from __future__ import annotations

import numpy as np
import pytest

from pmnav_bt.config import load_config
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.scene.camera_effects import CameraEffects, motion_blur
from pmnav_bt.sim.world import SimWorld

BUILDING = "straight_office"


def world(*sets: str, seed: int = 0) -> SimWorld:
    return SimWorld(BUILDING, scene=load_config(None, list(sets)).world, seed=seed)


def frame(w: SimWorld, turn: float = 0.0, **kw) -> tuple[SimBase, np.ndarray]:
    base = SimBase(w, SimClock(), width=160, height=120, **kw)
    if turn:
        base.set_velocity(0.0, turn)
    return base, base.observe().rgb


def test_the_clean_camera_passes_frames_through():
    cam = CameraEffects()
    img = np.random.default_rng(0).integers(0, 256, (4, 5, 3), dtype=np.uint8)
    assert cam.identity and cam.apply(img, yaw_rate=1.9, fx=100.0, key=(0.0,)) is img


def test_blur_spreads_a_line_over_the_sweep_and_keeps_its_light():
    img = np.zeros((3, 41, 3), np.uint8)
    img[:, 20] = 200
    cam = CameraEffects(exposure_time=0.02)
    out = cam.apply(img, yaw_rate=1.0, fx=250.0, key=(0.0,))  # 1 * 0.02 * 250 = 5 px
    assert np.count_nonzero(out[1, :, 0]) == 5
    assert int(out[1, :, 0].sum()) == pytest.approx(200, abs=3)
    assert np.array_equal(cam.apply(img, yaw_rate=0.0, fx=250.0, key=(0.0,)), img)
    two = motion_blur(img[..., 0].astype(np.float32), 2.0)  # half a pixel on each side
    assert two[1, 19:22].tolist() == [50.0, 100.0, 50.0]


def test_blur_only_while_the_body_turns():
    with world() as w:
        _, still_clean = frame(w)
        _, turning_clean = frame(w, turn=1.9)
    assert np.array_equal(still_clean, turning_clean)
    with world("world.camera_exposure_time=0.05") as w:
        _, still = frame(w)
        _, forward = frame(w, turn=0.0)
        base, turning = frame(w, turn=1.9)
        assert base.yaw_rate() == pytest.approx(1.9)
    assert np.array_equal(still, still_clean) and np.array_equal(forward, still_clean)
    assert not np.array_equal(turning, still_clean)
    # blurred along x only: the horizontal detail drops, each column's mean stays
    dx = np.abs(np.diff(turning.astype(float), axis=1)).mean()
    assert dx < 0.7 * np.abs(np.diff(still_clean.astype(float), axis=1)).mean()


def test_exposure_gain_scales_brightness():
    with world() as w:
        _, clean = frame(w)
    with world("world.camera_exposure=[1.5,1.5]") as w:
        _, bright = frame(w)
    ok = clean < 160  # not clipped at 255 once brightened
    ratio = bright[ok].astype(float).sum() / clean[ok].astype(float).sum()
    assert ratio == pytest.approx(1.5, abs=0.01)


def test_noise_has_the_set_std_differs_per_frame_and_repeats_per_seed():
    with world() as w:
        _, clean = frame(w)
    with world("world.camera_noise=0.05", seed=4) as w:
        base, noisy = frame(w)
        base.clock.wait(0.5)
        later = base.observe().rgb
    with world("world.camera_noise=0.05", seed=4) as w:
        _, again = frame(w)
    with world("world.camera_noise=0.05", seed=5) as w:
        _, other_seed = frame(w)
    ok = (clean > 60) & (clean < 195)  # away from clipping at 0 and 255
    diff = noisy.astype(float) - clean.astype(float)
    assert diff[ok].std() == pytest.approx(0.05 * 255, rel=0.05)
    assert abs(diff[ok].mean()) < 0.5
    assert np.array_equal(noisy, again)
    assert not np.array_equal(noisy, later) and not np.array_equal(noisy, other_seed)


def test_reading_crops_are_taken_by_the_same_camera():
    """A crop rendered alone blurs and brightens as the whole reading view does (it is
    rendered wider by the blur's reach), and gets noise of the same size."""
    sets = ("world.camera_exposure_time=0.05", "world.camera_exposure=[1.3,1.3]")
    with world(*sets) as w:
        base = SimBase(w, SimClock(), width=160, height=120, reading_width=320)
        base.set_velocity(0.0, -1.5)
        obs = base.observe()
        box = (50, 40, 170, 130)
        crop = obs.reading.crop(box)
        full = obs.reading.rgb()
        assert np.array_equal(crop, full[40:130, 50:170])
        still = SimBase(w, SimClock(), width=160, height=120, reading_width=320).observe()
        assert not np.array_equal(still.reading.crop(box), crop)
    with world("world.camera_noise=0.05") as w:
        reading = SimBase(w, SimClock(), width=160, height=120, reading_width=320).observe()
        noisy_crop = reading.reading.crop(box).astype(float)
    with world() as w:
        reading = SimBase(w, SimClock(), width=160, height=120, reading_width=320).observe()
        clean_crop = reading.reading.crop(box).astype(float)
    ok = (clean_crop > 60) & (clean_crop < 195)
    assert (noisy_crop - clean_crop)[ok].std() == pytest.approx(0.05 * 255, rel=0.1)


def test_a_frames_noise_depends_on_its_key_alone():
    """Frames rendered in another order (worker threads) get the same noise each."""
    small = np.full((120, 160, 3), 128, np.uint8)
    large = np.full((480, 640, 3), 128, np.uint8)
    first = CameraEffects(noise=0.05, seed=3)
    a = first.apply(small, yaw_rate=0.0, fx=100.0, key=(1.0,))
    first.apply(large, yaw_rate=0.0, fx=100.0, key=(2.0,))
    assert np.array_equal(first.apply(small, yaw_rate=0.0, fx=100.0, key=(1.0,)), a)
    other = CameraEffects(noise=0.05, seed=3)
    other.apply(large, yaw_rate=0.0, fx=100.0, key=(2.0,))
    assert np.array_equal(other.apply(small, yaw_rate=0.0, fx=100.0, key=(1.0,)), a)
    assert not np.array_equal(other.apply(small, yaw_rate=0.0, fx=100.0, key=(1.5,)), a)
