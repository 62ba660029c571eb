"""Floor and walls from depth geometry, on synthetic depth images of a corridor."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.perception.corner import (
    MaskRatios,
    band_reach,
    central_band,
    is_corner,
    is_open_way,
    is_opening,
)
from pmnav_bt.perception.depth import plate_pose, surfaces
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.seams import CameraIntrinsics, Observation, Pose2D

K = CameraIntrinsics.from_hfov(320, 240, math.radians(60.0))
CAM_H = 1.6


def corridor_depth(ahead: float, half_width: float = 1.2) -> tuple[np.ndarray, np.ndarray]:
    """Depth of a corridor (floor, side walls, an end wall ``ahead`` m away, no ceiling)
    and the true labels: 0 floor, 1 wall."""
    v, u = np.mgrid[0 : K.height, 0 : K.width].astype(float)
    dy = (K.cx - u) / K.fx  # lateral per metre of depth
    dz = (K.cy - v) / K.fy  # up per metre of depth
    with np.errstate(divide="ignore"):
        t_floor = np.where(dz < 0, CAM_H / -dz, np.inf)
        t_side = np.where(dy != 0, half_width / np.abs(dy), np.inf)
    t_end = np.full_like(u, ahead)
    t_ceiling = np.where(dz > 0, (3.0 - CAM_H) / np.maximum(dz, 1e-9), np.inf)
    t = np.minimum.reduce([t_floor, t_side, t_end, t_ceiling])
    label = np.where(t == t_floor, 0, np.where(t == t_ceiling, 2, 1))
    return t.astype(np.float32), label


def obs_of(depth: np.ndarray) -> Observation:
    rgb = np.zeros((K.height, K.width, 3), np.uint8)
    return Observation(rgb, Pose2D(0, 0, 0), 0.0, K, depth=depth, camera_height=CAM_H)


def ratios(s) -> MaskRatios:
    rows, cols = central_band(s.floor.shape)
    return MaskRatios(float(s.wall[rows, cols].mean()), float(s.floor[rows, cols].mean()))


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / max((a | b).sum(), 1))


@pytest.mark.parametrize("ahead", [2.0, 12.0])
def test_floor_and_walls_match_the_geometry(ahead):
    depth, label = corridor_depth(ahead)
    s = surfaces(obs_of(depth))
    if ahead < 3.7:  # the floor comes into the 47 deg vertical view 3.7 m ahead
        assert not (label == 0).any() and not s.floor.any()
    else:
        assert iou(s.floor, label == 0) > 0.95
    assert iou(s.wall, label == 1) > 0.9
    assert not (s.wall & s.floor).any()
    assert not s.floor[label == 2].any() and not s.wall[label == 2].any()  # the ceiling


def test_the_mask_ratio_rule_tells_a_corner_from_a_corridor():
    assert is_corner(ratios(surfaces(obs_of(corridor_depth(1.8)[0]))))
    long = ratios(surfaces(obs_of(corridor_depth(15.0)[0])))
    assert is_opening(long) and not is_corner(long)


def test_the_band_shows_a_quarter_floor_where_the_floor_runs_its_reach():
    reach = band_reach(obs_of(corridor_depth(15.0)[0]))
    assert 4.5 < reach < 5.5  # the 1.6 m, 60 deg, 320 x 240 camera: about 4.9 m
    for ahead, share in ((reach - 0.3, False), (reach + 0.3, True)):
        assert is_opening(ratios(surfaces(obs_of(corridor_depth(ahead)[0])))) == share


@pytest.mark.parametrize(
    "ahead, run, open_",
    [
        (2.9, 2.9, True),  # a short leg to the next turn: the wall stands where the map's
        (2.2, 2.9, True),  # ... floor ends, or a little nearer (the estimate is off)
        (1.0, 2.9, False),  # a wall half a corridor ahead: a wrong turn
        (3.0, 10.0, False),  # the map's corridor goes on: the band decides, and says no
        (12.0, 10.0, True),  # ... and yes
    ],
)
def test_a_way_the_map_ends_short_is_judged_by_depth(ahead, run, open_):
    """The band sees no floor nearer than 3.7 m, so a way the map itself ends within the
    band's reach (a short leg, a lane towards a hall's far wall) is open when depth shows
    the floor free to about where the map's ends."""
    obs = obs_of(corridor_depth(ahead)[0])
    r = ratios(surfaces(obs))
    free = free_distance(obs, 0.0)
    assert free == pytest.approx(ahead, abs=0.1)
    assert is_open_way(r, free, run, band_reach(obs)) == open_
    assert not is_open_way(r, None, run, band_reach(obs)) or is_opening(r)  # no depth


def test_no_return_pixels_are_neither_and_the_rule_still_holds():
    rng = np.random.default_rng(0)
    depth, _ = corridor_depth(15.0)
    holes = rng.random(depth.shape) < 0.1
    depth[holes] = np.where(rng.random(holes.sum()) < 0.5, np.nan, 0.0)
    s = surfaces(obs_of(depth))
    r = ratios(s)
    assert is_opening(r) and not is_corner(r)
    isolated = holes & ~np.roll(holes, 1, 0) & ~np.roll(holes, -1, 0)
    assert s.floor[isolated].mean() < 1.0  # some holes stay unknown after closing


def test_without_depth_nothing_is_known():
    obs = Observation(np.zeros((240, 320, 3), np.uint8), Pose2D(0, 0, 0), 0.0, K)
    s = surfaces(obs)
    assert not s.floor.any() and not s.wall.any()


def test_a_plate_on_an_oblique_wall_is_placed_and_oriented():
    """A wall at 45 deg: the plate's normal points back at the camera, its 'left' runs
    along the wall."""
    v, u = np.mgrid[0 : K.height, 0 : K.width].astype(float)
    dy = (K.cx - u) / K.fx
    # Wall through (3, 0) with normal (-1, -1)/sqrt2 (facing the camera): x + y = 3.
    depth = (3.0 / (1.0 + dy)).astype(np.float32)
    p = plate_pose(obs_of(depth), (150, 110, 170, 130))
    assert p.centre[0] == pytest.approx(3.0, abs=0.1)
    assert p.normal[:2] @ np.array([-1, -1]) / math.sqrt(2) == pytest.approx(1.0, abs=0.02)
    # Facing the wall (along -normal, i.e. (1, 1)), left is along (-1, 1).
    assert p.left[:2] @ np.array([-1, 1]) / math.sqrt(2) == pytest.approx(1.0, abs=0.02)
