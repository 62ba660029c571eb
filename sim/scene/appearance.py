"""What a building's surfaces look like and how it is lit: wall, floor, door and skirting
colours, floor and wall textures, and the light the tiny renderer shades with.

``world.scene.appearance`` chooses the colours: ``clean`` is the world the paper's tables
were measured in (this module's clean constants, exactly); ``random`` draws a
palette per building and seed from what real functional buildings use:

- hospital: pale green, blue-grey, aqua or off-white walls, often two-tone with a darker
  wipe-clean lower band and a bumper rail; speckled or marbled sheet vinyl floors in grey,
  blue-grey or beige; light wood, painted or grey doors in steel frames.
- school: cream, pale yellow or light blue painted concrete block walls, often with a
  coloured lower band; linoleum (marbled) or 0.3 m vinyl tiles laid in a checker; doors
  painted red, blue, green or yellow, or wood.
- office: white, light or warm grey walls; 0.5 m carpet tiles in grey, charcoal or blue,
  each tile a shade apart (tiles are laid in alternating directions); wood, white or grey
  doors.

All three have suspended ceilings of 0.6 m tiles in a T-bar grid with a light panel
every few tiles. A building of another kind draws one of the three per seed. Textures are procedural
(numpy), tiled in metres (the tiny renderer wraps texture coordinates) on quads 1 mm in
front of the floor and the walls, so the boxes the robot collides with and every label are
unchanged (the boxes a quad covers are made invisible: the tiny renderer then skips them
instead of shading each of their pixels twice); plain walls get a per-segment shade
instead (paint batches, patching).

``light_level`` [min, max] and ``light_turn_deg`` draw the light per episode: the clean
light's ambient and diffuse coefficients scaled by the level (the tiny renderer's shade is
linear in both, so the frame's brightness follows the level), its direction turned in
azimuth. Sign plates face the light (they render evenly lit from every side), so they dim
with the level as a printed plate does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from shapely.geometry import LineString

from pmnav_bt.seams import CEILING_LABEL, FLOOR_LABEL, WALL_LABEL
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.scene.lifts import open_stretches
from pmnav_bt.sim.textures import write_png

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import WorldConfig
    from pmnav_bt.sim.scene.host import SceneWorld

RGBA = tuple[float, float, float, float]

# The clean world's look (every table before issue 36 was measured in it).
FLOOR_RGBA = (0.42, 0.45, 0.52, 1.0)
WALL_RGBA = (0.93, 0.90, 0.80, 1.0)
SKIRTING_RGBA = (0.25, 0.24, 0.22, 1.0)
CEILING_RGBA = (0.97, 0.97, 0.97, 1.0)
DOOR_RGBA = (0.58, 0.38, 0.20, 1.0)
FRAME_RGBA = (0.30, 0.22, 0.16, 1.0)
HANDLE_RGBA = (0.80, 0.80, 0.82, 1.0)
# Its light for the tiny renderer: direction towards the light (map frame), coefficients.
LIGHT_DIRECTION = tuple(
    float(v) for v in np.array([0.4, 0.3, 1.0]) / np.linalg.norm([0.4, 0.3, 1.0])
)
LIGHT_AMBIENT = 0.72
LIGHT_DIFFUSE = 0.35

WALL_THICKNESS = 0.10  # the corridor walls' boxes (the world builds them; quads cover them)
PALETTES = ("hospital", "school", "office")
TEXELS_PER_M = 64  # floor and wall textures: fine enough for 1 cm grout at 2 m, small files
SURFACE_OFFSET_M = 0.001  # textured quads stand this far in front of the floor and walls
WALL_SHADE = 0.03  # per-segment shade of plain walls (fraction of the colour)


@dataclass(frozen=True)
class Light:
    """The renderer's light: ``direction`` towards the light (unit, map frame) and the
    ambient and diffuse coefficients; ``level`` is their scale against the clean light."""

    direction: tuple[float, float, float]
    ambient: float
    diffuse: float
    level: float = 1.0


CLEAN_LIGHT = Light(LIGHT_DIRECTION, LIGHT_AMBIENT, LIGHT_DIFFUSE)


@dataclass(frozen=True, eq=False)
class Surface:
    """A texture tiled over a surface: ``image`` (RGB, top row = top) covers ``size_m``
    (along, up) metres; ``up`` None: it tiles upwards too (a floor); else the image spans
    the wall's height once."""

    kind: str
    image: np.ndarray
    size_m: tuple[float, float]


@dataclass(frozen=True, eq=False)
class Appearance:
    """The colours (RGBA), textures and light of one world. ``palette`` names where the
    colours came from ("clean" or a building kind)."""

    palette: str
    floor: RGBA
    wall: RGBA
    skirting: RGBA
    ceiling: RGBA
    door: RGBA
    frame: RGBA
    handle: RGBA
    light: Light = CLEAN_LIGHT
    floor_surface: Surface | None = None
    wall_surface: Surface | None = None
    ceiling_surface: Surface | None = None
    wall_shade: float = 0.0

    def dress(self, world: SceneWorld) -> None:
        """Put the textures on the built world's floor, ceiling and walls and shade plain
        wall segments; the clean appearance has none of these and adds nothing."""
        rng = world.rng("appearance_surfaces")
        if self.floor_surface is not None:
            _texture_floor(world, self.floor_surface)
        if self.ceiling_surface is not None and world.bodies_with_label(CEILING_LABEL):
            _texture_ceiling(world, self.ceiling_surface)
        if world.wall_source != "corridors":
            return  # walls from a grid's cells: one paint over the cells, no segments to vary
        if self.wall_surface is not None:
            _texture_walls(world, self.wall_surface, rng, self.wall_shade)
        elif self.wall_shade > 0.0:
            _shade_walls(world, self.wall, rng, self.wall_shade)


CLEAN_APPEARANCE = Appearance(
    "clean",
    floor=FLOOR_RGBA,
    wall=WALL_RGBA,
    skirting=SKIRTING_RGBA,
    ceiling=CEILING_RGBA,
    door=DOOR_RGBA,
    frame=FRAME_RGBA,
    handle=HANDLE_RGBA,
)


def appearance_of(world: SceneWorld) -> Appearance:
    """The appearance ``world.scene`` asks for, drawn from the world's seed: colours and
    textures from ``world.rng("appearance")``, the light from ``world.rng("light")``."""
    scene = world.scene
    light = draw_light(scene, world.rng("light"))
    if scene.appearance == "clean":
        return replace(CLEAN_APPEARANCE, light=light)
    rng = world.rng("appearance")
    kind = world.building.kind.lower()
    palette = kind if kind in PALETTES else PALETTES[int(rng.integers(len(PALETTES)))]
    return _DRAW[palette](rng, light, world.building.wall_height)


def draw_light(scene: WorldConfig, rng: np.random.Generator) -> Light:
    """The episode's light: level uniform in ``light_level``, direction turned in azimuth
    by up to ``light_turn_deg``; the clean light itself when neither varies."""
    lo, hi = scene.light_level
    level = float(lo) if lo == hi else float(rng.uniform(lo, hi))
    direction = LIGHT_DIRECTION
    if scene.light_turn_deg > 0.0:
        a = math.radians(float(rng.uniform(-scene.light_turn_deg, scene.light_turn_deg)))
        x, y, z = direction
        direction = (x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a), z)
    if level == 1.0 and direction == LIGHT_DIRECTION:
        return CLEAN_LIGHT
    return Light(direction, LIGHT_AMBIENT * level, LIGHT_DIFFUSE * level, level)


# -- palettes -------------------------------------------------------------------------------


def _pick(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def _rgba(rgb, rng: np.random.Generator | None = None, jitter: float = 0.0) -> RGBA:
    """An RGBA from RGB, each channel moved by up to ``jitter`` (two paints of one name)."""
    c = np.asarray(rgb, float)
    if rng is not None and jitter:
        c = c + rng.uniform(-jitter, jitter, 3)
    r, g, b = (float(v) for v in np.clip(c, 0.0, 1.0))
    return (r, g, b, 1.0)


_WOOD = ((0.76, 0.60, 0.42), (0.66, 0.47, 0.30), (0.52, 0.34, 0.20), (0.82, 0.70, 0.52))
_STEEL = ((0.55, 0.57, 0.60), (0.42, 0.44, 0.47), (0.88, 0.88, 0.86))
_HANDLE = ((0.80, 0.80, 0.82), (0.20, 0.20, 0.21))


def _hospital(rng: np.random.Generator, light: Light, wall_h: float) -> Appearance:
    wall = _pick(rng, ((0.80, 0.88, 0.82), (0.76, 0.81, 0.86), (0.94, 0.94, 0.92),
                       (0.78, 0.88, 0.88), (0.90, 0.92, 0.86)))
    floor = _pick(rng, ((0.62, 0.63, 0.62), (0.52, 0.58, 0.64), (0.72, 0.68, 0.60),
                        (0.55, 0.62, 0.58)))
    door = _pick(rng, (*_WOOD[:2], (0.90, 0.90, 0.88), (0.62, 0.72, 0.80), (0.60, 0.62, 0.64)))
    frame = _pick(rng, _STEEL)
    chips = [np.clip(np.asarray(floor) + d, 0, 1) for d in (-0.25, 0.18, -0.12)]
    floor_kind = _pick(rng, ("speckle", "marble"))
    floor_img = (
        _speckle(rng, floor, chips, 1.0) if floor_kind == "speckle" else _marble(rng, floor, 2.0)
    )
    wall_surface = None
    if rng.random() < 0.6:  # two-tone: a darker wipe-clean band below a bumper rail
        lower = np.clip(np.asarray(wall) * rng.uniform(0.70, 0.85), 0, 1)
        rail = _pick(rng, ((0.55, 0.57, 0.60), (0.70, 0.56, 0.40), np.asarray(wall) * 0.6))
        wall_surface = Surface("two_tone", _two_tone(wall, lower, rail, wall_h), (1.0, wall_h))
    return Appearance(
        "hospital",
        floor=_rgba(floor),
        wall=_rgba(wall, rng, 0.02),
        skirting=_rgba(_pick(rng, ((0.25, 0.24, 0.22), np.asarray(floor) * 0.7))),
        ceiling=CEILING_RGBA,
        door=_rgba(door, rng, 0.03),
        frame=_rgba(frame),
        handle=_rgba(_pick(rng, _HANDLE)),
        light=light,
        floor_surface=Surface(floor_kind, floor_img, (floor_img.shape[1] / TEXELS_PER_M,) * 2),
        wall_surface=wall_surface,
        wall_shade=WALL_SHADE,
        ceiling_surface=_ceiling(rng),
    )


def _school(rng: np.random.Generator, light: Light, wall_h: float) -> Appearance:
    wall = _pick(rng, ((0.95, 0.91, 0.78), (0.96, 0.93, 0.70), (0.80, 0.87, 0.93),
                       (0.93, 0.93, 0.90)))
    band = _pick(rng, ((0.20, 0.38, 0.65), (0.22, 0.55, 0.35), (0.72, 0.20, 0.18),
                       (0.90, 0.55, 0.15), None))
    door = _pick(rng, ((0.70, 0.16, 0.14), (0.18, 0.34, 0.62), (0.20, 0.50, 0.30),
                       (0.92, 0.74, 0.18), *_WOOD[:2]))
    if rng.random() < 0.5:  # vinyl composition tiles, 0.3 m, two colours in a checker
        a, b = _pick(rng, (((0.86, 0.84, 0.76), (0.55, 0.55, 0.55)),
                           ((0.88, 0.88, 0.86), (0.25, 0.40, 0.65)),
                           ((0.84, 0.80, 0.70), (0.62, 0.50, 0.40))))
        floor_img = _tiles(rng, 0.3, (a, b), checker=True)
        floor, floor_kind = np.add(a, b) / 2.0, "tiles"
    else:  # sheet linoleum, marbled
        floor = _pick(rng, ((0.45, 0.55, 0.45), (0.42, 0.50, 0.62), (0.60, 0.42, 0.32),
                            (0.70, 0.66, 0.56)))
        floor_img, floor_kind = _marble(rng, floor, 2.0), "marble"
    lower = np.asarray(band) if band is not None else np.asarray(wall)
    wall_img = _blocks(rng, wall, lower, band is not None, wall_h)
    return Appearance(
        "school",
        floor=_rgba(floor),
        wall=_rgba(wall),
        skirting=_rgba(_pick(rng, ((0.25, 0.24, 0.22), (0.15, 0.15, 0.16)))),
        ceiling=CEILING_RGBA,
        door=_rgba(door, rng, 0.03),
        frame=_rgba(_pick(rng, _STEEL)),
        handle=_rgba(_pick(rng, _HANDLE)),
        light=light,
        floor_surface=Surface(floor_kind, floor_img, (floor_img.shape[1] / TEXELS_PER_M,) * 2),
        wall_surface=Surface("blocks", wall_img, (wall_img.shape[1] / TEXELS_PER_M, wall_h)),
        wall_shade=WALL_SHADE,
        ceiling_surface=_ceiling(rng),
    )


def _office(rng: np.random.Generator, light: Light, wall_h: float) -> Appearance:
    wall = _pick(rng, ((0.93, 0.93, 0.92), (0.82, 0.82, 0.81), (0.86, 0.83, 0.78),
                       (0.88, 0.90, 0.91)))
    floor = _pick(rng, ((0.45, 0.46, 0.47), (0.30, 0.31, 0.33), (0.32, 0.38, 0.48),
                        (0.50, 0.46, 0.42)))
    door = _pick(rng, (*_WOOD, (0.92, 0.92, 0.90), (0.55, 0.56, 0.58)))
    floor_img = _carpet(rng, floor, 0.5)
    return Appearance(
        "office",
        floor=_rgba(floor),
        wall=_rgba(wall, rng, 0.015),
        skirting=_rgba(_pick(rng, ((0.18, 0.18, 0.19), (0.45, 0.45, 0.46), wall))),
        ceiling=CEILING_RGBA,
        door=_rgba(door, rng, 0.03),
        frame=_rgba(_pick(rng, (*_STEEL, np.asarray(door) * 0.85))),
        handle=_rgba(_pick(rng, _HANDLE)),
        light=light,
        floor_surface=Surface("carpet", floor_img, (floor_img.shape[1] / TEXELS_PER_M,) * 2),
        wall_shade=WALL_SHADE,
        ceiling_surface=_ceiling(rng),
    )


_DRAW = {"hospital": _hospital, "school": _school, "office": _office}


# -- procedural textures (RGB float images in [0, 1] -> uint8) ------------------------------


def _u8(img: np.ndarray) -> np.ndarray:
    return (np.clip(img, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)


def _noise(rng: np.random.Generator, n: int, cells: int) -> np.ndarray:
    """Smooth tileable noise (n x n, about [-1, 1]) from a ``cells`` x ``cells`` lattice."""
    lattice = rng.uniform(-1.0, 1.0, (cells, cells))
    t = np.arange(n) * cells / n
    i0 = np.floor(t).astype(int)
    f = t - i0
    f = f * f * (3 - 2 * f)
    i1 = (i0 + 1) % cells
    rows = lattice[i0] * (1 - f)[:, None] + lattice[i1] * f[:, None]
    return rows[:, i0] * (1 - f)[None, :] + rows[:, i1] * f[None, :]


def _speckle(rng, base, chips, size_m: float) -> np.ndarray:
    """Speckled vinyl: the base colour with small chips of a few others (about 12 %)."""
    n = int(size_m * TEXELS_PER_M)
    img = np.empty((n, n, 3))
    img[:] = base
    img += 0.03 * _noise(rng, n, 4)[..., None]
    which = rng.random((n, n))
    for k, chip in enumerate(chips):
        img[(which > 0.88 + 0.04 * k) & (which <= 0.92 + 0.04 * k)] = chip
    return _u8(img)


def _marble(rng, base, size_m: float) -> np.ndarray:
    """Sheet vinyl or linoleum: soft streaks of a lighter and darker shade of the base."""
    n = int(size_m * TEXELS_PER_M)
    streak = _noise(rng, n, 4) + 0.5 * _noise(rng, n, 8) + 0.25 * _noise(rng, n, 16)
    img = np.asarray(base, float) * (1.0 + 0.10 * streak[..., None])
    img += 0.015 * rng.standard_normal((n, n, 1))
    return _u8(img)


def _tiles(rng, tile_m: float, colours, *, checker: bool) -> np.ndarray:
    """Square floor tiles of ``tile_m`` with 1-texel dark grout, 4 x 4 tiles per image."""
    t = max(4, int(round(tile_m * TEXELS_PER_M)))
    n = 4 * t
    ij = np.arange(n) // t
    pick = (ij[:, None] + ij[None, :]) % 2 if checker else np.zeros((n, n), int)
    img = np.asarray(colours, float)[pick]
    shade = 1.0 + rng.uniform(-0.03, 0.03, (4, 4))
    img *= shade[ij[:, None], ij[None, :]][..., None]
    img += 0.012 * rng.standard_normal((n, n, 1))
    grout = (np.arange(n) % t) == 0
    img[grout, :] *= 0.6
    img[:, grout] *= 0.6
    return _u8(img)


def _carpet(rng, base, tile_m: float) -> np.ndarray:
    """Carpet tiles: fibre noise, each tile a shade apart, faint seams, 4 x 4 per image."""
    t = int(round(tile_m * TEXELS_PER_M))
    n = 4 * t
    ij = np.arange(n) // t
    shade = 1.0 + rng.uniform(-0.06, 0.06, (4, 4))
    img = np.asarray(base, float) * shade[ij[:, None], ij[None, :]][..., None]
    img *= 1.0 + 0.08 * rng.standard_normal((n, n, 1))
    seam = (np.arange(n) % t) == 0
    img[seam, :] *= 0.85
    img[:, seam] *= 0.85
    return _u8(img)


def _ceiling(rng) -> Surface:
    """A suspended ceiling: 0.6 m off-white tiles in a T-bar grid, a 0.6 x 1.2 m light
    panel (brighter) in each 2.4 m square; 4 x 4 tiles per image. The grid is white-painted
    steel, seen by its shadow line: a shade darker than the tiles, not a dark line."""
    t = int(round(0.6 * TEXELS_PER_M))
    n = 4 * t
    tile = np.asarray(_pick(rng, ((0.93, 0.93, 0.91), (0.90, 0.90, 0.88), (0.95, 0.95, 0.95))))
    img = np.empty((n, n, 3))
    img[:] = tile
    img *= 1.0 + 0.02 * rng.standard_normal((n, n, 1))
    img[t : 3 * t, t : 2 * t] = np.minimum(1.0, tile + 0.05)  # the light panel
    grid = (np.arange(n) % t) == 0
    img[grid, :] = tile * 0.85
    img[:, grid] = tile * 0.85
    return Surface("ceiling_tiles", _u8(img), (n / TEXELS_PER_M, n / TEXELS_PER_M))


def _two_tone(upper, lower, rail, wall_h: float) -> np.ndarray:
    """A wall 1 m wide and ``wall_h`` high: ``lower`` up to 0.9 m, a 0.12 m bumper rail,
    ``upper`` above (rows from the top)."""
    rows = int(round(wall_h * TEXELS_PER_M))
    z = (rows - 0.5 - np.arange(rows)) / TEXELS_PER_M  # height of each row's centre
    col = np.where(z[:, None] < 0.9, np.asarray(lower)[None], np.asarray(upper)[None])
    col = np.where(((z >= 0.9) & (z < 1.02))[:, None], np.asarray(rail)[None], col)
    return _u8(np.repeat(col[:, None, :], TEXELS_PER_M, axis=1))


def _blocks(rng, upper, lower, banded: bool, wall_h: float) -> np.ndarray:
    """Painted concrete blocks (0.4 x 0.2 m, running bond, mortar lines a shade darker),
    2 m wide; ``banded``: ``lower`` colour up to 1.2 m."""
    rows = int(round(wall_h * TEXELS_PER_M))
    n = 2 * TEXELS_PER_M
    z = (rows - 0.5 - np.arange(rows)) / TEXELS_PER_M
    col = np.where((z < 1.2)[:, None] & banded, np.asarray(lower)[None], np.asarray(upper)[None])
    img = np.repeat(col[:, None, :], n, axis=1)
    course = np.floor(z / 0.2).astype(int)
    bw = int(0.4 * TEXELS_PER_M)
    x = np.arange(n)[None, :] + (course[:, None] % 2) * (bw // 2)
    joint = ((x % bw) == 0) | (((z * TEXELS_PER_M).astype(int) % int(0.2 * TEXELS_PER_M)) == 0)[
        :, None
    ]
    img = img * (1.0 + 0.01 * rng.standard_normal((rows, n, 1)))
    img[joint] *= 0.86
    return _u8(img)


# -- putting textures on the built world ------------------------------------------------


def _quad(
    world: SceneWorld,
    corners: list[np.ndarray],
    uvs: list[list[float]],
    normal: tuple[float, float, float],
    texture: int,
    label: str,
    rgba: RGBA = (1.0, 1.0, 1.0, 1.0),
) -> int:
    """A textured quad (corners counter-clockwise seen from ``normal``'s side), no collision."""
    c = world.client
    centre = np.mean(corners, axis=0)
    with world.lock:
        vis = p.createVisualShape(
            p.GEOM_MESH,
            vertices=[(v - centre).tolist() for v in corners],
            indices=[0, 1, 2, 0, 2, 3],
            uvs=uvs,
            normals=[list(normal)] * 4,
            rgbaColor=rgba,
            physicsClientId=c,
        )
        body = p.createMultiBody(0.0, -1, vis, centre.tolist(), physicsClientId=c)
        p.changeVisualShape(body, -1, textureUniqueId=texture, physicsClientId=c)
    return world.register(body, label, solid=False)


def _load_texture(world: SceneWorld, surface: Surface, name: str) -> int:
    path = write_png(surface.image, Path(world._tmp.name) / f"{name}.png")
    with world.lock:
        return p.loadTexture(str(path), physicsClientId=world.client)


def _hide(world: SceneWorld, body: int) -> None:
    """Make a box the renderer draws no longer (alpha 0); it still blocks rays and the robot."""
    with world.lock:
        p.changeVisualShape(body, -1, rgbaColor=(1.0, 1.0, 1.0, 0.0), physicsClientId=world.client)


def _texture_floor(world: SceneWorld, surface: Surface) -> None:
    """One quad over the floor's extent, the texture repeating every ``size_m``; it
    replaces the floor box in the frames."""
    (floor_box,) = world.bodies_with_label(FLOOR_LABEL)
    tex = _load_texture(world, surface, "floor_surface")
    x0, y0, x1, y1 = world.bounds(margin=3.0)
    z = SURFACE_OFFSET_M
    corners = [np.array(v, float) for v in ((x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z))]
    su, sv = surface.size_m
    uvs = [[x0 / su, y0 / sv], [x1 / su, y0 / sv], [x1 / su, y1 / sv], [x0 / su, y1 / sv]]
    _quad(world, corners, uvs, (0.0, 0.0, 1.0), tex, FLOOR_LABEL)
    _hide(world, floor_box)


def _texture_ceiling(world: SceneWorld, surface: Surface) -> None:
    """One quad under the ceiling, facing down, the texture repeating every ``size_m``; it
    replaces the ceiling box in the frames."""
    (ceiling_box,) = world.bodies_with_label(CEILING_LABEL)
    tex = _load_texture(world, surface, "ceiling_surface")
    x0, y0, x1, y1 = world.bounds(margin=3.0)
    z = world.building.wall_height - SURFACE_OFFSET_M
    corners = [np.array(v, float) for v in ((x0, y0, z), (x0, y1, z), (x1, y1, z), (x1, y0, z))]
    su, sv = surface.size_m
    uvs = [[x0 / su, y0 / sv], [x0 / su, y1 / sv], [x1 / su, y1 / sv], [x1 / su, y0 / sv]]
    _quad(world, corners, uvs, (0.0, 0.0, -1.0), tex, CEILING_LABEL)
    _hide(world, ceiling_box)


def _texture_walls(world: SceneWorld, surface: Surface, rng: np.random.Generator, shade: float):
    """A quad on the corridor face of every wall segment: the texture repeats every
    ``size_m[0]`` along the wall and spans its height once; each segment is shaded a little.
    The quads replace the wall boxes they cover whole in the frames (a box cut for an
    opening stays drawn)."""
    boxes = _segment_boxes(world)
    tex = _load_texture(world, surface, "wall_surface")
    h = world.building.wall_height
    su = surface.size_m[0]
    for w in world.walls:
        n = np.asarray(w.normal, float)
        k = float(1.0 - rng.uniform(0.0, shade))
        ends = np.asarray(w.a, float), np.asarray(w.b, float)
        length = w.length
        # a lift's doorway stays open (sim/scene/lifts.py): the face either side of it
        for s0, s1 in open_stretches(world.cabins.values(), w.a, w.b):
            a = _along(ends, length, s0) + n * SURFACE_OFFSET_M
            b = _along(ends, length, s1) + n * SURFACE_OFFSET_M
            # Seen from the corridor (looking along -n) b is on the left: b, a, a-top, b-top
            # runs counter-clockwise, as the sign quads do.
            corners = [np.append(b, 0.0), np.append(a, 0.0), np.append(a, h), np.append(b, h)]
            ub, ua = (length - s1) / su, (length - s0) / su  # one texture along the wall
            _quad(
                world,
                corners,
                [[ub, 0.0], [ua, 0.0], [ua, 1.0], [ub, 1.0]],
                (float(n[0]), float(n[1]), 0.0),
                tex,
                WALL_LABEL,
                (k, k, k, 1.0),
            )
    for body in boxes:
        _hide(world, body)


def _along(ends: tuple[np.ndarray, np.ndarray], length: float, s: float) -> np.ndarray:
    """The point ``s`` m from the first of a wall's ``ends`` (its ends themselves exactly)."""
    if s <= 0.0:
        return ends[0]
    if s >= length:
        return ends[1]
    return ends[0] + (ends[1] - ends[0]) * (s / length)


def _segment_boxes(world: SceneWorld) -> list[int]:
    """The solid wall boxes that run the whole length of a wall segment, behind it: the
    walls a corridor-face quad covers entirely."""
    behind = [
        LineString(
            [np.asarray(w.a) - np.asarray(w.normal) * WALL_THICKNESS / 2.0,
             np.asarray(w.b) - np.asarray(w.normal) * WALL_THICKNESS / 2.0]
        )
        for w in world.walls
    ]
    out = []
    for body in world.bodies_with_label(WALL_LABEL):
        if body not in world._solid:
            continue
        footprint = world._boxes[body][0].buffer(1e-6)
        if any(footprint.covers(line) for line in behind):
            out.append(body)
    return out


def _shade_walls(world: SceneWorld, rgba: RGBA, rng: np.random.Generator, shade: float) -> None:
    """Plain walls: each wall box its own shade, up to ``shade`` darker than ``rgba``."""
    for body in world.bodies_with_label(WALL_LABEL):
        if body not in world._solid:
            continue  # the skirting
        k = float(1.0 - rng.uniform(0.0, shade))
        with world.lock:
            p.changeVisualShape(
                body, -1, rgbaColor=(rgba[0] * k, rgba[1] * k, rgba[2] * k, 1.0),
                physicsClientId=world.client,
            )
