"""The site file: a building of several levels (floors), joined by lifts.

A functional building is rarely one floor: "take the samples to the lab in room 315"
starts at the lift lobby on level 1. A *site* is a list of *levels*, each an ordinary
building (``map/building.py``: its corridors, rooms, signs, landmarks and floor plan),
and the *lifts* that join them. A lift is known on each level it serves by its *lobby*:
a landmark of kind ``elevator`` or ``lift`` in that level's building (the lift's doors on
that level, which the robot looks for and drives to like any landmark). Stairs join
levels the same way (their lobbies are ``stairs`` landmarks); they are recorded for
completeness and never driven: a Create 3 cannot climb them.

A one-floor building file is a site of one level, so every caller can take either
(``load_site``). Loading validates the site file's structure (pydantic: unknown keys,
wrong types, with field paths), then each level's building (its problems prefixed with
the level's field path), then the site's meaning: duplicate level names, a lobby on an
unknown level or not a lift landmark of its level, a lift with a lobby on one level
only, and (with more than one level) a level from whose corridors no lift leaves, or
levels no chain of lifts joins. Every problem is a ``Problem`` of one
``BuildingFileError``, as for building files (docs/building-format.md, "Levels and
lifts").
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from types import MappingProxyType
from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError, field_validator

from pmnav_bt.errors import BuildingFileError, Problem, UnknownNameError
from pmnav_bt.loading import InputFileError, load_yaml
from pmnav_bt.map.building import (
    MAX_COORD_M,
    MAX_DESCRIPTION_CHARS,
    MAX_TEXT_CHARS,
    SITE_VERSION,
    Building,
    Finite,
    Ident,
    Text,
    building_from_data,
    pydantic_problems,
    read_building_file,
)
from pmnav_bt.map.landmark_kinds import ELEVATOR, STAIRS, landmark_shape

ONE_LEVEL = "L1"
"""The level name of a one-floor building opened as a site (``load_site``)."""

# What a site can plausibly be (docs/building-format.md, "Levels and lifts"). The tallest
# buildings have about 160 floors; a hospital a few dozen, with a handful of lift banks.
MAX_LEVELS = 200
MAX_LINKS = 500  # lifts, and stairs
MAX_ELEVATION_M = MAX_COORD_M

# A level name is written in a qualified goal ("L3/room 315", "room 315 on L3") and in a
# plan step ("take the lift to level L3"): one word, no slash.
_LEVEL_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,31}")


def _level_name(v: str) -> str:
    if not _LEVEL_NAME.fullmatch(v):
        raise ValueError(
            "a level name is one word of at most 32 letters, digits, '_', '.' or '-', "
            "starting with a letter or digit"
        )
    return v


LevelName = Annotated[str, Field(strict=True), AfterValidator(_level_name)]

SITE_SUFFIXES = (".yaml", ".yml")
BUILTIN_SITES_DIR = Path(__file__).parent.parent / "data" / "sites"


# -- the file's structure ---------------------------------------------------------------


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class LevelEntry(_Strict):
    """One level as the file writes it: its name, elevation and building (a file path
    relative to the site file, a built-in building name, or the building inline)."""

    name: LevelName
    elevation: Annotated[Finite, Field(ge=-MAX_ELEVATION_M, le=MAX_ELEVATION_M)] = 0.0
    building: Any

    @field_validator("building")
    @classmethod
    def _building_ref(cls, v: Any) -> Any:
        if isinstance(v, dict):
            return v
        if not isinstance(v, str) or not 1 <= len(v) <= MAX_TEXT_CHARS:
            raise ValueError(
                "give the level's building file (a path relative to the site file), a "
                f"built-in building's name (at most {MAX_TEXT_CHARS} characters), or the "
                "building itself as a mapping"
            )
        return v


class LinkEntry(_Strict):
    """A lift (or stairs) as the file writes it: level name -> its lobby landmark there."""

    id: Ident
    name: Text = ""
    lobbies: dict[LevelName, Ident] = Field(max_length=MAX_LEVELS)


class SiteFile(_Strict):
    """The content of a site file, before its buildings are read."""

    site_version: Annotated[int, Field(strict=True)]
    name: Annotated[Text, Field(min_length=1)]
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION_CHARS, strict=True)] = ""
    levels: tuple[LevelEntry, ...] = Field(max_length=MAX_LEVELS)
    lifts: tuple[LinkEntry, ...] = Field(default=(), max_length=MAX_LINKS)
    stairs: tuple[LinkEntry, ...] = Field(default=(), max_length=MAX_LINKS)


# -- the model --------------------------------------------------------------------------


@dataclass(frozen=True)
class Level:
    """One floor: its name (``L2``), elevation (m, for ordering and drawing) and building.
    ``path``: the building's file (None for a building written inline in the site file),
    where a caller finds its floor plan and hash."""

    name: str
    elevation: float
    building: Building
    path: Path | None = None


@dataclass(frozen=True)
class LiftLink:
    """A lift (or stairs) joining levels: ``lobbies`` maps a level name to the landmark id
    of its doors on that level."""

    id: str
    name: str
    lobbies: Mapping[str, str]

    @property
    def display_name(self) -> str:
        return self.name or self.id

    @property
    def levels(self) -> tuple[str, ...]:
        return tuple(self.lobbies)


@dataclass(frozen=True)
class Site:
    """A building of one or more levels and the lifts (and stairs) that join them."""

    name: str
    levels: tuple[Level, ...]
    lifts: tuple[LiftLink, ...] = ()
    stairs: tuple[LiftLink, ...] = ()
    description: str = ""
    path: Path | None = field(default=None, compare=False)

    def level(self, name: str) -> Level:
        """The level of that name (exact, else ignoring case), or UnknownNameError."""
        found = self._level_index.get(name) or self._level_index.get(name.casefold())
        if found is None:
            names = [lv.name for lv in self.levels]
            raise UnknownNameError(
                f"no level {name[:40]!r} in {self.name}; levels: {', '.join(names)}", names
            )
        return found

    def lift(self, ident: str) -> LiftLink:
        """The lift of that id, or UnknownNameError."""
        for lift in self.lifts:
            if lift.id == ident:
                return lift
        ids = [lift.id for lift in self.lifts]
        raise UnknownNameError(
            f"no lift {ident[:40]!r} in {self.name}; lifts: {', '.join(ids) or 'none'}", ids
        )

    def lifts_at(self, level: str) -> tuple[LiftLink, ...]:
        """The lifts with a lobby on ``level``."""
        return tuple(lift for lift in self.lifts if level in lift.lobbies)

    def rank(self, level: str) -> int:
        """The level's place counted from the lowest (0), by elevation then file order:
        a ride from rank 1 to rank 4 passes 3 levels."""
        return self._ranks[level]

    @property
    def level_names(self) -> tuple[str, ...]:
        return tuple(lv.name for lv in self.levels)

    @cached_property
    def _level_index(self) -> dict[str, Level]:
        index = {lv.name.casefold(): lv for lv in self.levels}
        index.update({lv.name: lv for lv in self.levels})
        return index

    @cached_property
    def _ranks(self) -> dict[str, int]:
        order = sorted(range(len(self.levels)), key=lambda i: (self.levels[i].elevation, i))
        return {self.levels[i].name: r for r, i in enumerate(order)}


def one_level_site(building: Building, path: Path | None = None) -> Site:
    """A one-floor building as a site of one level (``ONE_LEVEL``) and no lifts."""
    return Site(building.name, (Level(ONE_LEVEL, 0.0, building, path),), path=path)


# -- loading ----------------------------------------------------------------------------


def is_site_data(data: Any) -> bool:
    """True for the data of a site file (it has ``site_version``), not a building file."""
    return isinstance(data, dict) and "site_version" in data


def site_from_data(data: Any, source: str = "<data>", base_dir: Path | None = None) -> Site:
    """Validate plain data (as read from a site file) into a Site, or raise
    BuildingFileError listing every problem. ``base_dir``: where the level files named by
    relative paths are (the site file's folder)."""
    if not isinstance(data, dict):
        raise BuildingFileError(
            source, [Problem("", f"expected a mapping at the top level, got {type(data).__name__}")]
        )
    try:
        sf = SiteFile.model_validate(data)
    except ValidationError as err:
        raise BuildingFileError(source, pydantic_problems(err)) from None
    if sf.site_version != SITE_VERSION:
        raise BuildingFileError(
            source,
            [
                Problem(
                    "site_version",
                    f"this version of pmnav reads site_version {SITE_VERSION}, not "
                    f"{sf.site_version}",
                )
            ],
        )
    base = base_dir if base_dir is not None else Path(".")
    problems: list[Problem] = []
    levels: list[Level] = []
    for i, entry in enumerate(sf.levels):
        try:
            building, path = _level_building(entry.building, base, source)
        except BuildingFileError as err:
            problems.extend(_level_problems(i, entry.building, err))
            continue
        levels.append(Level(entry.name, float(entry.elevation), building, path))
    problems += site_problems(sf, {lv.name: lv.building for lv in levels}, len(levels))
    if problems:
        raise BuildingFileError(source, problems)
    links = [
        tuple(LiftLink(e.id, e.name, MappingProxyType(dict(e.lobbies))) for e in group)
        for group in (sf.lifts, sf.stairs)
    ]
    return Site(sf.name, tuple(levels), links[0], links[1], sf.description)


def _level_building(ref: str | dict, base: Path, source: str) -> tuple[Building, Path | None]:
    """A level's building: inline data, a file relative to the site file, or a built-in
    (or generated) building's name."""
    if isinstance(ref, dict):
        return building_from_data(ref, source, base), None
    p = Path(ref)
    if p.suffix in SITE_SUFFIXES or len(p.parts) > 1:
        path = p if p.is_absolute() else base / p
    else:
        from pmnav_bt.map.catalogue import resolve_building_path  # above this module

        path = resolve_building_path(ref)
    return read_building_file(path), path


def _level_problems(i: int, ref: str | dict, err: BuildingFileError) -> list[Problem]:
    """A level building's problems under the level's field (``levels[1].building...``):
    an inline building's by their field; a file's with the file named."""
    at = f"levels[{i}].building"
    if isinstance(ref, dict):
        return [Problem(f"{at}.{p.field}" if p.field else at, p.message) for p in err.problems]
    return [Problem(at, f"{err.path}: {p}") for p in err.problems]


def site_problems(sf: SiteFile, buildings: Mapping[str, Building], n_read: int) -> list[Problem]:
    """Problems of meaning in a structurally valid site file whose level buildings (by
    level name) were read; ``n_read``: how many levels' buildings were read (the lift
    checks that need every level wait until each reads)."""
    problems: list[Problem] = []
    if not sf.levels:
        problems.append(Problem("levels", "a site needs at least 1 level"))
    first: dict[str, int] = {}
    for i, entry in enumerate(sf.levels):
        key = entry.name.casefold()
        if key in first:
            problems.append(
                Problem(
                    f"levels[{i}].name",
                    f"duplicate level {entry.name!r} (also at levels[{first[key]}]; level "
                    "names differ in more than case)",
                )
            )
        first.setdefault(key, i)
    names = [e.name for e in sf.levels]
    link_at: dict[str, str] = {}
    for group, links, shape in (("lifts", sf.lifts, ELEVATOR), ("stairs", sf.stairs, STAIRS)):
        for i, link in enumerate(links):
            where = f"{group}[{i}]"
            if link.id in link_at:
                problems.append(
                    Problem(f"{where}.id", f"duplicate id {link.id!r} (also at {link_at[link.id]})")
                )
            link_at.setdefault(link.id, where)
            what = "lift" if group == "lifts" else "stairs"
            if len(link.lobbies) < 2:
                on = ", ".join(link.lobbies) or "none"
                problems.append(
                    Problem(
                        f"{where}.lobbies",
                        f"{what} {link.id!r} has a lobby on {len(link.lobbies)} level(s) ({on}); "
                        f"a {what} joins 2 or more levels: give its lobby on each level it serves",
                    )
                )
            for level, lobby in link.lobbies.items():
                problems += _lobby_problems(
                    f"{where}.lobbies.{level}", what, level, lobby, names, buildings, shape
                )
    if len(sf.levels) > 1 and n_read == len(sf.levels) and not problems:
        problems += _reach_problems(sf)
    return problems


def _lobby_problems(
    at: str,
    what: str,
    level: str,
    lobby: str,
    names: list[str],
    buildings: Mapping[str, Building],
    shape,
) -> list[Problem]:
    if level not in names:
        return [Problem(at, f"unknown level {level!r} (levels: {', '.join(names)})")]
    b = buildings.get(level)
    if b is None:  # its building did not read: its own problems say why
        return []
    kinds = " or ".join(shape.kinds[:2])
    ok = [lm.id for lm in b.landmarks if landmark_shape(lm.kind) is shape]
    try:
        lm = b.landmark(lobby)
    except KeyError:
        hint = f"its {what} landmarks: {', '.join(ok[:8])}" if ok else f"it has no {kinds}"
        return [Problem(at, f"{lobby!r} is not a landmark of level {level} ({hint})")]
    if landmark_shape(lm.kind) is not shape:
        return [
            Problem(
                at,
                f"{lobby!r} on level {level} is a {lm.kind}, not a {what} landmark (kind "
                f"{kinds}); a {what}'s lobby is its doors on that level",
            )
        ]
    return []


def _reach_problems(sf: SiteFile) -> list[Problem]:
    """With several levels: a level with no lift lobby (its corridors lead to no lift:
    stairs are never driven), and levels no chain of lifts joins."""
    problems = []
    served = {level for link in sf.lifts for level in link.lobbies}
    for i, entry in enumerate(sf.levels):
        if entry.name not in served:
            stairs = [s.id for s in sf.stairs if entry.name in s.lobbies]
            tail = f" (stairs {', '.join(stairs)} are never driven)" if stairs else ""
            problems.append(
                Problem(
                    f"levels[{i}]",
                    f"level {entry.name!r} has no way from its corridors to any lift: no lift "
                    f"has a lobby on it{tail}; give a lift's lobby on this level",
                )
            )
    if problems:
        return problems
    parent = {e.name: e.name for e in sf.levels}

    def root(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for link in sf.lifts:
        first, *rest = link.lobbies
        for level in rest:
            parent[root(level)] = root(first)
    parts: dict[str, list[str]] = {}
    for e in sf.levels:
        parts.setdefault(root(e.name), []).append(e.name)
    if len(parts) > 1:
        shown = "; ".join("{" + ", ".join(p) + "}" for p in parts.values())
        problems.append(
            Problem("lifts", f"the lifts join the levels in {len(parts)} separate parts: {shown}")
        )
    return problems


def read_site_file(path: str | Path) -> Site:
    """Read and validate a site file (every level's building with it)."""
    path = Path(path)
    try:
        data = load_yaml(path, "building")
    except InputFileError as err:
        raise BuildingFileError(str(path), [Problem(err.field, err.message)]) from None
    if not is_site_data(data):
        raise BuildingFileError(
            str(path), [Problem("site_version", "required key is missing (not a site file)")]
        )
    site = site_from_data(data, str(path), path.parent)
    return Site(site.name, site.levels, site.lifts, site.stairs, site.description, path)


def builtin_sites() -> list[str]:
    """Names of the sites shipped with the package."""
    return sorted(p.stem for p in BUILTIN_SITES_DIR.glob("*.yaml"))


def resolve_site_path(name_or_path: str | Path) -> Path:
    """A path as given, a built-in site's file, a generated site's (``hospital_site_3``,
    written to the cache folder), or a building's (``catalogue``)."""
    from pmnav_bt.map.catalogue import (  # above this module
        generated_site_file,
        resolve_building_path,
    )

    text = str(name_or_path)
    p = Path(name_or_path)
    if p.suffix not in SITE_SUFFIXES and len(p.parts) == 1 and not os.path.lexists(p):
        builtin = BUILTIN_SITES_DIR / f"{text}.yaml"
        if len(text) <= 255 and "\0" not in text and builtin.is_file():
            return builtin
        generated = generated_site_file(text)
        if generated is not None:
            return generated

    try:
        return resolve_building_path(name_or_path)
    except BuildingFileError as err:
        if p.suffix in SITE_SUFFIXES or len(p.parts) > 1:
            raise
        sites = ", ".join(builtin_sites()) or "none"
        raise BuildingFileError(
            err.path, [Problem("", f"{err.problems[0].message}; built-in sites: {sites}")]
        ) from None


def load_site(name_or_path: str | Path) -> Site:
    """A site from a site file, a one-floor building file (a site of one level), or the
    name of a built-in site or building: every command that takes a building takes either."""
    path = resolve_site_path(name_or_path)
    try:
        data = load_yaml(path, "building")
    except InputFileError as err:
        raise BuildingFileError(str(path), [Problem(err.field, err.message)]) from None
    if is_site_data(data):
        site = site_from_data(data, str(path), path.parent)
        return Site(site.name, site.levels, site.lifts, site.stairs, site.description, path)
    return one_level_site(building_from_data(data, str(path), path.parent), path)


def open_site(name_or_path: str | Path) -> Site:
    """A site as a command opens it: ``load_site``, then each level's floor plan opened
    and decoded (as ``catalogue.open_building`` does for one building)."""
    from pmnav_bt.map.catalogue import check_floor_plan  # above this module

    site = load_site(name_or_path)
    for i, lv in enumerate(site.levels):
        if lv.path is None or lv.building.floor_plan is None:
            continue
        try:
            check_floor_plan(lv.building, lv.path)
        except BuildingFileError as err:
            if len(site.levels) == 1:
                raise
            raise BuildingFileError(
                str(site.path), [Problem(f"levels[{i}].building", str(err))]
            ) from None
    return site
