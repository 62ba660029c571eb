"""How much of a building a draft found: its corridors against a person's hand annotation.

An annotation file (YAML) holds the corridor centre lines a person draws on a real map,
in map metres, and the open areas (halls) where any way across is right:

    map: examples/hospital/hospital.yaml     # the grid, relative to the project root
    corridors:
      - [[-6.0, 3.0], [-6.0, -34.5]]         # a polyline
    open_areas:
      - [[-13.8, 3.0], [11.6, 3.0], [11.6, 16.2], [-13.8, 16.2]]   # a polygon

Two numbers, both over length sampled every ``STEP_M``:

- **coverage**: the fraction of the annotated corridor length that has a drafted
  corridor centre line within ``tol_m`` (a robot following the draft drives there);
- **spurious**: the fraction of the drafted corridor length, outside the open areas,
  farther than ``tol_m`` from every annotated line (corridors into rooms, along
  laser fans, round furniture).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import LineString, MultiLineString, Point, Polygon

from pmnav_bt.loading import InputFileError, load_yaml
from pmnav_bt.map.building import Building
from pmnav_bt.map.floorplan import FloorPlanImage

TOL_M = 0.75  # a drafted centre line this close to the annotated one covers it
STEP_M = 0.1


@dataclass(frozen=True)
class Annotation:
    """A person's corridor centre lines and open areas on one map."""

    map: str
    corridors: list[LineString]
    open_areas: list[Polygon]

    @property
    def length_m(self) -> float:
        return float(sum(c.length for c in self.corridors))


def load_annotation(path: str | Path) -> Annotation:
    """Read an annotation file; a malformed one is an InputFileError naming its field."""
    data = load_yaml(path, "annotation")
    if not isinstance(data, dict) or not isinstance(data.get("corridors"), list):
        raise InputFileError(path, "expected a list of polylines", "corridors")
    try:
        lines = [LineString([tuple(map(float, p)) for p in c]) for c in data["corridors"]]
        areas = [Polygon([tuple(map(float, p)) for p in a]) for a in data.get("open_areas") or []]
    except (TypeError, ValueError) as err:
        raise InputFileError(path, f"expected [[x, y], ...] lists: {err}", "corridors") from err
    return Annotation(str(data.get("map", "")), lines, areas)


@dataclass(frozen=True)
class Coverage:
    """The draft against the annotation (fractions 0..1, lengths in metres)."""

    coverage: float
    spurious: float
    annotated_m: float
    drafted_m: float


def _samples(line: LineString) -> list[Point]:
    n = max(2, int(np.ceil(line.length / STEP_M)) + 1)
    return [line.interpolate(t, normalized=True) for t in np.linspace(0.0, 1.0, n)]


def drafted_lines(b: Building) -> MultiLineString:
    """The building's corridor centre lines."""
    pos = {w.id: w.pos for w in b.waypoints}
    return MultiLineString([[pos[e.a], pos[e.b]] for e in b.edges])


def measure(b: Building, ann: Annotation, tol_m: float = TOL_M) -> Coverage:
    """Coverage and spurious fraction of ``b``'s corridors against ``ann``."""
    drafted = drafted_lines(b)
    truth = MultiLineString(ann.corridors)
    halls = shapely.union_all(ann.open_areas) if ann.open_areas else None
    ann_pts = [p for c in ann.corridors for p in _samples(c)]
    covered = np.mean([drafted.distance(p) <= tol_m for p in ann_pts]) if ann_pts else 0.0
    out_pts = [
        p
        for e in drafted.geoms
        for p in _samples(e)
        if halls is None or not halls.contains(p)
    ]
    spurious = np.mean([truth.distance(p) > tol_m for p in out_pts]) if out_pts else 0.0
    return Coverage(float(covered), float(spurious), ann.length_m, float(drafted.length))


@dataclass(frozen=True)
class LineFit:
    """How well an annotated centre line sits in a grid's free space.

    ``outside``: the share of the line's length on cells the grid does not read free (a
    line through a wall or unknown space is no corridor). ``off_centre_m``: the median,
    over points every 0.5 m with a wall on both sides (a corridor open to a hall on one
    side has no middle there), of how far the point lies from the middle of the free run
    square to the line (half the difference of the free distances either side: a line
    drawn along one wall is off by half the corridor's width); junctions, doors and
    pillars put single points off, the median is the line's own. ``narrowest_m``: the
    narrowest free run square to the line, every ``STEP_M`` on free cells (a line drawn
    through a door is as narrow there as the door).
    """

    outside: float
    off_centre_m: float
    narrowest_m: float


def line_fit(plan: FloorPlanImage, line: LineString, reach_m: float = 3.0) -> LineFit:
    """``LineFit`` of an annotated line on ``plan``; free runs looked for up to ``reach_m``."""
    free = plan.occupancy() == 0
    res = plan.resolution

    def is_free(pts: np.ndarray) -> np.ndarray:
        c, r = np.moveaxis(plan.world_to_pixel(pts.reshape(-1, 2)).round().astype(int), 1, 0)
        ok = (r >= 0) & (r < free.shape[0]) & (c >= 0) & (c < free.shape[1])
        out = np.zeros(len(r), bool)
        out[ok] = free[r[ok], c[ok]]
        return out.reshape(pts.shape[:-1])

    def runs(ts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Points at ``ts`` along the line and the free distance either side of each."""
        pts = np.array([line.interpolate(t).coords[0] for t in ts])
        ahead = np.array([line.interpolate(t + 0.05).coords[0] for t in ts]) - pts
        u = ahead / np.linalg.norm(ahead, axis=1, keepdims=True)
        normal = np.stack([-u[:, 1], u[:, 0]], axis=1)
        steps = np.arange(1, round(reach_m / res) + 1) * res
        out = []
        for side in (1.0, -1.0):
            blocked = ~is_free(pts[:, None, :] + side * steps[None, :, None] * normal[:, None, :])
            out.append(np.where(blocked.any(axis=1), np.argmax(blocked, axis=1), len(steps)) * res)
        return pts, out[0], out[1]

    def along(step: float) -> np.ndarray:
        ts = np.arange(0.5, line.length - 0.5, step)
        return ts if len(ts) else np.array([line.length / 2.0])

    _, left, right = runs(along(0.5))
    walled = (left < reach_m) & (right < reach_m)
    off = np.abs(left - right)[walled] / 2.0
    pts, left, right = runs(along(STEP_M))
    across = (left + right + res)[is_free(pts)]
    on = np.array([p.coords[0] for p in _samples(line)])
    return LineFit(
        float(1.0 - is_free(on).mean()),
        float(np.median(off)) if len(off) else 0.0,
        float(across.min()) if len(across) else 0.0,
    )
