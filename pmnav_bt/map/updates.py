"""Where the building file is wrong: the disagreements a run saw, kept for a person to review.

A prior floor plan goes stale: a room is renamed, a lift moves with a refit, a corridor
is closed for works. The robot sees some of this while it drives, and what it sees is
worth more than the run: every disagreement between the world and the map is written
down as a :class:`MapUpdate`, with its evidence (the pose, the clock time, the reads, a
crop of the image), and a person decides later whether the building file should change
(``pmnav map updates FILE``). Nothing here edits a building silently.

The kinds (``UPDATE_KINDS``), what each records and what accepting it does:

- ``sign_text``: a room's or landmark's sign reads differently from the map ("117
  Pharmacy" on the map, "117 Quiet Room" on the wall); accepting sets the sign (and the
  name, when the map had one) to what was read.
- ``moved``: a room's door or a landmark was seen more than a few metres from where the
  map puts it; accepting moves it to where it was seen.
- ``corridor_blocked``: a corridor stayed blocked (the tree stopped routing through it);
  accepting removes that corridor from the map.
- ``door_closed``: a door on the route was closed; a building file has no door that
  closes, so it is listed for a person and cannot be applied.

The file (``<episode>.map_updates.jsonl``, beside a run's tree log) is JSON Lines: a header line
``{"format": "pmnav-map-updates", "version": 1, "building": ...}`` naming the building
the robot was given (a built-in's name or the file's path), then one record per
disagreement, appended as it is seen, so a run that stops keeps what it found. Crops are
small PNGs in the folder beside it named like it without ``.jsonl``, named in the record.

A run hands a :class:`MapUpdateSink` to the tree; ``UpdatesFile`` is the one that writes
the file, ``NO_MAP_UPDATES`` the one that keeps nothing (a run without an output folder).
"""

from __future__ import annotations

import json
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from pmnav_bt.loading import (
    InputFileError,
    atomic_write_bytes,
    iter_text_lines,
    parse_json,
    safe_filename,
)

FORMAT = "pmnav-map-updates"
VERSION = 1
SUFFIX = ".map_updates.jsonl"
MAX_RECORDS = 10_000  # a run that disagrees this often has a wrong map, not stale parts
MAX_TEXT = 200  # characters of one read or value kept

UPDATE_KINDS: dict[str, str] = {
    "sign_text": "a sign reads differently from the map",
    "moved": "a door or landmark is not where the map puts it",
    "corridor_blocked": "a corridor stayed blocked",
    "door_closed": "a door on the route was closed",
}
SUBJECT_KINDS = ("room", "landmark", "segment", "door")


class MapUpdatesError(InputFileError):
    """A map-updates file that cannot be read, or an update that cannot be applied."""


@dataclass(frozen=True)
class Evidence:
    """What the robot had when it saw a disagreement: the clock time (s), the odometry
    pose and the map pose (None before localization), the texts read (or the failure
    messages), and the crop's file name relative to the updates file (None: no image)."""

    time: float
    odom: tuple[float, float, float]
    pose: tuple[float, float, float] | None
    reads: tuple[str, ...] = ()
    crop: str | None = None


@dataclass(frozen=True)
class MapUpdate:
    """One disagreement: ``kind`` (see ``UPDATE_KINDS``), ``subject`` (its kind and id: a
    room, a landmark, a priori-map segment "seg13", a door), what the map says
    (``mapped``) and what was seen (``seen``), and where it was seen in the map frame
    (``at``, None where the pose was not known)."""

    kind: str
    subject_kind: str
    subject: str
    mapped: str
    seen: str
    at: tuple[float, float] | None
    evidence: Evidence

    def to_dict(self) -> dict[str, Any]:
        e = self.evidence
        return {
            "kind": self.kind,
            "subject": {"kind": self.subject_kind, "id": self.subject},
            "mapped": self.mapped,
            "seen": self.seen,
            "at": None if self.at is None else [round(v, 2) for v in self.at],
            "evidence": {
                "time": round(e.time, 2),
                "odom": [round(v, 3) for v in e.odom],
                "pose": None if e.pose is None else [round(v, 3) for v in e.pose],
                "reads": list(e.reads),
                "crop": e.crop,
            },
        }


class MapUpdateSink(Protocol):
    """Where a run puts the disagreements it sees (the seam the simulator run and the
    ROS node both fill: a file in the run's output folder, or nothing)."""

    def record(self, update: MapUpdate, crop: np.ndarray | None = None) -> None:
        """Keep ``update``; ``crop`` (H, W, 3 uint8) is the image evidence, if any."""
        ...


class _NoMapUpdates:
    """Keeps nothing: a run without an output folder."""

    def record(self, update: MapUpdate, crop: np.ndarray | None = None) -> None:
        return None


NO_MAP_UPDATES: MapUpdateSink = _NoMapUpdates()


@dataclass
class UpdatesFile:
    """Writes a map-updates file at ``path`` (``<episode>.map_updates.jsonl`` beside the
    tree log) and its crops in the folder of the same name without ``.jsonl``; the header
    names ``building`` (how a person opens the map again: a built-in's name or a file
    path). Records may come from the worker thread and the tick alike: writes hold a lock."""

    path: Path
    building: str
    count: int = field(init=False, default=0)
    _lock: threading.Lock = field(init=False, default_factory=threading.Lock, repr=False)

    def __post_init__(self) -> None:
        self.path = Path(self.path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        header = {"format": FORMAT, "version": VERSION, "building": self.building}
        atomic_write_bytes(self.path, (json.dumps(header) + "\n").encode())

    @property
    def crops(self) -> Path:
        return self.path.with_name(self.path.name.removesuffix(".jsonl"))

    def record(self, update: MapUpdate, crop: np.ndarray | None = None) -> None:
        import cv2

        with self._lock:
            if self.count >= MAX_RECORDS:
                return
            self.count += 1
            if crop is not None and crop.size:
                name = f"{self.count:03d}_{safe_filename(update.subject, 40)}.png"
                self.crops.mkdir(exist_ok=True)
                ok, png = cv2.imencode(".png", np.ascontiguousarray(crop[..., ::-1]))
                if ok:
                    atomic_write_bytes(self.crops / name, png.tobytes())
                    update = _with_crop(update, f"{self.crops.name}/{name}", update.evidence)
            with open(self.path, "a", encoding="utf-8") as f:
                f.write(json.dumps(update.to_dict()) + "\n")


def _with_crop(u: MapUpdate, crop: str, ev: Evidence) -> MapUpdate:
    return MapUpdate(
        u.kind, u.subject_kind, u.subject, u.mapped, u.seen, u.at,
        Evidence(ev.time, ev.odom, ev.pose, ev.reads, crop),
    )  # fmt: skip


# -- reading ----------------------------------------------------------------------------


@dataclass(frozen=True)
class UpdatesLog:
    """A read map-updates file: the building the robot was given and the updates."""

    path: Path
    building: str
    updates: tuple[MapUpdate, ...]


def load_updates(path: str | Path) -> UpdatesLog:
    """Read a map-updates file; any problem is one ``MapUpdatesError`` naming the line."""
    path = Path(path)
    header: dict | None = None
    updates: list[MapUpdate] = []
    for i, text, _ in iter_text_lines(path, "map updates"):
        if not text.strip():
            continue
        where = f"line {i}"
        try:
            data = parse_json(text, path, where)
        except InputFileError as err:
            raise MapUpdatesError(path, err.message, where) from None
        if header is None:
            header = _header(data, path, where)
            continue
        if len(updates) >= MAX_RECORDS:
            raise MapUpdatesError(path, f"more than {MAX_RECORDS} updates", where)
        updates.append(_update(data, path, where))
    if header is None:
        raise MapUpdatesError(path, "empty; a map-updates file starts with its header line")
    return UpdatesLog(path, header["building"], tuple(updates))


def _header(data: Any, path: Path, where: str) -> dict:
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise MapUpdatesError(
            path, f"not a map-updates file (the first line must have format {FORMAT!r})", where
        )
    if data.get("version") != VERSION:
        raise MapUpdatesError(
            path, f"version {data.get('version')!r}: this pmnav reads version {VERSION}", where
        )
    if not isinstance(data.get("building"), str) or not data["building"]:
        raise MapUpdatesError(path, "the header names no building", where)
    return data


def _update(d: Any, path: Path, where: str) -> MapUpdate:
    def bad(msg: str) -> MapUpdatesError:
        return MapUpdatesError(path, msg, where)

    if not isinstance(d, dict):
        raise bad("expected an update object")
    kind = d.get("kind")
    if kind not in UPDATE_KINDS:
        raise bad(f"kind {str(kind)[:40]!r}: expected one of {', '.join(UPDATE_KINDS)}")
    subj = d.get("subject")
    if not isinstance(subj, dict) or subj.get("kind") not in SUBJECT_KINDS:
        raise bad(f"subject: expected {{kind: {'|'.join(SUBJECT_KINDS)}, id: ...}}")
    ident = _text(subj.get("id"), "subject.id", bad, empty=False)
    mapped = _text(d.get("mapped"), "mapped", bad)
    seen = _text(d.get("seen"), "seen", bad)
    at = _point(d.get("at"), "at", 2, bad, optional=True)
    ev = d.get("evidence")
    if not isinstance(ev, dict):
        raise bad("evidence: expected an object")
    t = ev.get("time")
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0 <= t < 1e9:
        raise bad("evidence.time: expected seconds >= 0")
    reads = ev.get("reads", [])
    if not isinstance(reads, list) or len(reads) > 100:
        raise bad("evidence.reads: expected a list of at most 100 texts")
    crop = ev.get("crop")
    if crop is not None:
        crop = _text(crop, "evidence.crop", bad, empty=False)
        if Path(crop).is_absolute() or ".." in Path(crop).parts:
            raise bad("evidence.crop: expected a file name beside the updates file")
    evidence = Evidence(
        float(t),
        _point(ev.get("odom"), "evidence.odom", 3, bad),  # type: ignore[arg-type]
        _point(ev.get("pose"), "evidence.pose", 3, bad, optional=True),  # type: ignore[arg-type]
        tuple(_text(r, "evidence.reads", bad) for r in reads),
        crop,
    )
    return MapUpdate(kind, subj["kind"], ident, mapped, seen, at, evidence)  # type: ignore[arg-type]


def _text(v: Any, name: str, bad, empty: bool = True) -> str:
    if not isinstance(v, str) or (not empty and not v) or len(v) > MAX_TEXT:
        raise bad(f"{name}: expected text of at most {MAX_TEXT} characters")
    return v


def _point(v: Any, name: str, n: int, bad, optional: bool = False):
    if v is None and optional:
        return None
    ok = isinstance(v, list) and len(v) == n
    ok = ok and all(
        not isinstance(c, bool) and isinstance(c, (int, float)) and abs(c) < 1e6 for c in v
    )
    if not ok:
        raise bad(f"{name}: expected {n} numbers" + (" or null" if optional else ""))
    return tuple(float(c) for c in v)


def corridor_blocked(pm, segment: int, time: float, odom, pose, reason: str) -> MapUpdate:
    """The update for priori-map segment ``segment`` (its index) found blocked for good:
    at clock ``time``, from the odometry pose ``odom`` and the map pose ``pose`` (None
    when not localized; both ``Pose2D``), after the failure ``reason``."""
    seg = pm.segment(segment)
    return MapUpdate(
        kind="corridor_blocked",
        subject_kind="segment",
        subject=seg.short,
        mapped="open",
        seen="blocked",
        at=None if pose is None else (round(pose.x, 2), round(pose.y, 2)),
        evidence=Evidence(
            time=float(time),
            odom=(odom.x, odom.y, odom.yaw),
            pose=None if pose is None else (pose.x, pose.y, pose.yaw),
            reads=(reason[:MAX_TEXT],),
        ),
    )
