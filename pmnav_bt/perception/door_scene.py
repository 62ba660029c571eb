"""A read sign's door, found in the scene around it rather than assumed from one convention.

Buildings hang room signs beside the door on either side, on the door leaf, above the
frame, or as a flag projecting from the wall beside it (``sim/scene/sign_mounting.py``).
One convention (``doors.door_from_sign``: the door ``sign_to_door`` beside the plate) puts
the door a metre off for every plate on or above its door, and nowhere sensible for a
flag, whose plate stands across the corridor. So the door is looked for in RGB-D:

1. **The wall the plate belongs to.** Wall lines are fitted in depth near the plate
   (``walls.wall_lines``). A flat plate lies on a line parallel to it; a flag's plate is
   perpendicular to its wall and stands out of it (``FLAG_OUT_M``), and its foot on the
   wall stands in for the plate. Without a line, the plate's own plane is the wall.
2. **A profile along that wall**, ``WINDOW_M`` either side of the plate, in the band of
   heights ``BAND_M`` (above a hospital's bumper rail and wipe-clean lower band, below the
   door frame's top): every pixel's ray is followed to the wall plane, so a pixel of an
   open doorway or a glazed leaf (depth behind the wall) counts where it crosses the
   wall. A pixel behind the wall is door (an opening or a recessed leaf); one on the wall
   is door when its colour is ``MIN_CONTRAST`` from the wall's own (the median of the
   same wall above the doors, ``REF_BAND_M``, as ``door_sightings`` takes it; seen too
   near for that, of the wall round the plate, what it hangs on); one in
   front of the wall (clutter, a person) tells nothing, nor do the plate's own pixels.
   Runs of door bins a door's width long are the doors; a run that reaches the edge of
   what is seen is cut, and only its seen end is its edge.
3. **Which door is the plate's.** A run under the plate's foot is its door (a plate on
   the leaf, or above the frame). Otherwise the runs on either side whose near edge is
   within the plate's reach (``REACH_M`` past the plate's edge: the 0.15 m gap buildings
   leave to the frame, and slack) are its candidates, and the nearer wins; the building's
   mounting, where its file gives one, and ``grounder.door_side`` only break a tie.
4. **No door seen**: the priors decide. A file that mounts the room's plate on or above its
   door puts the door at the plate's foot; otherwise ``door_from_sign`` (the convention,
   its side read from colour) is asked at the plate, or at a flag's foot on the wall.

Where the run seen on the convention's side agrees with the convention (its centre within
``AGREE_M`` of ``sign_to_door``: the bins and the frame's edges are 0.1 m coarse), the
convention's exact spot is kept, so a building that follows it (the clean world) places
most of its doors exactly as before, and none more than 0.25 m away. It runs once per
read room plate: about 30 ms of CPU at 320x240, most of it the wall fit
(``benchmarks/bench_door_from_sign.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from pmnav_bt.map.building import Building
from pmnav_bt.map.signage import Mounting
from pmnav_bt.perception.depth import PlatePose, back_project, polygon_mask, surfaces, wall_rect
from pmnav_bt.perception.door_sightings import REF_BAND_M  # the wall's colour: above the doors
from pmnav_bt.perception.doors import DoorEstimate, DoorLayout, door_beside, door_from_sign
from pmnav_bt.pose.walls import wall_lines, wall_points
from pmnav_bt.seams import Observation

WINDOW_M = 2.6  # along the wall either side of the plate: a beside plate's far door edge
# is 0.15 + 1.16 m past the plate's edge, a flag's foot 0.15 m from the frame
NEAR_M = 3.0  # wall pixels this near the plate fit its wall ...
WALL_STRIDE = 4  # ... every this many pixels (the fit's cost is in its points)
BAND_M = (1.1, 2.0)  # heights looked at: above a bumper rail (0.9-1.02 m), below a frame's top
ON_WALL_M = 0.12  # a point this near the wall plane is on it (frames stand 4 cm out)
BEHIND_M = 0.12  # ... this far behind it: an opening, a glazed or recessed leaf
IN_FRONT_M = 0.25  # ... this far in front: something standing before the wall
MIN_CONTRAST = 20.0  # CIELAB distance from the wall's colour of a door pixel (only faces of
# the one wall plane are compared, so a face shaded otherwise, which ``door_sightings``
# weighs lightness down for, does not arise: a grey frame on a grey wall differs in it)
MIN_REF_PX = 30  # pixels above the doors for the wall's colour to be known
BIN_M = 0.1
MIN_BIN_PX = 3  # a bin with fewer pixels is not seen
BIN_DOOR_SHARE = 0.5  # a seen bin this much door is door
GAP_BINS = 2  # a run ends at this many seen wall bins
DOOR_RUN_M = (0.5, 1.8)  # a room door's run, frame to frame (a 1.16 m frame; a corridor
# opening is wider)
FRAME_RUN_M = 0.3  # a run this short may be one jamb of a frame
MIN_CUT_RUN_M = 0.3  # a run cut by the view's edge needs this much of it seen
ON_PLATE_M = 0.1  # a run this near the plate's foot is under it
REACH_M = 0.45  # a beside plate's door starts within its half width + this (0.15 m gap)
TIE_M = 0.1  # doors either side alike in nearness to a bin: the priors choose
ON_PLANE_M = 0.1  # a flat plate's centre this near a wall line hangs on it (a door
# plate stands a leaf's thickness out)
FLAG_OUT_M = (0.1, 0.8)  # a flag's points stand this far out of its wall (a 5 cm bracket,
# plates to 0.45 m wide)
FLAG_MIN_SHARE = 0.3  # ... at least this share of its box's points (the rest: wall behind)
AGREE_M = 0.15  # a run's centre this near the convention's spot confirms the convention
PLATE_MARGIN_PX = 2  # the plate's box grown by this much is not looked at
BACKING_RING = 0.5  # the ring round a plate its backing's colour is taken in, in plate sizes


@dataclass(frozen=True)
class WallFrame:
    """The wall a plate belongs to, in the camera body frame's floor plane: unit normal
    towards the camera, unit direction to the viewer's left facing the wall, the plate's
    foot on it, and whether the plate stands across it (a flag)."""

    normal: np.ndarray  # (2,)
    left: np.ndarray  # (2,)
    foot: np.ndarray  # (2,)
    flag: bool


@dataclass(frozen=True)
class DoorRun:
    """A door seen along the wall: its ends (m along ``WallFrame.left`` from the foot),
    and whether the view's edge cut it at its low or high end."""

    lo: float
    hi: float
    cut_lo: bool
    cut_hi: bool


def mounting_prior(building: Building, room_id: str) -> Mounting | None:
    """How the building's file says ``room_id``'s plate hangs (its ``signage:`` section: the
    room's own entry, else the building's style), None where it does not say."""
    sg = building.signage
    if sg is None:
        return None
    own = sg.rooms.get(room_id)
    if own is not None and own.mounting is not None:
        return own.mounting
    return sg.style.mounting


def door_for_plate(
    obs: Observation,
    plate: PlatePose,
    box: tuple[float, float, float, float],
    layout: DoorLayout,
    prior: Mounting | None = None,
) -> DoorEstimate:
    """The door of the plate at ``plate`` (its image ``box``), found in the scene (see the
    module docstring); ``prior``: the building's mounting for it, where its file says."""
    pts = back_project(obs)
    wall = plate_wall(obs, pts, plate, box)
    runs = door_runs(obs, pts, wall, box)
    s = _choose(runs, plate, layout, prior)
    if s is None:
        return _fallback(obs, plate, wall, layout, prior)
    agreed = _convention(obs, s, plate, wall, layout)
    if agreed is not None:
        return agreed
    return _estimate(obs, wall, s, layout, seen=True)


def door_runs(
    obs: Observation, pts: np.ndarray, wall: WallFrame, box: tuple[float, float, float, float]
) -> list[DoorRun]:
    """The door runs along ``wall`` within ``WINDOW_M`` of its foot (see the module
    docstring, step 2), nearest the foot first."""
    n, d, foot = wall.normal, wall.left, wall.foot
    o = float(n @ foot)
    xy = pts[..., :2]
    with np.errstate(invalid="ignore", divide="ignore"):
        along_n = xy @ n
        t = o / along_n  # the ray's crossing of the wall plane, as a share of the point
        q = xy * t[..., None]
        z_q = (pts[..., 2] * t) + obs.camera_height
        s = (q - foot) @ d
        h = along_n - o  # in front of the wall (towards the camera) is positive
    ok = np.isfinite(s) & np.isfinite(h) & (t > 0) & (np.abs(s) <= WINDOW_M)
    ok &= (z_q > BAND_M[0]) & (z_q < BAND_M[1]) & (h < IN_FRONT_M)
    ok &= ~_box_mask(obs, box)
    if ok.sum() < MIN_BIN_PX:
        return []
    lab = cv2.cvtColor(obs.rgb, cv2.COLOR_RGB2LAB).astype(np.float32)
    behind = h[ok] < -BEHIND_M
    on_wall = np.abs(h[ok]) <= ON_WALL_M
    colour = lab[ok]
    ref = _wall_colour(obs, pts, wall, lab, box)
    if ref is None:
        # Too near to see above the doors: what the plate hangs on, round its box.
        ref = _backing_colour(obs, pts, wall, lab, box)
    if ref is None and on_wall.sum() >= MIN_REF_PX:
        # Nor that (a flag's box has no wall round it): the band's own median. Where a
        # leaf fills the view that is the leaf's colour, and its frame's jambs stand out
        # of it instead.
        ref = np.median(colour[on_wall], axis=0)
    if ref is None:
        door = behind
    else:
        unlike = np.linalg.norm(colour - ref, axis=1) > MIN_CONTRAST
        door = behind | (on_wall & unlike)
    return _runs(s[ok], door)


def plate_wall(obs: Observation, pts: np.ndarray, plate: PlatePose, box) -> WallFrame:
    """The wall ``plate`` hangs on or projects from (step 1). The lines are fitted on the
    wall pixels near the plate outside its box; the box's own points then tell a flat
    plate (on the line) from a flag (standing out of it, ``FLAG_OUT_M``), whose points all
    fall on one spot of the wall: its foot."""
    c = plate.centre[:2]
    in_box = _box_mask(obs, box, margin=0)
    wall_mask = surfaces(obs).wall & ~in_box
    p = wall_points(obs, wall_mask, stride=WALL_STRIDE)
    p = p[np.linalg.norm(p - c, axis=1) <= NEAR_M] if len(p) else p
    own = pts[in_box][:, :2]
    own = own[np.isfinite(own).all(axis=1)]
    for line in wall_lines(p, 2) if len(p) and len(own) else []:
        n = np.array([-math.sin(line.angle), math.cos(line.angle)])
        o = line.offset
        if o > 0:  # the normal towards the camera (the origin)
            n, o = -n, -o
        left = np.array([n[1], -n[0]])
        off = own @ n - o
        if abs(float(n @ c - o)) <= ON_PLANE_M:
            return WallFrame(n, left, c - float(n @ c - o) * n, flag=False)
        out = own[(off >= FLAG_OUT_M[0]) & (off <= FLAG_OUT_M[1])]
        if len(out) >= FLAG_MIN_SHARE * len(own):
            foot = np.median(out, axis=0)
            return WallFrame(n, left, foot - float(n @ foot - o) * n, flag=True)
    return WallFrame(plate.normal[:2].copy(), plate.left[:2].copy(), c.copy(), flag=False)


def _wall_colour(obs: Observation, pts, wall: WallFrame, lab, box) -> np.ndarray | None:
    """The wall's own colour: the median of its pixels above the doors (None: too few)."""
    h = pts[..., :2] @ wall.normal - float(wall.normal @ wall.foot)
    z = pts[..., 2] + obs.camera_height
    m = np.nan_to_num(np.abs(h), nan=1e9) <= ON_WALL_M
    m &= (np.nan_to_num(z, nan=-1) > REF_BAND_M[0]) & (np.nan_to_num(z, nan=9) < REF_BAND_M[1])
    m &= ~_box_mask(obs, box)
    if m.sum() < MIN_REF_PX:
        return None
    return np.median(lab[m], axis=0)


def _backing_colour(obs: Observation, pts, wall: WallFrame, lab, box) -> np.ndarray | None:
    """The colour of what a flat plate hangs on: the median of the wall plane's pixels in
    a ring round its box (``BACKING_RING``, the plate's own size out). Beside a door or
    above it that is the wall; on the door, the leaf, whose frame's jambs then stand out
    of it. Seen close, the band of door heights may be more leaf than wall, and its median
    would take the leaf for the wall and the wall beside it for a door. None: too few."""
    ring = max(box[2] - box[0], box[3] - box[1]) * BACKING_RING
    grown = (box[0] - ring, box[1] - ring, box[2] + ring, box[3] + ring)
    h = pts[..., :2] @ wall.normal - float(wall.normal @ wall.foot)
    m = _box_mask(obs, grown, margin=0) & ~_box_mask(obs, box)
    m &= np.nan_to_num(np.abs(h), nan=1e9) <= ON_WALL_M
    if m.sum() < MIN_REF_PX:
        return None
    return np.median(lab[m], axis=0)


def _box_mask(obs: Observation, box, margin: int = PLATE_MARGIN_PX) -> np.ndarray:
    """The pixels of the plate's ``box``, grown by ``margin``."""
    hgt, wid = obs.rgb.shape[:2]
    m = np.zeros((hgt, wid), bool)
    x0 = max(0, int(math.floor(box[0])) - margin)
    y0 = max(0, int(math.floor(box[1])) - margin)
    x1 = min(wid, int(math.ceil(box[2])) + margin + 1)
    y1 = min(hgt, int(math.ceil(box[3])) + margin + 1)
    m[y0:y1, x0:x1] = True
    return m


def _runs(s: np.ndarray, door: np.ndarray) -> list[DoorRun]:
    """Runs of door bins along the wall: a bin with too few pixels neither ends nor makes a
    run; ``GAP_BINS`` seen wall bins end one. A run whose outer neighbour bin is unseen
    (out of the frame, behind something) is cut there."""
    lo = math.floor(-WINDOW_M / BIN_M)
    nbins = int(math.ceil(2 * WINDOW_M / BIN_M)) + 1
    idx = np.clip(np.floor(s / BIN_M).astype(int) - lo, 0, nbins - 1)
    total = np.bincount(idx, minlength=nbins)
    hits = np.bincount(idx, weights=door.astype(float), minlength=nbins)
    seen = total >= MIN_BIN_PX
    is_door = seen & (hits >= BIN_DOOR_SHARE * np.maximum(total, 1))
    runs: list[tuple[int, int]] = []
    start = last = None
    walls = 0
    for i in range(nbins):
        if is_door[i]:
            if start is None:
                start = i
            last, walls = i, 0
        elif seen[i] and start is not None:
            walls += 1
            if walls >= GAP_BINS:
                runs.append((start, last))
                start, walls = None, 0
    if start is not None:
        runs.append((start, last))
    out = []
    for a, b in runs + _frame_pairs(runs):
        cut_lo = a == 0 or not seen[a - 1]
        cut_hi = b == nbins - 1 or not seen[b + 1]
        length = (b - a + 1) * BIN_M
        full = DOOR_RUN_M[0] <= length <= DOOR_RUN_M[1]
        if full or ((cut_lo or cut_hi) and MIN_CUT_RUN_M <= length <= DOOR_RUN_M[1]):
            out.append(DoorRun((lo + a) * BIN_M, (lo + b + 1) * BIN_M, cut_lo, cut_hi))
    return sorted(out, key=lambda r: _gap(r, 0.0))


def _frame_pairs(runs: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """A leaf painted like its wall shows only its frame: two narrow runs (the jambs) a
    door's width apart, outer edge to outer edge, are a door too."""
    narrow = [(a, b) for a, b in runs if (b - a + 1) * BIN_M <= FRAME_RUN_M]
    return [
        (a0, b1)
        for (a0, _), (_, b1) in zip(narrow, narrow[1:], strict=False)
        if DOOR_RUN_M[0] <= (b1 - a0 + 1) * BIN_M <= DOOR_RUN_M[1]
    ]


def _gap(run: DoorRun, s: float) -> float:
    """How far ``s`` is from ``run`` (0 inside it)."""
    return max(run.lo - s, s - run.hi, 0.0)


def _centre(run: DoorRun, width: float) -> float:
    """The door's centre along the wall: the run's middle, or a door's half width from its
    seen end where the view cut it."""
    if run.cut_lo and not run.cut_hi:
        return run.hi - width / 2.0
    if run.cut_hi and not run.cut_lo:
        return run.lo + width / 2.0
    return (run.lo + run.hi) / 2.0


def _choose(
    runs: list[DoorRun], plate: PlatePose, layout: DoorLayout, prior: Mounting | None
) -> float | None:
    """Where along the wall the plate's door is (step 3), None: no door seen."""
    if not runs:
        return None
    under = [r for r in runs if _gap(r, 0.0) <= ON_PLATE_M]
    if under:
        return _centre(under[0], layout.door_width)
    reach = plate.width / 2.0 + REACH_M
    near = [r for r in runs if _gap(r, 0.0) <= reach]
    if not near:
        return None
    sides = {("left" if r.lo > 0 else "right"): r for r in reversed(near)}  # nearest kept
    r = near[0]
    if len(sides) == 2 and abs(_gap(sides["left"], 0.0) - _gap(sides["right"], 0.0)) <= TIE_M:
        r = sides[_prior_side(prior, layout)]
    return _centre(r, layout.door_width)


def _prior_side(prior: Mounting | None, layout: DoorLayout) -> str:
    """The side of its plate a door is on, by the building's mounting or the convention: a
    plate hung ``beside_left`` is on the viewer's left of its door (the door on its right)."""
    if prior == "beside_left":
        return "right"
    if prior in ("beside", "beside_right"):
        return "left"
    return layout.default_side


def _convention(
    obs: Observation, s: float, plate: PlatePose, wall: WallFrame, layout: DoorLayout
) -> DoorEstimate | None:
    """The convention's spot where the door seen confirms it (see the module docstring)."""
    if wall.flag:
        return None
    for side, sgn in (("left", 1.0), ("right", -1.0)):
        if abs(s - sgn * layout.sign_to_door) <= AGREE_M:
            return door_beside(obs, plate, layout, side, seen=True)  # type: ignore[arg-type]
    return None


def _estimate(
    obs: Observation, wall: WallFrame, s: float, layout: DoorLayout, seen: bool
) -> DoorEstimate:
    """The door centred ``s`` along ``wall`` from the plate's foot, at mid-height, its mask."""
    floor_z = -obs.camera_height
    xy = wall.foot + s * wall.left
    centre = np.array([xy[0], xy[1], floor_z + layout.door_height / 2.0])
    left3 = np.array([wall.left[0], wall.left[1], 0.0])
    top = floor_z + layout.door_height
    m = polygon_mask(obs, wall_rect(centre, left3, layout.door_width / 2.0, floor_z, top))
    if m is not None and not m.any():
        m = None
    side = "left" if s > 0 else "right"
    if abs(s) <= ON_PLATE_M + layout.door_width / 2.0:
        side = "at"  # the plate's foot is within the door
    return DoorEstimate(centre, side, seen, m)  # type: ignore[arg-type]


def _fallback(
    obs: Observation, plate: PlatePose, wall: WallFrame, layout: DoorLayout, prior: Mounting | None
) -> DoorEstimate:
    """No door seen near the plate: the priors (step 4)."""
    if prior in ("on_door", "above_door"):
        return _estimate(obs, wall, 0.0, layout, seen=False)
    if not wall.flag:
        return door_from_sign(obs, plate, layout)
    foot = np.array([wall.foot[0], wall.foot[1], float(plate.centre[2])])
    n3 = np.array([wall.normal[0], wall.normal[1], 0.0])
    left3 = np.array([wall.left[0], wall.left[1], 0.0])
    return door_from_sign(obs, PlatePose(foot, left3, n3, plate.width), layout)
