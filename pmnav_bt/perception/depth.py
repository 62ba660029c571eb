"""Depth geometry: pixels to 3D points, floor and wall surfaces, a plate's pose on its wall.

The camera looks along the body's +x from ``camera_height`` with zero pitch; depth is
metres along the optical axis, and a real depth camera's "no return" (NaN, 0, inf) is
treated as unknown. Points are in the camera body frame: x forward, y left, z up (z = 0
at the camera; the floor is at z = -camera_height).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from pmnav_bt.seams import Observation, SurfaceMasks

FLOOR_TOL = 0.06  # m: |height| of a floor point, plus FLOOR_TOL_PER_M per metre of range
FLOOR_TOL_PER_M = 0.015
MAX_VERTICAL_NZ = 0.35  # |normal z| of a vertical surface
NORMAL_STEP = 3  # pixels between the neighbours a normal is taken from


def valid(depth: np.ndarray) -> np.ndarray:
    """Where the depth image has a return."""
    return np.isfinite(depth) & (depth > 0.0)


def back_project(obs: Observation) -> np.ndarray:
    """(H, W, 3) points in the camera body frame; NaN where depth has no return."""
    if obs.depth is None:
        raise ValueError("back_project needs an observation with depth")
    k = obs.intrinsics
    d = np.where(valid(obs.depth), obs.depth, np.nan).astype(np.float32)
    h, w = d.shape
    u = np.arange(w, dtype=np.float32)[None, :]
    v = np.arange(h, dtype=np.float32)[:, None]
    y = (k.cx - u) * d / k.fx
    z = (k.cy - v) * d / k.fy
    return np.dstack([d, y, z])


def normals(points: np.ndarray, step: int = NORMAL_STEP) -> np.ndarray:
    """(H, W, 3) unit surface normals from neighbouring points (NaN where unknown)."""
    p = points
    du = np.full_like(p, np.nan)
    dv = np.full_like(p, np.nan)
    du[:, step:-step] = p[:, 2 * step :] - p[:, : -2 * step]
    dv[step:-step] = p[2 * step :] - p[: -2 * step]
    n = np.cross(du, dv)
    norm = np.linalg.norm(n, axis=2, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return n / norm


def surfaces(obs: Observation) -> SurfaceMasks:
    """Floor (points at height ~0) and walls (vertical surfaces above the floor) from depth.

    Without depth both masks are empty (nothing is known).
    """
    h, w = obs.rgb.shape[:2]
    if obs.depth is None:
        empty = np.zeros((h, w), bool)
        return SurfaceMasks(empty, empty.copy())
    pts = back_project(obs)
    height = pts[..., 2] + obs.camera_height  # above the floor
    rng = pts[..., 0]
    ok = np.isfinite(height)
    tol = FLOOR_TOL + FLOOR_TOL_PER_M * np.nan_to_num(rng, nan=0.0)
    nz = np.abs(normals(pts)[..., 2])
    vertical = np.isfinite(nz) & (nz <= MAX_VERTICAL_NZ)
    # Floor: at floor height, and not the foot of a wall (unknown normals are allowed).
    floor = ok & (np.abs(np.nan_to_num(height, nan=1e9)) <= tol) & ~vertical
    wall = ok & ~floor & vertical & (np.nan_to_num(height, nan=-1.0) > tol)
    # Fill the one-pixel gaps that depth edges leave between neighbouring estimates.
    kernel = np.ones((3, 3), np.uint8)
    wall = cv2.morphologyEx(wall.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
    floor = cv2.morphologyEx(floor.astype(np.uint8), cv2.MORPH_CLOSE, kernel).astype(bool)
    return SurfaceMasks(floor=floor, wall=wall & ~floor)


@dataclass(frozen=True)
class PlatePose:
    """A plate on a wall, in the camera body frame: centre, unit wall direction towards the
    viewer's left, unit normal towards the camera (both horizontal), width along the wall."""

    centre: np.ndarray  # (3,)
    left: np.ndarray  # (3,), z = 0
    normal: np.ndarray  # (3,), z = 0
    width: float


def plate_pose(obs: Observation, box: tuple[float, float, float, float]) -> PlatePose | None:
    """Where the plate in ``box`` is, from the depth inside it (None without enough depth)."""
    if obs.depth is None:
        return None
    h, w = obs.depth.shape
    x0, y0 = max(0, int(math.floor(box[0]))), max(0, int(math.floor(box[1])))
    x1, y1 = min(w, int(math.ceil(box[2])) + 1), min(h, int(math.ceil(box[3])) + 1)
    pts = back_project(obs)[y0:y1, x0:x1].reshape(-1, 3)
    pts = pts[np.isfinite(pts).all(axis=1)]
    if len(pts) < 8:
        return None
    centre = np.median(pts, axis=0)
    # Drop what is far behind or in front of the plate (background through the box).
    pts = pts[np.abs(pts[:, 0] - centre[0]) < max(0.5, 0.25 * centre[0])]
    if len(pts) < 8:
        return None
    xy = pts[:, :2] - pts[:, :2].mean(axis=0)
    _, _, vt = np.linalg.svd(xy, full_matrices=False)
    t = vt[0]
    n = np.array([-t[1], t[0]])
    c2 = centre[:2]
    if float(n @ -c2) < 0:  # the normal points towards the camera
        n = -n
    left = np.array([n[1], -n[0]])  # facing the wall (along -n), left is -n turned +90 deg
    along = xy @ t
    width = float(np.percentile(along, 98) - np.percentile(along, 2))
    return PlatePose(
        centre=centre.astype(float),
        left=np.array([left[0], left[1], 0.0]),
        normal=np.array([n[0], n[1], 0.0]),
        width=width,
    )


def project(obs: Observation, pts: np.ndarray) -> np.ndarray:
    """Camera-body points (N, 3) -> pixels (N, 2) (u, v); points behind the camera -> NaN."""
    k = obs.intrinsics
    x = pts[:, 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where(x > 0.05, k.cx - pts[:, 1] * k.fx / x, np.nan)
        v = np.where(x > 0.05, k.cy - pts[:, 2] * k.fy / x, np.nan)
    return np.stack([u, v], axis=1)


def wall_rect(
    centre: np.ndarray, left: np.ndarray, half_width: float, z0: float, z1: float
) -> np.ndarray:
    """Corners (4, 3) of an upright rectangle on the wall: ``centre``'s lateral position,
    +-``half_width`` along ``left``, from height ``z0`` to ``z1`` (camera frame z)."""
    a = centre - left * half_width
    b = centre + left * half_width
    return np.array([[a[0], a[1], z1], [b[0], b[1], z1], [b[0], b[1], z0], [a[0], a[1], z0]], float)


def polygon_mask(obs: Observation, corners: np.ndarray) -> np.ndarray | None:
    """The image mask of a planar polygon in front of the camera (None if behind it)."""
    uv = project(obs, corners)
    if not np.isfinite(uv).all():
        return None
    h, w = obs.rgb.shape[:2]
    m = np.zeros((h, w), np.uint8)
    cv2.fillPoly(m, [np.round(uv).astype(np.int32)], 1)
    return m.astype(bool)
