"""Seeded multi-level hospitals, schools and offices: sites of 2-4 floors (issue 40).

A real building's floors share one structure: the same footprint, the same corridors
above each other, the lift shaft and the stairwells at the same place on every floor. A
generated site is built that way from the seed, with the one-floor family's parts
(:mod:`pmnav_bt.map.functional`):

1. one *shell* for the building: its type's corridor widths and layout, drawn once
   (``functional.draw_shell``), and one *core*: where the lift, the main stairs and the
   escape stairs stand (``functional.draw_core``), the same on every level, so that
   ``lift1`` on L1 and ``lift1`` on L3 are one shaft;
2. 2-4 levels ``L1`` ... (elevations a storey apart), each with its own departments,
   department signs and rooms drawn from the type's programme by a stream of its own
   (``{kind}_site:{seed}:L{k}``): a ward floor above an outpatients floor, a science floor
   above the classrooms. Only the ground floor (L1) has the reception desk at its
   entrance (its ``start`` waypoint, where a visitor comes in); above it the entrance
   lobby is a lift lobby like any other;
3. one numbering scheme for the building, with the floor in every code: L2 of a ``117``
   building numbers ``201``, ``202`` ... (``L2-204``, ``2.04``, ``B201``). The per-wing
   ``1G`` scheme has no floor in its codes, so its floors would repeat each other's plates
   and a robot off the lift could not tell by a door's number that it is on the wrong
   floor: no site uses it;
4. the site: the lift ``lift1`` with its lobby on every level, the stairs ``stairs1``
   (and ``stairs2``, where the far corridor had room for them) joining every level, never
   driven. The robot rides this lift, so the map (``lift_doorway``) and the simulator cut
   its doorway through the wall its point is on, and the point must be on a corridor's
   wall: the lift stands on the main corridor's wall beside the lift lobby, the first
   stretch past its mouth (``functional.core_landmarks(shaft=True)``), not on the lobby's
   back wall where the one-floor family hangs it (its point in front of that wall, which
   the map's doorway and the world's nearest wall would disagree about).

Members are named like the one-floor families with ``_site`` after the type:
``hospital_site_3``; the catalogue (``map/catalogue.py``) writes one once to its cache
folder as a site file and a building file per level, so episodes name it by that name.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from pmnav_bt.map.building import SITE_VERSION, building_from_data, dump_building
from pmnav_bt.map.functional import (
    BUILDING_KINDS,
    core_landmarks,
    department_signs,
    departments,
    draw_core,
    draw_shell,
    fill_rooms,
    floor_data,
    has_courtyard,
)
from pmnav_bt.map.numbering import SCHEMES

SITE_SUFFIX = "_site"
SITE_KINDS = tuple(f"{kind}{SITE_SUFFIX}" for kind in BUILDING_KINDS)  # hospital_site ...

LEVELS = (2, 4)  # fewest and most floors: a ride of 1-3 levels
# Floor-to-floor heights (m): a hospital's deep service voids, a school's and an office's
# ordinary storeys. They only order and draw the levels.
STOREY_M = {"hospital": 4.2, "school": 3.6, "office": 3.6}
FLOOR_SCHEMES = tuple(s for s in SCHEMES if s != "1G")  # the schemes with the floor in a code
LIFT_ID = "lift1"  # functional.core_landmarks' lift, at the core of every floor


@dataclass(frozen=True)
class GeneratedSite:
    """A generated site as file data: ``levels`` maps a level name to its building file's
    data; ``site_data(refs)`` is the site file's data, each level's building given by
    ``refs[level]`` (a file path relative to the site file, or the building data itself)."""

    name: str
    description: str
    levels: dict[str, dict]
    elevations: dict[str, float]
    lifts: tuple[dict, ...]
    stairs: tuple[dict, ...]

    def site_data(self, refs: dict[str, str | dict] | None = None) -> dict:
        """The site file's data; by default with every level's building inline."""
        refs = refs if refs is not None else self.levels
        return {
            "site_version": SITE_VERSION,
            "name": self.name,
            "description": self.description,
            "levels": [
                {"name": lv, "elevation": self.elevations[lv], "building": refs[lv]}
                for lv in self.levels
            ],
            "lifts": list(self.lifts),
            "stairs": list(self.stairs),
        }

    def level_texts(self) -> dict[str, str]:
        """Each level's building file, as YAML text (validated on the way)."""
        return {
            lv: dump_building(building_from_data(d, source=f"{self.name}/{lv}"))
            for lv, d in self.levels.items()
        }


def generate_functional_site(kind: str, seed: int) -> GeneratedSite:
    """A ``kind`` site (hospital, school or office) of 2-4 levels; the same seed, the same
    site (see the module)."""
    if kind not in BUILDING_KINDS:
        raise ValueError(f"unknown building kind {kind!r}; choose {', '.join(BUILDING_KINDS)}")
    name = f"{kind}{SITE_SUFFIX}_{seed}"
    rng = random.Random(f"{kind}{SITE_SUFFIX}:{seed}")  # not the one-floor member's stream
    shell = draw_shell(rng, kind)
    n_levels = rng.randint(*LEVELS)
    core = draw_core(rng, shell, shell.walls())
    scheme = rng.choice(FLOOR_SCHEMES)
    odd_even = rng.random() < 0.5
    courtyard = has_courtyard(rng, shell.prog)  # a courtyard is open the building's height
    levels: dict[str, dict] = {}
    for floor in range(1, n_levels + 1):
        level = f"L{floor}"
        lrng = random.Random(f"{kind}{SITE_SUFFIX}:{seed}:{level}")
        walls = shell.walls()
        states = departments(lrng, shell, floor)
        landmarks = core_landmarks(shell, walls, core, reception=floor == 1, shaft=True)
        landmarks += department_signs(lrng, shell, walls, states)
        rooms = fill_rooms(lrng, shell, walls, states, scheme, odd_even, floor, courtyard)
        wings = ", ".join(s.title for _, s in sorted(states.items()) if s.title) or "no wings"
        entry = "the entrance lobby with reception, " if floor == 1 else ""
        description = (
            f"Level {floor} of {name}: {shell.layout.describe()}; {entry}the lift lobby "
            "and stairs at the core; "
            f"{wings}; {len(rooms)} rooms numbered like "
            f"{rooms[0]['sign'].split()[0] if rooms else scheme}."
        )
        levels[level] = floor_data(shell, f"{name}_{level}", description, rooms, landmarks)
    names = list(levels)
    on_every = {lm["id"] for lm in levels[names[0]]["landmarks"]}
    stairs = [s for s in ("stairs1", "stairs2") if s in on_every]
    return GeneratedSite(
        name=name,
        description=(
            f"Generated {kind} of {n_levels} levels (seed {seed}): one footprint, the lift "
            f"and stairs at the core of every level, rooms numbered in scheme {scheme} "
            "with the floor in each code."
        ),
        levels=levels,
        elevations={lv: round(k * STOREY_M[kind], 2) for k, lv in enumerate(names)},
        lifts=({"id": LIFT_ID, "name": _name(levels[names[0]], LIFT_ID),
                "lobbies": dict.fromkeys(names, LIFT_ID)},),
        stairs=tuple(
            {"id": s, "name": _name(levels[names[0]], s), "lobbies": dict.fromkeys(names, s)}
            for s in stairs
        ),
    )  # fmt: skip


def _name(level: dict, ident: str) -> str:
    return next(lm["name"] for lm in level["landmarks"] if lm["id"] == ident)
