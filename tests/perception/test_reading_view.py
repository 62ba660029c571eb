"""Signs read in the wider view a body offers (``Observation.reading``), boxes in the frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.seams import Entity, ImageReading, Pose2D, ReadingView

pytest.importorskip("rapidocr_onnxruntime")

# fig2_hospital's start, turned towards the 101 plate about 3 m down the corridor: a view
# the 320x240 frame cannot read and the 640x480 one can (bench_signs: 49 % vs 84 % at
# 2.5-3.5 m).
LOOK_AT_101 = Pose2D(0.0, 30.0, math.radians(-120.0))


@pytest.fixture(scope="module")
def world():
    from pmnav_bt.sim.world import SimWorld

    with SimWorld("fig2_hospital") as w:
        yield w


def _base(world, reading_width):
    from pmnav_bt.sim.robot import SimBase

    return SimBase(world, pose=LOOK_AT_101, reading_width=reading_width)


def test_the_sim_body_offers_a_wider_view_rendered_when_asked(world):
    obs = _base(world, 640).observe()
    assert obs.rgb.shape == (240, 320, 3)
    r = obs.reading
    assert isinstance(r, ReadingView) and (r.width, r.height) == (640, 480)
    assert r._rgb is None  # nothing rendered until the reader asks
    big = r.rgb()
    assert big.shape == (480, 640, 3) and r.rgb() is big
    # The same view: shrunk to the frame's size it is the frame, give or take aliasing.
    import cv2

    small = cv2.resize(big, (320, 240), interpolation=cv2.INTER_AREA)
    assert np.abs(small.astype(int) - obs.rgb.astype(int)).mean() < 12
    # A plate's crop alone: the same pixels, rendered without the rest of the view.
    fresh = _base(world, 640).observe().reading
    part = fresh.crop((300, 200, 420, 260))
    assert fresh._rgb is None and np.array_equal(part, big[200:260, 300:420])
    assert _base(world, 0).observe().reading is None
    assert _base(world, 320).observe().reading is None  # no wider than the frame


def test_a_sign_too_small_in_the_frame_is_read_in_the_wider_view(world, fig2):
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    g = OcrGrounder(fig2)
    assert g.read_signs(_base(world, 0).observe()) == []
    obs = _base(world, 640).observe()
    signs = g.read_signs(obs)
    assert [d.entity for d in signs] == [Entity.room("room1")]
    x0, y0, x1, y1 = signs[0].box  # in the frame's pixels, where its depth is
    assert 0 <= x0 < x1 <= 320 and 0 <= y0 < y1 <= 240
    assert signs[0].point is not None and 2.0 < signs[0].point[0] < 4.5


def test_a_frame_without_plate_candidates_never_makes_the_wider_view(wall, fig2):
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    class Refuses:
        width, height = 640, 480

        def rgb(self):
            raise AssertionError("made the reading view for a plain wall")

        crop = rgb

    from dataclasses import replace

    g = OcrGrounder(fig2)
    assert g.read_signs(replace(wall.frame([]), reading=Refuses())) == []
    # An image at hand serves as the view too (a robot camera's full frame).
    obs = wall.frame([("102 Pharmacy", 0.0)])
    big = np.repeat(np.repeat(obs.rgb, 2, axis=0), 2, axis=1)
    signs = g.read_signs(replace(obs, reading=ImageReading(big)))
    assert [d.entity for d in signs] == [Entity.room("room2")]
    assert signs[0].box[2] <= 320
    assert isinstance(ImageReading(big), ReadingView)
    assert ImageReading(big).crop((10, 20, 30, 60)).shape == (40, 20, 3)
