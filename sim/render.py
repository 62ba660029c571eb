"""Images of a SimWorld: first-person camera frames (tiny renderer) and a drawn top-down map."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import cv2
import numpy as np
import shapely

from pmnav_bt.seams import CAMERA_HEIGHT_M, CREATE3_RADIUS_M, CameraIntrinsics, Pose2D
from pmnav_bt.sim._pybullet import p

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.sim.world import SimWorld

NEAR = 0.05  # clipping planes, metres
FAR = 100.0
# The tiny renderer never returns when the eye lies (to float32 precision) in the plane of a
# face, which round teleport poses easily hit (a camera at x = -1.3 beside a wall face at
# x = -1.3). The eye is therefore moved by this sub-millimetre offset, off all round numbers.
GRID_WALL_RGB = (130, 120, 100)  # top-down: the grid's walls (walls="grid")
EYE_JITTER = (1.37e-4, 1.71e-4, 1.13e-4)


@dataclass
class Frame:
    """One camera frame: RGB, depth along the optical axis (m), label-id segmentation."""

    rgb: np.ndarray  # (H, W, 3) uint8
    depth: np.ndarray | None  # (H, W) float32
    segmentation: np.ndarray | None  # (H, W) int32 label ids (SimWorld.labels)


def linearise_depth(zbuf: np.ndarray, near: float = NEAR, far: float = FAR) -> np.ndarray:
    """OpenGL z-buffer values in [0, 1] -> metric depth along the optical axis."""
    z = np.asarray(zbuf, np.float64)
    return (far * near / (far - (far - near) * z)).astype(np.float32)


def render_camera(
    world: SimWorld,
    x: float,
    y: float,
    yaw: float,
    intrinsics: CameraIntrinsics,
    *,
    height: float = CAMERA_HEIGHT_M,
    pitch: float = 0.0,
    depth: bool = True,
    segmentation: bool = True,
    window: tuple[int, int, int, int] | None = None,
) -> Frame:
    """Render the view of a camera at (x, y, height) looking along ``yaw`` (tilted by ``pitch``).

    ``window`` (x0, y0, x1, y1, pixels of the camera's image): render only that part of
    the image (an off-axis frustum: the same pixels, for a fraction of the cost).
    Uses pybullet's headless tiny renderer, under the world's lock, lit by the world's
    light (``world.appearance.light``).
    """
    w, h = intrinsics.width, intrinsics.height
    vfov = 2.0 * math.atan((h / 2.0) / intrinsics.fy)
    full_w = w
    if window is not None:
        x0, y0, x1, y1 = window
        w, h = x1 - x0, y1 - y0
    fwd = (math.cos(yaw) * math.cos(pitch), math.sin(yaw) * math.cos(pitch), math.sin(pitch))
    jx, jy, jz = EYE_JITTER
    eye = (x + jx, y + jy, height + jz)
    target = (eye[0] + fwd[0], eye[1] + fwd[1], eye[2] + fwd[2])
    flags = 0 if segmentation else p.ER_NO_SEGMENTATION_MASK
    light = world.appearance.light
    with world.lock:
        world.people.show()  # the walking people where they are now
        c = world.client
        view = p.computeViewMatrix(eye, target, (0.0, 0.0, 1.0), physicsClientId=c)
        if window is None:
            proj = p.computeProjectionMatrixFOV(
                math.degrees(vfov), w / h, NEAR, FAR, physicsClientId=c
            )
        else:  # the sub-frustum of the full image's pixels x0..x1, y0..y1
            top = NEAR * math.tan(vfov / 2.0)
            right = top * full_w / intrinsics.height
            sx, sy = 2.0 * right / full_w, 2.0 * top / intrinsics.height
            proj = p.computeProjectionMatrix(
                -right + sx * x0,
                -right + sx * x1,
                top - sy * y1,
                top - sy * y0,
                NEAR,
                FAR,
                physicsClientId=c,
            )
        _, _, rgba, zbuf, seg = p.getCameraImage(
            w,
            h,
            view,
            proj,
            shadow=0,
            lightDirection=light.direction,
            lightAmbientCoeff=light.ambient,
            lightDiffuseCoeff=light.diffuse,
            lightSpecularCoeff=0.0,
            renderer=p.ER_TINY_RENDERER,
            flags=flags,
            physicsClientId=c,
        )
        labels = (
            world.segmentation_to_labels(np.asarray(seg).reshape(h, w)) if segmentation else None
        )
    rgb = np.ascontiguousarray(np.asarray(rgba, np.uint8).reshape(h, w, 4)[:, :, :3])
    d = linearise_depth(np.asarray(zbuf).reshape(h, w)) if depth else None
    return Frame(rgb, d, labels)


# -- false colour ------------------------------------------------------------------------


def colorize_depth(depth: np.ndarray, max_m: float = 15.0) -> np.ndarray:
    """Depth (m) -> RGB with the turbo colormap: near red, far (``max_m`` and beyond) dark blue."""
    d = np.clip(np.nan_to_num(depth, nan=max_m) / max_m, 0.0, 1.0)
    img = cv2.applyColorMap(((1.0 - d) * 255).astype(np.uint8), cv2.COLORMAP_TURBO)
    return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)


def label_colour(label: str) -> tuple[int, int, int]:
    """A fixed RGB colour per label (kind colours for the fixed labels, hashed otherwise)."""
    fixed = {
        "background": (0, 0, 0),
        "floor": (90, 90, 160),
        "wall": (200, 200, 200),
        "ceiling": (120, 120, 120),
        "obstacle": (255, 120, 0),
        "robot": (255, 0, 255),
    }
    if label in fixed:
        return fixed[label]
    h = sum((i + 1) * ord(ch) for i, ch in enumerate(label))
    base = {"door": (150, 80, 20), "sign": (0, 200, 60), "landmark": (220, 40, 40)}
    r, g, b = base.get(label.split(":")[0], (200, 200, 0))
    jitter = (h * 37) % 70 - 35
    return tuple(int(np.clip(v + jitter, 0, 255)) for v in (r, g, b))  # type: ignore[return-value]


def colorize_segmentation(seg: np.ndarray, labels: dict[int, str]) -> np.ndarray:
    """Label-id image -> RGB."""
    lut = np.zeros((max(labels, default=0) + 1, 3), np.uint8)
    for i, name in labels.items():
        lut[i] = label_colour(name)
    return lut[np.clip(seg, 0, len(lut) - 1)]


def annotate_labels(rgb: np.ndarray, seg: np.ndarray, labels: dict[int, str]) -> np.ndarray:
    """Write each door/sign/landmark label at its region's centre (for a person to check)."""
    out = rgb.copy()
    for i in np.unique(seg):
        name = labels.get(int(i), "")
        if ":" not in name:
            continue
        ys, xs = np.nonzero(seg == i)
        if len(xs) < 30:
            continue
        org = (int(xs.mean()) - 4 * len(name), int(ys.mean()))
        cv2.putText(out, name, org, cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 2)
        cv2.putText(out, name, org, cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 0), 1)
    return out


# -- top-down map --------------------------------------------------------------------------


def draw_top_down(
    world: SimWorld,
    pose: Pose2D | None = None,
    *,
    px_per_m: float = 20.0,
    hfov: float = math.radians(60.0),
    margin_m: float = 3.0,
) -> np.ndarray:
    """A labelled plan of the world (RGB, north up): corridors, walls, doors, signs,
    landmarks, waypoints, obstacles and the robot with its field of view."""
    x0, y0, x1, y1 = world.bounds(margin=margin_m)
    w = int(math.ceil((x1 - x0) * px_per_m))
    h = int(math.ceil((y1 - y0) * px_per_m))
    img = np.full((h, w, 3), (60, 60, 60), np.uint8)

    def px(pt) -> tuple[int, int]:
        return int(round((pt[0] - x0) * px_per_m)), int(round((y1 - pt[1]) * px_per_m))

    def text(s: str, at, colour=(0, 0, 0), scale=0.4) -> None:
        cv2.putText(img, s, at, cv2.FONT_HERSHEY_SIMPLEX, scale, (255, 255, 255), 3, cv2.LINE_AA)
        cv2.putText(img, s, at, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv2.LINE_AA)

    polys = getattr(world.free_space, "geoms", [world.free_space])
    for poly in polys:
        cv2.fillPoly(
            img, [np.array([px(q) for q in poly.exterior.coords], np.int32)], (205, 210, 225)
        )
        for ring in poly.interiors:
            cv2.fillPoly(img, [np.array([px(q) for q in ring.coords], np.int32)], (60, 60, 60))
    thick = max(2, int(round(0.1 * px_per_m)))
    for wall in world.walls[: world.annotated_walls]:
        cv2.line(img, px(wall.a), px(wall.b), (235, 225, 190), thick)
    if world.wall_source == "grid":  # the grid's walls, which the items hang on
        grid_walls = shapely.box(*world.bounds()).difference(world.floor_space())
        for g in getattr(grid_walls, "geoms", [grid_walls]):
            rings = (g.exterior, *g.interiors)
            pts = [np.array([px(q) for q in r.coords], np.int32) for r in rings]
            cv2.fillPoly(img, pts, GRID_WALL_RGB)

    b = world.building
    pos = {wp.id: wp.pos for wp in b.waypoints}
    for e in b.edges:
        cv2.line(img, px(pos[e.a]), px(pos[e.b]), (150, 150, 170), 1, cv2.LINE_AA)
    for wp in b.waypoints:
        cv2.circle(img, px(wp.pos), 4, (40, 40, 200), -1)
        q = px(wp.pos)
        text(f"{wp.id} ({wp.kind.value})", (q[0] + 5, q[1] - 5), (40, 40, 200))

    def mark(item, colour, half_depth: float) -> None:
        n = np.asarray(item.normal)
        t = np.array([-n[1], n[0]])
        c = np.asarray(item.centre)
        corners = [
            c + t * item.width / 2,
            c - t * item.width / 2,
            c - t * item.width / 2 + n * half_depth,
            c + t * item.width / 2 + n * half_depth,
        ]
        cv2.fillPoly(img, [np.array([px(q) for q in corners], np.int32)], colour)

    for rid, door in world.doors.items():
        mark(door, _door_colour(world, rid), 0.25)
        n = np.asarray(door.normal)
        q = px(np.asarray(door.centre) - n * 0.9)
        text(rid, (q[0] - 4 * len(rid), q[1] + 4), (120, 60, 20))
    for sign in world.signs.values():
        mark(sign, (0, 170, 60), 0.15)
    for lid, lm in world.landmarks.items():
        mark(lm, (200, 40, 40), 0.5)
        n = np.asarray(lm.normal)
        q = px(np.asarray(lm.centre) - n * 1.4)
        text(f"{lid} [{lm.kind}]", (q[0] - 3 * len(lid), q[1] + 4), (170, 20, 20))
    for sign in world.landmark_signs.values():
        mark(sign, (0, 170, 60), 0.15)
    for sign in world.directional_signs.values():  # wayfinding signs, blue
        mark(sign, (30, 110, 230), 0.15)
    _draw_clutter(img, world, px)
    _draw_people(img, world, px, px_per_m)
    for ox, oy, size in world.obstacles.values():
        cv2.rectangle(
            img,
            px((ox - size / 2, oy + size / 2)),
            px((ox + size / 2, oy - size / 2)),
            (255, 120, 0),
            -1,
        )

    if pose is not None:
        c = px((pose.x, pose.y))
        r = max(3, int(round(CREATE3_RADIUS_M * px_per_m)))
        reach = 4.0
        for s in (-1, 1):
            end = (
                pose.x + reach * math.cos(pose.yaw + s * hfov / 2),
                pose.y + reach * math.sin(pose.yaw + s * hfov / 2),
            )
            cv2.line(img, c, px(end), (255, 0, 255), 1, cv2.LINE_AA)
        cv2.circle(img, c, r, (255, 0, 255), -1)
        tip = (pose.x + 0.5 * math.cos(pose.yaw), pose.y + 0.5 * math.sin(pose.yaw))
        cv2.line(img, c, px(tip), (0, 0, 0), 2, cv2.LINE_AA)
    _legend(img, world)
    title = f"{b.name} ({b.kind})   1 m = {px_per_m:g} px"
    cv2.putText(
        img, title, (8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.55, (255, 255, 255), 1, cv2.LINE_AA
    )
    return img


# Clutter kinds in the top-down plan (RGB), and how the plan tells them apart.
CLUTTER_COLOURS = {
    "bench": (200, 190, 60),
    "chair": (230, 150, 40),
    "cart": (70, 130, 200),
    "bed": (240, 240, 240),
    "plant": (30, 110, 30),
    "notice_board": (170, 60, 170),
}


def _draw_clutter(img: np.ndarray, world: SimWorld, px) -> None:
    """Each clutter item's footprint in its kind's colour, outlined in black (a thin one,
    a notice board, drawn 0.1 m deep so that it shows)."""
    for item in world.clutter:
        fp = item.footprint
        if item.depth < 0.1:
            fp = fp.buffer(0.05, join_style="mitre")
        pts = np.array([px(q) for q in fp.exterior.coords], np.int32)
        cv2.fillPoly(img, [pts], CLUTTER_COLOURS.get(item.kind, (255, 120, 0)))
        if item.depth >= 0.1:
            cv2.polylines(img, [pts], True, (0, 0, 0), 1, cv2.LINE_AA)


PERSON_COLOUR = (230, 40, 90)
OPEN_DOOR_COLOUR = (30, 30, 30)
GLASS_DOOR_COLOUR = (140, 200, 225)


def _door_colour(world: SimWorld, room: str) -> tuple[int, int, int]:
    """A door in the plan: brown when closed, black when open, pale blue when glazed."""
    state = world.door_states.get(room)
    if state is not None and state.open:
        return OPEN_DOOR_COLOUR
    if state is not None and state.glass:
        return GLASS_DOOR_COLOUR
    return (150, 90, 40)


def _draw_people(img: np.ndarray, world: SimWorld, px, px_per_m: float) -> None:
    """Each walking person where they stand now: a disc of their size, a tick where they face."""
    from pmnav_bt.sim.scene.people import PERSON_RADIUS_M

    r = max(3, int(round(PERSON_RADIUS_M * px_per_m)))
    for q in world.people.poses():
        c = px((q.x, q.y))
        cv2.circle(img, c, r, PERSON_COLOUR, -1, cv2.LINE_AA)
        cv2.circle(img, c, r, (255, 255, 255), 1, cv2.LINE_AA)
        tip = (q.x + 0.5 * math.cos(q.yaw), q.y + 0.5 * math.sin(q.yaw))
        cv2.line(img, c, px(tip), (0, 0, 0), 2, cv2.LINE_AA)


def _legend(img: np.ndarray, world: SimWorld) -> None:
    """The clutter kinds present, in a row along the bottom edge (in the plan's margin)."""
    x, y = 8, img.shape[0] - 8
    for kind in sorted({item.kind for item in world.clutter}):
        cv2.rectangle(img, (x, y - 11), (x + 12, y), CLUTTER_COLOURS.get(kind, (255, 120, 0)), -1)
        cv2.rectangle(img, (x, y - 11), (x + 12, y), (0, 0, 0), 1)
        cv2.putText(
            img, kind, (x + 18, y), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1, cv2.LINE_AA
        )
        x += 18 + 10 * len(kind) + 16
    if world.people.people:
        cv2.circle(img, (x + 6, y - 5), 6, PERSON_COLOUR, -1, cv2.LINE_AA)
        cv2.putText(
            img, "person", (x + 18, y), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (255, 255, 255), 1,
            cv2.LINE_AA,
        )
