"""Plate textures in a building's style: sizes in metres, colours, layouts, fonts,
pictograms and arrows, checked on the pixels (no OCR)."""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
import pytest

from pmnav_bt.map.signage import SIGN_FONTS
from pmnav_bt.sim.scene.plates import (
    TEXELS_PER_M_LIMITS,
    make_line_plate,
    make_plate,
    plate_lines,
    texels_per_m,
)
from pmnav_bt.sim.scene.signage import CLEAN_STYLE

NAVY = replace(
    CLEAN_STYLE,
    plate_width=0.3,
    cap_height=0.035,
    font="dejavu_sans_bold",
    text_rgb=(255, 255, 255),
    plate_rgb=(20, 60, 120),
)


def ink(image: np.ndarray, style) -> np.ndarray:
    """Pixels nearer the text colour than the plate colour."""
    im = image.astype(float)
    d_text = np.linalg.norm(im - np.array(style.text_rgb), axis=2)
    d_plate = np.linalg.norm(im - np.array(style.plate_rgb), axis=2)
    return d_text < d_plate


def test_plate_size_is_the_styles_in_metres():
    t = make_plate("2.04 Radiology", NAVY)
    assert t.width_m == pytest.approx(0.3, abs=0.005)
    assert t.image.shape[1] == round(0.3 * texels_per_m(0.035))
    assert t.height_m == pytest.approx(t.image.shape[0] / texels_per_m(0.035))
    assert t.lines == ("2.04", "Radiology") and t.text == "2.04 Radiology"


def test_capital_height_sets_the_text_height():
    rows = []
    for cap in (0.025, 0.05):
        style = replace(NAVY, plate_width=0.45, cap_height=cap, layout="number_only")
        t = make_plate("117", style)
        ys = np.nonzero(ink(t.image, style).any(axis=1))[0]
        rows.append((ys.max() - ys.min() + 1) / texels_per_m(cap))
    assert rows[0] == pytest.approx(0.025, rel=0.15)
    assert rows[1] == pytest.approx(0.05, rel=0.15)


def test_small_capitals_get_more_texels_per_metre_within_limits():
    assert texels_per_m(0.02) > texels_per_m(0.05) > texels_per_m(0.08)
    assert texels_per_m(0.001) == TEXELS_PER_M_LIMITS[1]
    assert texels_per_m(1.0) == TEXELS_PER_M_LIMITS[0]


def test_light_on_dark_has_a_dark_plate_and_light_text():
    t = make_plate("117 Laboratory", NAVY)
    grey = t.image.mean(axis=2)
    border = np.concatenate([grey[0], grey[-1], grey[:, 0], grey[:, -1]])
    assert border.max() < 90  # the navy plate all round
    assert grey.max() > 230  # white capitals
    assert 0.03 < ink(t.image, NAVY).mean() < 0.4


@pytest.mark.parametrize("layout", ["number_only", "name_only"])
def test_one_line_layouts_print_less_than_number_and_name(layout):
    both = make_plate("117 Laboratory", NAVY)
    one = make_plate("117 Laboratory", replace(NAVY, layout=layout))
    assert one.lines == (("117",) if layout == "number_only" else ("Laboratory",))
    assert one.height_m < both.height_m
    assert ink(one.image, NAVY).sum() < ink(both.image, NAVY).sum()


def test_a_layout_without_its_part_shows_what_the_sign_has():
    assert plate_lines("Radiology", replace(NAVY, layout="number_only")) == ["Radiology"]
    assert plate_lines("105", replace(NAVY, layout="name_only")) == ["105"]


def test_fonts_draw_differently():
    inked = {}
    for f in SIGN_FONTS:  # the text's ink on a common grid (fonts differ in line height)
        m = ink(make_plate("2.04 Radiology", replace(NAVY, font=f)).image, NAVY)
        inked[f] = cv2.resize(m.astype(np.uint8), (270, 130), interpolation=cv2.INTER_AREA)
    names = list(inked)
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            assert (inked[a] != inked[b]).mean() > 0.01, (a, b)


def test_a_long_name_wraps_within_the_plate():
    t = make_plate("L2-204 One-Stop Service Centre", NAVY)
    assert t.lines[0] == "L2-204" and 3 <= len(t.lines) <= 3
    cols = np.nonzero(ink(t.image, NAVY).any(axis=0))[0]
    assert cols.min() > 0 and cols.max() < t.image.shape[1] - 1  # nothing cut at the edges


def test_toilet_pictogram_has_three_figures_and_no_text():
    style = replace(NAVY, pictogram="toilet")
    t = make_plate("WC", style)
    assert t.text == "" and t.lines == ()
    m = ink(t.image, style)
    w = m.shape[1]
    thirds = [m[:, int(k * w / 3) + 3 : int((k + 1) * w / 3) - 3] for k in range(3)]
    for panel in thirds:
        assert 0.05 < panel.mean() < 0.5  # a figure in every panel, not a filled block


@pytest.mark.parametrize("text, side", [("Radiology ->", "right"), ("<- 101-120", "left")])
def test_directional_signs_draw_the_arrow_at_its_end(text, side):
    t = make_line_plate(text, NAVY)
    m = ink(t.image, NAVY)
    h, w = m.shape
    row = np.concatenate([[0], m[h // 2].astype(int), [0]])
    edges = np.flatnonzero(np.diff(row))
    starts, ends = edges[::2], edges[1::2]
    k = int(np.argmax(ends - starts))  # the longest stroke on the middle line: the shaft
    assert ends[k] - starts[k] > 0.05 * w
    centre = (starts[k] + ends[k]) / 2.0 / w
    assert centre > 0.8 if side == "right" else centre < 0.2
    assert t.text == text
