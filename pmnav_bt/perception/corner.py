"""Corner and opening checks from the wall/floor mask ratio ahead (paper, "Navigation").

In the lower-central band of a forward view, a corridor that goes on shows floor;
a corner shows wall. ``mask_ratios`` measures both; ``is_corner`` and
``is_opening`` decide.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.seams import Grounder, Observation


@dataclass(frozen=True)
class MaskRatios:
    """Fractions of the band that are wall and floor."""

    wall: float
    floor: float


def central_band(shape: tuple[int, int], width_frac: float = 0.3) -> tuple[slice, slice]:
    """Rows from the horizon down, columns in the central ``width_frac`` of the image."""
    h, w = shape
    c0, c1 = int(w * (0.5 - width_frac / 2)), int(w * (0.5 + width_frac / 2))
    return slice(h // 2, h), slice(c0, max(c1, c0 + 1))


def mask_ratios(obs: Observation, grounder: Grounder) -> MaskRatios:
    """Wall and floor fractions in the lower-central band, from the grounder's surfaces."""
    rows, cols = central_band(obs.rgb.shape[:2])
    area = (rows.stop - rows.start) * (cols.stop - cols.start)
    masks = grounder.surfaces(obs)
    return MaskRatios(
        wall=float(masks.wall[rows, cols].sum()) / area,
        floor=float(masks.floor[rows, cols].sum()) / area,
    )


def is_corner(r: MaskRatios, max_floor: float = 0.15, min_wall: float = 0.5) -> bool:
    """A wall fills the way ahead: little floor, much wall."""
    return r.floor <= max_floor and r.wall >= min_wall


def is_opening(r: MaskRatios, min_floor: float = 0.25) -> bool:
    """The corridor goes on in this direction: plenty of floor in the band."""
    return r.floor >= min_floor
