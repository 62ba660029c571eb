"""Which style each sign of a building gets: the file's ``signage:`` section, and with
``world.signage=random`` a signage system drawn per building and seed for what it leaves
unset.

A real building has one signage system (one plate size, font, colour scheme, mounting
and layout for every room) with a few exceptions; so a random draw picks one style per
building and episode seed, then varies it per room only where buildings do: toilets
get pictogram plates when the map says the room is a toilet (``map.amenities``: the
file's ``amenity``, else the room's name). Across seeds every
mounting, layout, font and colour scheme below is drawn.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from pmnav_bt.map.amenities import room_amenity
from pmnav_bt.map.building import Building
from pmnav_bt.map.signage import SIGN_FONTS, DirectionalSignSpec, PlateStyle
from pmnav_bt.seams import CAMERA_HEIGHT_M

# Today's plate as a style: 0.8 m wide, black Hershey text on white beside the door at the
# camera's height; capitals 72 % of the 0.12 m line pitch.
CLEAN_STYLE = PlateStyle(
    plate_width=0.8,
    cap_height=0.72 * 0.12,
    font="hershey",
    text_rgb=(0, 0, 0),
    plate_rgb=(255, 255, 255),
    mounting="beside",
    layout="number_and_name",
    height=CAMERA_HEIGHT_M,
)

# Colour schemes of real room signage as (text, plate) RGB: light-on-dark (the common
# corporate and hospital look), dark-on-light, and the high-contrast yellow of some
# schools and public buildings.
COLOUR_SCHEMES: dict[str, tuple[tuple[int, int, int], tuple[int, int, int]]] = {
    "white_on_navy": ((255, 255, 255), (22, 52, 112)),
    "white_on_green": ((255, 255, 255), (18, 92, 62)),
    "white_on_black": ((242, 242, 242), (28, 28, 30)),
    "white_on_burgundy": ((255, 255, 255), (112, 28, 44)),
    "white_on_grey": ((255, 255, 255), (100, 106, 112)),
    "black_on_white": ((18, 18, 18), (244, 244, 240)),
    "navy_on_silver": ((22, 40, 92), (200, 203, 207)),
    "black_on_yellow": ((20, 20, 20), (246, 196, 42)),
}
# How often each mounting is a building's system: most hang plates beside the door; door
# plates, plates over the door and projecting flags (hospitals, offices) are common too.
MOUNTING_WEIGHTS = {
    "beside": 0.25,
    "beside_left": 0.12,
    "beside_right": 0.12,
    "on_door": 0.2,
    "above_door": 0.15,
    "flag": 0.16,
}
LAYOUT_WEIGHTS = {"number_and_name": 0.55, "number_only": 0.25, "name_only": 0.2}
PLATE_WIDTH_M = (0.15, 0.45)  # room plates, from real practice
CAP_HEIGHT_M = (0.02, 0.08)
CAP_PER_WIDTH = 0.22  # capitals at most this fraction of the plate's width (fits a word)
WALL_HEIGHT_M = (1.35, 1.7)  # plate centre of wall and door plates (ADA: 1.22-1.52 m baseline)
FLAG_HEIGHT_M = (2.2, 2.45)  # flag signs hang above head height
TOILET_PICTOGRAM_P = 0.75  # buildings whose toilets carry pictogram plates


@dataclass(frozen=True)
class BuildingSignage:
    """The decided style of every room sign and the directional signs to put up."""

    style: PlateStyle  # the building's system
    rooms: dict[str, PlateStyle]
    directional: tuple[DirectionalSignSpec, ...]  # the file's
    wayfinding: bool  # draw signs at the junctions where the file lists none (random)


def draw_style(rng: np.random.Generator) -> PlateStyle:
    """One building's signage system, drawn from the kinds real buildings use."""

    def pick(weights: dict[str, float]) -> str:
        keys = list(weights)
        p = np.array([weights[k] for k in keys])
        return keys[int(rng.choice(len(keys), p=p / p.sum()))]

    text_rgb, plate_rgb = COLOUR_SCHEMES[pick(dict.fromkeys(COLOUR_SCHEMES, 1.0))]
    width = float(rng.uniform(*PLATE_WIDTH_M))
    cap_hi = min(CAP_HEIGHT_M[1], CAP_PER_WIDTH * width)
    mounting = pick(MOUNTING_WEIGHTS)
    height = FLAG_HEIGHT_M if mounting == "flag" else WALL_HEIGHT_M
    return PlateStyle(
        plate_width=round(width, 3),
        cap_height=round(float(rng.uniform(CAP_HEIGHT_M[0], cap_hi)), 4),
        font=pick(dict.fromkeys(SIGN_FONTS, 1.0)),
        text_rgb=text_rgb,
        plate_rgb=plate_rgb,
        mounting=mounting,
        layout=pick(LAYOUT_WEIGHTS),
        height=round(float(rng.uniform(*height)), 3),
    )


def resolve_signage(b: Building, mode: str, rng: np.random.Generator) -> BuildingSignage | None:
    """The styles of ``b``'s signs for ``world.signage`` = ``mode`` (``file`` or ``random``);
    None when the file has no section and nothing is drawn: today's plates, unchanged."""
    section = b.signage
    if mode == "file":
        if section is None:
            return None
        base = CLEAN_STYLE
    else:
        base = draw_style(rng)
    if section is not None:
        base = base.merged(section.style)
    pictogram_toilets = mode == "random" and rng.random() < TOILET_PICTOGRAM_P
    rooms = {}
    for room in b.rooms:
        style = base
        if pictogram_toilets and room_amenity(room) == "toilet":
            style = replace(style, pictogram="toilet")
        override = section.rooms.get(room.id) if section is not None else None
        if override is not None:
            style = style.merged(override)
        rooms[room.id] = style
    directional = section.directional if section is not None else ()
    return BuildingSignage(base, rooms, directional, mode == "random")
