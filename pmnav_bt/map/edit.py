"""An editable building: add, move, delete and rename its parts, with undo and live checks.

The data is the building file's own layout (plain dicts), so what is saved is what
was edited, even while the building is not yet valid. ``problems()`` lists the load
errors and ``pmnav validate`` warnings of the current state. The Tk annotation tool
(``pmnav annotate``) is a view on this model.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import yaml

from pmnav_bt.errors import BuildingFileError, PmNavError
from pmnav_bt.map.building import Building, building_from_data, dump_building
from pmnav_bt.map.catalogue import load_building

GROUPS = ("waypoints", "rooms", "landmarks")
POS_KEY = {"waypoints": "pos", "rooms": "door", "landmarks": "pos"}
UNDO_DEPTH = 200


class EditError(PmNavError):
    """An edit that cannot be made (unknown id, duplicate id, bad field)."""


class BuildingEditor:
    """The building being edited: plain data, an undo stack and the file it came from."""

    def __init__(self, data: dict[str, Any], path: str | Path | None = None):
        self.data = copy.deepcopy(data)
        for g in (*GROUPS, "edges"):
            self.data.setdefault(g, [])
        self.path = Path(path) if path is not None else None
        self._undo: list[dict[str, Any]] = []
        self.dirty = False

    @classmethod
    def open(cls, path: str | Path) -> BuildingEditor:
        """Edit a building file; it must load (fix load errors with 'pmnav validate' first)."""
        b = load_building(path)
        return cls(b.to_dict(), path)

    # -- undo -----------------------------------------------------------------------------

    def _snapshot(self) -> None:
        self._undo.append(copy.deepcopy(self.data))
        del self._undo[:-UNDO_DEPTH]
        self.dirty = True

    def undo(self) -> bool:
        """Go back one edit; False when there is nothing to undo."""
        if not self._undo:
            return False
        self.data = self._undo.pop()
        self.dirty = True
        return True

    @property
    def can_undo(self) -> bool:
        return bool(self._undo)

    # -- lookups --------------------------------------------------------------------------

    def items(self, group: str) -> list[dict[str, Any]]:
        return self.data[group]

    def find(self, ident: str) -> tuple[str, dict[str, Any]]:
        for g in GROUPS:
            for it in self.data[g]:
                if it["id"] == ident:
                    return g, it
        raise EditError(f"no waypoint, room or landmark with id {ident!r}")

    def ids(self) -> set[str]:
        return {it["id"] for g in GROUPS for it in self.data[g]}

    def new_id(self, prefix: str) -> str:
        taken = self.ids()
        k = 1
        while f"{prefix}{k}" in taken:
            k += 1
        return f"{prefix}{k}"

    def position(self, ident: str) -> tuple[float, float]:
        g, it = self.find(ident)
        x, y = it[POS_KEY[g]]
        return float(x), float(y)

    def nearest(self, xy, within: float) -> str | None:
        """The id of the item nearest to ``xy`` within ``within`` metres, or None."""
        best, best_d = None, within
        for g in GROUPS:
            for it in self.data[g]:
                d = math.dist(xy, it[POS_KEY[g]])
                if d <= best_d:
                    best, best_d = it["id"], d
        return best

    def edge_ends(self) -> list[tuple[str, str, float | None]]:
        out = []
        for e in self.data["edges"]:
            if isinstance(e, dict):
                out.append((e["from"], e["to"], e.get("width")))
            else:
                out.append((e[0], e[1], None))
        return out

    # -- edits ----------------------------------------------------------------------------

    def add_room(self, xy, ident: str | None = None, **fields: Any) -> str:
        ident = ident or self.new_id("room")
        self._check_new(ident)
        self._snapshot()
        self.data["rooms"].append({"id": ident, **fields, "door": _pt(xy)})
        return ident

    def add_waypoint(self, xy, kind: str = "end", ident: str | None = None) -> str:
        ident = ident or self.new_id(kind)
        self._check_new(ident)
        self._snapshot()
        self.data["waypoints"].append({"id": ident, "kind": kind, "pos": _pt(xy)})
        return ident

    def add_landmark(self, xy, kind: str = "sign", ident: str | None = None, **fields) -> str:
        ident = ident or self.new_id(kind)
        self._check_new(ident)
        self._snapshot()
        self.data["landmarks"].append({"id": ident, "kind": kind, **fields, "pos": _pt(xy)})
        return ident

    def add_edge(self, a: str, b: str, width: float | None = None) -> None:
        for w in (a, b):
            if self.find(w)[0] != "waypoints":
                raise EditError(f"{w!r} is not a waypoint; corridors join waypoints")
        if a == b or any({a, b} == {x, y} for x, y, _ in self.edge_ends()):
            raise EditError(
                f"there is already a corridor {a}-{b}, or it joins a waypoint to itself"
            )
        self._snapshot()
        self.data["edges"].append([a, b] if width is None else {"from": a, "to": b, "width": width})

    def move(self, ident: str, xy) -> None:
        g, it = self.find(ident)
        self._snapshot()
        it[POS_KEY[g]] = _pt(xy)

    def delete(self, ident: str) -> None:
        """Delete an item; a waypoint takes its corridor edges with it."""
        g, it = self.find(ident)
        self._snapshot()
        self.data[g].remove(it)
        if g == "waypoints":
            self.data["edges"] = [
                e
                for e, (a, b, _) in zip(self.data["edges"], self.edge_ends(), strict=True)
                if ident not in (a, b)
            ]

    def delete_edge(self, a: str, b: str) -> None:
        keep = [
            e
            for e, (x, y, _) in zip(self.data["edges"], self.edge_ends(), strict=True)
            if {x, y} != {a, b}
        ]
        if len(keep) == len(self.data["edges"]):
            raise EditError(f"no corridor {a}-{b}")
        self._snapshot()
        self.data["edges"] = keep

    def set_fields(self, ident: str, **fields: Any) -> str:
        """Change fields (id, name, aliases, sign, kind); an empty value removes the field.

        A new id is carried into the corridor edges. Returns the (new) id.
        """
        g, it = self.find(ident)
        new_id = fields.pop("id", ident) or ident
        if new_id != ident:
            self._check_new(new_id)
        self._snapshot()
        for k, v in fields.items():
            if k == "aliases" and isinstance(v, str):
                v = [a.strip() for a in v.split(",") if a.strip()]
            if v in ("", [], None):
                it.pop(k, None)
            else:
                it[k] = v
        if new_id != ident:
            it["id"] = new_id
            if g == "waypoints":
                self.data["edges"] = [_rename_edge(e, ident, new_id) for e in self.data["edges"]]
        return new_id

    def _check_new(self, ident: str) -> None:
        if not ident:
            raise EditError("an id must not be empty")
        if ident in self.ids():
            raise EditError(f"the id {ident!r} is taken; ids are unique among all items")

    # -- checks and saving ------------------------------------------------------------------

    def building(self) -> Building:
        """The current state as a Building (raises BuildingFileError while invalid)."""
        base = self.path.parent if self.path else None
        return building_from_data(self.data, str(self.path or "<edit>"), base)

    def problems(self) -> list[str]:
        """Load errors, or else the warnings of 'pmnav validate', one line each."""
        from pmnav_bt.map.checks import building_warnings

        try:
            b = self.building()
        except BuildingFileError as err:
            return [f"error: {p}" for p in err.problems]
        base = self.path.parent if self.path else None
        return [f"warning: {w}" for w in building_warnings(b, base)]

    def save(self, path: str | Path | None = None) -> Path:
        """Write the file: the canonical layout when valid, else the data as it stands."""
        path = Path(path) if path is not None else self.path
        if path is None:
            raise EditError("no file to save to")
        try:
            text = dump_building(self.building())
        except BuildingFileError:
            text = yaml.safe_dump(self.data, sort_keys=False, allow_unicode=True, width=100)
        path.write_text(text, encoding="utf-8")
        self.path = path
        self.dirty = False
        return path


def _pt(xy) -> list[float]:
    return [round(float(xy[0]), 2), round(float(xy[1]), 2)]


def _rename_edge(e, old: str, new: str):
    if isinstance(e, dict):
        return {
            **e,
            "from": new if e["from"] == old else e["from"],
            "to": new if e["to"] == old else e["to"],
        }
    return [new if w == old else w for w in e]
