"""The trajectory plot of an episode, like the paper's Fig. 4.

The annotated priori-map with the planned path (blue) and the driven path (red);
lettered markers where landmarks were detected, the pose was fixed, a corner was
seen or the goal reached; and a strip of first-person thumbnails, one per letter.
"""

from __future__ import annotations

import string
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.render.annotate import make_canvas, put_text, render_annotated_map

ACTUAL_COLOUR = (40, 40, 220)  # BGR red
EVENT_COLOUR = {
    "fix": (60, 160, 60),
    "detection": (0, 140, 255),
    "corner": (180, 60, 160),
    "obstacle": (0, 0, 0),
    "arrive": (40, 40, 220),
}
EVENT_NAME = {
    "fix": "positioning",
    "detection": "landmark",
    "corner": "corner check",
    "obstacle": "obstacle",
    "arrive": "arrival",
}
MAX_THUMBS = 8


@dataclass(frozen=True)
class KeyNode:
    """A marked point of the run: what happened, where (map frame), and what the robot saw."""

    kind: str
    label: str
    xy: tuple[float, float]
    thumbnail: np.ndarray | None = None  # RGB


def _pick(nodes: list[KeyNode]) -> list[KeyNode]:
    """At most MAX_THUMBS nodes with thumbnails, spread over the run, the last one kept."""
    with_thumbs = [n for n in nodes if n.thumbnail is not None]
    if len(with_thumbs) <= MAX_THUMBS:
        return with_thumbs
    idx = np.linspace(0, len(with_thumbs) - 1, MAX_THUMBS).round().astype(int)
    return [with_thumbs[i] for i in sorted(set(idx))]


def render_trajectory(
    pm: PrioriMap,
    planned_xy: list[tuple[float, float]],
    actual_xy: list[tuple[float, float]],
    nodes: list[KeyNode],
    path: str | Path | None = None,
    caption: str = "",
    base_dir: str | Path = ".",
) -> np.ndarray:
    """Draw the plot (BGR) and write it to ``path`` when given.

    ``base_dir``: the folder the building's floor plan path is relative to.
    """
    img = render_annotated_map(pm, path_xy=planned_xy or None, base_dir=base_dir)
    canvas = make_canvas(pm)
    if len(actual_xy) >= 2:
        pts = np.rint(canvas.to_px(actual_xy)).astype(np.int32)
        cv2.polylines(img, [pts], False, ACTUAL_COLOUR, 2, cv2.LINE_AA)
    for n in nodes:
        if n.kind in EVENT_COLOUR and n.thumbnail is None:
            cv2.circle(img, canvas.ipx(n.xy), 5, EVENT_COLOUR[n.kind], -1, cv2.LINE_AA)
    picked = _pick(nodes)
    for letter, n in zip(string.ascii_uppercase, picked, strict=False):
        c = canvas.ipx(n.xy)
        colour = EVENT_COLOUR.get(n.kind, (0, 0, 0))
        cv2.circle(img, c, 11, colour, -1, cv2.LINE_AA)
        cv2.circle(img, c, 11, (255, 255, 255), 2, cv2.LINE_AA)
        put_text(img, letter, (c[0] - 6, c[1] + 6), 0.5, (255, 255, 255), 2)
    strip = _thumb_strip(picked, img.shape[1], caption)
    out = np.vstack([img, strip])
    if path is not None and not cv2.imwrite(str(path), out):
        raise PmNavError(f"{path}: cannot write the PNG; check that the folder exists")
    return out


def _thumb_strip(nodes: list[KeyNode], width: int, caption: str) -> np.ndarray:
    """First-person thumbnails with their letters and what happened there."""
    th_w = max(120, min(220, (width - 20) // max(1, len(nodes)) - 10))
    th_h = int(th_w * 0.75)
    strip = np.full((th_h + 70, width, 3), 255, np.uint8)
    put_text(
        strip, "planned path (blue), driven path (red). " + caption, (10, 20), 0.5, (0, 0, 0), 1
    )
    x = 10
    for letter, n in zip(string.ascii_uppercase, nodes, strict=False):
        thumb = cv2.cvtColor(cv2.resize(n.thumbnail, (th_w, th_h)), cv2.COLOR_RGB2BGR)
        strip[30 : 30 + th_h, x : x + th_w] = thumb
        cv2.rectangle(
            strip, (x, 30), (x + th_w - 1, 30 + th_h - 1), EVENT_COLOUR.get(n.kind, (0, 0, 0)), 2
        )
        text = f"{letter}: {EVENT_NAME.get(n.kind, n.kind)} {n.label}"
        put_text(strip, text[:28], (x, 30 + th_h + 20), 0.45, (0, 0, 0), 1)
        x += th_w + 10
        if x + th_w > width:
            break
    return strip
