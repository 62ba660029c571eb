"""The ``vlm`` coarse-direction back end (paper, "Action Generation"): the views stitched
into one panorama with their angles written above them; the VLM says which view shows
the target; the target is then grounded in that view.

The answer names a view by its angle (``{"angle": 60}``); an angle more than
``ANGLE_TOLERANCE_DEG`` from every view, or ``null``, means "not seen". The detection
returned is the grounder's best in the chosen view (from the view's own detections when
it carries them); where the grounder finds nothing there, a coarse detection spanning the
frame stands for "straight ahead of that view", which is what the paper's coarse output
is. A server failure or timeout raises VlmError: callers run ``choose`` in the worker,
and the tree reports VLM_ERROR.
"""

from __future__ import annotations

import json
import logging
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field

import cv2
import numpy as np

from pmnav_bt.errors import VlmError
from pmnav_bt.map.building import Building
from pmnav_bt.seams import CoarseChoice, Detection, Entity, EntityKind, Grounder, View
from pmnav_bt.vlm.client import VlmClient, user_message
from pmnav_bt.vlm.prompts import coarse_text

log = logging.getLogger(__name__)

ANGLE_TOLERANCE_DEG = 20.0
LABEL_BAND_PX = 34
GAP_PX = 6


def view_angle_deg(view: View) -> int:
    return int(round(math.degrees(view.relative_yaw)))


def stitch_panorama(views: Sequence[View], height: int = 240) -> tuple[np.ndarray, list[int]]:
    """The views side by side, leftmost (largest angle) first, each with its angle in degrees
    written in a band above it; BGR. Returns the image and the angles in image order."""
    if not views:
        raise ValueError("no views to stitch")
    order = sorted(views, key=lambda v: -v.relative_yaw)
    tiles, angles = [], []
    for v in order:
        rgb = v.observation.rgb
        h, w = rgb.shape[:2]
        size = (max(1, round(w * height / h)), height)
        tile = cv2.resize(rgb, size, interpolation=cv2.INTER_AREA)
        tile = cv2.cvtColor(tile, cv2.COLOR_RGB2BGR)
        band = np.full((LABEL_BAND_PX, tile.shape[1], 3), 255, np.uint8)
        a = view_angle_deg(v)
        text = f"{a:+d} deg"
        (tw, th), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.8, 2)
        cv2.putText(
            band,
            text,
            ((tile.shape[1] - tw) // 2, (LABEL_BAND_PX + th) // 2),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.8,
            (0, 0, 0),
            2,
            cv2.LINE_AA,
        )
        tiles.append(np.vstack([band, tile]))
        angles.append(a)
    gap = np.full((LABEL_BAND_PX + height, GAP_PX, 3), 255, np.uint8)
    parts = []
    for t in tiles:
        parts += [t, gap]
    return np.hstack(parts[:-1]), angles


def describe_target(building: Building, target: Entity) -> str:
    """The target as the prompt names it: a room by its door sign, a landmark by its kind."""
    if target.kind is EntityKind.ROOM:
        r = building.room(target.id)
        return f'the door of {r.display_name} (its sign reads "{r.sign_text}")'
    lm = building.landmark(target.id)
    return f'the {lm.kind.replace("_", " ")} "{lm.display_name}"'


_ANGLE = re.compile(r"\"?angle\"?\s*[:=]\s*(null|none|[-+]?\d+(?:\.\d+)?)", re.IGNORECASE)


def parse_angle(text: str) -> float | None:
    """The angle an answer names, or None for null / none; raises ValueError if it names none."""
    m = _ANGLE.search(text)
    if m is None:
        try:
            data = json.loads(text.strip().strip("`").removeprefix("json").strip())
            value = data.get("angle") if isinstance(data, dict) else data
        except ValueError:
            nums = re.findall(r"[-+]?\d+(?:\.\d+)?", text)
            if len(nums) == 1:
                return float(nums[0])
            if re.search(r"\b(none|null|no view|not visible|not seen)\b", text, re.I):
                return None
            raise ValueError(f"no angle in the answer: {text[:120]!r}") from None
        return None if value is None else float(value)
    v = m.group(1).lower()
    return None if v in ("null", "none") else float(v)


@dataclass
class CoarseStats:
    calls: int = 0
    seen: int = 0
    not_seen: int = 0
    unreadable: int = 0  # answers with no angle, or an angle of no view
    transcripts: list = field(default_factory=list)


@dataclass
class VlmCoarseDirection:
    """Coarse direction by a VLM over the stitched panorama (back end ``vlm``)."""

    client: VlmClient
    building: Building
    grounder: Grounder | None = None
    min_score: float = 0.3
    stats: CoarseStats = field(default_factory=CoarseStats)

    def choose(self, views: Sequence[View], target: Entity) -> CoarseChoice | None:
        if not views:
            return None
        pano, angles = stitch_panorama(views)
        text = coarse_text(describe_target(self.building, target), angles)
        reply = self.client.chat([user_message(text, [pano])], purpose="coarse")
        self.stats.calls += 1
        try:
            angle = parse_angle(reply.text)
        except ValueError as err:
            self.stats.unreadable += 1
            raise VlmError(f"coarse direction: {err}") from None
        if angle is None:
            self.stats.not_seen += 1
            return None
        view = min(views, key=lambda v: abs(math.degrees(v.relative_yaw) - angle))
        if abs(math.degrees(view.relative_yaw) - angle) > ANGLE_TOLERANCE_DEG:
            self.stats.unreadable += 1
            log.warning("coarse direction: %.0f deg is no view (%s)", angle, angles)
            return None
        self.stats.seen += 1
        return CoarseChoice(view, self._detection(view, target))

    def _detection(self, view: View, target: Entity) -> Detection:
        dets = view.detections
        if dets is None and self.grounder is not None:
            dets = tuple(self.grounder.detect(view.observation, target))
        good = [d for d in dets or () if d.score >= self.min_score]
        if good:
            return max(good, key=lambda d: d.score)
        h, w = view.observation.rgb.shape[:2]
        return Detection(
            label=str(target), box=(0.0, 0.0, float(w), float(h)), score=0.5, entity=target
        )


def build(deps) -> VlmCoarseDirection:
    """Factory of the ``vlm`` coarse-direction back end (registry)."""
    return VlmCoarseDirection(
        VlmClient.from_config(deps.config.vlm),
        deps.pm.building,
        deps.grounder,
        deps.config.coarse.min_score,
    )
