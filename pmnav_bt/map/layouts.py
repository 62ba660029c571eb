"""Corridor layouts of functional buildings: a main corridor with wings, or a ring round a core.

Real hospitals, schools and offices are mostly built on a few plans, and these are drawn
here, seeded, with square corners:

- **spine** (the "hospital street", the finger-plan school, the double-loaded office
  corridor): one main corridor with wings off either side. A wing at an end of the main
  corridor bends it into an L (one end) or a U (both); a wing may end in a hook (a bend).
- **ring** (the racetrack ward, the office floor round its lift-and-stair core, the
  courtyard school): a rectangular loop, with wings off its outer sides.

Either way the entrance is a wide lobby off the main corridor (the start of every plan),
and the lobby's far end (the *core*) is where lifts and stairs are. Corridors that do not
meet keep rooms' depth between them on both sides (``room_depth``), so no room is cut
in half by another corridor. A layout is geometry only: :mod:`pmnav_bt.map.functional`
gives it rooms, numbers and landmarks.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field

from shapely.geometry import LineString, Point

WING_LENGTH_M = (4.0, 16.0)  # beyond two rooms' depth
HOOK_LENGTH_M = (8.0, 14.0)
LOBBY_LENGTH_M = (7.0, 11.0)
END_STUB_M = 6.0  # a wing off the main corridor leaves at least this much of it beyond
END_WING_P = 0.35  # chance a wing stands at an end of the main corridor (an L or a U)
HOOK_P = 0.35  # chance a wing ends in a bend
TRIES = 40  # draws of one wing before it is left out


@dataclass(frozen=True)
class Corridor:
    """A straight corridor between two layout nodes; ``wing`` 0 is the lobby and the main
    corridor (or ring), k > 0 the k-th wing with its hook."""

    a: int
    b: int
    width: float
    wing: int
    role: str  # "lobby", "main", "ring", "wing"


@dataclass
class Layout:
    """Nodes (positions in metres), corridors, the entrance node and the core node."""

    shape: str  # "spine" or "ring"
    lobby_width: float
    pos: list[tuple[float, float]] = field(default_factory=list)
    corridors: list[Corridor] = field(default_factory=list)
    entrance: int = -1
    core: int = -1
    wings: int = 0
    hooks: int = 0
    centre: tuple[float, float] | None = None  # a ring's centre (its core lies round it)

    def node(self, x: float, y: float) -> int:
        p = (round(x, 2), round(y, 2))
        if p in self.pos:
            return self.pos.index(p)
        self.pos.append(p)
        return len(self.pos) - 1

    def chain(self, points: list[tuple[float, float]], width: float, wing: int, role: str):
        """Corridors along a polyline through ``points`` (in order, duplicates skipped)."""
        ids = [self.node(*p) for p in points]
        for a, b in zip(ids, ids[1:]):  # noqa: B905 - one shorter by construction
            if a != b:
                self.corridors.append(Corridor(a, b, width, wing, role))

    def describe(self) -> str:
        wings = f"{self.wings} wing{'s' if self.wings != 1 else ''}"
        hooks = f" ({self.hooks} with a bend)" if self.hooks else ""
        if self.shape == "ring":
            return f"a ring corridor round a core, with {wings}{hooks}"
        return f"a main corridor with {wings}{hooks}"


def _touch(g1: LineString, g2: LineString) -> bool:
    """Whether two corridors meet: at a point that ends at least one of them (an L or T
    junction), not crossing in the middle of both."""
    if g1.distance(g2) > 1e-6:
        return False
    hit = g1.intersection(g2)
    ends = [Point(c) for g in (g1, g2) for c in (g.coords[0], g.coords[-1])]
    return hit.geom_type == "Point" and any(hit.distance(e) < 1e-6 for e in ends)


def _clear(segs: list[tuple[LineString, float]], new: list[tuple[LineString, float]], depth):
    """Whether the ``new`` corridors keep two rooms' depth between their walls and those of
    every corridor they do not meet (``segs`` and each other)."""
    for i, (g1, w1) in enumerate(new):
        for g2, w2 in segs + new[i + 1 :]:
            if not _touch(g1, g2) and g1.distance(g2) < (w1 + w2) / 2.0 + 2.0 * depth:
                return False
    return True


def _wing(
    rng: random.Random, root: tuple[float, float], out: tuple[float, float], depth: float
) -> tuple[list[tuple[float, float]], bool]:
    """A wing's polyline from ``root`` in direction ``out`` (a unit axis), maybe ending in a
    hook; long enough that a hook keeps two rooms' depth from the corridor it leaves."""
    length = round(rng.uniform(*WING_LENGTH_M) + 2.0 * depth, 1)
    tip = (root[0] + out[0] * length, root[1] + out[1] * length)
    pts = [root, tip]
    hooked = rng.random() < HOOK_P
    if hooked:
        side = rng.choice((-1.0, 1.0))
        h = round(rng.uniform(*HOOK_LENGTH_M), 1)
        pts.append((tip[0] - out[1] * side * h, tip[1] + out[0] * side * h))
    return pts, hooked


def _draw_wings(
    rng: random.Random,
    segs: list[tuple[LineString, float]],
    roots,
    count: int,
    width: float,
    depth: float,
    keep_clear: list[tuple[float, float, float]],
) -> tuple[list[list[tuple[float, float]]], int]:
    """Up to ``count`` wings from ``roots(rng)`` draws of (root, out), each clear of the
    corridors ``segs`` and of the wings before it; no wing starts within a (x, y, radius)
    of ``keep_clear``. Returns the wings' polylines and how many end in a hook."""
    wings: list[list[tuple[float, float]]] = []
    hooks = 0
    for _ in range(count):
        for _try in range(TRIES):
            root, out = roots(rng)
            if any(abs(root[0] - x) + abs(root[1] - y) < r for x, y, r in keep_clear):
                continue
            if any(w[0] == root for w in wings):
                continue
            pts, hooked = _wing(rng, root, out, depth)
            new = [(LineString([p, q]), width) for p, q in zip(pts, pts[1:])]  # noqa: B905
            if _clear(segs, new, depth):
                segs = segs + new
                wings.append(pts)
                hooks += hooked
                break
    return wings, hooks


def _lines(points, width) -> list[tuple[LineString, float]]:
    return [(LineString([p, q]), width) for p, q in zip(points, points[1:])]  # noqa: B905


def _with_lobby_and_wings(
    layout: Layout, lx: float, lobby_len: float, lobby_w: float, wings, wing_w: float
) -> Layout:
    """``layout`` with what every plan has after its main corridors: the lobby running
    ``lobby_len`` south to the entrance from the core at (lx, 0), and the wings."""
    layout.chain([(lx, -lobby_len), (lx, 0.0)], lobby_w, 0, "lobby")
    for k, pts in enumerate(sorted(wings)):
        layout.chain(pts, wing_w, k + 1, "wing")
    layout.entrance = layout.node(lx, -lobby_len)
    layout.core = layout.node(lx, 0.0)
    return layout


def spine_layout(
    rng: random.Random,
    main_w: float,
    wing_w: float,
    lobby_w: float,
    depth: float,
    main_m: tuple[float, float],
) -> Layout:
    """A main corridor along x, ``main_m`` long, with 1-4 wings (north, and south away
    from the lobby)."""
    length = round(rng.uniform(*main_m), 1)
    lx = round(rng.uniform(0.3, 0.7) * length, 1)
    lobby_len = round(rng.uniform(*LOBBY_LENGTH_M), 1)

    def roots(r: random.Random):
        if r.random() < END_WING_P:
            x = r.choice((0.0, length))
        else:  # not so near an end that a stub of corridor is left beyond the wing
            x = round(r.uniform(END_STUB_M, length - END_STUB_M))
        return (float(x), 0.0), (0.0, 1.0 if r.random() < 0.7 else -1.0)

    segs = _lines([(0.0, 0.0), (length, 0.0)], main_w) + _lines(
        [(lx, -lobby_len), (lx, 0.0)], lobby_w
    )
    keep = [(lx, 0.0, lobby_w / 2.0 + wing_w / 2.0 + 3.0)]
    wings, hooks = _draw_wings(rng, segs, roots, rng.randint(1, 4), wing_w, depth, keep)
    layout = Layout("spine", lobby_w, wings=len(wings), hooks=hooks)
    xs = sorted({0.0, length, lx, *(w[0][0] for w in wings)})
    layout.chain([(x, 0.0) for x in xs], main_w, 0, "main")
    return _with_lobby_and_wings(layout, lx, lobby_len, lobby_w, wings, wing_w)


def ring_layout(
    rng: random.Random,
    main_w: float,
    wing_w: float,
    lobby_w: float,
    depth: float,
    size_m: tuple[tuple[float, float], tuple[float, float]],
    wings_n: tuple[int, int],
) -> Layout:
    """A rectangular ring whose inside is the core: its length and its core's depth
    between the walls drawn from the ranges ``size_m``; the lobby off the south side and
    ``wings_n`` (fewest, most) wings off the others."""
    w = round(rng.uniform(*size_m[0]), 1)
    h = round(rng.uniform(*size_m[1]) + main_w, 1)
    lx = round(rng.uniform(0.3, 0.7) * w, 1)
    lobby_len = round(rng.uniform(*LOBBY_LENGTH_M), 1)

    def roots(r: random.Random):
        side = r.choice(("north", "east", "west"))
        if side == "north":
            return (float(round(r.uniform(0.0, w))), h), (0.0, 1.0)
        x, out = (w, 1.0) if side == "east" else (0.0, -1.0)
        return (x, float(round(r.uniform(0.0, h)))), (out, 0.0)

    ring = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)]
    segs = _lines(ring, main_w) + _lines([(lx, -lobby_len), (lx, 0.0)], lobby_w)
    corners = [(x, y, wing_w / 2.0 + main_w + 1.0) for x, y in ring[:4]]
    n = rng.randint(*wings_n)
    wings, hooks = _draw_wings(rng, segs, roots, n, wing_w, depth, corners)
    layout = Layout("ring", lobby_w, wings=len(wings), hooks=hooks, centre=(w / 2.0, h / 2.0))
    on: dict[str, set[float]] = {"s": {0.0, w, lx}, "e": {0.0, h}, "n": {0.0, w}, "w": {0.0, h}}
    for (x, y), *_ in wings:
        side = "n" if y == h else "e" if x == w else "w"
        on[side].add(y if side in "ew" else x)
    layout.chain([(x, 0.0) for x in sorted(on["s"])], main_w, 0, "ring")
    layout.chain([(w, y) for y in sorted(on["e"])], main_w, 0, "ring")
    layout.chain([(x, h) for x in sorted(on["n"], reverse=True)], main_w, 0, "ring")
    layout.chain([(0.0, y) for y in sorted(on["w"], reverse=True)], main_w, 0, "ring")
    return _with_lobby_and_wings(layout, lx, lobby_len, lobby_w, wings, wing_w)
