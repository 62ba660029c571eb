"""Resolve what a person types into map entities: goal rooms and plan starts.

Room names match by ID, display name or alias, ignoring case, spaces and
punctuation ("Room 17", "room17", "one-stop service centre"). An unknown or
ambiguous name is an UnknownNameError that lists the closest candidates.
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass

import numpy as np

from pmnav_bt.cli_values import MAX_POSE_COORD_M
from pmnav_bt.errors import UnknownNameError
from pmnav_bt.map.building import Building
from pmnav_bt.map.priori_map import PrioriMap, Segment, clipped
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.seams import Entity, EntityKind, PlanStart, Pose2D


def normalise(name: str) -> str:
    """Lower case, letters and digits only: 'One-Stop  Service Centre' -> 'onestopservicecentre'."""
    return re.sub(r"[^0-9a-z]", "", name.casefold())


def _index(pm: PrioriMap) -> tuple[dict[str, set[str]], dict[str, str]]:
    """normalised key -> room ids; room id -> label for messages (cached on the map)."""
    cached = pm.__dict__.get("_room_name_index")
    if cached is not None:
        return cached
    keys: dict[str, set[str]] = {}
    labels: dict[str, str] = {}
    for r in pm.building.rooms:
        labels[r.id] = f"{r.id} ({r.display_name})" if r.name else r.id
        for name in (r.id, r.name, r.sign, *r.aliases):
            if name and normalise(name):
                keys.setdefault(normalise(name), set()).add(r.id)
    pm.__dict__["_room_name_index"] = (keys, labels)
    return keys, labels


def resolve_room(pm: PrioriMap, name: str) -> str:
    """The ID of the room a person means by ``name``."""
    keys, labels = _index(pm)
    key = normalise(name)
    ids = keys.get(key, set())
    if len(ids) == 1:
        return next(iter(ids))
    if len(ids) > 1:
        cands = sorted(labels[i] for i in ids)
        raise UnknownNameError(
            f"room name {name!r} is ambiguous: it matches {', '.join(cands)}; give the room ID",
            cands,
        )
    if key:
        for lm in pm.building.landmarks:
            if key in {normalise(n) for n in (lm.id, lm.name, lm.kind, *lm.aliases) if n}:
                raise UnknownNameError(
                    f"{name!r} is a landmark ({lm.kind}), not a room; plans go to rooms"
                )
    close = difflib.get_close_matches(key, list(keys), n=5, cutoff=0.5) if key else []
    cands = sorted({labels[i] for k in close for i in keys[k]})
    hint = f"; closest: {', '.join(cands)}" if cands else ""
    raise UnknownNameError(f"no room called {name!r} in {pm.building.name}{hint}", cands)


def resolve_site_room(sm: SiteMap, name: str) -> tuple[str, str]:
    """The level and the ID of the room a person means by ``name`` in a site of several
    levels: a name found on one level only ("pharmacy"), or qualified by its level
    ("L2/toilets", "toilets on L2", "toilets on level L2"). A name on several levels is an
    UnknownNameError that lists them and how to qualify it."""
    site = sm.site
    if sm.single:
        level = site.levels[0].name
        return level, resolve_room(sm.maps[level], name)
    qualified = _qualified(sm, name)
    if qualified is not None:
        level, room = qualified
        return level, resolve_room(sm.maps[level], room)
    key = normalise(name)
    found = {lv: ids for lv, pm in sm.maps.items() if (ids := _index(pm)[0].get(key, set()))}
    if len(found) == 1:
        level = next(iter(found))
        return level, resolve_room(sm.maps[level], name)
    shown = clipped(name)
    if found:
        where = "; ".join(
            f"{lv} ({', '.join(sorted(_index(sm.maps[lv])[1][i] for i in ids))})"
            for lv, ids in found.items()
        )
        lv = next(iter(found))
        raise UnknownNameError(
            f"room name {shown!r} is on {len(found)} levels: {where}; give its level: "
            f"'{lv}/{shown}' or '{shown} on {lv}'",
            [f"{lv}/{i}" for lv, ids in found.items() for i in sorted(ids)],
        )
    cands: list[str] = []
    for lv, pm in sm.maps.items():
        try:
            resolve_room(pm, name)
        except UnknownNameError as err:
            if "is a landmark" in str(err):
                raise UnknownNameError(f"{str(err)} (on level {lv})") from None
            cands += [f"{lv}/{c}" for c in err.candidates]
    hint = f"; closest: {', '.join(cands[:8])}" if cands else ""
    raise UnknownNameError(f"no room called {shown!r} on any level of {site.name}{hint}", cands)


_ON_LEVEL = re.compile(r"(?is)\s*(.+?)\s+on\s+(?:level\s+)?(\S+)\s*")


def _qualified(sm: SiteMap, name: str) -> tuple[str, str] | None:
    """(level, room name) of a name qualified by a level of the site, else None."""
    head, sep, tail = name.partition("/")
    if sep and head.strip() and tail.strip():
        level = _site_level(sm, head.strip())
        if level is not None:
            return level, tail.strip()
    m = _ON_LEVEL.fullmatch(name)
    if m:
        level = _site_level(sm, m.group(2))
        if level is not None:
            return level, m.group(1)
    return None


def _site_level(sm: SiteMap, text: str) -> str | None:
    try:
        return sm.site.level(text).name
    except UnknownNameError:
        return None


@dataclass(frozen=True)
class StartPoint:
    """A resolved start: on ``segment`` at fraction ``t`` from a to b, heading if known."""

    description: str
    segment: Segment
    t: float
    heading: float | None = None


_POSE = re.compile(r"^\s*(-?[\d.]+)\s*,\s*(-?[\d.]+)\s*(?:,\s*(-?[\d.]+)\s*)?$")


def resolve_start(pm: PrioriMap, spec: PlanStart) -> StartPoint:
    """A start given as an estimated map ``Pose2D`` (inside the loop), or as a person types
    it: a segment ("seg13", "seg13(room14-room7)"), a waypoint or room ID, or a map pose
    "x,y" / "x,y,yaw_deg" (degrees, counter-clockwise from east)."""
    if isinstance(spec, Pose2D):
        return _pose_start(pm, spec.x, spec.y, spec.yaw)
    spec = spec.strip()
    m = _POSE.match(spec)
    if m:
        try:
            x, y = float(m.group(1)), float(m.group(2))
            yaw = math.radians(float(m.group(3))) if m.group(3) is not None else None
        except ValueError:
            raise UnknownNameError(f"bad pose {spec!r}: expected 'x,y' or 'x,y,yaw_deg'") from None
        if not all(map(math.isfinite, (x, y, yaw if yaw is not None else 0.0))):
            raise UnknownNameError(f"bad pose {spec[:60]!r}: the numbers must be finite")
        if max(abs(x), abs(y)) > MAX_POSE_COORD_M:
            raise UnknownNameError(
                f"bad pose {spec[:60]!r}: x and y must be within +-{MAX_POSE_COORD_M:g} m"
            )
        return _pose_start(pm, x, y, yaw)
    if re.fullmatch(r"(?i)seg\s*\d+.*", spec):
        seg = pm.segment(spec)
        return StartPoint(seg.name, seg, 0.5)
    node = spec if spec in pm.nodes else pm.places[spec].node if spec in pm.places else None
    if node is None:
        # A room given by name or alias starts at its room waypoint.
        try:
            node = pm.places[resolve_room(pm, spec)].node
        except UnknownNameError:
            node = None
    if node is not None:
        segs = pm.segments_at(node)
        if not segs:
            raise UnknownNameError(f"{spec!r} is not on any corridor")
        seg = segs[0]
        return StartPoint(spec, seg, 0.0 if seg.a == node else 1.0)
    keys = list(pm.nodes) + [s.short for s in pm.segments]
    close = difflib.get_close_matches(spec, keys, n=5, cutoff=0.5)
    hint = f"; closest: {', '.join(close)}" if close else ""
    raise UnknownNameError(
        f"unknown start {spec!r}: give a segment (seg13), a waypoint or room ID, "
        f"or a pose 'x,y[,yaw_deg]'{hint}",
        close,
    )


def _pose_start(pm: PrioriMap, x: float, y: float, yaw: float | None) -> StartPoint:
    """The point of the nearest corridor to a map pose (which must be in a corridor)."""
    loc = pm.locate(x, y)
    limit = loc.segment.width / 2.0 + 1.0
    if loc.offset > limit:
        raise UnknownNameError(
            f"pose ({x:.2f}, {y:.2f}) is {loc.offset:.2f} m from the nearest corridor "
            f"({loc.segment.name}); a start must be in a corridor"
        )
    return StartPoint(f"pose ({x:.1f}, {y:.1f})", loc.segment, loc.t, yaw)


def entity_index(building: Building) -> dict[str, Entity]:
    """Normalised sign text / name / ID / alias -> the room or landmark it names.

    The first entity to claim a name keeps it (rooms before landmarks).
    """
    cached = building.__dict__.get("_entity_index")
    if cached is not None:
        return cached
    index: dict[str, Entity] = {}
    for r in building.rooms:
        for n in (r.id, r.name, r.sign_text, *r.aliases):
            if n and normalise(n):
                index.setdefault(normalise(n), Entity.room(r.id))
    for lm in building.landmarks:
        for n in (lm.id, lm.name, lm.sign, *lm.aliases):
            if n and normalise(n):
                index.setdefault(normalise(n), Entity.landmark(lm.id))
    building.__dict__["_entity_index"] = index
    return index


def step_entity(building: Building, ident: str) -> Entity:
    """The entity a plan step looks for (``PlanStep.look_for``: a room or landmark ID)."""
    if ident in {r.id for r in building.rooms}:
        return Entity.room(ident)
    building.landmark(ident)  # an unknown ID is a KeyError here, not a wrong entity later
    return Entity.landmark(ident)


def sign_text(building: Building, entity: Entity) -> str:
    """What a person reads on the sign of a room or landmark."""
    if entity.kind is EntityKind.ROOM:
        return building.room(entity.id).sign_text
    return building.landmark(entity.id).sign_text


def entity_position(pm: PrioriMap, entity: Entity) -> tuple[float, float]:
    """Where a room or landmark is seen: a room's door; a landmark's face on the corridor
    wall nearest to it (landmarks are mounted on the wall; the file may place them behind
    it)."""
    b = pm.building
    if entity.kind is EntityKind.ROOM:
        return b.room(entity.id).door
    ident = entity.id
    pos = np.asarray(b.landmark(ident).pos, dtype=float)
    place = pm.places[ident]
    node = pm.node_xy(place.node)
    d = pos - node
    dist = float(np.linalg.norm(d))
    half = pm.segments[place.segment - 1].width / 2.0
    if dist <= half:
        return float(pos[0]), float(pos[1])
    face = node + d * (half / dist)
    return float(face[0]), float(face[1])
