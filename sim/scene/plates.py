"""Sign plates in a building's own style: fonts, colours, sizes, layouts, pictograms, arrows.

A plate is drawn from its text and a ``PlateStyle`` (pmnav_bt.map.signage): the capitals
are ``cap_height`` metres tall and the plate ``plate_width`` wide, so a small plate
carries small text, as on a real door. Text is TrueType from the DejaVu family that
matplotlib ships (rendered with Pillow), or OpenCV's Hershey font (the historical
plates'); nothing is downloaded.

Texel density: the tiny renderer samples textures nearest-neighbour without mipmaps
(sim/textures.py). The historical 0.8 m plate used 200 texels per metre for ~86 mm
capitals, about 17 texels a capital. A 25 mm capital needs more texels per metre to stay
legible at 1-2 m, where a 640x480 camera with a 60 deg field of view puts 7-14 pixels on
it: each capital gets ``TEXELS_PER_CAP`` texels (so the texture is never coarser than the
screen at 1 m), within 200-1200 texels per metre (a 0.45 m plate is then at most 540
texels wide).
"""

from __future__ import annotations

import math
from functools import lru_cache
from pathlib import Path

import cv2
import matplotlib
import numpy as np
from PIL import Image, ImageDraw, ImageFont

from pmnav_bt.map.signage import SIGN_FONTS, PlateStyle, split_number
from pmnav_bt.sim.textures import SignTexture

TEXELS_PER_CAP = 32  # texels across one capital letter's height
TEXELS_PER_M_LIMITS = (200.0, 1200.0)
LINE_PITCH_CAPS = 1.7  # baseline-to-baseline distance, in capital heights
MARGIN_CAPS = 0.8  # blank border around the text, in capital heights
MIN_SHRINK = 0.45  # a long word shrinks its line's text down to this fraction, then wraps
MAX_LINES = 3
PICTOGRAM_ASPECT = 0.5  # a toilet plate's height over its width (three figures side by side)
# Capitals of one-line plates (wayfinding signs, landmark names): 1.5 times the room
# plates', within these limits, since they are read from farther away.
LINE_PLATE_CAP_M = (0.045, 0.09)
# OpenCV's strokes and shapes are drawn this much larger, then shrunk with area averaging
# (anti-aliased edges); FreeType anti-aliases TrueType text itself, at the final size.
_SUPERSAMPLE = 3


def _supersample(style: PlateStyle) -> int:
    return _SUPERSAMPLE if style.pictogram or SIGN_FONTS[style.font] is None else 1
_HERSHEY = cv2.FONT_HERSHEY_DUPLEX
FONT_DIR = Path(matplotlib.get_data_path()) / "fonts" / "ttf"


def texels_per_m(cap_height: float) -> float:
    """Texture resolution for capitals ``cap_height`` metres tall (module docstring)."""
    lo, hi = TEXELS_PER_M_LIMITS
    return float(np.clip(TEXELS_PER_CAP / cap_height, lo, hi))


def plate_lines(text: str, style: PlateStyle) -> list[str]:
    """The text lines a plate of ``style`` shows for a sign reading ``text`` (before
    wrapping): number and name on two lines, the number alone or the name alone (a sign
    without the part a layout wants shows what it has); none for a pictogram."""
    if style.pictogram:
        return []
    number, name = split_number(text)
    if style.layout == "number_only":
        return [number or name]
    if style.layout == "name_only":
        return [name or number]
    return [x for x in (number, name) if x]


# -- fonts --------------------------------------------------------------------------------


class _Font:
    """One font at one capital height in pixels: measures and draws a line."""

    def __init__(self, name: str, cap_px: float) -> None:
        self.file = SIGN_FONTS[name]
        self.cap_px = cap_px
        if self.file is None:
            (_, cap), _ = cv2.getTextSize("H", _HERSHEY, 1.0, 1)
            self.scale = cap_px / cap
            self.thick = max(1, int(round(self.scale * 2.6)))
        else:
            self.pil = _truetype(self.file, cap_px)

    def width(self, line: str) -> float:
        if self.file is None:
            (w, _), _ = cv2.getTextSize(line, _HERSHEY, self.scale, self.thick)
            return float(w)
        return float(self.pil.getlength(line))

    def draw(self, img: np.ndarray, line: str, x: float, baseline: float, rgb) -> np.ndarray:
        """Draw ``line`` with its left end at ``x`` and its baseline at ``baseline``."""
        if self.file is None:
            org = (int(round(x)), int(round(baseline)))
            cv2.putText(img, line, org, _HERSHEY, self.scale, rgb, self.thick, cv2.LINE_AA)
            return img
        im = Image.fromarray(img)
        ImageDraw.Draw(im).text((x, baseline), line, font=self.pil, fill=tuple(rgb), anchor="ls")
        return np.asarray(im).copy()


@lru_cache(maxsize=256)
def _truetype(file: str, cap_px: float) -> ImageFont.FreeTypeFont:
    """The TrueType font ``file`` at the point size whose capital H is ``cap_px`` tall."""
    probe = ImageFont.truetype(str(FONT_DIR / file), 100)
    _, top, _, bottom = probe.getbbox("H", anchor="ls")
    size = max(1, int(round(100 * cap_px / (bottom - top))))
    return ImageFont.truetype(str(FONT_DIR / file), size)


def _wrap(words: list[str], font: _Font, avail: float) -> list[str]:
    lines: list[str] = []
    current = ""
    for w in words:
        trial = f"{current} {w}" if current else w
        if current and font.width(trial) > avail:
            lines.append(current)
            current = w
        else:
            current = trial
    if current:
        lines.append(current)
    return lines


def _fit(lines: list[str], style: PlateStyle, cap_px: float, avail: float):
    """Wrap the lines to the plate's width in at most ``MAX_LINES`` lines, shrinking the
    capitals step by step (to ``MIN_SHRINK``) only while a word is wider than the plate or
    the lines are too many; past that the text shrinks to fit. Returns (lines, font)."""
    shrink = 1.0
    while True:
        font = _Font(style.font, cap_px * shrink)
        out: list[str] = []
        for line in lines:
            out.extend(_wrap(line.split(), font, avail))
        widest = max((font.width(line) for line in out), default=0.0)
        if (widest <= avail and len(out) <= MAX_LINES) or shrink <= MIN_SHRINK:
            break
        shrink = max(MIN_SHRINK, shrink * 0.9)
    if len(out) > MAX_LINES:
        out = out[: MAX_LINES - 1] + [" ".join(out[MAX_LINES - 1 :])]
    widest = max((font.width(line) for line in out), default=0.0)
    if widest > avail:
        font = _Font(style.font, font.cap_px * avail / widest)
    return out, font


# -- plates -------------------------------------------------------------------------------


def make_plate(text: str, style: PlateStyle) -> SignTexture:
    """A room plate of ``style`` for a sign reading ``text``; ``SignTexture.text`` is what
    the plate shows (empty for a pictogram)."""
    tpm = texels_per_m(style.cap_height)
    s = _supersample(style)
    w_px = int(round(style.plate_width * tpm))
    if style.pictogram:
        h_px = int(round(style.plate_width * PICTOGRAM_ASPECT * tpm))
        big = np.full((h_px * s, w_px * s, 3), style.plate_rgb, np.uint8)
        _draw_toilet(big, style.text_rgb)
        return _texture("", (), big, w_px, h_px, tpm)
    cap_px = style.cap_height * tpm * s
    margin = MARGIN_CAPS * cap_px
    lines, font = _fit(plate_lines(text, style), style, cap_px, w_px * s - 2 * margin)
    pitch = LINE_PITCH_CAPS * font.cap_px
    h_px = int(math.ceil((2 * margin + (len(lines) - 1) * pitch + font.cap_px) / s))
    big = np.full((h_px * s, w_px * s, 3), style.plate_rgb, np.uint8)
    top = (h_px * s - (len(lines) - 1) * pitch - font.cap_px) / 2.0
    for i, line in enumerate(lines):
        x = (w_px * s - font.width(line)) / 2.0
        big = font.draw(big, line, x, top + font.cap_px + i * pitch, style.text_rgb)
    return _texture(" ".join(lines), tuple(lines), big, w_px, h_px, tpm)


def make_line_plate(text: str, style: PlateStyle) -> SignTexture:
    """A one-line plate as wide as its text needs, with capitals larger than a room
    plate's: a wayfinding sign (``->`` at the end or ``<-`` at the start is drawn as an
    arrow there) or a landmark's name plate."""
    lo, hi = LINE_PLATE_CAP_M
    cap_m = float(np.clip(1.5 * style.cap_height, lo, hi))
    tpm = texels_per_m(cap_m)
    s = _supersample(style)
    cap_px = cap_m * tpm * s
    right, left = text.rstrip().endswith("->"), text.lstrip().startswith("<-")
    words = text.replace("->", " ").replace("<-", " ").split()
    line = " ".join(words)
    font = _Font(style.font, cap_px)
    arrow = 1.6 * cap_px
    gap = 0.6 * cap_px
    margin = MARGIN_CAPS * cap_px
    text_w = font.width(line)
    w_big = 2 * margin + text_w + (arrow + gap) * (right + left)
    w_px = int(math.ceil(w_big / s))
    h_px = int(math.ceil((2 * margin + 1.2 * cap_px) / s))
    big = np.full((h_px * s, w_px * s, 3), style.plate_rgb, np.uint8)
    mid = h_px * s / 2.0
    x = margin + (arrow + gap) * left
    big = font.draw(big, line, x, mid + cap_px / 2.0, style.text_rgb)
    if left:
        _draw_arrow(big, margin, margin + arrow, mid, cap_px, style.text_rgb)
    if right:
        x1 = w_px * s - margin
        _draw_arrow(big, x1, x1 - arrow, mid, cap_px, style.text_rgb)
    shown = ("<- " if left else "") + line + (" ->" if right else "")
    return _texture(shown, (shown,), big, w_px, h_px, tpm)


def _texture(shown: str, lines: tuple[str, ...], big, w_px: int, h_px: int, tpm: float):
    image = cv2.resize(big, (w_px, h_px), interpolation=cv2.INTER_AREA)
    return SignTexture(shown, lines, image, w_px / tpm, h_px / tpm)


def _draw_arrow(img: np.ndarray, tip: float, tail: float, mid: float, cap: float, rgb) -> None:
    """A bold arrow from ``tail`` to ``tip`` (x, pixels) on the line ``mid``."""
    d = 1.0 if tip > tail else -1.0
    head = 0.55 * cap
    shaft = 0.18 * cap
    pts = [
        (tail, mid - shaft),
        (tip - d * head, mid - shaft),
        (tip - d * head, mid - 0.6 * cap),
        (tip, mid),
        (tip - d * head, mid + 0.6 * cap),
        (tip - d * head, mid + shaft),
        (tail, mid + shaft),
    ]
    cv2.fillPoly(img, [np.round(np.array(pts)).astype(np.int32)], tuple(int(c) for c in rgb))


def _draw_toilet(img: np.ndarray, rgb) -> None:
    """The usual toilet pictograms: a man, a woman (triangle dress) and a wheelchair user,
    in three panels divided by thin lines."""
    h, w = img.shape[:2]
    col = tuple(int(c) for c in rgb)
    panel = w / 3.0
    for k in (1, 2):
        x = int(round(k * panel))
        cv2.line(img, (x, int(0.15 * h)), (x, int(0.85 * h)), col, max(1, int(0.012 * w)))
    u = min(panel, h) / 10.0  # one unit: a tenth of a panel's smaller side

    def person(cx: float, dress: bool) -> None:
        top = h / 2.0 - 4.2 * u
        cv2.circle(img, (int(cx), int(top + 0.8 * u)), int(0.8 * u), col, -1)
        body_top, body_bot = top + 1.9 * u, top + 5.2 * u
        if dress:  # a narrow bodice, then a skirt flaring to the knees
            bodice = ((int(cx - 0.8 * u), int(body_top)), (int(cx + 0.8 * u), int(top + 3.1 * u)))
            cv2.rectangle(img, *bodice, col, -1)
            skirt = np.array([(-0.8, 2.8), (0.8, 2.8), (1.6, 5.4), (-1.6, 5.4)]) * u + (cx, top)
            cv2.fillPoly(img, [skirt.astype(np.int32)], col)
        else:
            cv2.rectangle(
                img, (int(cx - 1.0 * u), int(body_top)), (int(cx + 1.0 * u), int(body_bot)), col, -1
            )
        for side in (-1, 1):  # legs
            x0 = cx + side * 0.55 * u
            cv2.rectangle(
                img,
                (int(x0 - 0.35 * u), int(body_bot - 0.1 * u)),
                (int(x0 + 0.35 * u), int(top + 8.4 * u)),
                col,
                -1,
            )
        for side in (-1, 1):  # arms
            x0 = cx + side * (1.3 * u if dress else 1.5 * u)
            cv2.rectangle(
                img,
                (int(x0 - 0.3 * u), int(body_top + 0.1 * u)),
                (int(x0 + 0.3 * u), int(body_top + (1.4 if dress else 2.8) * u)),
                col,
                -1,
            )

    person(0.5 * panel, dress=False)
    person(1.5 * panel, dress=True)
    # The wheelchair symbol (ISO 7001): head, seated body, a wheel.
    cx, cy = 2.5 * panel, h / 2.0
    thick = max(1, int(0.7 * u))
    cv2.circle(img, (int(cx - 0.3 * u), int(cy - 3.6 * u)), int(0.8 * u), col, -1)
    body = np.array([(-0.7, -2.4), (-0.7, 0.4), (1.8, 0.4), (2.6, 3.0)]) * u + (cx, cy)
    cv2.polylines(img, [body.astype(np.int32)], False, col, thick, cv2.LINE_AA)
    wheel = (int(cx - 0.4 * u), int(cy + 1.6 * u))
    cv2.circle(img, wheel, int(2.4 * u), col, max(1, int(0.45 * u)))
