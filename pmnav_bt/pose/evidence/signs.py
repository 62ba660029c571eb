"""Signs read at a look round as evidence: read where the map puts them, missed, misread.

Under a hypothesis, the map says which signs are readable where it puts the robot
(``Visibility.lattice_points``: in sight and within reading range). Then

- a sign read that the map says is readable there supports the hypothesis as far as
  where it was seen agrees with where the map puts it (a Gaussian of ``SIGHT_SIGMA_M``,
  growing with the odometry distance from the reference by ``DRIFT_PER_M``, and with how
  exactly the plate sits at the map's point, ``PLACE_SIGMA_M``), floored at ``MISREAD``:
  readable here, but read far from its place;
- a sign read that the map says cannot be read there counts ``P_SPURIOUS`` (a misread);
  one read but cut by the image border (its place not known, ``Glimpse.named``) only
  ``P_OCCLUDED`` when it is within reading range (round a corner one of plate and door
  may be in sight when the other is not);
- a sign the map says is readable but that was not read is a likely miss: ``P_MISS``,
  or, with the reader's measured ``recall`` (by distance and angle off the plate's
  normal), 1 - recall from where the hypothesis puts the robot, at least ``P_MISS``.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.seams import Entity, EntityKind

P_MISS = 0.25  # a sign the map says is readable is not read
P_SPURIOUS = 0.005  # a sign is read that the map says cannot be read from there
P_OCCLUDED = 0.1  # ... from there, but it is within reading range (round a corner)
SIGHT_SIGMA_M = 0.8  # spread of a sign's seen position around the map's
DRIFT_PER_M = 0.05  # the sight spread grows with odometry distance from the reference
# How far (m, one sigma) a sign's seen place may be from the map's point: a door is found
# where the map puts it (the grounders return the door, not its plate); an elevator's or
# a stair's plate hangs beside it, 0.8-2.2 m along the wall in the simulator.
PLACE_SIGMA_M = {EntityKind.ROOM: 0.2, EntityKind.LANDMARK: 1.0}
MISREAD = math.log(P_MISS * P_SPURIOUS)  # readable here, but read far from its place

Recall = Callable[[Entity, float, float], float]


def sight_sigma(travelled: float) -> float:
    """How far (m) a sign's seen place may be from the map's, ``travelled`` m (odometry)
    from the reference."""
    return math.hypot(SIGHT_SIGMA_M, DRIFT_PER_M * travelled)


@dataclass(frozen=True)
class Signs:
    """The map's signs as the reader sees them: ``vis`` (what is readable where),
    ``recall`` (recall(entity, distance m, angle rad off the plate's normal), None:
    1 - ``P_MISS`` within reading range) and each sign's plate (``plates``: where the map
    puts it and its wall's normal)."""

    pm: PrioriMap
    vis: Visibility
    recall: Recall | None
    plates: dict[Entity, tuple[np.ndarray, np.ndarray]]

    @classmethod
    def of(cls, pm: PrioriMap, vis: Visibility, recall: Recall | None) -> Signs:
        plates = {
            e: (xy, n)
            for e, xy, n in zip(vis.entities, vis.sign_xy, vis.sign_normal, strict=True)
        }
        return cls(pm, vis, recall, plates)

    def miss_log(self, entity: Entity, xy: np.ndarray) -> float:
        """The log-probability that ``entity``'s sign, in sight, is not read from ``xy``
        (map): by the reader's recall from that distance and angle off the plate's normal.
        From where the hypothesis puts the robot, not its lattice point on the centre
        line: a plate on the wall the robot drives beside is seen along the wall (no
        evidence when not read), the same plate from the centre line at 50 degrees."""
        plate, normal = self.plates[entity]
        v = xy - plate
        d = float(math.hypot(v[0], v[1]))
        off = math.acos(min(1.0, max(-1.0, float(v @ normal) / max(d, 1e-9))))
        return math.log(max(P_MISS, 1.0 - self.recall(entity, d, off)))

    def weigh(
        self,
        logw: np.ndarray,
        seen: dict[Entity, tuple[float, float]],
        named: frozenset[Entity],
        tfs: np.ndarray,
        here_xy: np.ndarray,
        near: np.ndarray,
        sigma: float,
    ) -> None:
        """Add to ``logw`` the signs read at a look round (``seen``: where each was seen,
        odometry; ``named``: read but not placed) under each hypothesis of ``tfs``, which
        puts the robot at ``here_xy`` (map), nearest lattice point ``near``; ``sigma``:
        ``sight_sigma`` there."""
        # What the map says is readable at each hypothesis's position for this glimpse.
        readable = [self.vis.lattice_points[j].readable for j in near]
        keys = seen.keys()
        named = named - keys
        map_xy = {e: np.array(entity_xy(self.pm, e)) for e in keys}
        seen_map = {e: apply_many(tfs, xy) for e, xy in seen.items()}  # (N, 2) per sign
        d_seen = {e: np.linalg.norm(seen_map[e] - map_xy[e], axis=1) for e in keys}
        # An elevator's plate hangs beside it: its sighting tells the place less exactly.
        sig = {e: math.hypot(sigma, PLACE_SIGMA_M[e.kind]) for e in keys}
        # Read, but the map says out of sight here: unlikely. A plate read but cut by the
        # image border, whose place is not known, much less so within reading range: the
        # plate hangs a metre beside the door the map's sight line ends at, and round a
        # corner one of the two is in sight when the other is not.
        spurious = {
            e: np.where(
                np.linalg.norm(here_xy - np.array(entity_xy(self.pm, e)), axis=1)
                <= self.vis.read_range,
                math.log(P_OCCLUDED),
                math.log(P_SPURIOUS),
            )
            for e in named
        }
        for i, r in enumerate(readable):
            if self.recall is None:
                lw = len(r - keys - named) * math.log(P_MISS)
            else:
                lw = sum(self.miss_log(e, here_xy[i]) for e in r - keys - named)
            lw += sum(spurious[e][i] for e in named - r)
            for e in keys:
                if e in r:
                    lw += max(-0.5 * (d_seen[e][i] / sig[e]) ** 2, MISREAD)
                else:
                    lw += math.log(P_SPURIOUS)
            logw[i] += lw
