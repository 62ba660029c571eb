"""The map the web view draws over: the building's annotated priori-map as a PNG, the
affine transform from map metres to its pixels, and where each room's door and each
landmark is (the page marks the ones the robot has seen)."""

from __future__ import annotations

from dataclasses import dataclass

import cv2

from pmnav_bt.errors import PmNavError


@dataclass(frozen=True)
class MapView:
    """The map picture (PNG bytes) and its facts for the page (``info``, JSON-ready)."""

    png: bytes
    info: dict


def load_map_view(building: str) -> MapView:
    """The annotated map of ``building`` (a built-in name or a building file's path).

    PmNavError (one line) when the building cannot be read."""
    from pmnav_bt.map.catalogue import load_building, resolve_building_path
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.planning.resolve import entity_position
    from pmnav_bt.render.annotate import make_canvas, render_annotated_map
    from pmnav_bt.seams import Entity

    b = load_building(building)
    pm = parse_building(b)
    img = render_annotated_map(pm, base_dir=resolve_building_path(building).parent)
    ok, buf = cv2.imencode(".png", img)
    if not ok:  # pragma: no cover - a BGR image always encodes
        raise PmNavError(f"{building}: could not encode the map as PNG")
    canvas = make_canvas(pm)
    entities = [Entity.room(r.id) for r in b.rooms] + [Entity.landmark(x.id) for x in b.landmarks]
    names = {r.id: r.display_name for r in b.rooms} | {x.id: x.display_name for x in b.landmarks}
    info = {
        "building": b.name,
        "size": [int(img.shape[1]), int(img.shape[0])],
        "affine": [[round(float(v), 6) for v in row] for row in canvas.affine()],
        "entities": {
            str(e): {
                "name": names.get(e.id, e.id),
                "xy": [round(float(v), 3) for v in entity_position(pm, e)],
            }
            for e in entities
        },
    }
    return MapView(buf.tobytes(), info)
