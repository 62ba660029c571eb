"""Import every level of a multi-level Open-RMF building as a site (``pmnav map import-rmf``
without ``--level``).

Each level is imported as ``rmf_import`` imports one (a building file and its walls'
grid), written beside the site file as ``<site stem>_<level>.yaml``; the site file names
them, with each level's elevation from the RMF file, and joins them by the RMF lifts: a
lift's lobby on a level is the ``elevator`` landmark the import made of its door there.
A lift whose door is reached on fewer than two levels joins nothing and is left out
(listed); the written site is read back and validated like any site file
(``site.read_site_file``), so a level no lift reaches is refused there, in the site
format's words.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import yaml

from pmnav_bt.errors import BuildingFileError
from pmnav_bt.loading import atomic_write_text
from pmnav_bt.map.rmf_import import Imported, RmfImportError, import_rmf, write_import
from pmnav_bt.map.rmf_read import level_elevations
from pmnav_bt.map.site import SITE_VERSION, Site, read_site_file


@dataclass
class ImportedSite:
    """The imported site: its file, the validated site, each level's import, what was
    left out of the site (lifts that join nothing)."""

    path: Path
    site: Site
    levels: dict[str, Imported]  # site level name -> its import
    skipped: list[str]


def is_multi_level(path: str | Path) -> bool:
    """True when the RMF building has more than one level."""
    return len(level_elevations(path)) > 1


def import_rmf_site(path: str | Path, out: str | Path) -> ImportedSite:
    """Import every level of the RMF building at ``path``; write the level files and the
    site file ``out``; return what was written, validated."""
    out = Path(out)
    elevations = level_elevations(path)
    names = _level_names(list(elevations))
    levels: dict[str, Imported] = {}
    for rmf_name, name in names.items():
        level_out = out.with_name(f"{out.stem}_{name}.yaml")
        imp = import_rmf(path, level_out, rmf_name)
        write_import(imp, level_out)
        levels[name] = imp
    skipped: list[str] = []
    lifts = []
    rmf_lifts = sorted({ld.lift for imp in levels.values() for ld in imp.level.lift_doors})
    for lift in rmf_lifts:
        lobbies = {
            name: imp.lift_landmarks[lift][0]
            for name, imp in levels.items()
            if imp.lift_landmarks.get(lift)
        }
        if len(lobbies) < 2:
            where = f"on {', '.join(lobbies)} only" if lobbies else "on no level"
            skipped.append(f"lift {lift!r}: its door is on a corridor {where}; it joins nothing")
            continue
        lifts.append({"id": _ident(lift), "name": lift.replace("_", " "), "lobbies": lobbies})
    data = {
        "site_version": SITE_VERSION,
        "name": _ident(Path(path).name.split(".")[0]),
        "description": f"Imported from the Open-RMF building {Path(path).name} by "
        "'pmnav map import-rmf'.",
        "levels": [
            {
                "name": name,
                "elevation": float(elevations[rmf_name]),
                "building": f"{out.stem}_{name}.yaml",
            }
            for rmf_name, name in names.items()
        ],
        "lifts": lifts,
    }
    head = f"# Imported by 'pmnav map import-rmf' from {Path(path).name}: every level, its lifts.\n"
    text = head + yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)
    atomic_write_text(out, text)
    try:
        site = read_site_file(out)
    except BuildingFileError as err:
        why = f" ({'; '.join(skipped)})" if skipped else ""
        raise RmfImportError(
            f"{path}: the imported site does not validate: {err.problems[0]}{why}"
        ) from None
    return ImportedSite(out, site, levels, skipped)


def _level_names(rmf_names: list[str]) -> dict[str, str]:
    """RMF level name -> a site level name (one word: letters, digits, '_', '.', '-')."""
    out: dict[str, str] = {}
    for raw in rmf_names:
        base = re.sub(r"[^A-Za-z0-9_.-]+", "_", raw).strip("_.-")[:32] or "level"
        if not base[0].isalnum():
            base = f"L{base}"[:32]
        name, k = base, 2
        while name.casefold() in {n.casefold() for n in out.values()}:
            name, k = f"{base[:29]}_{k}", k + 1
        out[raw] = name
    return out


def _ident(text: str) -> str:
    return (re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "lift")[:64]
