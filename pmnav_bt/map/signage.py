"""The building file's optional ``signage:`` section: how the building's signs look.

A real building has one signage system: every room plate the same size, font, colours
and mounting, with a few exceptions (toilets as pictograms, a flag sign at a busy
door). The section models that as a building-wide ``style``, per-room overrides in
``rooms``, and ``directional`` signs at junctions ("Radiology ->"). Every field is
optional; what the file leaves unset is today's plate (``CLEAN_STYLE`` in
``pmnav_bt.sim.scene.signage``) with
``world.signage=file``, or drawn per building and seed with ``world.signage=random``
(``pmnav_bt.sim.scene.signage``).

The limits are what real signage uses: room plates are about 0.15-0.45 m wide with
capitals of 20-80 mm (ADA 703.2 asks 5/8 to 2 inches for tactile characters, and
wayfinding guides 25-75 mm for room plates read at 1-3 m); the upper limits also admit
the simulator's historical 0.8 m plate with ~86 mm capitals, so ``clean`` can be written
as a style. Documented field by field in docs/building-format.md ("signage").
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from typing import Annotated, Any, Literal, get_args

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field

from pmnav_bt.errors import Problem

# Fonts by name: a TrueType file that matplotlib ships (mpl-data/fonts/ttf), or None for
# OpenCV's Hershey font (the simulator's historical plates). Nothing is downloaded.
SIGN_FONTS: dict[str, str | None] = {
    "hershey": None,
    "dejavu_sans": "DejaVuSans.ttf",
    "dejavu_sans_bold": "DejaVuSans-Bold.ttf",
    "dejavu_serif": "DejaVuSerif.ttf",
    "dejavu_serif_bold": "DejaVuSerif-Bold.ttf",
    "dejavu_sans_mono": "DejaVuSansMono.ttf",
    "dejavu_sans_mono_bold": "DejaVuSansMono-Bold.ttf",
}

HISTORICAL_PLATE_M = 0.8  # the simulator's first plates: every one this wide (sim/textures.py)
PLATE_WIDTH_LIMITS_M = (0.1, HISTORICAL_PLATE_M)  # a door-number plate to the historical plate
CAP_HEIGHT_LIMITS_M = (0.015, 0.09)  # capitals; 0.0864 m is the historical plate's
HEIGHT_LIMITS_M = (0.9, 2.8)  # plate centre above the floor (flag signs hang at 2.1-2.5 m)
MAX_DIRECTIONAL = 500

# A room number at the front of a sign's text, in the schemes buildings use:
# 117, 1G, 2.04, L2-204, B117.
ROOM_NUMBER = re.compile(r"^[A-Za-z]{0,2}\d+(?:[.\-]\d+)*[A-Za-z]?$")

Mounting = Literal["beside", "beside_left", "beside_right", "on_door", "above_door", "flag"]
Layout = Literal["number_and_name", "number_only", "name_only"]
Pictogram = Literal["toilet"]
MOUNTINGS: tuple[str, ...] = get_args(Mounting)
LAYOUTS: tuple[str, ...] = get_args(Layout)


def _font(v: Any) -> Any:
    if isinstance(v, str) and v not in SIGN_FONTS:
        raise ValueError(f"unknown font; choose one of {', '.join(SIGN_FONTS)}")
    return v


FontName = Annotated[str, Field(strict=True), AfterValidator(_font)]


def _colour(v: Any) -> Any:
    ok = (
        isinstance(v, (list, tuple))
        and len(v) == 3
        and all(isinstance(c, int) and not isinstance(c, bool) and 0 <= c <= 255 for c in v)
    )
    if not ok:
        got = f" (got {list(v)!r})" if isinstance(v, (list, tuple)) else ""
        raise ValueError(f"a colour is 3 integers 0-255, [red, green, blue]{got}")
    return tuple(v)


Colour = Annotated[tuple[int, int, int], BeforeValidator(_colour)]


def _metres(lo: float, hi: float) -> Any:
    return Field(allow_inf_nan=False, strict=True, ge=lo, le=hi)


PlateWidth = Annotated[float, _metres(*PLATE_WIDTH_LIMITS_M)]
CapHeight = Annotated[float, _metres(*CAP_HEIGHT_LIMITS_M)]
Height = Annotated[float, _metres(*HEIGHT_LIMITS_M)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class SignStyleSpec(_Strict):
    """How plates look and hang; every field optional (unset: the building's, or today's)."""

    plate_width: PlateWidth | None = None
    cap_height: CapHeight | None = None
    font: FontName | None = None
    text_rgb: Colour | None = None
    plate_rgb: Colour | None = None
    mounting: Mounting | None = None
    layout: Layout | None = None
    height: Height | None = None


class RoomSignSpec(SignStyleSpec):
    """One room's exceptions to the building's style; ``pictogram`` replaces the text."""

    pictogram: Pictogram | None = None


class DirectionalSignSpec(_Strict):
    """A wayfinding sign on the wall nearest ``at``; ``->`` / ``<-`` in the text draw arrows."""

    # a map point within the building file's coordinate limits (building.MAX_COORD_M)
    at: tuple[Annotated[float, _metres(-1000, 1000)], Annotated[float, _metres(-1000, 1000)]]
    text: Annotated[str, Field(min_length=1, max_length=60, strict=True)]


class Signage(_Strict):
    """The ``signage:`` section of a building file."""

    style: SignStyleSpec = SignStyleSpec()
    rooms: dict[Annotated[str, Field(min_length=1, max_length=64)], RoomSignSpec] = Field(
        default_factory=dict, max_length=10_000
    )
    directional: tuple[DirectionalSignSpec, ...] = Field(default=(), max_length=MAX_DIRECTIONAL)


@dataclass(frozen=True)
class PlateStyle:
    """A plate's style with every field decided (what the renderer and mounting use)."""

    plate_width: float
    cap_height: float
    font: str
    text_rgb: tuple[int, int, int]
    plate_rgb: tuple[int, int, int]
    mounting: str
    layout: str
    height: float
    pictogram: str | None = None

    def merged(self, spec: SignStyleSpec) -> PlateStyle:
        """This style with the fields ``spec`` sets (not None) replaced."""
        return replace(self, **{k: v for k, v in spec.model_dump().items() if v is not None})




def split_number(text: str) -> tuple[str, str]:
    """A sign's text as (room number, name): ``"2.04 Radiology"`` -> ``("2.04", "Radiology")``;
    no leading number: ``("", text)``; a number alone: ``(number, "")``."""
    words = text.split()
    if words and ROOM_NUMBER.match(words[0]):
        return words[0], " ".join(words[1:])
    return "", " ".join(words)


def signage_problems(s: Signage, room_ids: set[str]) -> list[Problem]:
    """Problems of meaning in a structurally valid section (a directional sign off the
    corridors is found with the doors, in ``building.semantic_problems``)."""
    return [
        Problem(f"signage.rooms.{rid}", f"unknown room {rid!r} (not in rooms)")
        for rid in s.rooms
        if rid not in room_ids
    ]
