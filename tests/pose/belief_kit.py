"""Shared by the corridor belief's tests: what a robot at a true pose would see, in an
odometry frame that is anywhere (``ODOM_T_MAP``), and simple drives along the corridors."""

from __future__ import annotations

import math

import numpy as np
import shapely

from pmnav_bt.behaviours.belief import FREE_BEARINGS, RAY_HALF_WIDTH_M
from pmnav_bt.geometry import se2_apply, se2_compose
from pmnav_bt.pose.belief import CorridorBelief
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.seams import Pose2D

ODOM_T_MAP = (3.0, -2.0, 0.7)  # the odometry frame is anywhere


def glimpse(pm, true: tuple[float, float, float], entities, blocked=None, depth=False):
    """What a panorama at ``true`` (map) sees, in odometry; ``depth``: the free floor
    ahead in the four directions along and across the robot's heading, as depth gives it."""
    odom = se2_compose(ODOM_T_MAP, true)
    seen = {e: tuple(se2_apply(ODOM_T_MAP, entity_xy(pm, e))) for e in entities}
    free = ()
    if depth:
        free = tuple(
            (h + ODOM_T_MAP[2], free_along(pm, true, h))
            for h in (true[2] + k * math.pi / 2 for k in range(4))
        )
    return Glimpse(Pose2D(*odom), seen, blocked, free)


def free_along(pm, true, h: float, step: float = 0.25, half_width: float = 0.0) -> float:
    """The free floor along heading ``h`` (map) from ``true``, to ``step``, as depth sees it
    along a strip ``half_width`` either side of the line."""
    poly = Visibility.of(pm).corridors
    u, n = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    free = 50.0
    for side in {-half_width, 0.0, half_width}:
        o = np.asarray(true[:2]) + side * n
        for i in range(1, int(15.0 / step)):
            if not poly.covers(shapely.Point(*(o + step * i * u))):
                free = min(free, step * (i - 1))
                break
    return free


def points_reading(pm, n_readable):
    vis = Visibility.of(pm)
    return [p for p in vis.lattice_points if len(p.readable) == n_readable]


def drive_on_centre(pm, xy, map_heading: float, distance: float):
    """Move ``distance`` along a heading, staying on the corridor centre lines."""
    p = np.asarray(xy, dtype=float)
    for _ in range(int(distance / 0.25)):
        q = p + 0.25 * np.array([math.cos(map_heading), math.sin(map_heading)])
        loc = pm.locate(*q)
        if loc.offset > 0.3:  # a wall or a dead end ahead
            break
        p = loc.point(pm)
    return p


def drive_straight(pm, xy, map_heading: float, distance: float):
    """Move ``distance`` straight on (a robot that keeps its heading, off the centre line
    too) until 0.3 m from a wall."""
    floor = shapely.buffer(Visibility.of(pm).corridors, -0.3)
    u = np.array([math.cos(map_heading), math.sin(map_heading)])
    p = np.asarray(xy, dtype=float)
    for _ in range(int(distance / 0.25)):
        if not floor.covers(shapely.Point(*(p + 0.25 * u))):
            break
        p = p + 0.25 * u
    return p


def apply_tfs(tfs: np.ndarray, p) -> np.ndarray:
    return np.stack([se2_apply(tuple(t), p) for t in tfs])


def weight_near(b: CorridorBelief, odom, xy, yaw) -> float:
    """The weight of the hypothesis that puts the robot nearest ``xy`` facing ``yaw`` (map)."""
    tfs = b.map_T_odoms()
    here = apply_tfs(tfs, (odom.x, odom.y))
    err = np.linalg.norm(here - np.asarray(xy), axis=1) + 3.0 * np.abs(
        np.angle(np.exp(1j * (tfs[:, 2] + odom.yaw - yaw)))
    )
    return float(b.weights()[int(np.argmin(err))])


def look_at(pm, true, odom_xy, blocked=None) -> Glimpse:
    """A panorama at ``true`` (map pose) with the robot at ``odom_xy`` in odometry: no
    sign read, the free floor along each view's thin rays (as ``read_panorama`` gives)."""
    yaw = true[2] + ODOM_T_MAP[2]
    rays = [math.radians(60.0 * v) + b for v in range(6) for b in FREE_BEARINGS]
    free = tuple((yaw + a, free_along(pm, true, true[2] + a, 0.05, RAY_HALF_WIDTH_M)) for a in rays)
    return Glimpse(Pose2D(odom_xy[0], odom_xy[1], yaw), {}, blocked, free)


def drive_rays(pm, b: CorridorBelief, true, odom_xy, distance: float) -> tuple[float, float]:
    """Drive ``distance`` straight on from ``true`` (map pose; odometry ``odom_xy``), a
    depth ray and the walls' axis a metre to the belief; the odometry position at the end."""
    (x, y, h), step = true, 0.25
    yaw = h + ODOM_T_MAP[2]
    for i in range(1, int(distance / step) + 1):
        odom = Pose2D(
            odom_xy[0] + i * step * math.cos(yaw), odom_xy[1] + i * step * math.sin(yaw), yaw
        )
        if i % 4 == 0:
            here = (x + i * step * math.cos(h), y + i * step * math.sin(h), h)
            b.observe_ray(odom, free_along(pm, here, h), yaw)
    return odom.x, odom.y
