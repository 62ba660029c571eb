"""Simulator ground-truth grounder: reads the segmentation, with configurable failures.

- ``detect(obs, entity)``: a room is grounded as its *door* (the sign beside it must be
  readable and the door in view), a landmark as itself;
- ``read_signs(obs)``: every readable room sign and landmark in view, each detection
  carrying the entity it names and the text a person would read (localization);
- ``surfaces(obs)``: the floor and wall masks (corner and opening checks).

A sign is readable only with enough pixels and close enough. Misses, false positives
(another visible sign read as the target) and mask noise are drawn from a seeded
generator.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import cv2
import numpy as np

from pmnav_bt.errors import BackendError
from pmnav_bt.map.building import Building
from pmnav_bt.planning.resolve import sign_text
from pmnav_bt.seams import (
    FLOOR_LABEL,
    WALL_LABEL,
    Detection,
    Entity,
    EntityKind,
    Observation,
    SurfaceMasks,
    door_label,
    parse_label,
)

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.backends import BackendDeps

_SIGN_KINDS = {"sign": EntityKind.ROOM, "landmark": EntityKind.LANDMARK}


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
    needs_sim_labels = True
    _rng: random.Random = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._rng = random.Random(self.seed)

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        readable = self._readable(obs)
        text = sign_text(self.building, target)
        hits = []
        if target in readable and self._rng.random() >= self.miss_rate:
            mask, score = readable[target]
            hits.append(_detection(text, self._noisy(mask), score, target))
        others = [e for e in readable if e != target]
        if others and self._rng.random() < self.false_positive_rate:
            wrong = others[self._rng.randrange(len(others))]
            mask, score = readable[wrong]  # misread as the target: it says it is the target
            hits.append(_detection(text, self._noisy(mask), 0.6 * score, target))
        return sorted(hits, key=lambda d: -d.score)

    def read_signs(self, obs: Observation) -> list[Detection]:
        out = []
        for entity, (mask, score) in self._readable(obs).items():
            if self._rng.random() >= self.miss_rate:
                text = sign_text(self.building, entity)
                out.append(_detection(text, self._noisy(mask), score, entity))
        return out

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        seg = _segmentation(obs)

        def mask(label: str) -> np.ndarray:
            return np.isin(seg, [i for i, lab in obs.labels.items() if lab == label])

        return SurfaceMasks(floor=mask(FLOOR_LABEL), wall=mask(WALL_LABEL))

    def _readable(self, obs: Observation) -> dict[Entity, tuple[np.ndarray, float]]:
        """Entities whose sign can be read in this frame: entity -> (mask to return, score)."""
        seg = _segmentation(obs)
        present = np.unique(seg)
        by_label = {lab: i for i, lab in obs.labels.items() if i in present}
        out: dict[Entity, tuple[np.ndarray, float]] = {}
        for lab, i in by_label.items():
            kind, ident = parse_label(lab)
            if kind not in _SIGN_KINDS or ident in self.hidden:
                continue
            sign = seg == i
            n = int(sign.sum())
            if n < self.min_sign_pixels:
                continue
            if obs.depth is not None and float(np.median(obs.depth[sign])) > self.max_range:
                continue
            score = min(1.0, 0.5 + n / 2000.0)
            entity = Entity(_SIGN_KINDS[kind], ident)
            if entity.kind is EntityKind.ROOM:
                door_id = by_label.get(door_label(ident))
                if door_id is None:
                    continue  # the sign alone: no door in view to go to or to locate
                mask = seg == door_id
            else:
                mask = sign
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


def build(deps: BackendDeps) -> GroundTruthGrounder:
    """The ``sim_gt`` back end from ``config.grounder`` (registry factory)."""
    g = deps.config.grounder
    return GroundTruthGrounder(
        deps.pm.building,
        miss_rate=g.miss_rate,
        false_positive_rate=g.false_positive_rate,
        mask_noise_px=g.mask_noise_px,
        min_sign_pixels=g.min_sign_pixels,
        max_range=g.max_range,
        hidden=frozenset(g.hidden),
        seed=deps.seed,
    )


def _segmentation(obs: Observation) -> np.ndarray:
    if obs.segmentation is None:
        raise BackendError(
            "grounder.backend 'sim_gt' needs the simulator's segmentation, and this "
            "observation has none"
        )
    return obs.segmentation


def _truncated(mask: np.ndarray) -> bool:
    return bool(mask[:, 0].any() or mask[:, -1].any())


def _detection(label: str, mask: np.ndarray, score: float, entity: Entity) -> Detection:
    ys, xs = np.nonzero(mask)
    box = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
    return Detection(label=label, box=box, score=float(score), mask=mask, entity=entity)
