"""The building catalogue: every building a command can name, by its name or its file.

A building is named three ways (``--building``, an episode's record, a test): a path to
its YAML file; the name of a building shipped with the package (``fig2_hospital``, from
``pmnav_bt/data/buildings``); or the name of a member of a generated family
(``sign_sparse_3``, ``gen_small_0``: family and seed), whose file is written once to a
cache folder so that it has a path and a hash like any other. This module turns such a
name into a file, a hash and a ``Building``. It sits above ``building`` (the file format)
and ``generate`` (the seeded generator), so those two need not know each other.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

from pmnav_bt.errors import BuildingFileError, Problem
from pmnav_bt.map.building import Building, dump_building, read_building_file
from pmnav_bt.map.generate import (
    SIGN_SPARSE_FAMILY,
    SMALL_FAMILY,
    generate_sign_sparse,
    generate_small,
)

BUILTIN_DIR = Path(__file__).parent.parent / "data" / "buildings"

# The generated families by name: "sign_sparse_3" is generate_sign_sparse(seed=3).
FAMILIES = {SIGN_SPARSE_FAMILY: generate_sign_sparse, SMALL_FAMILY: generate_small}


def load_building(name_or_path: str | Path) -> Building:
    """Read and validate a building file (or a built-in building's name, or a generated
    family's: "sign_sparse_<seed>")."""
    return read_building_file(resolve_building_path(name_or_path))


def open_building(name_or_path: str | Path) -> Building:
    """A building as a command opens it: the file read and validated (``load_building``)
    and its floor plan, when it has one, opened and decoded. ``validate``, ``map``,
    ``plan`` and ``sim run`` all judge a building file this way, so a broken image or ROS
    map is refused by each of them alike, not only by the ones that draw or drive in it."""
    path = resolve_building_path(name_or_path)
    b = read_building_file(path)
    if b.floor_plan is not None:
        from pmnav_bt.map.floorplan import FloorPlanError, load_floor_plan  # imports cv2

        try:
            load_floor_plan(b, path.parent)
        except FloorPlanError as err:
            field = "floor_plan.ros_map" if b.floor_plan.ros_map else "floor_plan.image"
            raise BuildingFileError(str(path), [Problem(field, str(err))]) from None
    return b


def builtin_buildings() -> list[str]:
    """Names of the buildings shipped with the package."""
    return sorted(p.stem for p in BUILTIN_DIR.glob("*.yaml"))


def building_sha256(name_or_path: str | Path) -> str:
    """The sha256 (hex) of a building file's bytes (a path or a built-in name)."""
    path = resolve_building_path(name_or_path)
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError as err:
        raise BuildingFileError(
            str(path), [Problem("", f"cannot read file: {err.strerror}")]
        ) from None


def resolve_building_path(name_or_path: str | Path) -> Path:
    """A path as given, or the file of a built-in building of that name."""
    p = Path(name_or_path)
    text = str(name_or_path)
    if text.endswith(("/", os.sep)):  # Path() drops the slash; "x.yaml/" names a folder
        raise BuildingFileError(
            text, [Problem("", "a path ending in '/' names a folder; give the building file")]
        )
    if len(text) > 255 or "\0" in text or p.suffix in (".yaml", ".yml") or len(p.parts) > 1:
        return p
    if os.path.lexists(p):
        return p
    generated = generated_file(text)  # "sign_sparse_3": written once to the cache folder
    if generated is not None:
        return generated
    builtin = BUILTIN_DIR / f"{name_or_path}.yaml"
    if builtin.is_file():
        return builtin
    raise BuildingFileError(
        str(name_or_path),
        [
            Problem(
                "",
                f"no such file, and no built-in building of that name "
                f"(built-in: {', '.join(builtin_buildings()) or 'none'})",
            )
        ],
    )


# -- generated families -----------------------------------------------------------------


def is_generated_name(name: str) -> bool:
    """True for a generated family's building name, such as "sign_sparse_3"."""
    stem, _, seed = name.rpartition("_")
    return stem in FAMILIES and seed.isdigit() and len(seed) < 10


def family_members(spec: str) -> list[str] | None:
    """ "FAMILY:N" -> the family's first N building names ("gen_small:3" -> gen_small_0,
    gen_small_1, gen_small_2); None when ``spec`` is not of that form; ValueError for an
    unknown family or a bad N."""
    family, sep, count = spec.partition(":")
    if not sep:
        return None
    if family not in FAMILIES:
        raise ValueError(
            f"{spec!r}: unknown building family {family!r}; choose {', '.join(FAMILIES)}"
        )
    if not count.isdigit() or not 1 <= int(count) <= 100_000:
        raise ValueError(f"{spec!r}: expected {family}:N with N from 1 to 100000")
    return [f"{family}_{k}" for k in range(int(count))]


def generated_family(name: str) -> Building | None:
    """The generated building a name such as "sign_sparse_3" denotes, or None."""
    if not is_generated_name(name):
        return None
    stem, _, seed = name.rpartition("_")
    return FAMILIES[stem](int(seed))


def generated_file(name: str) -> Path | None:
    """The building file of a generated family's name, written once to the cache folder
    (``$PMNAV_CACHE`` or ``$XDG_CACHE_HOME/pmnav``, default ``~/.cache/pmnav``), so that a
    generated building has a file like any other (episodes record its path and hash)."""
    b = generated_family(name)
    if b is None:
        return None
    root = os.environ.get("PMNAV_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "pmnav"
    )
    path = Path(root) / "buildings" / f"{name}.yaml"
    text = dump_building(b)
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)  # atomic: parallel runs never read half a file
    return path
