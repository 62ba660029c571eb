"""The reader measures a plate's text size itself: a coloured plate whose text and border
close into one blob is not taken for one line of text as tall as the plate."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from pmnav_bt.perception.signs import ink_line_height
from pmnav_bt.sim.scene.plates import make_plate, texels_per_m
from pmnav_bt.sim.scene.signage import CLEAN_STYLE, COLOUR_SCHEMES

WALL = (176, 172, 166)


def plate_frame(text: str, scheme: str, cap_px: float) -> tuple[np.ndarray, tuple]:
    """A 640x480 frame of a wall with one plate of ``scheme`` whose capitals are
    ``cap_px`` pixels tall; and the plate's box."""
    text_rgb, plate_rgb = COLOUR_SCHEMES[scheme]
    style = replace(
        CLEAN_STYLE, font="dejavu_sans", plate_width=0.3, cap_height=0.04,
        text_rgb=text_rgb, plate_rgb=plate_rgb,
    )
    tex = make_plate(text, style)
    s = cap_px / (style.cap_height * texels_per_m(style.cap_height))
    plate = cv2.resize(tex.image, None, fx=s, fy=s, interpolation=cv2.INTER_AREA)
    img = np.full((480, 640, 3), WALL, np.uint8)
    h, w = plate.shape[:2]
    img[200 : 200 + h, 300 : 300 + w] = plate
    return img, (300.0, 200.0, 300.0 + w, 200.0 + h)


@pytest.mark.parametrize("scheme", ["white_on_navy", "black_on_yellow", "black_on_white"])
def test_the_text_line_is_measured_whatever_the_colours(scheme):
    img, box = plate_frame("224 Physiotherapy", scheme, cap_px=8.0)
    line = ink_line_height(img, box)
    assert line is not None
    # a line of 8 px capitals (or of their lower case, 4.5 px), not the plate (3 lines)
    assert 5.0 <= line <= 14.0, line
    assert line < (box[3] - box[1]) / 2


def test_a_plate_without_text_measures_nothing():
    img, box = plate_frame("224", "white_on_navy", cap_px=8.0)
    x0, y0, x1, y1 = (int(v) for v in box)
    img[y0:y1, x0:x1] = COLOUR_SCHEMES["white_on_navy"][1]
    assert ink_line_height(img, box) is None

