"""The building catalogue: every building a command can name, by its name or its file.

A building is named three ways (``--building``, an episode's record, a test): a path to
its YAML file; the name of a building shipped with the package (``fig2_hospital``, from
``pmnav_bt/data/buildings``); or the name of a member of a generated family
(``sign_sparse_3``, ``gen_small_0``, ``hospital_12``: family and seed), whose file is
written once to a cache folder so that it has a path and a hash like any other. Specs
name several members at once: ``FAMILY:N`` (the first N development members) and
``FAMILY_heldout:N`` (the first N held-out members; see ``HELDOUT_SEEDS``). This module
turns such a name into a file, a hash and a ``Building``. It sits above ``building`` (the
file format) and the seeded generators (``generate``, ``functional``,
``functional_site``), so those need not know each other.

Generated sites of several levels (``hospital_site_3``; ``functional_site:N`` takes the
three types in turn) are named the same way; ``generated_site_file`` writes one as a site
file and a building file per level, which ``site.resolve_site_path`` finds by its name.
"""

from __future__ import annotations

import hashlib
import os
from functools import partial
from pathlib import Path

import yaml

from pmnav_bt.errors import BuildingFileError, Problem
from pmnav_bt.map.building import Building, dump_building, read_building_file
from pmnav_bt.map.functional import BUILDING_KINDS, generate_functional
from pmnav_bt.map.functional_site import SITE_KINDS, SITE_SUFFIX, generate_functional_site
from pmnav_bt.map.generate import (
    SIGN_SPARSE_FAMILY,
    SMALL_FAMILY,
    generate_sign_sparse,
    generate_small,
)

BUILTIN_DIR = Path(__file__).parent.parent / "data" / "buildings"

# The generated families by name: "sign_sparse_3" is generate_sign_sparse(seed=3),
# "hospital_12" is generate_functional("hospital", 12).
FAMILIES = {
    SIGN_SPARSE_FAMILY: generate_sign_sparse,
    SMALL_FAMILY: generate_small,
    **{kind: partial(generate_functional, kind) for kind in BUILDING_KINDS},
}

DEV_SEEDS = range(0, 1000)
"""Development seeds of the realistic families (hospital, school, office, functional):
the members the project looks at, tunes and debugs on. ``FAMILY:N`` names the first N."""

HELDOUT_SEEDS = range(1000, 2000)
"""Held-out seeds of the realistic families: for evaluation only. The project never tunes
on them, never looks at their episodes to fix a failure, and reports them apart (issue
36): a result on them says how the robot does in buildings nobody has seen.
``FAMILY_heldout:N`` names the first N (``hospital_heldout:3`` is hospital_1000, 1001,
1002). A seed outside both ranges names no member of these families."""

HELDOUT_SUFFIX = "_heldout"
RANGED_FAMILIES = BUILDING_KINDS  # the families with a development and a held-out range
MIXED_FAMILY = "functional"
"""Not a family of its own: ``functional:N`` names the realistic families' members in
turn, hospital, school, office, hospital ... (``functional:4`` is hospital_0, school_0,
office_0, hospital_1), so that one spec spans every building type."""

# The generated sites of several levels by name: "hospital_site_3" is
# generate_functional_site("hospital", 3). Their seeds are ranged as the floors' are.
SITE_FAMILIES = {
    family: partial(generate_functional_site, family.removesuffix(SITE_SUFFIX))
    for family in SITE_KINDS
}
MIXED_SITE_FAMILY = MIXED_FAMILY + SITE_SUFFIX
"""``functional_site:N``: the site families' members in turn (hospital_site_0,
school_site_0, office_site_0, hospital_site_1 ...), as ``functional:N`` for floors."""
_MIXED = {MIXED_FAMILY: RANGED_FAMILIES, MIXED_SITE_FAMILY: SITE_KINDS}
_RANGED = (*RANGED_FAMILIES, *SITE_KINDS)


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
    check_floor_plan(b, path)
    return b


def check_floor_plan(b: Building, path: Path) -> None:
    """Open and decode the floor plan of the building read from ``path``, when it has one;
    a broken image or ROS map is a BuildingFileError naming the field."""
    if b.floor_plan is None:
        return
    from pmnav_bt.map.floorplan import FloorPlanError, load_floor_plan  # imports cv2

    try:
        load_floor_plan(b, path.parent)
    except FloorPlanError as err:
        field = "floor_plan.ros_map" if b.floor_plan.ros_map else "floor_plan.image"
        raise BuildingFileError(str(path), [Problem(field, str(err))]) from None


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
    try:
        members = family_members(text)
    except ValueError:
        members = None
    if members:  # "hospital:3" where one building is wanted
        raise BuildingFileError(
            text,
            [Problem("", f"names {len(members)} buildings; give one, such as {members[0]}")],
        )
    if is_generated_site_name(text):
        raise BuildingFileError(
            text, [Problem("", "a generated site of several levels, not one building")]
        )
    stem, _, seed = text.rpartition("_")
    if stem in _RANGED and seed.isdigit():
        raise BuildingFileError(
            text,
            [
                Problem(
                    "",
                    f"no such member: {stem} seeds are {DEV_SEEDS.start}-{DEV_SEEDS.stop - 1} "
                    f"(development) and {HELDOUT_SEEDS.start}-{HELDOUT_SEEDS.stop - 1} "
                    "(held-out, for evaluation only)",
                )
            ],
        )
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


def _member(name: str, families, ranged) -> tuple[str, int] | None:
    """(family, seed) of a generated member's name such as "sign_sparse_3" among
    ``families``; None for any other name, or a seed of a ``ranged`` family outside its
    development and held-out ranges."""
    stem, _, seed = name.rpartition("_")
    if stem not in families or not seed.isdigit() or len(seed) >= 10:
        return None
    if stem in ranged and int(seed) not in DEV_SEEDS and int(seed) not in HELDOUT_SEEDS:
        return None
    return stem, int(seed)


def is_generated_name(name: str) -> bool:
    """True for a generated family's building name, such as "sign_sparse_3" or
    "hospital_1004" (a realistic family's seed must be in its development or held-out
    range)."""
    return _member(name, FAMILIES, RANGED_FAMILIES) is not None


def family_members(spec: str) -> list[str] | None:
    """ "FAMILY:N" -> the family's first N development members ("gen_small:3" ->
    gen_small_0, gen_small_1, gen_small_2); "FAMILY_heldout:N" -> its first N held-out
    members; "functional:N" / "functional_heldout:N" -> the realistic families' members
    in turn; the site families alike ("functional_site:2" -> hospital_site_0,
    school_site_0). None when ``spec`` is not of that form; ValueError (one line) for an
    unknown family or a bad N."""
    family, sep, count = spec.partition(":")
    if not sep:
        return None
    base = family.removesuffix(HELDOUT_SUFFIX)
    heldout = base != family
    ranged = (*_RANGED, *_MIXED)
    if base not in FAMILIES and base not in SITE_FAMILIES and base not in _MIXED:
        known = [*FAMILIES, *SITE_FAMILIES, *_MIXED, *(f + HELDOUT_SUFFIX for f in ranged)]
        raise ValueError(f"{spec!r}: unknown building family {family!r}; choose {', '.join(known)}")
    if heldout and base not in ranged:
        raise ValueError(
            f"{spec!r}: {base} has no held-out seeds; held-out families: "
            + ", ".join(f + HELDOUT_SUFFIX for f in ranged)
        )
    seeds = HELDOUT_SEEDS if heldout else DEV_SEEDS
    kinds = _MIXED.get(base, (base,))
    most = len(seeds) * len(kinds) if base in ranged else 100_000
    if not count.isdigit() or not 1 <= int(count) <= most:
        raise ValueError(f"{spec!r}: expected {family}:N with N from 1 to {most}")
    if base not in ranged:
        return [f"{base}_{k}" for k in range(int(count))]
    return [f"{kinds[k % len(kinds)]}_{seeds[k // len(kinds)]}" for k in range(int(count))]


def generated_family(name: str) -> Building | None:
    """The generated building a name such as "sign_sparse_3" denotes, or None."""
    member = _member(name, FAMILIES, RANGED_FAMILIES)
    if member is None:
        return None
    family, seed = member
    return FAMILIES[family](seed)


def generated_file(name: str) -> Path | None:
    """The building file of a generated family's name, written once to the cache folder
    (``$PMNAV_CACHE`` or ``$XDG_CACHE_HOME/pmnav``, default ``~/.cache/pmnav``), so that a
    generated building has a file like any other (episodes record its path and hash)."""
    b = generated_family(name)
    if b is None:
        return None
    path = _cache_root() / "buildings" / f"{name}.yaml"
    _write_once(path, dump_building(b))
    return path


def is_generated_site_name(name: str) -> bool:
    """True for a generated site's name, such as "hospital_site_3" or "office_site_1004"
    (its seed in the development or the held-out range)."""
    return _member(name, SITE_FAMILIES, SITE_FAMILIES) is not None


def generated_site_path(name: str) -> Path:
    """Where the cache folder keeps the site file of a generated site's name (its levels'
    building files in the folder of that name beside it)."""
    return _cache_root() / "sites" / f"{name}.yaml"


def generated_site_file(name: str) -> Path | None:
    """The site file of a generated site's name ("hospital_site_3"), written once to the
    cache folder with its levels' building files (``generated_site_path``), or None for
    any other name. A site travels by its name: a Ray node writes its own copy."""
    member = _member(name, SITE_FAMILIES, SITE_FAMILIES)
    if member is None:
        return None
    family, seed = member
    gen = SITE_FAMILIES[family](seed)
    path = generated_site_path(name)
    refs = {}
    for level, text in gen.level_texts().items():
        refs[level] = f"{name}/{level}.yaml"
        _write_once(path.parent / refs[level], text)
    _write_once(path, yaml.safe_dump(gen.site_data(refs), sort_keys=False, width=100))
    return path


def _cache_root() -> Path:
    return Path(
        os.environ.get("PMNAV_CACHE")
        or os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "pmnav")
    )


def _write_once(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` unless it holds it already."""
    if not path.is_file() or path.read_text(encoding="utf-8") != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(path)  # atomic: parallel runs never read half a file
