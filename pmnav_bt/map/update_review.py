"""A person's review of a run's map updates: each described in the building's words, and
the accepted ones applied to the building file through the building editor.

``describe`` says where an update is as a person walking the building would ("room14
'117 Pharmacy', on the corridor between room8 and turn2") and what the evidence is;
``apply`` makes the accepted changes in a :class:`~pmnav_bt.map.edit.BuildingEditor`
(one undoable edit each), so the caller can show the diff, check the result and write
it (``pmnav map updates``). What each kind changes: ``pmnav_bt.map.updates``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from pmnav_bt.errors import PmNavError, UnknownNameError
from pmnav_bt.map.edit import BuildingEditor, EditError
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.signage import split_number
from pmnav_bt.map.updates import MapUpdate


class ReviewError(PmNavError):
    """An update that does not fit the building it is applied to, or a bad choice."""


def where(pm: PrioriMap, u: MapUpdate) -> str:
    """Where ``u`` is, in the building's words."""
    b = pm.building
    if u.subject_kind == "segment":
        try:
            seg = pm.segment(u.subject)
        except UnknownNameError:
            return f"{u.subject} (not in this building)"
        return f"corridor between {seg.a} and {seg.b} ({seg.short})"
    ids = {r.id: r for r in b.rooms} | {lm.id: lm for lm in b.landmarks}
    item = ids.get(u.subject)
    if item is None:
        return f"{u.subject} (not in this building)"
    place = pm.places.get(u.subject)
    if place is None:
        return f"{u.subject} '{item.sign_text}'"
    seg = pm.segments[place.segment - 1]
    return f"{u.subject} '{item.sign_text}', on the corridor between {seg.a} and {seg.b}"


def evidence(u: MapUpdate) -> str:
    """The evidence in one line: what was seen against the map, how often, where, when."""
    e = u.evidence
    reads = sorted(set(e.reads))
    said = f"map {u.mapped!r}, seen {u.seen!r}"
    if reads:
        said += f"; {len(e.reads)} read(s): " + ", ".join(repr(r) for r in reads[:3])
        if len(reads) > 3:
            said += f" (+{len(reads) - 3})"
    pose = e.pose or e.odom
    frame = "map" if e.pose is not None else "odom"
    said += f"; at t={e.time:.0f} s from ({pose[0]:.1f}, {pose[1]:.1f}) {frame}"
    return said + (f"; image {e.crop}" if e.crop else "")


def applies(u: MapUpdate) -> bool:
    """Whether accepting ``u`` can change a building file (a closed door cannot)."""
    return u.kind != "door_closed"


def parse_choice(text: str, count: int) -> list[int]:
    """``--accept 1,3`` (1-based, as listed) -> sorted 0-based indices; ``all`` takes all."""
    if text.strip().lower() == "all":
        return list(range(count))
    out = set()
    for part in text.split(","):
        part = part.strip()
        if not part.isdigit() or not 1 <= int(part) <= count:
            raise ReviewError(f"--accept {text[:40]!r}: expected numbers 1 to {count}, or all")
        out.add(int(part) - 1)
    return sorted(out)


def apply(editor: BuildingEditor, pm: PrioriMap, updates: Sequence[MapUpdate]) -> list[str]:
    """Make each update's change in ``editor``; one line per change made."""
    done = []
    for u in updates:
        try:
            done.append(_apply_one(editor, pm, u))
        except (EditError, UnknownNameError) as err:
            raise ReviewError(f"{u.kind} {u.subject}: {err}") from None
    return done


def _apply_one(editor: BuildingEditor, pm: PrioriMap, u: MapUpdate) -> str:
    if not applies(u):
        raise ReviewError(
            f"{u.kind} {u.subject}: a building file has no door that closes; "
            "note it on the plan by hand if it stays closed"
        )
    if u.kind == "sign_text":
        group, item = editor.find(u.subject)
        if group == "waypoints":
            raise ReviewError(f"sign_text {u.subject}: a waypoint has no sign")
        fields = {"sign": u.seen}
        name = split_number(u.seen)[1]
        if item.get("name") and name:
            fields["name"] = name
        editor.set_fields(u.subject, **fields)
        return f"{u.subject}: sign {u.mapped!r} -> {u.seen!r}"
    if u.kind == "moved":
        if u.at is None:
            raise ReviewError(f"moved {u.subject}: the update has no position (seen unlocalized)")
        old = editor.position(u.subject)
        editor.move(u.subject, u.at)
        dist = math.dist(old, u.at)
        return f"{u.subject}: moved {dist:.1f} m to ({u.at[0]:.2f}, {u.at[1]:.2f})"
    seg = pm.segment(u.subject)
    a, b = seg.corridor
    editor.delete_edge(a, b)
    return f"corridor {a}-{b} removed (its {seg.short}, between {seg.a} and {seg.b}, blocked)"
