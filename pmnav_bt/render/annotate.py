"""The annotated priori-map (paper, "VLM Planning"): the floor plan with visual tags.

Room IDs sit behind their doors, segment labels (``seg13``) at segment midpoints,
key waypoints (start/turn/branch/end) carry a marker and a tag, landmarks a star
and a tag; a north arrow, scale bar, title and legend frame the map. The
background is the building's floor plan when there is one, otherwise a clean
drawing of corridors, walls, doors and room boxes.

Tags never overlap: ``layout_labels`` places them greedily (waypoints, rooms,
landmarks, then segments) over candidate positions around each anchor, checking
rectangles, and draws a leader line where a tag had to move away. Segment labels
that find no free place are dropped and counted; room, waypoint and landmark tags
are always placed.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.floorplan import (
    DOOR_WIDTH_M,
    DoorFrame,
    FloorPlanImage,
    building_bounds,
    corridor_quads,
    door_frames,
    load_floor_plan,
)
from pmnav_bt.map.priori_map import PrioriMap, natural_key

log = logging.getLogger(__name__)

FONT = cv2.FONT_HERSHEY_SIMPLEX
WHITE = (255, 255, 255)
KIND_COLOUR = {  # BGR
    "start": (0, 140, 0),
    "turn": (0, 110, 230),
    "branch": (170, 0, 170),
    "end": (0, 0, 200),
    "landmark": (120, 100, 0),
}
# Text style per label kind: font scale, thickness, colour.
STYLE = {
    "waypoint": (0.6, 2, None),  # colour of the waypoint's kind
    "room": (0.55, 1, (20, 20, 20)),
    "landmark": (0.5, 1, KIND_COLOUR["landmark"]),
    "segment": (0.5, 1, (130, 70, 20)),
}
PLACE_ORDER = ("waypoint", "room", "landmark", "segment")
CORRIDOR_FILL = (205, 232, 248)
CORRIDOR_TINT = (235, 170, 90)  # BGR, corridors over a floor plan (blended)
CORRIDOR_EDGE = (190, 110, 40)
GRID_MINOR = (225, 225, 225)
GRID_MAJOR = (170, 170, 170)
ROOM_FILL, ROOM_EDGE = (246, 246, 246), (175, 175, 175)
WALL, DOOR, CENTRE_LINE, LEADER = (60, 60, 60), (30, 80, 170), (175, 175, 175), (90, 90, 90)
PATH_COLOUR = (220, 90, 20)

MARKER_R = 9  # px, key waypoint and landmark markers
LABEL_PAD = 3  # px around text (holds the white halo)
LABEL_WASH = 0.7  # how far a tag's box is lightened towards white behind the text
LEADER_MIN = 6  # px; a tag farther than this from its anchor gets a leader line
INK_MAX = 90  # grey level below which a background pixel is ink (a wall) tags keep off
INK_PENALTY = 48  # candidates (three rings) a tag may move outwards to keep off ink
HEADER_H = 44
TITLE_SCALE = 0.8
MARK = (30, 30, 200)  # BGR: the red of the marks a caller adds (lift links)
MIN_WIDTH = 640  # px, room for the legend
MAP_PAD = 80  # px around the building, room for tags outside the walls
ROOM_DEPTH_M, ROOM_WIDTH_M = 2.8, 3.2
AUTO_LONG_SIDE = 1600  # px the map's long side aims at when no scale is given
MIN_SCALE, MAX_SCALE = 20.0, 40.0  # px per metre


@dataclass(frozen=True)
class Canvas:
    """The drawing frame: map (x, y) to canvas pixels, with a title band above, legend below."""

    xmin: float
    ymax: float
    scale: float  # px per metre
    width: int
    map_left: int  # px; wider canvases (a long title, the legend) centre the map
    map_top: int
    map_height: int
    footer_height: int

    @property
    def height(self) -> int:
        return self.map_top + self.map_height + self.footer_height

    @property
    def map_box(self) -> tuple[int, int, int, int]:
        """(x0, y0, x1, y1) of the map area, where tags may go."""
        return 0, self.map_top, self.width, self.map_top + self.map_height

    def affine(self) -> np.ndarray:
        """The 2x3 matrix taking map (x, y) to canvas (u, v)."""
        s = self.scale
        return np.array(
            [
                [s, 0.0, self.map_left + MAP_PAD - s * self.xmin],
                [0.0, -s, self.map_top + MAP_PAD + s * self.ymax],
            ]
        )

    def to_px(self, xy) -> np.ndarray:
        """Map points (N, 2) to canvas pixels (N, 2), float."""
        m = self.affine()
        return np.asarray(xy, dtype=float).reshape(-1, 2) @ m[:, :2].T + m[:, 2]

    def ipx(self, xy) -> tuple[int, int]:
        """One map point as an integer canvas pixel."""
        u, v = self.to_px(xy)[0]
        return int(round(u)), int(round(v))


@dataclass(frozen=True)
class Label:
    """A placed tag: its text, kind, anchor (canvas px) and box (x0, y0, x1, y1)."""

    text: str
    kind: str  # waypoint | room | landmark | segment
    anchor: tuple[float, float]
    box: tuple[int, int, int, int]
    colour: tuple[int, int, int]

    @property
    def leader(self) -> bool:
        """True where the tag sits away from its anchor and needs a leader line."""
        return _box_distance(self.box, self.anchor) > LEADER_MIN


@dataclass(frozen=True)
class LabelLayout:
    """Every placed tag, and the segment labels dropped for want of a free place."""

    canvas: Canvas
    labels: tuple[Label, ...]
    dropped: tuple[str, ...]

    def texts(self, kind: str) -> set[str]:
        return {lb.text for lb in self.labels if lb.kind == kind}


@dataclass(frozen=True)
class _Request:
    text: str
    kind: str
    anchor: np.ndarray  # canvas px
    prefer: float  # preferred direction from the anchor, canvas radians
    gap: float  # px between anchor and the nearest candidate box
    slide: np.ndarray | None = None  # unit canvas direction a segment label may slide along
    slide_max: float = 0.0
    colour: tuple[int, int, int] | None = None  # default: the kind's text colour


# -- the frame -------------------------------------------------------------------------


def make_canvas(pm: PrioriMap, scale_px_per_m: float | None = None) -> Canvas:
    """The drawing frame of a priori-map; without a scale, the map's long side is ~1600 px."""
    xmin, ymin, xmax, ymax = _world_extent(pm)
    if scale_px_per_m is None:
        span = max(xmax - xmin, ymax - ymin, 1.0)
        scale_px_per_m = float(np.clip(AUTO_LONG_SIDE / span, MIN_SCALE, MAX_SCALE))
    if scale_px_per_m <= 0:
        raise PmNavError(
            f"scale_px_per_m must be a positive number of pixels per metre, got {scale_px_per_m}"
        )
    map_w = int(math.ceil((xmax - xmin) * scale_px_per_m)) + 2 * MAP_PAD
    map_h = int(math.ceil((ymax - ymin) * scale_px_per_m)) + 2 * MAP_PAD
    title_w = cv2.getTextSize(_title(pm), FONT, TITLE_SCALE, 2)[0][0] + 24
    width = max(map_w, title_w, MIN_WIDTH)
    rows = _legend_rows(_legend_entries(with_path=True), width)
    footer = 40 + max(70, 26 * len(rows))  # the last line holds the dropped-labels note
    left = (width - map_w) // 2
    return Canvas(xmin, ymax, float(scale_px_per_m), width, left, HEADER_H, map_h, footer)


def _world_extent(pm: PrioriMap) -> tuple[float, float, float, float]:
    xmin, ymin, xmax, ymax = building_bounds(pm.building)
    boxes = [_room_box(f, w) for f, w in _room_widths(pm)]
    if boxes:
        pts = np.vstack(boxes)
        xmin, ymin = min(xmin, pts[:, 0].min()), min(ymin, pts[:, 1].min())
        xmax, ymax = max(xmax, pts[:, 0].max()), max(ymax, pts[:, 1].max())
    return float(xmin), float(ymin), float(xmax), float(ymax)


def _room_widths(pm: PrioriMap) -> list[tuple[DoorFrame, float]]:
    """Each door with the width of its room box: narrower where doors are close together."""
    frames = door_frames(pm.building)
    doors = np.array([f.door for f in frames]).reshape(-1, 2)
    out = []
    for i, f in enumerate(frames):
        d = np.linalg.norm(doors - doors[i], axis=1)
        d[i] = np.inf
        out.append((f, float(np.clip(d.min() - 0.6, 1.2, ROOM_WIDTH_M))))
    return out


def _room_box(f: DoorFrame, width: float) -> np.ndarray:
    """The room drawn behind a door (4, 2), map frame."""
    foot, u, n = (np.asarray(v) for v in (f.foot, f.along, f.out))
    wall = foot + n * f.wall
    h = width / 2.0
    return np.array(
        [
            wall - u * h,
            wall + u * h,
            wall + u * h + n * ROOM_DEPTH_M,
            wall - u * h + n * ROOM_DEPTH_M,
        ]
    )


# -- label layout ----------------------------------------------------------------------


def layout_labels(
    pm: PrioriMap,
    canvas: Canvas | None = None,
    background: np.ndarray | None = None,
    marks: Sequence[tuple[tuple[float, float], str]] = (),
) -> LabelLayout:
    """Place every tag without overlap; drop segment labels only where no place is free.
    ``marks``: extra tags (a map point, a text), placed after the landmarks' tags.

    Tags also keep off the dark lines (walls) of ``background`` where they can; without
    one, the clean drawing of the building is used.
    """
    canvas = canvas or make_canvas(pm)
    if background is None:
        background = np.full((canvas.height, canvas.width, 3), 255, dtype=np.uint8)
        _draw_building(background, pm, canvas)
    ink = cv2.integral((cv2.cvtColor(background, cv2.COLOR_BGR2GRAY) < INK_MAX).astype(np.uint8))
    occupied = [_marker_boxes(pm, canvas)]
    placed: list[Label] = []
    dropped: list[str] = []
    for req in _requests(pm, canvas, marks):
        box = _place(req, np.vstack(occupied), canvas.map_box, ink)
        if box is None:
            dropped.append(req.text)
            continue
        occupied.append(np.array([box], dtype=float))
        anchor = (float(req.anchor[0]), float(req.anchor[1]))
        colour = req.colour or STYLE[req.kind][2]
        placed.append(Label(req.text, req.kind, anchor, box, colour))
    if dropped:
        log.info("annotated map: %d segment labels dropped (%s)", len(dropped), ", ".join(dropped))
    return LabelLayout(canvas, tuple(placed), tuple(dropped))


def _requests(
    pm: PrioriMap, canvas: Canvas, marks: Sequence[tuple[tuple[float, float], str]] = ()
) -> list[_Request]:
    reqs = _waypoint_requests(pm, canvas) + _room_requests(pm, canvas)
    reqs += _landmark_requests(pm, canvas)
    reqs += [
        _Request(t, "landmark", canvas.to_px(xy)[0], _away(pm, xy), 2 * MARKER_R, None, 0, MARK)
        for xy, t in marks
    ]
    reqs += _segment_requests(pm, canvas)
    return sorted(reqs, key=lambda r: PLACE_ORDER.index(r.kind))


def _waypoint_requests(pm: PrioriMap, canvas: Canvas) -> list[_Request]:
    out = []
    for n in pm.key_waypoints:
        here = pm.node_xy(n.id)
        away = np.zeros(2)
        for s in pm.segments_at(n.id):
            other = pm.node_xy(s.b if s.a == n.id else s.a)
            away -= (other - here) / max(np.linalg.norm(other - here), 1e-9)
        if np.linalg.norm(away) < 0.1:  # straight through: beside the corridor
            away = np.array([-away[1], away[0]]) if np.any(away) else np.array([0.0, 1.0])
        anchor = canvas.to_px(here)[0]
        colour = KIND_COLOUR[n.kind]
        out.append(
            _Request(n.id, "waypoint", anchor, _canvas_angle(away), MARKER_R + 3, colour=colour)
        )
    return out


def _room_requests(pm: PrioriMap, canvas: Canvas) -> list[_Request]:
    frames = sorted(door_frames(pm.building), key=lambda f: natural_key(f.room))
    return [
        _Request(f.room, "room", canvas.to_px(f.door)[0], _canvas_angle(f.out), 5) for f in frames
    ]


def _landmark_requests(pm: PrioriMap, canvas: Canvas) -> list[_Request]:
    return [
        _Request(lm.id, "landmark", canvas.to_px(lm.pos)[0], _away(pm, lm.pos), MARKER_R + 2)
        for lm in pm.building.landmarks
    ]


def _away(pm: PrioriMap, xy) -> float:
    """The canvas direction from a point beside a corridor away from its centre line."""
    p = np.asarray(xy, dtype=float)
    where = pm.locate(*p)
    off = p - where.point(pm)
    if np.linalg.norm(off) < 0.2:
        off = np.array([-math.sin(where.segment.heading), math.cos(where.segment.heading)])
    return _canvas_angle(off)


def _segment_requests(pm: PrioriMap, canvas: Canvas) -> list[_Request]:
    out = []
    for s in pm.segments:
        a, b = canvas.to_px([pm.nodes[s.a].pos, pm.nodes[s.b].pos])
        length = float(np.linalg.norm(b - a))
        along = (b - a) / max(length, 1e-9)
        normal = math.atan2(along[0], -along[1])
        mid = (a + b) / 2.0
        out.append(_Request(s.short, "segment", mid, normal, 4, along, length / 2.0 - 6.0))
    return out


def _canvas_angle(world_dir) -> float:
    """Angle in canvas pixels (v down) of a map-frame direction."""
    return math.atan2(-float(world_dir[1]), float(world_dir[0]))


def _text_size(text: str, kind: str) -> tuple[int, int, int]:
    scale, thick, _ = STYLE[kind]
    (w, h), base = cv2.getTextSize(text, FONT, scale, thick)
    return w + 2 * LABEL_PAD, h + base + 2 * LABEL_PAD, base


def _candidates(req: _Request) -> np.ndarray:
    """Candidate boxes (C, 4), best first: along the segment (segment labels), then rings
    around the anchor, nearest the preferred direction first."""
    w, h, _ = _text_size(req.text, req.kind)
    hw, hh = w / 2.0, h / 2.0
    centres = []
    if req.slide is not None:  # on the segment itself, sliding away from the midpoint
        steps = np.arange(0.0, max(req.slide_max - hw, 0.0) + 1e-9, 6.0)
        for t in np.concatenate([[0.0], np.ravel(np.column_stack([steps[1:], -steps[1:]]))]):
            centres.append(req.anchor + t * req.slide)
    angles = sorted(
        (k * math.pi / 8.0 for k in range(16)),
        key=lambda a: abs(math.remainder(a - req.prefer, 2.0 * math.pi)),
    )
    rings = 8 if req.kind == "segment" else 40
    for ring in range(rings):
        r = req.gap + 8.0 * ring
        for a in angles:
            d = np.array([math.cos(a), math.sin(a)])
            reach = min(hw / max(abs(d[0]), 1e-9), hh / max(abs(d[1]), 1e-9))
            centres.append(req.anchor + d * (r + reach))
    c = np.array(centres)
    return np.column_stack([c[:, 0] - hw, c[:, 1] - hh, c[:, 0] + hw, c[:, 1] + hh])


def _place(
    req: _Request, occupied: np.ndarray, area, ink: np.ndarray
) -> tuple[int, int, int, int] | None:
    """The best candidate box inside ``area`` that overlaps nothing, crossing ink only when
    that saves INK_PENALTY candidates; for a must-place tag with no free candidate, the
    first one inside the area."""
    boxes = np.rint(_candidates(req)).astype(int)
    inside = (
        (boxes[:, 0] >= area[0])
        & (boxes[:, 1] >= area[1])
        & (boxes[:, 2] <= area[2])
        & (boxes[:, 3] <= area[3])
    )
    hit = (
        (boxes[:, None, 0] <= occupied[None, :, 2])
        & (occupied[None, :, 0] <= boxes[:, None, 2])
        & (boxes[:, None, 1] <= occupied[None, :, 3])
        & (occupied[None, :, 1] <= boxes[:, None, 3])
    ).any(axis=1)
    ok = inside & ~hit
    if ok.any():
        cost = np.arange(len(boxes)) + INK_PENALTY * (_ink_in(ink, boxes) > 0)
        return tuple(int(v) for v in boxes[np.argmin(np.where(ok, cost, np.inf))])
    if req.kind == "segment":
        return None
    log.warning(
        "annotated map: no free place for %s %r; it overlaps another tag", req.kind, req.text
    )
    fallback = np.flatnonzero(inside)
    return tuple(int(v) for v in boxes[fallback[0] if len(fallback) else 0])


def _ink_in(ink: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """Dark pixels inside each box, from the integral image of the ink mask."""
    h, w = ink.shape[0] - 1, ink.shape[1] - 1
    x0, x1 = np.clip(boxes[:, 0], 0, w), np.clip(boxes[:, 2], 0, w)
    y0, y1 = np.clip(boxes[:, 1], 0, h), np.clip(boxes[:, 3], 0, h)
    return ink[y1, x1] - ink[y0, x1] - ink[y1, x0] + ink[y0, x0]


def _marker_boxes(pm: PrioriMap, canvas: Canvas) -> np.ndarray:
    """Boxes that tags must not cover: waypoint and landmark markers, node dots, doors."""
    boxes = []
    for n in pm.nodes.values():
        u, v = canvas.to_px(n.pos)[0]
        r = MARKER_R + 1 if n.is_key else 4
        boxes.append((u - r, v - r, u + r, v + r))
    for lm in pm.building.landmarks:
        u, v = canvas.to_px(lm.pos)[0]
        boxes.append((u - MARKER_R, v - MARKER_R, u + MARKER_R, v + MARKER_R))
    for f in door_frames(pm.building):
        ends = canvas.to_px(_door_mark(f))
        lo, hi = ends.min(axis=0) - 2, ends.max(axis=0) + 2
        boxes.append((lo[0], lo[1], hi[0], hi[1]))
    return np.array(boxes, dtype=float).reshape(-1, 4)


def _box_distance(box, p) -> float:
    dx = max(box[0] - p[0], 0.0, p[0] - box[2])
    dy = max(box[1] - p[1], 0.0, p[1] - box[3])
    return math.hypot(dx, dy)


# -- drawing ---------------------------------------------------------------------------


def render_annotated_map(
    pm: PrioriMap,
    path: str | Path | None = None,
    *,
    scale_px_per_m: float | None = None,
    path_xy: list[tuple[float, float]] | None = None,
    floor_plan: FloorPlanImage | None = None,
    base_dir: str | Path = ".",
    grid_m: float | None = None,
    marks: Sequence[tuple[tuple[float, float], str]] = (),
) -> np.ndarray:
    """Draw the annotated priori-map (BGR) and write it to ``path`` (PNG) when given.

    ``floor_plan`` overrides the building's own plan, whose files are looked up
    relative to ``base_dir``; over a plan, the corridors are drawn translucent at their
    annotated widths with the doors marked on the annotated walls, so a mismatch with
    the plan shows. ``path_xy`` (map points) is drawn as a blue polyline; ``grid_m``
    adds a metre grid with lines that many metres apart; ``marks`` (a map point and a
    text) are tags of their own in a strong colour, placed with the others (a level's
    lift lobbies with the levels they go to).
    """
    canvas, floor_plan, img = _blank_page(pm, scale_px_per_m, floor_plan, base_dir)
    if floor_plan is not None:
        _draw_plan_background(img, floor_plan, canvas)
        _draw_annotation_over_plan(img, pm, canvas)
    else:
        _draw_building(img, pm, canvas)
    if grid_m:
        _draw_metre_grid(img, canvas, grid_m)
    layout = layout_labels(pm, canvas, img, marks)
    _draw_centre_lines(img, pm, canvas)
    if path_xy:
        pts = np.rint(canvas.to_px(path_xy)).astype(np.int32)
        cv2.polylines(img, [pts], False, PATH_COLOUR, 3, cv2.LINE_AA)
    _draw_markers(img, pm, canvas)
    _draw_labels(img, layout)
    _draw_header(img, pm, canvas)
    _draw_footer(img, canvas, layout, bool(path_xy), True)
    if path is not None and not cv2.imwrite(str(path), img):
        raise PmNavError(f"{path}: cannot write the PNG; check that the folder exists")
    return img


def _blank_page(
    pm: PrioriMap,
    scale_px_per_m: float | None,
    floor_plan: FloorPlanImage | None,
    base_dir: str | Path,
) -> tuple[Canvas, FloorPlanImage | None, np.ndarray]:
    """The building's canvas, its floor plan (loaded from the building when not given;
    None when it has none) and a white BGR image the canvas's size."""
    canvas = make_canvas(pm, scale_px_per_m)
    if floor_plan is None:
        floor_plan = load_floor_plan(pm.building, base_dir)
    return canvas, floor_plan, np.full((canvas.height, canvas.width, 3), 255, dtype=np.uint8)


def render_environment_map(
    pm: PrioriMap,
    *,
    scale_px_per_m: float | None = None,
    floor_plan: FloorPlanImage | None = None,
    base_dir: str | Path = ".",
) -> np.ndarray:
    """The raw environmental map (BGR), as the paper's O-EM/H-EM baselines see it: the floor
    plan (or the clean drawing) with only what a printed plan shows, room numbers at their
    rooms, a north arrow and a scale bar; no waypoints, segments or landmark tags."""
    canvas, floor_plan, img = _blank_page(pm, scale_px_per_m, floor_plan, base_dir)
    if floor_plan is not None:
        _draw_plan_background(img, floor_plan, canvas)
    else:
        _draw_building(img, pm, canvas)
    for f, w in _room_widths(pm):
        centre = canvas.to_px([_room_box(f, w).mean(axis=0)])[0]
        (tw, th), _ = cv2.getTextSize(f.room, FONT, 0.45, 1)
        org = (int(centre[0] - tw / 2), int(centre[1] + th / 2))
        put_text(img, f.room, org, 0.45, (20, 20, 20))
    top = canvas.map_top + canvas.map_height
    img[top:] = 255
    _draw_north_arrow(img, (28, top + 56))
    _draw_scale_bar(img, canvas, (60, top + 50))
    put_text(img, f"Floor plan: {pm.building.name}", (10, 30), TITLE_SCALE, (30, 30, 30), 2)
    return img


def _draw_plan_background(img: np.ndarray, plan: FloorPlanImage, canvas: Canvas) -> None:
    """Warp the plan image into the map area of the canvas."""
    to_canvas = np.vstack([canvas.affine(), [0.0, 0.0, 1.0]])
    to_plan = np.vstack([plan.affine(), [0.0, 0.0, 1.0]])
    canvas_to_plan = (to_plan @ np.linalg.inv(to_canvas))[:2]
    warped = cv2.warpAffine(
        plan.bgr(),
        canvas_to_plan,
        (canvas.width, canvas.height),
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
        borderValue=WHITE,
    )
    x0, y0, x1, y1 = canvas.map_box
    img[y0:y1, x0:x1] = warped[y0:y1, x0:x1]


def _draw_annotation_over_plan(img: np.ndarray, pm: PrioriMap, canvas: Canvas) -> None:
    """Corridors at their widths (translucent, outlined) and door marks over a floor plan."""
    tint = img.copy()
    quads = [_poly(canvas, q) for q in corridor_quads(pm.building)]
    for q in quads:
        cv2.fillConvexPoly(tint, q, CORRIDOR_TINT, cv2.LINE_AA)
    cv2.addWeighted(tint, 0.35, img, 0.65, 0.0, dst=img)
    for q in quads:
        cv2.polylines(img, [q], True, CORRIDOR_EDGE, 1, cv2.LINE_AA)
    for f in door_frames(pm.building):
        a, b = _door_mark(f)
        cv2.line(img, canvas.ipx(a), canvas.ipx(b), DOOR, 5, cv2.LINE_AA)


def _draw_metre_grid(img: np.ndarray, canvas: Canvas, step: float) -> None:
    """Light lines every ``step`` metres over the map area, darker every fifth."""
    if not (math.isfinite(step) and step > 0):
        raise PmNavError(f"grid spacing must be a positive number of metres, got {step}")
    w0, w1 = _corners(canvas)
    for axis in (0, 1):
        lo, hi = sorted((w0[axis], w1[axis]))
        for k in range(math.ceil(lo / step), math.floor(hi / step) + 1):
            v = k * step
            pts = [[v, w0[1]], [v, w1[1]]] if axis == 0 else [[w0[0], v], [w1[0], v]]
            a, b = (canvas.ipx(p) for p in pts)
            major = abs(v / step) % 5 == 0
            cv2.line(img, a, b, GRID_MAJOR if major else GRID_MINOR, 1)


def _corners(canvas: Canvas) -> tuple[np.ndarray, np.ndarray]:
    """Map coordinates of the map area's bottom-left and top-right pixels."""
    x0, y0, x1, y1 = canvas.map_box
    inv = np.linalg.inv(np.vstack([canvas.affine(), [0.0, 0.0, 1.0]]))[:2]
    pts = np.array([[x0, y1, 1.0], [x1, y0, 1.0]]) @ inv.T
    return pts[0], pts[1]


def _draw_building(img: np.ndarray, pm: PrioriMap, canvas: Canvas) -> None:
    """Room boxes, walls, corridor floor and doors."""
    for f, w in _room_widths(pm):
        poly = _poly(canvas, _room_box(f, w))
        cv2.fillConvexPoly(img, poly, ROOM_FILL, cv2.LINE_AA)
        cv2.polylines(img, [poly], True, ROOM_EDGE, 1, cv2.LINE_AA)
    wall_m = 3.0 / canvas.scale
    for q in corridor_quads(pm.building, wall_m):
        cv2.fillConvexPoly(img, _poly(canvas, q), WALL, cv2.LINE_AA)
    for q in corridor_quads(pm.building):
        cv2.fillConvexPoly(img, _poly(canvas, q), CORRIDOR_FILL, cv2.LINE_AA)
    for f in door_frames(pm.building):
        a, b = _door_mark(f)
        cv2.line(img, canvas.ipx(a), canvas.ipx(b), DOOR, 5, cv2.LINE_AA)


def _door_mark(f: DoorFrame) -> np.ndarray:
    """The door's two jambs on the wall line (2, 2), map frame."""
    foot, u, n = (np.asarray(v) for v in (f.foot, f.along, f.out))
    mid = foot + n * f.wall
    h = DOOR_WIDTH_M / 2.0
    return np.array([mid - u * h, mid + u * h])


def _poly(canvas: Canvas, pts) -> np.ndarray:
    return np.rint(canvas.to_px(pts)).astype(np.int32)


def _draw_centre_lines(img: np.ndarray, pm: PrioriMap, canvas: Canvas) -> None:
    """Thin centre lines and a dot at each room/landmark node (where segments meet)."""
    for s in pm.segments:
        a, b = canvas.ipx(pm.nodes[s.a].pos), canvas.ipx(pm.nodes[s.b].pos)
        cv2.line(img, a, b, CENTRE_LINE, 1, cv2.LINE_AA)
    for n in pm.nodes.values():
        if not n.is_key:
            cv2.circle(img, canvas.ipx(n.pos), 3, (120, 120, 120), -1, cv2.LINE_AA)


def _draw_markers(img: np.ndarray, pm: PrioriMap, canvas: Canvas) -> None:
    for lm in pm.building.landmarks:
        draw_marker(img, "landmark", canvas.ipx(lm.pos))
    for n in pm.key_waypoints:
        draw_marker(img, n.kind, canvas.ipx(n.pos))


def draw_marker(img: np.ndarray, kind: str, centre: tuple[int, int], r: int = MARKER_R) -> None:
    """A marker of a distinct shape per kind: start circle, turn square, branch diamond,
    end triangle, landmark star."""
    colour = KIND_COLOUR[kind]
    u, v = centre
    shapes = {
        "turn": [(-1, -1), (1, -1), (1, 1), (-1, 1)],
        "branch": [(0, -1.3), (1.3, 0), (0, 1.3), (-1.3, 0)],
        "end": [(0, -1.2), (1.1, 0.9), (-1.1, 0.9)],
    }
    if kind == "start":
        cv2.circle(img, centre, r, colour, -1, cv2.LINE_AA)
        cv2.circle(img, centre, r, WHITE, 1, cv2.LINE_AA)
    elif kind == "landmark":
        cv2.drawMarker(img, centre, WHITE, cv2.MARKER_STAR, 2 * r + 2, 4, cv2.LINE_AA)
        cv2.drawMarker(img, centre, colour, cv2.MARKER_STAR, 2 * r, 2, cv2.LINE_AA)
    else:
        pts = np.array([(u + x * r, v + y * r) for x, y in shapes[kind]], dtype=np.int32)
        cv2.fillConvexPoly(img, pts, colour, cv2.LINE_AA)
        cv2.polylines(img, [pts], True, WHITE, 1, cv2.LINE_AA)


def _draw_labels(img: np.ndarray, layout: LabelLayout) -> None:
    for lb in layout.labels:
        if lb.leader:
            x0, y0, x1, y1 = lb.box
            u, v = lb.anchor
            near = (round(min(max(u, x0), x1)), round(min(max(v, y0), y1)))
            cv2.line(img, (round(u), round(v)), near, LEADER, 1, cv2.LINE_AA)
    for lb in layout.labels:
        x0, y0, x1, y1 = lb.box
        wash = img[y0:y1, x0:x1] * (1.0 - LABEL_WASH) + 255.0 * LABEL_WASH
        img[y0:y1, x0:x1] = wash.astype(np.uint8)
        scale, thick, _ = STYLE[lb.kind]
        _, _, base = _text_size(lb.text, lb.kind)
        org = (lb.box[0] + LABEL_PAD, lb.box[3] - LABEL_PAD - base)
        put_text(img, lb.text, org, scale, lb.colour, thick)


def put_text(img, text, org, scale, colour, thickness=1) -> None:
    """Anti-aliased text with a white halo."""
    cv2.putText(img, text, org, FONT, scale, WHITE, thickness + 3, cv2.LINE_AA)
    cv2.putText(img, text, org, FONT, scale, colour, thickness, cv2.LINE_AA)


def _title(pm: PrioriMap) -> str:
    return f"{pm.building.name} ({pm.building.kind}): annotated priori-map"


def _draw_header(img: np.ndarray, pm: PrioriMap, canvas: Canvas) -> None:
    img[: canvas.map_top] = 255
    put_text(img, _title(pm), (12, 30), TITLE_SCALE, (20, 20, 20), 2)
    cv2.line(img, (0, canvas.map_top - 1), (canvas.width, canvas.map_top - 1), (200, 200, 200), 1)


# -- footer: north arrow, scale bar, legend ---------------------------------------------

LEGEND_X = 240  # px where the legend starts, right of the north arrow and scale bar
LEGEND_ITEM_GAP = 22


def _legend_entries(with_path: bool, with_doors: bool = True) -> list[tuple[str, str]]:
    """(icon, text) pairs; door marks are drawn only on the clean drawing."""
    entries = [
        ("start", "start"),
        ("turn", "turn"),
        ("branch", "branch (fork)"),
        ("end", "end"),
        ("landmark", "landmark"),
        ("door" if with_doors else "", "roomN: room ID at its door"),
        ("segment", "segN: corridor segment"),
    ]
    return entries + [("path", "planned path")] if with_path else entries


def _legend_rows(entries: list[tuple[str, str]], width: int) -> list[list[tuple[str, str, int]]]:
    """Flow the entries into rows that fit the width: (icon, text, x) per entry."""
    rows: list[list[tuple[str, str, int]]] = [[]]
    x = LEGEND_X
    for icon, text in entries:
        w = 26 + cv2.getTextSize(text, FONT, 0.5, 1)[0][0]
        if rows[-1] and x + w > width - 10:
            rows.append([])
            x = LEGEND_X
        rows[-1].append((icon, text, x))
        x += w + LEGEND_ITEM_GAP
    return rows


def _draw_footer(
    img: np.ndarray, canvas: Canvas, layout: LabelLayout, with_path: bool, with_doors: bool
) -> None:
    top = canvas.map_top + canvas.map_height
    img[top:] = 255
    cv2.line(img, (0, top), (canvas.width, top), (200, 200, 200), 1)
    _draw_north_arrow(img, (28, top + 56))
    _draw_scale_bar(img, canvas, (60, top + 50))
    entries = _legend_entries(with_path, with_doors)
    for k, row in enumerate(_legend_rows(entries, canvas.width)):
        y = top + 26 + 26 * k
        for icon, text, x in row:
            _draw_legend_icon(img, icon, (x + 9, y))
            put_text(img, text, (x + 24, y + 6), 0.5, (30, 30, 30))
    if layout.dropped:
        note = f"{len(layout.dropped)} segment labels left out (no free space)"
        put_text(img, note, (LEGEND_X, canvas.height - 8), 0.45, (0, 0, 160))


def _draw_legend_icon(img: np.ndarray, icon: str, c: tuple[int, int]) -> None:
    u, v = c
    if icon in KIND_COLOUR:
        draw_marker(img, icon, c, 7)
    elif icon == "door":
        cv2.line(img, (u - 9, v + 2), (u + 9, v + 2), WALL, 2, cv2.LINE_AA)
        cv2.line(img, (u - 5, v + 2), (u + 5, v + 2), DOOR, 5, cv2.LINE_AA)
    elif icon == "segment":
        cv2.line(img, (u - 9, v), (u + 9, v), CENTRE_LINE, 1, cv2.LINE_AA)
        for x in (u - 9, u + 9):
            cv2.circle(img, (x, v), 3, (120, 120, 120), -1, cv2.LINE_AA)
    elif icon == "path":
        cv2.line(img, (u - 9, v), (u + 9, v), PATH_COLOUR, 3, cv2.LINE_AA)


def _draw_north_arrow(img: np.ndarray, base: tuple[int, int]) -> None:
    """An arrow pointing to map north (+y, canvas up) with an N above it."""
    u, v = base
    cv2.arrowedLine(img, (u, v), (u, v - 34), (30, 30, 30), 3, cv2.LINE_AA, tipLength=0.35)
    put_text(img, "N", (u - 7, v - 38), 0.6, (30, 30, 30), 2)


def _draw_scale_bar(img: np.ndarray, canvas: Canvas, origin: tuple[int, int]) -> None:
    """A bar of a round length (1, 2, 5 x 10^k m), about 120 px long."""
    metres = nice_length(120.0 / canvas.scale)
    px = int(round(metres * canvas.scale))
    u, v = origin
    cv2.rectangle(img, (u, v - 4), (u + px, v + 2), (30, 30, 30), -1)
    cv2.rectangle(img, (u + px // 2, v - 3), (u + px - 1, v + 1), WHITE, -1)
    put_text(img, f"{metres:g} m", (u, v - 10), 0.5, (30, 30, 30))


def nice_length(target: float) -> float:
    """The length of the form 1, 2 or 5 x 10^k closest to ``target`` (on a log scale)."""
    k = math.floor(math.log10(target))
    options = [m * 10.0**e for e in (k, k + 1) for m in (1, 2, 5)]
    return min(options, key=lambda x: abs(math.log(x / target)))
