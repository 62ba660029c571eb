"""Corner and opening checks from the wall/floor mask ratio ahead (paper, "Navigation").

In the lower-central band of a forward view, a corridor that goes on shows floor;
a corner shows wall. ``mask_ratios`` measures both; ``is_corner`` and
``is_opening`` decide.

The band sees the floor only from some metres out: a camera ``camera_height`` above
the floor with zero pitch sees its lowest row's floor at ``camera_height * fy / (h - cy)``
(3.7 m for the simulator's 1.6 m, 60 deg, 320 x 240 camera), and a wall closer than that
fills the band whatever lies before it. ``is_opening``'s floor share so needs the floor to
run on some 5 m (``band_reach``): right for a corridor that goes on, wrong for a way the
map itself ends sooner (a short leg to the next turn, a lane across a hall towards its
far wall). ``is_open_way`` judges such a way by depth against the map instead.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.seams import Grounder, Observation

MIN_FLOOR = 0.25  # is_opening: the band's floor share of a way that goes on
# A way the map ends within ``band_reach`` is open when depth shows the floor free to
# where the map's floor ends, less this: how far along the way the estimate may be off
# (the corner check trusts a corner 2 m from the map's; a wall at a wrong turn stands
# half a corridor width, about 1 m, ahead).
RUN_SLACK_M = 1.0


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


def is_opening(r: MaskRatios, min_floor: float = MIN_FLOOR) -> bool:
    """The corridor goes on in this direction: plenty of floor in the band."""
    return r.floor >= min_floor


def band_reach(obs: Observation, min_floor: float = MIN_FLOOR) -> float:
    """How far (m) the floor must run straight ahead, up to a wall across the view, for
    ``min_floor`` of the band to be floor: the depth of the floor seen in the band's row
    ``min_floor`` of its height above its bottom."""
    k = obs.intrinsics
    rows, _ = central_band((k.height, k.width))
    row = rows.stop - min_floor * (rows.stop - rows.start)
    return obs.camera_height * k.fy / max(row - k.cy, 1e-9)


def is_open_way(
    r: MaskRatios,
    free: float | None,
    run: float,
    reach: float,
    min_floor: float = MIN_FLOOR,
    slack: float = RUN_SLACK_M,
) -> bool:
    """The way ahead is open as far as the map says it is.

    ``r``: the band's masks; ``free``: how far depth shows the floor free straight ahead
    (None without depth); ``run``: how far the map's floor runs ahead from the estimated
    pose; ``reach``: ``band_reach``. Where the map's floor runs as far as the band can
    show, the band decides (``is_opening``, the paper's check); where the map ends it
    sooner, the band cannot tell a way that ends where the map says from a wall just
    ahead, and depth decides: free to within ``slack`` of where the map's floor ends.
    """
    if is_opening(r, min_floor):
        return True
    return free is not None and run < reach and free >= run - slack
