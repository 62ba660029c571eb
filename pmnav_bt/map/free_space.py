"""The drivable floor of a building: the union of its corridor rectangles (no pybullet).

The simulator builds its walls around this polygon, and the evaluation measures shortest
paths inside it, so both see the same free space.
"""

from __future__ import annotations

import shapely
from shapely.geometry import LineString, MultiPolygon, Polygon
from shapely.geometry.polygon import orient

from pmnav_bt.map.building import Building


def free_space_polygon(building: Building) -> Polygon | MultiPolygon:
    """Union of the corridor rectangles (square ends), oriented (exterior CCW), simplified.

    Each corridor is its centre line buffered by half its width with square ends, so dead
    ends close half a width beyond the end waypoint and corners are square.
    """
    pos = {w.id: w.pos for w in building.waypoints}
    parts = [
        LineString([pos[e.a], pos[e.b]]).buffer(
            building.edge_width(e) / 2.0, cap_style="square", join_style="mitre"
        )
        for e in building.edges
    ]
    geom = shapely.union_all(parts).simplify(1e-4)
    if isinstance(geom, MultiPolygon):
        return MultiPolygon([orient(g, 1.0) for g in geom.geoms])
    return orient(geom, 1.0)


def free_space_rings(geom: Polygon | MultiPolygon) -> list[list[tuple[float, float]]]:
    """The boundary of the free space as closed rings of points (the last point not
    repeated): each part's exterior (counter-clockwise) and its holes (clockwise), so the
    free space is on the left going round every ring."""
    polys = geom.geoms if isinstance(geom, MultiPolygon) else [geom]
    rings = []
    for poly in polys:
        rings.append([(float(x), float(y)) for x, y in poly.exterior.coords[:-1]])
        rings.extend([(float(x), float(y)) for x, y in r.coords[:-1]] for r in poly.interiors)
    return rings
