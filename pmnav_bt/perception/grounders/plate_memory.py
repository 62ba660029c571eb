"""Reads of plates remembered by where they hang: consistency across reads, corridor order.

One read of a plate may leave two codes open (``2.04`` or ``2.40``, both one character
from what was read). Two things settle it without guessing:

- **the same plate read again**: reads of a plate (its centre within ``SAME_PLATE_M`` of
  a remembered one, in the odometry frame) are independent looks, so their evidence adds
  up (``sign_match.Evidence.add``); two consistent reads can name a room that neither
  names alone, and a contradicting one takes a sighting back to ambiguous;
- **the rooms along the corridor**: the map knows where each room's door is. A plate
  already named (room X, here) and the plate being read (there) stand as far apart as
  the doors of X and of the room it shows, up to the plate's offset from its door and
  odometry drift (``SPACING_SD_M``, plus ``SPACING_SD_PER_M`` of the distance). So
  between the plates of 2.03 and 2.05 the plate is likelier 2.04 than 2.40, which lies
  down another corridor. The prior is a mixture with a floor (``SPACING_FLOOR``), taken
  relative to the room that fits best: a named neighbour shifts the odds among the rooms,
  it neither makes a room out of nothing nor a known plate unknown.

Only plates named by a sighting serve as neighbours, and only those read within
``NEIGHBOUR_M`` (the spacing of a few doors: drift over that run is small) and the last
``MEMORY_S`` seconds (so odometry has not drifted far since).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from pmnav_bt.perception.sign_match import Evidence, Match, decide
from pmnav_bt.seams import Entity

SAME_PLATE_M = 0.4  # plate centres closer than this are one plate (plates are >= 0.15 m)
NEIGHBOUR_M = 12.0  # a named plate this near informs the prior (a few doors apart)
MEMORY_S = 120.0  # reads older than this are forgotten (odometry drifts)
MAX_PLATES = 64
SPACING_SD_M = 0.8  # plate beside, over or on its door, either side: about a door's width
SPACING_SD_PER_M = 0.1  # odometry drift, per metre between the plates
SPACING_FLOOR = 0.05  # prior of a room whose door is not where the spacing says


SAME_VIEW_M = 0.2  # reads from viewpoints this close (and turned less than SAME_VIEW_RAD)
SAME_VIEW_RAD = math.radians(10.0)  # see the same pixels: the later replaces the earlier


@dataclass
class _Plate:
    """A plate: where it hangs, when last read, its reads by viewpoint, what it is."""

    xy: tuple[float, float]
    stamp: float
    reads: list[tuple[tuple[float, float, float], Evidence]]
    named: Entity | None = None

    @property
    def evidence(self) -> Evidence:
        total = self.reads[0][1]
        for _, ev in self.reads[1:]:
            total = total.add(ev)
        return total


class PlateMemory:
    """Plates read recently (odometry frame) and what their reads add up to.

    ``door_of(entity)``: where the map puts that entity's door (None where it has none)."""

    def __init__(self, door_of: Callable[[Entity], tuple[float, float] | None]):
        self.door_of = door_of
        self.plates: list[_Plate] = []

    def read(
        self,
        xy: tuple[float, float],
        view: tuple[float, float, float],
        stamp: float,
        ev: Evidence,
    ) -> Match | None:
        """Remember a read of the plate at ``xy`` (odometry frame, metres) from the pose
        ``view`` (x, y, yaw) at ``stamp`` (seconds), and say what the plate is, all its
        reads and its neighbours weighed. A read from the viewpoint of an earlier one sees
        the same pixels, so it replaces that read instead of adding to it."""
        self.plates = [p for p in self.plates if stamp - p.stamp <= MEMORY_S][-MAX_PLATES:]
        plate = next((p for p in self.plates if _dist(p.xy, xy) < SAME_PLATE_M), None)
        if plate is None:
            plate = _Plate(xy, stamp, [])
            self.plates.append(plate)
        plate.stamp = stamp
        plate.reads = [r for r in plate.reads if not _same_view(r[0], view)] + [(view, ev)]
        ev = plate.evidence
        m = decide(ev, self._prior(plate, list(ev.entities)))
        plate.named = None if m is None else m.entity
        return m

    def _prior(self, plate: _Plate, candidates: list[Entity]) -> dict[Entity, float]:
        """log prior of each candidate from the plates named near ``plate`` (module doc)."""
        prior: dict[Entity, float] = {}
        for other in self.plates:
            if other is plate or other.named is None:
                continue
            seen = _dist(other.xy, plate.xy)
            anchor = self.door_of(other.named)
            if seen > NEIGHBOUR_M or anchor is None:
                continue
            sd = SPACING_SD_M + SPACING_SD_PER_M * seen
            for c in candidates:
                door = self.door_of(c)
                if door is None or c == other.named:
                    p = SPACING_FLOOR
                else:
                    z = (_dist(door, anchor) - seen) / sd
                    p = SPACING_FLOOR + (1.0 - SPACING_FLOOR) * math.exp(-0.5 * z * z)
                prior[c] = prior.get(c, 0.0) + math.log(p)
        # Relative to the candidate that fits best: the neighbours shift the odds among
        # the building's rooms, not against a plate the building does not hold.
        top = max(prior.values(), default=0.0)
        return {c: v - top for c, v in prior.items()}


def _dist(a: tuple[float, float], b: tuple[float, float]) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _same_view(a: tuple[float, float, float], b: tuple[float, float, float]) -> bool:
    turn = abs((a[2] - b[2] + math.pi) % (2 * math.pi) - math.pi)
    return _dist(a[:2], b[:2]) < SAME_VIEW_M and turn < SAME_VIEW_RAD
