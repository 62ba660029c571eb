"""The ``ocr`` grounder: reads door and landmark signs in RGB, floor and walls from depth.

- ``read_signs``: every plate whose text names a room or landmark of the building
  (``SignReader`` + ``SignMatcher``), its reads in earlier frames and the rooms named
  around it weighed (``PlateMemory``); an ambiguous plate names nothing. The box is the
  sign's, its ``point`` where the named entity is, the point the priori-map knows it by:
  for a room its door (derived from the sign, as ``detect`` does), for a landmark its
  sign; None without depth. Localization pairs these points with the map's. A plate
  whose text names nothing is shown to the pictogram reader (``perception/pictograms.py``,
  when one is given): a toilet pictogram read above its calibrated confidence names the
  rooms the map says are toilets (``SignMatcher.pictogram_evidence``), through the same
  plate memory, when depth hangs the plate where signs hang; a read short of that
  confidence is not a sighting.
- ``detect(room)``: the room's *door*, found in RGB-D around its sign
  (``door_scene.door_for_plate``; the file's signage mounting a prior): box and mask of
  the door rectangle projected into the image, ``point`` its centre.
  Without depth the door cannot be placed: the sign's detection stands in for it.
- ``detect(landmark)``: the landmark's sign.
- ``surfaces``: floor and walls from depth geometry (``depth.surfaces``).
- ``unread_plates``: the plates it found but could not read, or read and could not tell
  apart (``perception/unread_plates.py``), placed by depth, for the tree's active read;
  a plate the pictogram reader is unsure of is one of them. ``plate_named``: the plate
  last read as naming a room or landmark, placed alike.

Where the body offers a wider view of the frame for reading (``Observation.reading``),
plates are looked for in the frame and their crops read in that view (only the crops are
made); boxes stay in frame pixels.
No simulator labels are read. Results are cached for the last frame, so the tree can
ask ``read_signs`` and ``detect`` of one frame at the cost of one reading.
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, replace

import numpy as np

from pmnav_bt.backends import BackendDeps
from pmnav_bt.map.building import Building
from pmnav_bt.perception import depth as depth_geom
from pmnav_bt.perception.door_scene import door_for_plate, mounting_prior
from pmnav_bt.perception.doors import DoorLayout
from pmnav_bt.perception.grounders.plate_memory import PlateMemory
from pmnav_bt.perception.pictograms import PictogramRead, PictogramReader
from pmnav_bt.perception.sign_match import Evidence, Match, SignMatcher, decide
from pmnav_bt.perception.signs import (
    MIN_LINE_PX,
    Box,
    SignReader,
    SignText,
    scale_box,
    scale_sign,
)
from pmnav_bt.perception.unread_plates import (
    UnreadPlate,
    UnreadPlates,
    ambiguous,
    hangs_like_a_plate,
    unread_plate,
)
from pmnav_bt.seams import Detection, Entity, EntityKind, Observation, SurfaceMasks


@dataclass
class _Read:
    """One frame's signs, and the door derived from each room sign (None: not derived)."""

    signs: list[Detection]
    doors: list[Detection | None]


class OcrGrounder:
    """Grounder by reading signs (see the module docstring)."""

    needs_sim_labels = False

    def __init__(
        self,
        building: Building,
        reader: SignReader | None = None,
        layout: DoorLayout | None = None,
        pictograms: PictogramReader | None = None,
    ):
        self.building = building
        self.reader = reader if reader is not None else SignReader()
        self.pictograms = pictograms  # None: no pictogram is read
        self.matcher = SignMatcher(building)
        self.memory = PlateMemory(self._door_of)
        self.unread = UnreadPlates()
        self.layout = layout if layout is not None else DoorLayout()
        self._lock = threading.Lock()
        self._memory_lock = threading.Lock()
        self._cache: tuple[np.ndarray, float, _Read] | None = None
        self._observer = None

    # -- Grounder seam ------------------------------------------------------------------

    def read_signs(self, obs: Observation) -> list[Detection]:
        return list(self._read(obs).signs)

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        r = self._read(obs)
        out = [
            door if door is not None else sign
            for sign, door in zip(r.signs, r.doors, strict=True)
            if sign.entity == target
        ]
        return sorted(out, key=lambda d: -d.score)

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        return depth_geom.surfaces(obs)

    # -- plates seen but not read (perception.unread_plates.SeesUnreadPlates) ------------

    def unread_plates(self, since: float) -> list[UnreadPlate]:
        return self.unread.since(since)

    def plate_named(self, entity: Entity) -> UnreadPlate | None:
        return self.unread.plate_named(entity)

    # -- what a map check watches (perception.map_check.WatchesReads) ---------------------

    def watch_reads(self, observer) -> None:
        """Tell ``observer(obs, signs, unmatched)`` what each new frame read shows:
        ``unmatched`` are the plates read with trusted digits that named nothing of the
        map (``entity`` None, ``point`` the plate's centre). None stops telling."""
        self._observer = observer

    # -- internals ----------------------------------------------------------------------

    def _read(self, obs: Observation) -> _Read:
        with self._lock:  # the same frame object (kept alive here, so never a reused id)
            c = self._cache
            if c is not None and c[0] is obs.rgb and c[1] == obs.stamp:
                return c[2]
        signs, doors, unmatched = [], [], []
        unnamed: list[tuple[Box, float, SignText | None, Evidence | None]] = []
        for box, line_px, sign in self._read_text(obs):
            if sign is None:  # a plate seen, its text not read
                unnamed.append((box, line_px, None, None))
                continue
            plate = depth_geom.plate_pose(obs, sign.box)
            m, ev = self._match(obs, sign, plate)
            if m is None:
                unnamed.append((box, line_px, sign, ev))
                continue
            self._sighting(obs, sign.text, sign.box, float(m.score * sign.score), m, plate,
                           signs, doors, text_at=(box, line_px))
        pictos = self._pictograms(obs, [box for box, _, _, _ in unnamed])
        for (box, line_px, sign, ev), picto in zip(unnamed, pictos, strict=True):
            if picto is not None and picto.sighting:
                # No words to confirm it: only a plate depth hangs where signs hang.
                plate = depth_geom.plate_pose(obs, box)
                if plate is None or not hangs_like_a_plate(obs, plate):
                    continue
                m = self._match_pictogram(obs, picto.kind, plate)
                if m is not None:
                    self._sighting(obs, f"[{picto.kind}]", box, float(m.score * picto.p), m,
                                   plate, signs, doors)
                continue  # a pictogram, not a room of this map, or the map's toilets alike
            if sign is None or ev is None:
                self._unread(obs, box, line_px, "")
                continue
            lines = [(ln.text, ln.score, ln.char_scores) for ln in sign.lines]
            # A read that names nothing for sure is a plate to read again, not another one.
            unsure = ambiguous(ev) or self.matcher.unsure(lines)
            if unsure or (picto is not None and picto.ambiguous):
                # its text's top where the reader found it, not the plate's border
                self._unread(obs, box, line_px, sign.text, sign.lines[0].box[1])
            if self._observer is not None and self.matcher.trusted(lines):
                unmatched.append(_unmatched(obs, sign))
        result = _Read(signs, doors)
        with self._lock:
            self._cache = (obs.rgb, obs.stamp, result)
        if self._observer is not None:
            self._observer(obs, list(signs), unmatched)
        return result

    def _sighting(
        self,
        obs: Observation,
        label: str,
        box: Box,
        score: float,
        m: Match,
        plate: depth_geom.PlatePose | None,
        signs: list[Detection],
        doors: list[Detection | None],
        text_at: tuple[Box, float] | None = None,
    ) -> None:
        """Add the plate in ``box`` named ``m.entity`` to ``signs``, with its door (a room's,
        placed from the scene) to ``doors``. ``text_at`` (the plate's box and text-line
        height in frame pixels, for a read text) also places it as the plate last read as
        ``m.entity`` (``plate_named``)."""
        if plate is not None:
            self.unread.read_at(_odom(obs, plate.centre))
            named = None if text_at is None else unread_plate(obs, *text_at, label)
            if named is not None:
                self.unread.named(m.entity, named)
        det = Detection(
            label=label,
            box=box,
            score=score,
            entity=m.entity,
            point=None if plate is None else tuple(float(v) for v in plate.centre),  # type: ignore[arg-type]
        )
        door = None
        if m.entity.kind == EntityKind.ROOM and plate is not None:
            door = self._door(obs, det, plate)
            det = replace(det, point=door.point)
        signs.append(det)
        doors.append(door)

    def _pictograms(self, obs: Observation, boxes: list[Box]) -> list[PictogramRead | None]:
        """The pictogram reader's read of each plate in ``boxes`` (frame pixels), made in
        the reading view where there is one; None where not read (no reader, too small)."""
        if self.pictograms is None or not boxes:
            return [None] * len(boxes)
        src, s = _reading_source(obs)
        scaled = [scale_box(b, s) for b in boxes]
        reads = {pr.box: pr for pr in self.pictograms.read(src, scaled)}
        return [reads.get(b) for b in scaled]

    def _match_pictogram(
        self, obs: Observation, kind: str, plate: depth_geom.PlatePose
    ) -> Match | None:
        """Which room a plate showing the pictogram of ``kind`` is: the map's rooms of that
        kind, weighed with the plate's earlier reads and its neighbours (``PlateMemory``)."""
        ev = self.matcher.pictogram_evidence(kind)
        p = obs.pose
        with self._memory_lock:
            return self.memory.read(_odom(obs, plate.centre), (p.x, p.y, p.yaw), obs.stamp, ev)

    def _match(
        self, obs: Observation, sign: SignText, plate: depth_geom.PlatePose | None
    ) -> tuple[Match | None, Evidence]:
        """What ``sign`` names: with its plate's place known, all reads of that plate and
        the plates named around it weighed (``PlateMemory``); else this read alone. With
        the evidence of this read."""
        ev = self.matcher.evidence([(ln.text, ln.score, ln.char_scores) for ln in sign.lines])
        if plate is None:
            return decide(ev), ev
        p = obs.pose
        with self._memory_lock:
            return self.memory.read(_odom(obs, plate.centre), (p.x, p.y, p.yaw), obs.stamp, ev), ev

    def _unread(
        self, obs: Observation, box: Box, line_px: float, read: str, top_px: float | None = None
    ) -> None:
        # A plate with text read: which way the text faces (a flag's along its wall) is
        # worth depth's wall fit; a patch of nothing read is not.
        plate = unread_plate(obs, box, line_px, read, flags=bool(read), text_top_px=top_px)
        if plate is not None:
            self.unread.seen(plate)

    def _door_of(self, e: Entity) -> tuple[float, float] | None:
        """Where the map puts ``e``'s door (a landmark: where it stands); None where the
        map does not say (the map-less baseline's sign vocabulary has no positions)."""
        b = self.building
        x, y = b.room(e.id).door if e.kind == EntityKind.ROOM else b.landmark(e.id).pos
        return (float(x), float(y)) if math.isfinite(x) and math.isfinite(y) else None

    def _read_text(self, obs: Observation) -> list[tuple[Box, float, SignText | None]]:
        """The frame's plate candidates (box and text-line height in the frame's pixels),
        each with its text (None: not read). Where the body offers a wider view
        (``obs.reading``), plates are looked for in the frame as the reader looks for them
        in that view (scaled lines as low), and only their crops of the view are made and
        read."""
        r, s = _reading_source(obs)
        if r is obs.rgb:
            found = self.reader.candidates(obs.rgb)
            return _by_candidate(found, self.reader.read(obs.rgb, found))
        found = self.reader.candidates(obs.rgb, min_line_px=MIN_LINE_PX / s)
        if not found:
            return []
        cands = [(scale_box(b, s), lh * s) for b, lh in found]
        return _by_candidate(found, [scale_sign(t, 1.0 / s) for t in self.reader.read(r, cands)])

    def _door(self, obs: Observation, sign: Detection, plate: depth_geom.PlatePose) -> Detection:
        prior = mounting_prior(self.building, sign.entity.id)  # type: ignore[union-attr]
        door = door_for_plate(obs, plate, sign.box, self.layout, prior)
        if door.mask is not None:
            ys, xs = np.nonzero(door.mask)
            box = (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
        else:
            box = sign.box
        return Detection(
            label=sign.label,
            box=box,
            score=sign.score if door.seen else 0.9 * sign.score,
            mask=door.mask,
            entity=sign.entity,
            point=tuple(float(v) for v in door.centre),  # type: ignore[arg-type]
        )


def _reading_source(obs: Observation):
    """Where plates are read: the body's wider reading view (``obs.reading``) where it
    offers one wider than the frame, else the frame; with the scale from frame pixels to
    its pixels."""
    r, w = obs.reading, obs.rgb.shape[1]
    if r is None or r.width <= w:
        return obs.rgb, 1.0
    return r, r.width / w

def _by_candidate(
    found: list[tuple[Box, float]], read: list[SignText]
) -> list[tuple[Box, float, SignText | None]]:
    """Each candidate (box, line height) with the text read in it (the reader keeps a
    candidate's box for its text), or None."""
    out = []
    for box, line_px in found:
        same = (t for t in read if max(abs(a - b) for a, b in zip(t.box, box, strict=True)) < 1)
        out.append((box, line_px, next(same, None)))
    return out


def _odom(obs: Observation, centre: np.ndarray) -> tuple[float, float]:
    """A point of the camera body frame (x forward, y left) in the odometry frame."""
    p = obs.pose
    x, y = float(centre[0]), float(centre[1])
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    return (p.x + c * x - s * y, p.y + s * x + c * y)


def _unmatched(obs: Observation, sign: SignText) -> Detection:
    plate = depth_geom.plate_pose(obs, sign.box)
    return Detection(
        label=sign.text,
        box=sign.box,
        score=float(sign.score),
        point=None if plate is None else tuple(float(v) for v in plate.centre),  # type: ignore[arg-type]
    )


def pictogram_reader(g) -> PictogramReader | None:
    """The pictogram reader ``config.grounder`` asks for (``pictograms``), or None."""
    return PictogramReader() if g.pictograms else None


def reader_and_layout(g) -> tuple[SignReader, DoorLayout]:
    """The sign reader and door layout ``config.grounder`` describes (ocr and gdino_sam)."""
    reader = SignReader(
        threads=g.ocr_threads, max_candidates=g.ocr_max_candidates, min_score=g.ocr_min_score
    )
    layout = DoorLayout(
        sign_to_door=g.sign_to_door,
        door_width=g.door_width,
        door_height=g.door_height,
        default_side=g.door_side,
    )
    return reader, layout


def build(deps: BackendDeps) -> OcrGrounder:
    """The ``ocr`` back end from ``config.grounder`` (registry factory)."""
    g = deps.config.grounder
    return OcrGrounder(deps.pm.building, *reader_and_layout(g), pictogram_reader(g))
