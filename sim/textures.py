"""Sign textures: big black text on a white plate, drawn with OpenCV.

A sign's text is laid out in at most a few short lines (a leading room number gets a
line of its own) and the plate's physical size follows from the line count. The tiny
renderer samples textures nearest-neighbour without mipmaps, so a fine texture aliases
away at a distance: 200 texels per metre with heavy strokes was the best compromise by
eye (legible at 640x480 from 2 m head-on to 4 m at 60 deg off the plate's normal).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.map.signage import HISTORICAL_PLATE_M, ROOM_NUMBER

PLATE_WIDTH_M = HISTORICAL_PLATE_M  # every plate is this wide
LINE_PITCH_M = 0.12  # height of one text line on the plate
MARGIN_M = 0.05  # white margin above and below the text
TEXELS_PER_M = 200.0  # texture resolution on the plate (see the module docstring)
MAX_CHARS = 14  # wrap lines longer than this (words are never split)
MAX_LINES = 4

_FONT = cv2.FONT_HERSHEY_DUPLEX
_SUPERSAMPLE = 4  # draw large, then shrink with area averaging (anti-aliased strokes)


@dataclass(frozen=True)
class SignTexture:
    """A rendered sign: RGB image (top row = top of the plate) and the plate size in metres."""

    text: str
    lines: tuple[str, ...]
    image: np.ndarray  # (H, W, 3) uint8, RGB
    width_m: float
    height_m: float


def sign_lines(text: str, max_chars: int = MAX_CHARS) -> list[str]:
    """Lines of a sign: a leading room number alone, then the words wrapped to ``max_chars``."""
    words = text.split()
    if not words:
        return [""]
    lines: list[str] = []
    if len(words) > 1 and ROOM_NUMBER.match(words[0]):
        lines.append(words.pop(0))
    current = ""
    for w in words:
        if current and len(current) + 1 + len(w) > max_chars:
            lines.append(current)
            current = w
        else:
            current = f"{current} {w}" if current else w
    if current:
        lines.append(current)
    if len(lines) > MAX_LINES:  # too long for the plate: merge the tail into the last line
        lines = lines[: MAX_LINES - 1] + [" ".join(lines[MAX_LINES - 1 :])]
    return lines


def plate_height_m(n_lines: int) -> float:
    """Physical height of a plate with ``n_lines`` lines of text."""
    return 2.0 * MARGIN_M + n_lines * LINE_PITCH_M


def make_sign(text: str, width_m: float = PLATE_WIDTH_M) -> SignTexture:
    """Lay out and draw ``text`` as a sign plate (black text on white with a dark border)."""
    lines = sign_lines(text)
    height_m = plate_height_m(len(lines))
    w_px = int(round(width_m * TEXELS_PER_M))
    h_px = int(round(height_m * TEXELS_PER_M))
    s = _SUPERSAMPLE
    big = np.full((h_px * s, w_px * s, 3), 255, np.uint8)

    pitch = LINE_PITCH_M * TEXELS_PER_M * s
    margin = MARGIN_M * TEXELS_PER_M * s
    border = max(2, int(0.012 * TEXELS_PER_M * s))
    cv2.rectangle(big, (0, 0), (w_px * s - 1, h_px * s - 1), (20, 20, 20), border * 2)

    # One font scale for all lines: cap height ~72% of the pitch, every line fits the width.
    (_, cap), _ = cv2.getTextSize("H", _FONT, 1.0, 1)
    avail_w = w_px * s - 2 * (margin + border)
    scale = 0.72 * pitch / cap
    for line in lines:
        (tw, _), _ = cv2.getTextSize(line, _FONT, 1.0, 1)
        if tw > 0:
            scale = min(scale, avail_w / (tw * 1.08))
    thick = max(1, int(round(scale * 3.4)))
    for i, line in enumerate(lines):
        (tw, th), _ = cv2.getTextSize(line, _FONT, scale, thick)
        x = int(round((w_px * s - tw) / 2.0))
        y = int(round(margin + (i + 0.5) * pitch + th / 2.0))
        cv2.putText(big, line, (x, y), _FONT, scale, (0, 0, 0), thick, cv2.LINE_AA)
    image = cv2.resize(big, (w_px, h_px), interpolation=cv2.INTER_AREA)
    return SignTexture(text, tuple(lines), image, width_m, height_m)


def write_png(image_rgb: np.ndarray, path: str | Path) -> Path:
    """Write an RGB image as PNG (OpenCV wants BGR)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), cv2.cvtColor(image_rgb, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write {path}")
    return path
