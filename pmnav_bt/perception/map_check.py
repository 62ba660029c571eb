"""Notices, in what perception reads, where the world disagrees with the map.

A grounder that reads plates (``ocr``, and ``gdino_sam`` through it) tells a watcher
what each new frame showed: the signs it matched to the map and the plates it read but
could not match (:class:`WatchesReads`). :class:`MapCheck` is such a watcher, and
compares each frame with the map:

- **a sign that reads differently** (``sign_text``): a plate with a name
  (``MIN_NAME_LETTERS``) that the matcher named by its room code but whose words are none
  of that room's names, or that names nothing of the map and starts with the code of one
  room's sign ("117 Quiet Room" where the map says "117 Pharmacy"), or, with no number,
  hangs within ``ATTRIBUTE_M`` of one room's door (by the pose estimate, once localized);
- **a landmark not where the map puts it** (``moved``): a landmark's sign seen more than
  ``MOVED_M`` from the map's place for it, by the pose estimate. Rooms are not judged so:
  directional signs ("Radiology ->") name rooms far from their doors.

Watching the reader, not wrapping the ``Grounder``, sees every frame read, whoever asked
(the tree's capture, the coarse direction and the refiner hold the grounder apiece), at
no further cost. The oracle (``sim_gt``) reads the map's own texts and has no watcher.

A disagreement is written to the run's ``MapUpdateSink`` once it has been seen in
``CONFIRM_READS`` frames (one misread is not a stale map), with the reads, the pose, the
clock time and a crop of the plate; each (kind, subject) once per run. The checks run
where the reading runs (on the worker), never in a tick.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import cv2
import numpy as np

from pmnav_bt.geometry import se2_apply, se2_compose
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.signage import split_number
from pmnav_bt.map.updates import Evidence, MapUpdate, MapUpdateSink
from pmnav_bt.perception.sign_match import SignMatcher, normalise
from pmnav_bt.planning.resolve import entity_position, sign_text
from pmnav_bt.seams import Detection, Entity, EntityKind, Observation

CONFIRM_READS = 2  # frames that must show a disagreement before it is written
MIN_NAME_LETTERS = 3  # a read with fewer letters beside its number names nothing ("1.8")
ATTRIBUTE_M = 1.5  # a plate without a number belongs to the room whose door is this near
ATTRIBUTE_MARGIN_M = 0.75  # ... and the next door is this much farther
# A landmark's sign seen this far from the landmark's place on the map: it has moved. Its
# sign may hang 1.5 m beside it and the pose estimate is good to about 1 m; the tree's
# own check of a sighting against the map rejects one 2 m off while tracking
# (search.Verify), so a sighting this far off is already out of the ordinary.
MOVED_M = 2.0
CROP_MAX_PX = 160  # the crop's longer side: enough to show the plate, small on disk
CROP_PAD = 0.3  # of the box's size, on each side

MapTOdom = Callable[[], "tuple[float, float, float] | None"]


ReadsObserver = Callable[[Observation, "list[Detection]", "list[Detection]"], None]


@runtime_checkable
class WatchesReads(Protocol):
    """A grounder that tells ``observer(obs, matched, unmatched)`` what each new frame it
    reads shows: the signs matched to the map, and the plates read that named nothing
    of it (``entity`` None, ``point`` the plate's centre). None stops telling."""

    def watch_reads(self, observer: ReadsObserver | None) -> None: ...


@dataclass
class _Seen:
    """A disagreement seen so far: the frames' reads, where, and the first frame's crop."""

    reads: list[str] = field(default_factory=list)
    at: list[tuple[float, float]] = field(default_factory=list)
    crop: np.ndarray | None = None
    stamps: set[float] = field(default_factory=set)  # a frame counts once


class MapCheck:
    """Writes what disagrees with the map (see the module docstring); give ``frame`` to a
    grounder's ``watch_reads``. ``map_T_odom()``: the tree's current map-from-odometry
    transform (None before localization)."""

    def __init__(self, pm: PrioriMap, sink: MapUpdateSink, map_T_odom: MapTOdom) -> None:
        self.pm = pm
        self.sink = sink
        self.map_T_odom = map_T_odom
        self.matcher = SignMatcher(pm.building)
        self._seen: dict[tuple[str, Entity, str], _Seen] = {}
        self._written: set[tuple[str, Entity]] = set()

    def frame(self, obs: Observation, matched: list[Detection], unmatched: list[Detection]):
        """Compare one frame's reads with the map."""
        tf = self.map_T_odom()
        for d in unmatched:
            if _name_letters(d.label) < MIN_NAME_LETTERS:
                continue  # digits and specks: a misread, not a sign with another name
            xy = plate_in_map(obs, d, tf)
            entity = self.matcher.numbered(d.label)
            if entity is None and xy is not None:
                entity = self._door_near(xy)
            if entity is not None:
                mapped = sign_text(self.pm.building, entity)
                self._note("sign_text", entity, mapped, d.label, obs, d, xy, tf)
        for d in matched:
            if d.entity is None:
                continue
            if d.entity.kind is EntityKind.ROOM:  # named by its code, with another name
                if _name_letters(d.label) >= MIN_NAME_LETTERS and self.matcher.names_other(
                    d.entity, d.label
                ):
                    mapped = sign_text(self.pm.building, d.entity)
                    self._note("sign_text", d.entity, mapped, d.label, obs, d, None, tf)
                continue
            xy = plate_in_map(obs, d, tf)
            if xy is None:
                continue
            mx, my = entity_position(self.pm, d.entity)
            if math.dist(xy, (mx, my)) > MOVED_M:
                self._note("moved", d.entity, f"({mx:.1f}, {my:.1f})", "", obs, d, xy, tf)

    def _note(self, kind, entity, mapped, read, obs, d, xy, tf) -> None:
        if (kind, entity) in self._written:
            return
        key = (kind, entity, normalise(read))
        seen = self._seen.setdefault(key, _Seen())
        if obs.stamp in seen.stamps:
            return
        seen.stamps.add(obs.stamp)
        seen.reads.append(read or d.label)
        if xy is not None:
            seen.at.append(xy)
        if seen.crop is None:
            seen.crop = crop(obs.rgb, d.box)
        if len(seen.reads) < CONFIRM_READS:
            return
        self._written.add((kind, entity))
        at = tuple(np.mean(seen.at, axis=0).round(2).tolist()) if seen.at else None
        if kind == "moved":
            read = "" if at is None else f"({at[0]:.1f}, {at[1]:.1f})"
        odom = (obs.pose.x, obs.pose.y, obs.pose.yaw)
        pose = se2_compose(tf, odom) if tf is not None else None
        update = MapUpdate(
            kind=kind,
            subject_kind=entity.kind.value,
            subject=entity.id,
            mapped=mapped,
            seen=read,
            at=at,  # type: ignore[arg-type]
            evidence=Evidence(
                time=float(obs.stamp),
                odom=odom,
                pose=None if pose is None else tuple(float(v) for v in pose),  # type: ignore[arg-type]
                reads=tuple(seen.reads),
            ),
        )
        self.sink.record(update, seen.crop)

    def _door_near(self, xy: tuple[float, float]) -> Entity | None:
        rooms = self.pm.building.rooms
        if not rooms:
            return None
        d = np.hypot(*(np.array([r.door for r in rooms], float) - np.asarray(xy)).T)
        order = np.argsort(d)
        if d[order[0]] > ATTRIBUTE_M:
            return None
        if len(order) > 1 and d[order[1]] - d[order[0]] < ATTRIBUTE_MARGIN_M:
            return None
        return Entity.room(rooms[int(order[0])].id)


def plate_in_map(obs: Observation, d: Detection, tf) -> tuple[float, float] | None:
    """Where the plate of ``d`` (its ``point`` in the body frame of ``obs``) is on the map,
    by the map-from-odometry transform ``tf``; None before localization or without depth."""
    if tf is None or d.point is None:
        return None
    odom = se2_apply((obs.pose.x, obs.pose.y, obs.pose.yaw), d.point[:2])
    x, y = se2_apply(tf, (float(odom[0]), float(odom[1])))
    return float(x), float(y)


def _name_letters(label: str) -> int:
    """Letters of a read beside its number."""
    return sum(c.isalpha() for c in split_number(label)[1])


def crop(rgb: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    """The part of ``rgb`` round ``box`` (padded by ``CROP_PAD``), at most ``CROP_MAX_PX``."""
    h, w = rgb.shape[:2]
    x0, y0, x1, y1 = box
    px, py = CROP_PAD * (x1 - x0), CROP_PAD * (y1 - y0)
    c0, c1 = int(max(0, x0 - px)), int(min(w, x1 + px + 1))
    r0, r1 = int(max(0, y0 - py)), int(min(h, y1 + py + 1))
    out = rgb[r0:r1, c0:c1]
    side = max(out.shape[:2]) if out.size else 0
    if side > CROP_MAX_PX:
        s = CROP_MAX_PX / side
        size = (max(1, round(out.shape[1] * s)), max(1, round(out.shape[0] * s)))
        out = cv2.resize(out, size, interpolation=cv2.INTER_AREA)
    return np.ascontiguousarray(out)
