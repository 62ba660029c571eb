"""Localization from landmarks (paper, "Localization"): two recognised landmarks fix the pose.

Each sighting pairs a landmark's known map position with where it was seen, in the
odometry frame. Two or more distinct landmarks give the rigid transform
``map_T_odom`` (2D least squares); sightings that do not fit the map (a misread
sign, a false detection) are dropped by trying every consistent subset.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.geometry import fit_se2, se2_apply, se2_compose
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.perception.geometry import target_point
from pmnav_bt.planning.resolve import entity_position
from pmnav_bt.seams import Detection, Entity, EntityKind, Observation, Pose2D

MAX_RESIDUAL = 0.8  # metres (RMS) for a set of sightings to count as consistent


@dataclass(frozen=True)
class Sighting:
    """A landmark seen: which one, its map position, and where it was seen (odom frame)."""

    entity: Entity
    map_xy: tuple[float, float]
    odom_xy: tuple[float, float]


@dataclass(frozen=True)
class Fix:
    """A localization result: map_T_odom, the landmarks used and the fit residual."""

    map_T_odom: tuple[float, float, float]
    entities: tuple[Entity, ...]
    residual: float

    def map_pose(self, odom: Pose2D) -> Pose2D:
        x, y, yaw = se2_compose(self.map_T_odom, (odom.x, odom.y, odom.yaw))
        return Pose2D(x, y, yaw)


def sighting(pm: PrioriMap, obs: Observation, det: Detection) -> Sighting | None:
    """A sighting from a detection, if the grounder said which entity it is and where it is
    (its ``point``, or depth over its mask)."""
    if det.entity is None or truncated(obs, det):
        return None
    p = det.point[:2] if det.point is not None else target_point(obs, det)
    if p is None:
        return None
    odom = se2_apply((obs.pose.x, obs.pose.y, obs.pose.yaw), p)
    m = entity_position(pm, det.entity)
    return Sighting(det.entity, (float(m[0]), float(m[1])), (float(odom[0]), float(odom[1])))


def truncated(obs: Observation, det: Detection) -> bool:
    """True when the detection touches the left or right image border (its centre is biased)."""
    x0, _, x1, _ = det.box
    return x0 <= 1 or x1 >= obs.intrinsics.width - 2


def fix_pose(sightings: list[Sighting], max_residual: float = MAX_RESIDUAL) -> Fix | None:
    """The best consistent fix from at least two distinct landmarks, or None.

    Doors are placed exactly by the map; other landmarks (desks, lifts) only roughly. So
    with two or more doors in view only doors are used.
    """
    doors = [s for s in sightings if s.entity.kind is EntityKind.ROOM]
    if len({s.entity for s in doors}) >= 2:
        sightings = doors
    by_entity: dict[Entity, list[Sighting]] = {}
    for s in sightings:
        by_entity.setdefault(s.entity, []).append(s)
    # One averaged sighting per landmark.
    merged = [
        Sighting(e, ss[0].map_xy, tuple(np.mean([s.odom_xy for s in ss], axis=0)))
        for e, ss in by_entity.items()
    ]
    if len(merged) < 2:
        return None
    best: Fix | None = None
    for k in range(len(merged), 1, -1):
        for subset in itertools.combinations(merged, k):
            src = np.array([s.odom_xy for s in subset])
            dst = np.array([s.map_xy for s in subset])
            if np.linalg.norm(dst.max(axis=0) - dst.min(axis=0)) < 0.5:
                continue  # landmarks too close together to fix a heading
            tf, res = fit_se2(src, dst)
            if res <= max_residual and (best is None or res < best.residual):
                best = Fix(tf, tuple(sorted(s.entity for s in subset)), res)
        if best is not None:
            return best  # the largest consistent set wins
    return None


SIGN_AGREE_M = 1.0  # signs fixing the position together must agree on it this well


def sign_shift(tf, src, dst, placed) -> tuple[np.ndarray, float, float]:
    """The shift that puts the signs read (``src``, odometry) on their map places (``dst``)
    under ``tf`` (map_T_odom), its residual (m, RMS over the signs kept) and its
    uncertainty (m) from how far each kept sign may be from its map place (``placed``, m
    per sighting): a fix's position from signs too close together to fix a heading.

    Each sign's shift is the mean of its sightings'; the signs kept are weighed by how
    exactly they are placed. Signs that disagree by more than
    ``SIGN_AGREE_M`` cannot all be right (a sign plate sits beside the door or elevator the
    map places, up to 1.7 m off): those that agree with the sign asking for the smallest
    shift, the one the belief's hypothesis (every sighting, depth, the corridors) already
    agrees with, are kept."""
    per: dict[tuple, list] = {}
    sigma: dict[tuple, float] = {}
    for s, d, p in zip(src, dst, placed, strict=True):
        per.setdefault(tuple(d), []).append(d - se2_apply(tf, s))
        sigma[tuple(d)] = p
    shifts = np.array([np.mean(v, axis=0) for v in per.values()])
    sig = np.array([sigma[k] for k in per])
    least = shifts[int(np.argmin(np.linalg.norm(shifts, axis=1)))]
    keep = np.linalg.norm(shifts - least, axis=1) <= SIGN_AGREE_M
    kept, wk = shifts[keep], 1.0 / sig[keep] ** 2
    shift = (kept * wk[:, None]).sum(axis=0) / wk.sum()
    res = float(np.sqrt(np.mean(np.sum((kept - shift) ** 2, axis=1))))
    return shift, res, float(1.0 / math.sqrt(wk.sum()))
