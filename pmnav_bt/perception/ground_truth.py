"""Simulator ground-truth grounder: reads the segmentation, with configurable failures.

Queries:
- "wall", "floor": the mask of that class (used by the corner check);
- "sign": every readable room sign and landmark in view, labelled with the text a
  person would read (localization);
- anything else: a room or landmark by sign text, name or ID; a room is grounded
  as its *door* (the door whose sign reads the query; the door must be in view), a
  landmark as itself.

A room is recognised only if its sign is readable: enough sign pixels and close
enough. Misses, false positives (another visible sign read as the target) and mask
noise are drawn from a seeded generator.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

import cv2
import numpy as np

from pmnav_bt.map.building import Building
from pmnav_bt.planning.resolve import entity_index, normalise
from pmnav_bt.seams import Detection, Observation

CLASS_QUERIES = ("wall", "floor")
ALL_SIGNS = "sign"


@dataclass
class GroundTruthGrounder:
    """Grounder over the simulator's semantic segmentation (the ``sim_gt`` back end)."""

    building: Building
    miss_rate: float = 0.0
    false_positive_rate: float = 0.0
    mask_noise_px: int = 0
    min_sign_pixels: int = 40
    max_range: float = 9.0
    hidden: frozenset[str] = frozenset()  # room/landmark IDs never detected (covered signs)
    seed: int = 0
    _rng: random.Random = field(init=False, repr=False)
    _names: dict[str, str] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rng = random.Random(self.seed)
        self._names = entity_index(self.building)

    def text_of(self, entity: str) -> str:
        """What a person reads on the sign of 'room:<id>' or 'landmark:<id>'."""
        kind, ident = entity.split(":", 1)
        if kind == "room":
            return self.building.room(ident).sign_text
        lm = self.building.landmark(ident)
        return lm.sign or lm.display_name

    def detect(self, obs: Observation, query: str) -> list[Detection]:
        if obs.segmentation is None:
            raise ValueError("the ground-truth grounder needs an observation with segmentation")
        q = query.strip().lower()
        if q in CLASS_QUERIES:
            ids = [i for i, lab in obs.labels.items() if lab == q]
            mask = np.isin(obs.segmentation, ids)
            return [_detection(q, mask, 1.0)] if mask.any() else []
        readable = self._readable(obs)
        if q == ALL_SIGNS:
            out = []
            for entity, (mask, score) in readable.items():
                if self._rng.random() >= self.miss_rate:
                    out.append(_detection(self.text_of(entity), self._noisy(mask), score))
            return out
        entity = self._names.get(normalise(query))
        hits = []
        if entity in readable and self._rng.random() >= self.miss_rate:
            mask, score = readable[entity]
            hits.append(_detection(query, self._noisy(mask), score))
        others = [e for e in readable if e != entity]
        if others and self._rng.random() < self.false_positive_rate:
            wrong = others[self._rng.randrange(len(others))]
            mask, score = readable[wrong]
            hits.append(_detection(query, self._noisy(mask), 0.6 * score))
        return sorted(hits, key=lambda d: -d.score)

    def _readable(self, obs: Observation) -> dict[str, tuple[np.ndarray, float]]:
        """Entities whose sign can be read in this frame: entity -> (mask to return, score)."""
        seg = obs.segmentation
        present = np.unique(seg)
        by_label = {lab: i for i, lab in obs.labels.items() if i in present}
        out: dict[str, tuple[np.ndarray, float]] = {}
        for lab, i in by_label.items():
            kind, _, ident = lab.partition(":")
            if kind not in ("sign", "landmark") or ident in self.hidden:
                continue
            sign = seg == i
            n = int(sign.sum())
            if n < self.min_sign_pixels:
                continue
            if obs.depth is not None and float(np.median(obs.depth[sign])) > self.max_range:
                continue
            score = min(1.0, 0.5 + n / 2000.0)
            if kind == "sign":
                door_id = by_label.get(f"door:{ident}")
                if door_id is None:
                    continue  # the sign alone: no door in view to go to or to locate
                mask, entity = seg == door_id, f"room:{ident}"
            else:
                mask, entity = sign, f"landmark:{ident}"
            if _truncated(sign) or _truncated(mask):  # cut by the image border: less sure
                score *= 0.6
            out[entity] = (mask, score)
        return out

    def _noisy(self, mask: np.ndarray) -> np.ndarray:
        k = self.mask_noise_px
        if k <= 0:
            return mask
        m = mask.astype(np.uint8)
        r = self._rng.randint(0, k)
        if r:
            kernel = np.ones((2 * r + 1, 2 * r + 1), np.uint8)
            m = cv2.dilate(m, kernel) if self._rng.random() < 0.5 else cv2.erode(m, kernel)
        dx, dy = self._rng.randint(-k, k), self._rng.randint(-k, k)
        m = np.roll(np.roll(m, dy, axis=0), dx, axis=1)
        return m.astype(bool) if m.any() else mask


def _truncated(mask: np.ndarray) -> bool:
    return bool(mask[:, 0].any() or mask[:, -1].any())


def _detection(label: str, mask: np.ndarray, score: float) -> Detection:
    ys, xs = np.nonzero(mask)
    box = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    return Detection(label=label, box=box, score=float(score), mask=mask)
