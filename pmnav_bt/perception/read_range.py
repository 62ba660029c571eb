"""How far a grounder names signs: the one source of the tree's search distances.

Each grounder declares its reading model in its registry spec (``GrounderSpec.reading``):
``PP_OCR`` here for the readers that read signs with PP-OCR (``ocr``, ``gdino_sam``), or
``ORACLE_READING`` (``sim_gt``: every sign in sight to its ``grounder.max_range``); a
grounder that declares none has no search ranges (an error, never PP-OCR's by default).

The PP-OCR reader's recall per distance band is measured by ``benchmarks/bench_signs.py``
(docs/perception.md) at two camera sizes. A sign counts as readable up to the far end of
the last band where the reader names at least ``RELIABLE_RECALL`` of the signs. Other
widths are interpolated between the measured ones (below the smallest, in proportion to
the width: a sign's text is that many pixels smaller; above the largest, no farther, as
the reader's crops are upscaled anyway). The width is the one signs are read at: the
camera's wider reading view where it offers one (``sim.reading_width``, on a robot the
camera's own width), else the frame's. Plates with a name read nearer than bare numbers:
each ``plate_kind`` has its own measured table where it differs.

From the read range follow (``search_settings``, ``SearchRanges`` per plate kind): how
close the tree goes to a target before searching for its sign (``tree.search_range``),
how far it moves on before searching again (``tree.research_distance``), and the range
the localization belief expects signs (all kinds) to be read from (``pose.visibility``),
and how likely each sign is read from a given distance (``sign_recall``: a sign not read
is evidence only where the reader would have read it).
Values set in the config win.
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from pmnav_bt.errors import ConfigError
from pmnav_bt.geometry import side_of
from pmnav_bt.seams import EntityKind

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import Config
    from pmnav_bt.map.building import Building
    from pmnav_bt.seams import Entity

# benchmarks/bench_signs.py --views 200 (2026-11, 8 built-in buildings, 0-70 deg off the
# plate): (band start m, band end m, recall) per camera width.
OCR_RECALL: dict[int, tuple[tuple[float, float, float], ...]] = {
    320: ((1.5, 2.5, 0.939), (2.5, 3.5, 0.490), (3.5, 4.5, 0.033), (4.5, 6.0, 0.045)),
    640: ((1.5, 2.5, 0.949), (2.5, 3.5, 0.837), (3.5, 4.5, 0.300), (4.5, 6.0, 0.136)),
}
# benchmarks/sign_ranges.py: reads per distance band of plates by capital height, font and
# camera width (the realistic preset's signage), for ``plate_read_range``.
SIGN_RANGES_FILE = Path(__file__).parent.parent / "data" / "sign_ranges.json"
# Plate kinds by the sign text (as the priori-map knows it; sim/textures.py lays plates out
# so: a leading room number on its own line, the name's words wrapped at LINE_CHARS).
PLATE_KINDS = ("number", "name", "long name")
LINE_CHARS = 14
LONG_LINE_CHARS = 10
# bench_signs.py --views 120 --kind name / --kind "long name" (2026-11): plates with a name
# are read from nearer than bare numbers (number plates: 100 / 100 / 45 / 20 % at 640 px,
# as all plates or better, so they keep the table above).
OCR_RECALL_BY_KIND: dict[str, dict[int, tuple[tuple[float, float, float], ...]]] = {
    "name": {
        320: ((1.5, 2.5, 0.900), (2.5, 3.5, 0.269), (3.5, 4.5, 0.0), (4.5, 6.0, 0.0)),
        640: ((1.5, 2.5, 0.967), (2.5, 3.5, 0.423), (3.5, 4.5, 0.100), (4.5, 6.0, 0.143)),
    },
    "long name": {
        320: ((1.5, 2.5, 0.880), (2.5, 3.5, 0.205), (3.5, 4.5, 0.0), (4.5, 6.0, 0.0)),
        640: ((1.5, 2.5, 0.960), (2.5, 3.5, 0.744), (3.5, 4.5, 0.391), (4.5, 6.0, 0.0)),
    },
}
# bench_signs.py --views 320 --angles 0,88 --widths 640 (2026-11): recall falls off past
# 70 deg off the plate's normal whatever the distance (at 1.5-2.5 m: 85 % at 60-70 deg,
# 50 % at 70-75, none of 14 views beyond 75; at 2.5-3.5 m: 73 / 33 / 0 of 24): the share
# of the 0-70 deg tables' recall kept up to each angle (deg).
ANGLE_RECALL = ((70.0, 1.0), (75.0, 0.4), (90.0, 0.0))
RELIABLE_RECALL = 0.75  # the tree searches where signs are read this often
PLATE_RECALL = 0.8  # an active read goes where a plate of its size is read this often
POSSIBLE_RECALL = 0.1  # beyond where signs are read this often, a reading is unexpected
# The oracle's search settings (a sign read to 9 m): the tree's settings before the reader.
MAX_SEARCH_RANGE_M = 4.5
MAX_RESEARCH_DISTANCE_M = 2.0
# A door's sign hangs beside it and the robot drives the corridor's centre: search from
# this much nearer than the read range.
SEARCH_MARGIN_M = 0.5
# ... ``grounder.sign_to_door`` from it, on the side ``grounder.door_side`` says: search
# from where that sign is seen within this angle of its plate's normal (ANGLE_RECALL keeps
# the full recall to 70 deg; the margin is for a robot off the centre line), no nearer
# than MIN_ABREAST_M before level with the door.
MAX_SEARCH_ANGLE_DEG = 65.0
MIN_ABREAST_M = 0.5


def plate_kind(text: str) -> str:
    """ "number": a bare number or word (one line); "name": a number and a name whose lines
    hold at most ``LONG_LINE_CHARS`` characters; "long name": one with a longer line."""
    words = text.split()
    if len(words) <= 1:
        return "number" if len(text.strip()) <= LONG_LINE_CHARS else "long name"
    if words[0][:1].isdigit():
        words = words[1:]
    longest, line = 0, ""
    for w in words:
        line = w if not line or len(line) + 1 + len(w) > LINE_CHARS else f"{line} {w}"
        longest = max(longest, len(line))
    return "long name" if longest > LONG_LINE_CHARS else "name"


def measured_range(width: int, recall: float = RELIABLE_RECALL, kind: str | None = None) -> float:
    """The far end of the last band with at least ``recall``, at a measured width, for
    plates of ``kind`` (None: all plates)."""
    bands = OCR_RECALL_BY_KIND.get(kind or "", OCR_RECALL)[width]
    far = bands[0][0]
    for _, end, r in bands:
        if r < recall:
            break
        far = end
    return far


def ocr_read_range(width: int, recall: float = RELIABLE_RECALL, kind: str | None = None) -> float:
    """How far (m) the OCR reader names at least ``recall`` of the signs (of plate
    ``kind``, None: all) with a camera ``width`` pixels wide."""
    widths = sorted(OCR_RECALL)
    if width <= widths[0]:
        return measured_range(widths[0], recall, kind) * width / widths[0]
    for lo, hi in zip(widths, widths[1:], strict=False):
        if width <= hi:
            a, b = measured_range(lo, recall, kind), measured_range(hi, recall, kind)
            return a + (b - a) * (width - lo) / (hi - lo)
    return measured_range(widths[-1], recall, kind)


def measured_recall(width: int, distance: float, kind: str | None = None) -> float:
    """The share of plates (of ``kind``, None: all) read from ``distance`` m at a measured
    ``width``: its band's recall; nearer than the first band, the first band's; beyond
    the last, none."""
    bands = OCR_RECALL_BY_KIND.get(kind or "", OCR_RECALL)[width]
    if distance < bands[0][0]:
        return bands[0][2]
    for _, end, r in bands:
        if distance <= end:
            return r
    return 0.0


def ocr_recall(width: int, distance: float, kind: str | None = None) -> float:
    """The share of plates (of ``kind``) the OCR reader names from ``distance`` m with a
    camera ``width`` pixels wide: between measured widths interpolated; below the
    smallest, at the distance scaled up (the text is that many pixels smaller); above the
    largest, as the largest (crops are upscaled anyway)."""
    widths = sorted(OCR_RECALL)
    if width <= widths[0]:
        return measured_recall(widths[0], distance * widths[0] / width, kind)
    for lo, hi in zip(widths, widths[1:], strict=False):
        if width <= hi:
            a, b = measured_recall(lo, distance, kind), measured_recall(hi, distance, kind)
            return a + (b - a) * (width - lo) / (hi - lo)
    return measured_recall(widths[-1], distance, kind)


def angle_share(angle: float) -> float:
    """The share of the tables' recall kept ``angle`` rad off the plate's normal."""
    deg = abs(math.degrees(angle))
    return next((share for upto, share in ANGLE_RECALL if deg <= upto), 0.0)


@dataclass(frozen=True)
class PlateRanges:
    """Recall by distance of plates by text size, from ``benchmarks/sign_ranges.py``
    (``SIGN_RANGES_FILE``): per camera width, rows of (text-line height the reader
    measures, m; recall per band of ``bands``), one row per capital height, pooled over
    the fonts. The row is keyed by the line height the candidate finder measures (the
    capitals and a pixel or two of edge: about 1.2 times the capitals), since that is
    what the robot knows of a plate it has not read."""

    bands: tuple[tuple[float, float], ...]
    rows: dict[int, tuple[tuple[float, tuple[float, ...]], ...]]

    @classmethod
    def from_counts(cls, table: dict) -> PlateRanges:
        bands = tuple((float(a), float(b)) for a, b in table["bands_m"])
        cells: dict[tuple[int, float], list[dict]] = {}
        for c in table["cells"]:
            cells.setdefault((int(c["width"]), float(c["cap_height_m"])), []).append(c)
        rows: dict[int, list] = {}
        for (width, cap), mine in sorted(cells.items()):
            views = [sum(c["views"][i] for c in mine) for i in range(len(bands))]
            reads = [sum(c["reads"][i] for c in mine) for i in range(len(bands))]
            lines = [c["line_height_m"] for c in mine if c.get("line_height_m")]
            line = sorted(lines)[len(lines) // 2] if lines else cap
            recall = tuple(r / v if v else 0.0 for r, v in zip(reads, views, strict=True))
            rows.setdefault(width, []).append((line, recall))
        return cls(bands, {w: tuple(sorted(r)) for w, r in rows.items()})

    def measured_range(self, width: int, row: int, recall: float) -> float:
        """The far end of the last band, counted from the nearest, with at least
        ``recall`` for ``row`` at a measured ``width``; the nearest band's start if none
        (nearer than that the benchmark did not look: the reading pose's least standoff
        is nearer still)."""
        far = self.bands[0][0]
        for (_, end), r in zip(self.bands, self.rows[width][row][1], strict=True):
            if r < recall:
                break
            far = end
        return far

    def at_width(self, width: int, line_height: float, recall: float) -> float:
        """How far a plate with text lines ``line_height`` m high is read at a measured
        ``width``: between rows interpolated; beyond them in proportion to the height
        (text that many pixels larger or smaller), no farther than the last band; never
        less far for larger text."""
        rows = self.rows[width]
        # larger text is read at least as far as smaller (a row's few views are noisy)
        measured = [self.measured_range(width, i, recall) for i in range(len(rows))]
        ranges = [float(r) for r in np.maximum.accumulate(measured)]
        heights = [h for h, _ in rows]
        if line_height <= heights[0]:
            return ranges[0] * line_height / heights[0]
        if line_height >= heights[-1]:
            return min(self.bands[-1][1], ranges[-1] * line_height / heights[-1])
        return float(np.interp(line_height, heights, ranges))

    def read_range(self, width: int, line_height: float, recall: float = PLATE_RECALL) -> float:
        """How far (m) a plate with text lines ``line_height`` m high is read at least
        ``recall`` of the time with a camera ``width`` pixels wide: other widths as
        ``ocr_read_range`` treats them."""
        widths = sorted(self.rows)
        if width <= widths[0]:
            return self.at_width(widths[0], line_height * width / widths[0], recall)
        for lo, hi in zip(widths, widths[1:], strict=False):
            if width <= hi:
                a = self.at_width(lo, line_height, recall)
                b = self.at_width(hi, line_height, recall)
                return a + (b - a) * (width - lo) / (hi - lo)
        return self.at_width(widths[-1], line_height, recall)


@functools.lru_cache(maxsize=2)
def shipped_plate_ranges(path: Path = SIGN_RANGES_FILE) -> PlateRanges:
    """The shipped table (``benchmarks/sign_ranges.py``), read once."""
    try:
        return PlateRanges.from_counts(json.loads(path.read_text()))
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise ConfigError(
            f"{path}: the sign reading ranges table is missing or damaged ({e}); "
            "regenerate it with python benchmarks/sign_ranges.py"
        ) from e


def ocr_plate_range(width: int, line_height: float, recall: float = PLATE_RECALL) -> float:
    """How far (m) the OCR reader reads a plate with text lines ``line_height`` m high at
    least ``recall`` of the time, with a camera ``width`` pixels wide (the shipped table)."""
    return shipped_plate_ranges().read_range(width, line_height, recall)


@dataclass(frozen=True)
class ReadingModel:
    """How far and how often a reader names signs (its *reading model*), as a grounder
    declares it (``registry.GrounderSpec.reading``): ``read_range(width, recall, kind)``,
    the far end (m) of where it names at least ``recall`` of the plates of ``kind`` (None:
    all) with a camera ``width`` pixels wide; ``recall(width, distance, kind)``, the share
    it names from ``distance`` m; ``angle_share(angle)``, the share of that kept ``angle``
    rad off the plate's normal; ``plate_range(width, line_height, recall)``, how far a
    plate of any style whose text lines are ``line_height`` m high is read at least
    ``recall`` of the time (where an active read goes to read a plate it saw). A grounder
    whose reading model is ``ORACLE_READING`` has none of these: it reads every sign in
    sight up to ``grounder.max_range``."""

    read_range: Callable[[int, float, str | None], float]
    recall: Callable[[int, float, str | None], float]
    angle_share: Callable[[float], float]
    plate_range: Callable[[int, float, float], float]


# bench_signs.py's tables (the first plates), sign_ranges.py's table (plates by text size)
PP_OCR = ReadingModel(ocr_read_range, ocr_recall, angle_share, ocr_plate_range)


def reading_model(config: Config) -> ReadingModel | None:
    """The configured grounder's declared reading model (``GrounderSpec.reading``); None
    for ``ORACLE_READING`` (every sign in sight to ``grounder.max_range``). ConfigError
    for a grounder that declares none: its ranges are unknown, not PP-OCR's."""
    from pmnav_bt.registry import GROUNDERS, ORACLE_READING, load

    spec = GROUNDERS.spec(config.grounder.backend)
    if spec.reading is None:
        raise ConfigError(
            f"grounder.backend {spec.name!r} declares no reading model (how far and how often "
            "it names signs: GrounderSpec.reading), which the tree's search ranges and the "
            "localization belief need"
        )
    return None if spec.reading == ORACLE_READING else load(spec.reading)


def reading_width(config: Config) -> int:
    """The width (pixels) signs are read at: ``sim.reading_width`` where the camera offers
    that wider view (``Observation.reading``), else the frame's ``sim.width``."""
    return max(config.sim.width, config.sim.reading_width)


def sign_read_range(config: Config, width: int | None = None, kind: str | None = None) -> float:
    """How far the configured grounder reliably names signs (m) of plate ``kind`` (None:
    all); ``width``: the reading camera's, if not ``reading_width(config)``."""
    model = reading_model(config)
    if model is None:
        return config.grounder.max_range
    return model.read_range(width or reading_width(config), RELIABLE_RECALL, kind)


def plate_read_range(config: Config, line_height: float, width: int | None = None) -> float | None:
    """How far (m) the configured grounder reads a plate whose text lines are
    ``line_height`` m high at least ``PLATE_RECALL`` of the time (the reading camera's
    ``width``, if not ``reading_width(config)``). None for the oracle: it reads every
    sign in sight."""
    model = reading_model(config)
    if model is None:
        return None
    return model.plate_range(width or reading_width(config), line_height, PLATE_RECALL)


def sign_visible_range(config: Config, width: int | None = None) -> float | None:
    """How far the localization belief expects signs to be read at all (m): a sign
    nearer and in sight but not read is a miss, one read from farther is unexpected.
    None for the oracle: the belief's own ``READ_RANGE_M``, checked against it."""
    model = reading_model(config)
    if model is None:
        return None
    return model.read_range(width or reading_width(config), POSSIBLE_RECALL, None)


def sign_lead_range(config: Config, width: int | None = None) -> float | None:
    """How far the localization belief counts on signs being read (m): where it drives to
    read them, and where a panorama may have missed one. None for the oracle: the
    belief's own ``READ_RANGE_M``."""
    if reading_model(config) is None:
        return None
    return sign_read_range(config, width)


def sign_recall(config: Config, building: Building, width: int | None = None):
    """``recall(entity, distance, angle)``: how likely the configured grounder names
    ``entity``'s sign (by its plate kind) from ``distance`` m and ``angle`` rad off the
    plate's normal, for the localization belief's misses (a sign 4 m off that OCR reads one
    time in three, or one seen along its wall, is no evidence when not read). None for the
    oracle: its misses are the belief's constant ``P_MISS``."""
    model = reading_model(config)
    if model is None:
        return None
    w = width or reading_width(config)
    kinds: dict = {}

    def recall(entity: Entity, distance: float, angle: float = 0.0) -> float:
        kind = kinds.get(entity)
        if kind is None:
            kind = kinds[entity] = entity_plate_kind(building, entity)
        return model.recall(w, distance, kind) * model.angle_share(angle)

    return recall


@dataclass(frozen=True)
class SearchSettings:
    """The tree's search distances (m): search within ``search_range`` of the target (by
    the map), move ``research_distance`` on before searching again."""

    search_range: float
    research_distance: float
    read_range: float


def search_settings(
    config: Config, width: int | None = None, kind: str | None = None
) -> SearchSettings:
    """``tree.search_range`` and ``tree.research_distance`` as set, else from the read range
    of plate ``kind`` (None: all plates): ``read_range - SEARCH_MARGIN_M`` (at most the
    oracle's 4.5 m) and half of that (at most 2 m)."""
    read = sign_read_range(config, width, kind)
    t = config.tree
    search = t.search_range
    if search is None:
        search = min(MAX_SEARCH_RANGE_M, max(1.0, read - SEARCH_MARGIN_M))
    research = t.research_distance
    if research is None:
        research = min(MAX_RESEARCH_DISTANCE_M, search / 2.0)
    return SearchSettings(search, research, read)


def entity_plate_kind(building: Building, entity: Entity) -> str:
    """The plate kind of the sign that names ``entity`` (by the priori-map's sign text)."""
    from pmnav_bt.planning.resolve import sign_text

    return plate_kind(sign_text(building, entity))


def landmark_ranges(config: Config) -> dict[str, float] | None:
    """How far (m) the configured grounder reliably names each plate kind: the range
    within which a landmark counts as readable, e.g. for Table 3's start classes. None for
    the oracle: the priori-map's own ``visibility.READ_RANGE_M`` for every plate."""
    if reading_model(config) is None:
        return None
    return {k: sign_read_range(config, kind=k) for k in PLATE_KINDS}


def abreast_range(across: float, beside: float) -> float:
    """How far before level with a door (m, along the corridor's centre line) its sign is
    seen within ``MAX_SEARCH_ANGLE_DEG`` of the plate's normal, the wall ``across`` m off
    the centre line and the sign ``beside`` m further along it than the door (negative:
    nearer; at least ``MIN_ABREAST_M``). From farther, a sign on the far side of its door
    is seen along its wall, where the reader names none (``ANGLE_RECALL``)."""
    reach = across * math.tan(math.radians(MAX_SEARCH_ANGLE_DEG)) - beside
    return max(MIN_ABREAST_M, reach)


def sign_ahead(config: Config, heading: float, node, door) -> int:
    """+1 where the building's convention (``grounder.door_side``: the side of its sign a
    door is on, seen facing the wall) hangs the sign of ``door`` further along the way
    than the door for a robot passing it at ``node`` heading ``heading`` (rad), -1 where
    nearer: a door on the left of the way with its sign on the viewer's right is passed
    after its door."""
    left = side_of(heading, node, door) == "left"
    sign_right = config.grounder.door_side == "left"
    return 1 if left == sign_right else -1


class SearchRanges:
    """The tree's search distances per plate kind (``search_settings``), looked up by the
    entity a step looks for: how close to go to read that entity's sign. For a reader
    (not the oracle) and a search range not set in the config, a room's search range is
    also at most its sign's ``abreast_range`` (``search_range_to``)."""

    def __init__(self, config: Config, building: Building, width: int | None = None):
        self.building = building
        self.by_kind = {k: search_settings(config, width, k) for k in PLATE_KINDS}
        self.default = search_settings(config, width)
        angled = reading_model(config) is not None and config.tree.search_range is None
        self.beside = config.grounder.sign_to_door if angled else None
        self.config = config

    def of(self, entity: Entity | None) -> SearchSettings:
        if entity is None:
            return self.default
        return self.by_kind[entity_plate_kind(self.building, entity)]

    def search_range_to(self, entity: Entity | None, node, door, heading: float) -> float:
        """How close (m, to its ``node`` on the centre line) to go before searching for
        ``entity``'s sign, arriving ``heading`` (rad): its plate kind's search range, and for
        a room with a ``door`` (None: none on the map) at most the ``abreast_range`` of its
        sign, on the side of the door the building's convention hangs it (``sign_ahead``)."""
        search = self.of(entity).search_range
        room = entity is not None and entity.kind == EntityKind.ROOM
        if self.beside is None or door is None or not room:
            return search
        ahead = sign_ahead(self.config, heading, node, door)
        return min(search, abreast_range(math.dist(door, node), self.beside * ahead))
