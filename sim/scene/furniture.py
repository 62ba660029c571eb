"""What stands along a corridor wall, kind by kind: benches, chairs, carts, beds, plants
and notice boards, each a few coloured boxes, cylinders and spheres of real size.

Each kind's builder draws one item's variant, size and colours from a random stream
and returns its ``Shape``: the pieces in the item's frame (``pmnav_bt.sim.scene.bodies``:
x along the wall, y out of the wall into the corridor, origin on the floor at the centre
of the footprint) and the box it occupies. Sizes are those of real furniture:

- bench: 1.5 x 0.45 m, seat at 0.45 m, backrest to 0.85 m (a waiting-area bench);
- chair: 0.5 x 0.5 m each, seat at 0.45 m, back to 0.85 m; a row of one to three;
- cart: 0.9 x 0.5 m; a supply cart (drawers, 1.0 m), a linen cart (covered, 1.45-1.6 m)
  or a cleaning trolley (bucket and bag, 1.0 m);
- bed: a hospital bed parked along the wall, 2.0 x 0.9 m, mattress at 0.6 m;
- plant: a pot of 0.4 m diameter with foliage up to 1.2-1.9 m, 0.6 m across;
- notice_board: on the wall, 0.9-1.5 m wide, 0.6-1.0 m tall from 1.0-1.2 m up, 3 cm
  deep, with pinned sheets of paper (lines of grey for print, no readable text).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pmnav_bt.sim.scene.bodies import RGBA, Part, box, cylinder, sphere

STEEL = (0.62, 0.64, 0.67, 1.0)
DARK = (0.16, 0.16, 0.17, 1.0)
WHITE = (0.93, 0.93, 0.91, 1.0)
WOODS = ((0.60, 0.42, 0.25, 1.0), (0.72, 0.55, 0.36, 1.0), (0.45, 0.30, 0.18, 1.0))
UPHOLSTERY = (
    (0.20, 0.35, 0.60, 1.0),
    (0.25, 0.50, 0.40, 1.0),
    (0.55, 0.18, 0.20, 1.0),
    (0.35, 0.35, 0.38, 1.0),
)
PLASTICS = (
    (0.90, 0.50, 0.15, 1.0),
    (0.20, 0.45, 0.75, 1.0),
    (0.55, 0.56, 0.58, 1.0),
    (0.30, 0.60, 0.35, 1.0),
    (0.85, 0.82, 0.75, 1.0),
)
DRAWERS = ((0.35, 0.55, 0.80, 1.0), (0.90, 0.75, 0.25, 1.0), (0.80, 0.30, 0.30, 1.0))
LINEN = ((0.30, 0.45, 0.70, 1.0), (0.90, 0.90, 0.92, 1.0), (0.35, 0.60, 0.50, 1.0))
SHEETS = ((0.95, 0.95, 0.95, 1.0), (0.75, 0.85, 0.95, 1.0), (0.85, 0.92, 0.88, 1.0))
POTS = ((0.70, 0.38, 0.22, 1.0), (0.92, 0.92, 0.90, 1.0), (0.30, 0.30, 0.32, 1.0))
LEAVES = ((0.16, 0.42, 0.18, 1.0), (0.24, 0.52, 0.20, 1.0), (0.12, 0.32, 0.14, 1.0))
BOARDS = ((0.74, 0.58, 0.38, 1.0), (0.30, 0.40, 0.58, 1.0), (0.36, 0.50, 0.36, 1.0))
PAPERS = (
    (0.97, 0.97, 0.95, 1.0),
    (0.98, 0.95, 0.60, 1.0),
    (0.95, 0.78, 0.80, 1.0),
    (0.75, 0.88, 0.97, 1.0),
)
PRINT = (0.35, 0.35, 0.38, 1.0)


@dataclass(frozen=True)
class Shape:
    """One item: its ``parts`` and the box it fills, ``length`` along the wall x ``depth``
    out of it, from ``bottom`` to ``top`` metres up."""

    parts: list[Part]
    length: float
    depth: float
    top: float
    bottom: float = 0.0


def _pick(rng: np.random.Generator, options: tuple[RGBA, ...]) -> RGBA:
    return options[int(rng.integers(len(options)))]


def bench(rng: np.random.Generator) -> Shape:
    L, D = 1.5, 0.45
    seat = _pick(rng, WOODS + UPHOLSTERY)
    x, y = L / 2.0, D / 2.0
    parts = [
        box(-x, x, -y, y, 0.40, 0.45, seat),
        box(-x, x, -y, -y + 0.05, 0.50, 0.85, seat),
    ]
    for sx in (-x + 0.06, x - 0.06):  # two end frames
        parts.append(box(sx - 0.02, sx + 0.02, -y + 0.02, y - 0.02, 0.0, 0.40, STEEL))
        parts.append(box(sx - 0.02, sx + 0.02, -y, -y + 0.04, 0.40, 0.80, STEEL))
    return Shape(parts, L, D, 0.85)


def _chair(parts: list[Part], cx: float, colour: RGBA) -> None:
    h = 0.25
    parts.append(box(cx - h, cx + h, -h, h, 0.42, 0.46, colour))
    parts.append(box(cx - h, cx + h, -h, -h + 0.04, 0.50, 0.85, colour))
    for lx in (cx - h + 0.03, cx + h - 0.03):
        for ly in (-h + 0.03, h - 0.03):
            parts.append(cylinder(lx, ly, 0.015, 0.0, 0.42, STEEL))


def chair(rng: np.random.Generator) -> Shape:
    n = int(rng.integers(1, 4))  # waiting chairs stand in rows
    pitch = 0.55
    colour = _pick(rng, PLASTICS + UPHOLSTERY)
    parts: list[Part] = []
    for k in range(n):
        _chair(parts, (k - (n - 1) / 2.0) * pitch, colour)
    return Shape(parts, 0.5 + (n - 1) * pitch, 0.5, 0.85)


def _casters(parts: list[Part], x: float, y: float) -> None:
    for cx in (-x + 0.05, x - 0.05):
        for cy in (-y + 0.05, y - 0.05):
            parts.append(box(cx - 0.03, cx + 0.03, cy - 0.03, cy + 0.03, 0.0, 0.10, DARK))


def cart(rng: np.random.Generator) -> Shape:
    L, D = 0.9, 0.5
    x, y = L / 2.0, D / 2.0
    variant = int(rng.integers(3))
    parts: list[Part] = []
    _casters(parts, x, y)
    if variant == 0:  # supply cart: a cabinet of drawers with a worktop
        body = _pick(rng, (WHITE, (0.80, 0.82, 0.85, 1.0)))
        parts.append(box(-x, x, -y, y, 0.10, 0.95, body))
        parts.append(box(-x - 0.02, x + 0.02, -y - 0.02, y + 0.02, 0.95, 0.99, STEEL))
        front = _pick(rng, DRAWERS)
        for k in range(4):
            z0 = 0.16 + k * 0.19
            parts.append(box(-x + 0.04, x - 0.04, y, y + 0.01, z0, z0 + 0.16, front))
        parts.append(box(x + 0.02, x + 0.05, -y + 0.08, y - 0.08, 0.85, 0.88, STEEL))
        return Shape(parts, L + 0.1, D + 0.04, 0.99)
    if variant == 1:  # linen cart: a steel frame under a fabric cover
        top = float(rng.uniform(1.45, 1.6))
        for cx in (-x + 0.02, x - 0.02):
            for cy in (-y + 0.02, y - 0.02):
                parts.append(box(cx - 0.015, cx + 0.015, cy - 0.015, cy + 0.015, 0.1, top, STEEL))
        cover = _pick(rng, LINEN)
        parts.append(box(-x + 0.03, x - 0.03, -y + 0.03, y - 0.03, 0.15, top - 0.05, cover))
        return Shape(parts, L, D, top)
    # cleaning trolley: a grey frame, a yellow bucket and a bin bag
    parts.append(box(-x, x, -y, y, 0.10, 0.16, (0.40, 0.42, 0.45, 1.0)))
    parts.append(box(x - 0.05, x, -y, y, 0.16, 1.0, (0.40, 0.42, 0.45, 1.0)))
    parts.append(cylinder(-x + 0.22, 0.0, 0.17, 0.16, 0.45, (0.95, 0.80, 0.10, 1.0)))
    bag = _pick(rng, ((0.10, 0.10, 0.10, 1.0), (0.85, 0.75, 0.15, 1.0)))
    parts.append(box(0.0, x - 0.06, -y + 0.05, y - 0.05, 0.16, 0.95, bag))
    return Shape(parts, L, D, 1.0)


def bed(rng: np.random.Generator) -> Shape:
    L, D = 2.0, 0.9
    x, y = L / 2.0, D / 2.0
    frame = _pick(rng, ((0.85, 0.86, 0.88, 1.0), (0.55, 0.58, 0.62, 1.0)))
    end = _pick(rng, ((0.80, 0.70, 0.55, 1.0), (0.85, 0.86, 0.88, 1.0), (0.45, 0.55, 0.70, 1.0)))
    head = x if rng.random() < 0.5 else -x  # which end the head is
    sgn = 1.0 if head > 0 else -1.0
    parts: list[Part] = []
    _casters(parts, x, y)
    parts.append(box(-0.3, 0.3, -0.15, 0.15, 0.10, 0.30, DARK))  # the lifting column
    parts.append(box(-x + 0.05, x - 0.05, -y + 0.03, y - 0.03, 0.30, 0.45, frame))
    parts.append(box(-x + 0.07, x - 0.07, -y + 0.05, y - 0.05, 0.45, 0.62, _pick(rng, SHEETS)))
    parts.append(box(head - sgn * 0.45, head - sgn * 0.10, -y + 0.15, y - 0.15, 0.62, 0.72, WHITE))
    parts.append(box(head, head - sgn * 0.05, -y, y, 0.30, 0.95, end))  # headboard
    parts.append(box(-head, -head + sgn * 0.05, -y, y, 0.30, 0.80, end))  # footboard
    parts.append(box(-0.35, 0.55, y - 0.03, y, 0.62, 0.78, STEEL))  # side rail, corridor side
    return Shape(parts, L, D, 0.95)


def plant(rng: np.random.Generator) -> Shape:
    pot_r, pot_h = 0.2, 0.42
    top = float(rng.uniform(1.2, 1.9))
    parts: list[Part] = [
        cylinder(0.0, 0.0, pot_r, 0.0, pot_h, _pick(rng, POTS)),
        cylinder(0.0, 0.0, pot_r - 0.02, pot_h, pot_h + 0.01, (0.25, 0.18, 0.12, 1.0)),
        cylinder(0.0, 0.0, 0.025, pot_h, top - 0.3, (0.35, 0.25, 0.15, 1.0)),
    ]
    # Foliage: spheres up the stem, the widest at the top (a ficus or a palm in a pot).
    n = int(rng.integers(2, 5))
    for k in range(n):
        f = (k + 1) / n
        r = 0.16 + 0.12 * f
        z = pot_h + 0.15 + f * (top - pot_h - 0.15) - r
        dx, dy = rng.uniform(-0.06, 0.06, size=2)
        parts.append(sphere(float(dx), float(dy), max(z, pot_h + r * 0.5), r, _pick(rng, LEAVES)))
    return Shape(parts, 0.6, 0.6, top)


def notice_board(rng: np.random.Generator) -> Shape:
    L = float(rng.choice((0.9, 1.2, 1.5)))
    H = float(rng.choice((0.6, 0.8, 1.0)))
    z0 = float(rng.uniform(1.0, 1.2))
    D = 0.03
    x, y = L / 2.0, D / 2.0
    frame = _pick(rng, (WOODS[0], STEEL))
    parts = [
        box(-x, x, -y, y - 0.005, z0, z0 + H, _pick(rng, BOARDS)),
        box(-x, x, -y, y, z0, z0 + 0.03, frame),
        box(-x, x, -y, y, z0 + H - 0.03, z0 + H, frame),
        box(-x, -x + 0.03, -y, y, z0, z0 + H, frame),
        box(x - 0.03, x, -y, y, z0, z0 + H, frame),
    ]
    for _ in range(int(rng.integers(3, 8))):  # sheets pinned at random, A4 or A5, upright
        w, h = (0.21, 0.297) if rng.random() < 0.6 else (0.148, 0.21)
        cx = float(rng.uniform(-x + 0.05 + w / 2, x - 0.05 - w / 2))
        cz = float(rng.uniform(z0 + 0.05 + h / 2, z0 + H - 0.05 - h / 2))
        sheet = _pick(rng, PAPERS)
        x0, x1 = cx - w / 2, cx + w / 2
        parts.append(box(x0, x1, y - 0.004, y + 0.001, cz - h / 2, cz + h / 2, sheet))
        for k in range(int(rng.integers(1, 4))):  # lines of print
            lz = cz + h / 2 - 0.04 - k * 0.03
            parts.append(box(x0 + 0.02, x1 - 0.02, y, y + 0.002, lz - 0.006, lz, PRINT))
    return Shape(parts, L, D, z0 + H, bottom=z0)


BUILDERS: dict[str, Callable[[np.random.Generator], Shape]] = {
    "bench": bench,
    "chair": chair,
    "cart": cart,
    "bed": bed,
    "plant": plant,
    "notice_board": notice_board,
}
KINDS = tuple(BUILDERS)
ON_WALL = frozenset({"notice_board"})  # hung on the wall, not standing on the floor
