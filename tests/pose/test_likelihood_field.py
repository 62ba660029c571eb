"""The grid wall model: depth weighed against a building's occupancy grid as a likelihood
field (``pose.evidence.likelihood_field``), and the choice of wall model by name
(``pose.evidence.floor_model``)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from pmnav_bt.behaviours.belief import FREE_BEARINGS
from pmnav_bt.errors import ConfigError
from pmnav_bt.map.floorplan import FloorPlanImage, load_ros_map
from pmnav_bt.pose.evidence.floor import P_DEPTH
from pmnav_bt.pose.evidence.floor_model import building_grid, wall_source
from pmnav_bt.pose.evidence.likelihood_field import GridFloor, LikelihoodField
from pmnav_bt.seams import Pose2D

HOSPITAL_MAP = Path(__file__).resolve().parents[2] / "examples" / "hospital" / "hospital.yaml"
ORIGIN = Pose2D(0.0, 0.0, 0.0)  # the robot's odometry pose: each hypothesis is its map pose
RES = 0.05


def look_round(occupied: np.ndarray, plan: FloorPlanImage, pose: tuple[float, float, float]):
    """What a six-view look round from ``pose`` (map) shows in depth: (bearing from the
    heading, free floor m) along each view's ``FREE_BEARINGS``, cast through the grid's
    non-free cells in 1 cm steps (not the model's own march)."""
    x, y, yaw = pose
    s = np.arange(0.01, 50.0, 0.01)
    rays = []
    for view in np.radians(np.arange(0.0, 360.0, 60.0)):
        for b in FREE_BEARINGS:
            a = yaw + view + b
            pts = np.stack([x + s * math.cos(a), y + s * math.sin(a)], 1)
            col, row = plan.world_to_cell(pts).T
            inside = (col >= 0) & (col < plan.width) & (row >= 0) & (row < plan.height)
            hit = ~inside
            hit[inside] |= occupied[row[inside], col[inside]]
            rays.append((float(view + b), float(s[np.argmax(hit)]) if hit.any() else 50.0))
    return rays


def weigh(floor: GridFloor, tfs: np.ndarray, rays) -> np.ndarray:
    logw = np.zeros(len(tfs))
    here = tfs[:, :2].copy()
    floor.stand(logw, here)
    for yaw, free in rays:
        floor.depth_ray(logw, tfs, here, ORIGIN, yaw, free, 0.0, True)
    return logw


@pytest.fixture(scope="module")
def hospital():
    if not HOSPITAL_MAP.exists():
        pytest.skip(f"the hospital's real SLAM map is not here ({HOSPITAL_MAP})")
    plan = load_ros_map(HOSPITAL_MAP)
    return plan, LikelihoodField.of(plan)


# Places in the hospital's corridors (map x, y, the corridor's heading): a long corridor,
# beside a cross corridor, the lobby's edge.
PLACES = [(-6.0, -12.6, -math.pi / 2), (3.9, -20.0, math.pi / 2), (-1.0, 0.4, 0.0)]


@pytest.mark.parametrize("place", PLACES)
def test_on_the_real_grid_the_true_pose_outweighs_one_half_a_metre_or_ten_degrees_off(
    hospital, place
):
    """The look round from the true pose, cast through the real grid (walls a few cells
    thick, rooms behind them, pillars), is explained best by the true pose: shifted 0.5 m
    along or across the corridor, or turned 10 deg, the returns end off the walls."""
    plan, field = hospital
    x, y, h = place
    assert field.surface(np.array([[x, y]]))[0] > 0.5, "the place must be on the floor"
    rays = look_round(plan.occupancy() != 0, plan, (x, y, h))
    along, across = np.array([math.cos(h), math.sin(h)]), np.array([-math.sin(h), math.cos(h)])
    off = [(*(np.array([x, y]) + d * v), h) for v in (along, across) for d in (-0.5, 0.5)]
    off += [(x, y, h + t) for t in (math.radians(-10.0), math.radians(10.0))]
    tfs = np.array([(x, y, h), *off])
    logw = weigh(GridFloor(field), tfs, rays)
    assert logw[0] > logw[1:].max(), logw


def corridor_and_room() -> FloorPlanImage:
    """A 10 x 6 m grid: a corridor 2 m wide along x (y 1-3), a room north of it (y 3.2-5.5,
    x 2-6) behind a wall 0.2 m thick (as the hospital's SLAM walls), with a door at x 5-6."""
    occ = np.zeros((120, 200), np.uint8)  # occupied (black)

    def free(x0, y0, x1, y1):
        occ[120 - round(y1 / RES) : 120 - round(y0 / RES), round(x0 / RES) : round(x1 / RES)] = 255

    free(0.5, 1.0, 9.5, 3.0)
    free(2.0, 3.2, 6.0, 5.5)
    free(5.0, 3.0, 6.0, 3.2)
    return FloorPlanImage(occ, RES, (0.0, 0.0, 0.0))


def test_floor_seen_through_a_thin_wall_costs_what_a_corridor_wall_does():
    """Depth saw 3 m of floor north from (3, 2): under a hypothesis with the room's wall
    1 m ahead (0.2 m thick, the room behind it free) that is floor through a wall
    (``P_DEPTH``); under one facing the door the floor runs on into the room."""
    floor = GridFloor(LikelihoodField.of(corridor_and_room()))
    north = math.pi / 2
    tfs = np.array([(3.0, 2.0, north), (5.5, 2.0, north)])
    logw = np.zeros(2)
    floor.depth_ray(logw, tfs, tfs[:, :2].copy(), ORIGIN, 0.0, 3.0, 0.0, True)
    assert logw[0] - logw[1] < 0.8 * math.log(P_DEPTH)


def test_a_ray_grazing_a_side_wall_a_little_off_is_no_contradiction():
    """The robot 0.25 m off where a hypothesis puts it: a ray 10 deg off the corridor
    ends on the side wall 1.4 m further than that hypothesis's wall, but only 0.25 m
    beyond it across the wall: within the slack, no ``P_DEPTH``."""
    floor = GridFloor(LikelihoodField.of(corridor_and_room()))
    truth = np.array([(2.5, 2.0, 0.0)])
    off = np.array([(2.5, 2.25, 0.0)])
    free = 1.0 / math.sin(math.radians(10.0))  # to the wall at y = 3 from y = 2
    for tfs in (truth, off):
        logw = np.zeros(1)
        floor.depth_ray(logw, tfs, tfs[:, :2].copy(), ORIGIN, math.radians(10.0), free, 0.0, True)
        assert logw[0] > math.log(P_DEPTH) / 2.0


def test_a_door_seen_through_a_wall_is_out_of_sight_and_through_its_doorway_in_sight():
    floor = GridFloor(LikelihoodField.of(corridor_and_room()))
    a = np.array([(3.0, 2.0), (5.5, 2.0)])
    b = np.array([(3.0, 4.5), (5.5, 4.5)])
    assert floor.clear(a, b).tolist() == [False, True]


def test_a_drive_blocked_where_the_floor_runs_on_is_unlikely():
    floor = GridFloor(LikelihoodField.of(corridor_and_room()))
    tfs = np.array([(8.7, 2.0, 0.0), (4.0, 2.0, 0.0)])  # 0.8 m from the end wall; open
    logw = floor.blocked_log(tfs, (0.0, 0.0), 0.0)
    assert logw[0] == 0.0 and logw[1] < 0.0


def test_the_floor_round_a_place_ends_at_the_walls():
    floor = GridFloor(LikelihoodField.of(corridor_and_room()))
    d = floor.reach(np.array([3.0, 2.0]), np.array([0.0, math.pi, -math.pi / 2]), 8.0)
    assert d == pytest.approx([6.5, 2.5, 1.0], abs=0.1)


def test_the_grid_is_the_default_wall_model_where_the_building_has_one():
    plan = corridor_and_room()
    assert wall_source(None, plan).name == "grid"
    assert wall_source(None, None).name == "corridors"
    assert wall_source("corridors", plan).field is None


def test_the_grid_wall_model_for_a_building_without_a_grid_is_one_clear_error():
    with pytest.raises(ConfigError, match="floor_plan.ros_map"):
        wall_source("grid", None)


def test_a_building_grid_is_its_ros_map_only():
    from pmnav_bt.map.catalogue import load_building

    assert building_grid(load_building("fig2_hospital"), ".") is None
    if not HOSPITAL_MAP.exists():
        pytest.skip("the hospital example is not here")
    plan = building_grid(load_building(HOSPITAL_MAP.parent / "building.yaml"), HOSPITAL_MAP.parent)
    assert plan is not None and plan.resolution == pytest.approx(0.05)


def test_a_plate_read_two_metres_from_its_door_does_not_move_a_fix_the_walls_placed(hospital):
    """examples/hospital, grid walls, Table 3 minimal #2: facing south at (-5.98, -23.46),
    room19's plate is read 2.2 m north of where the map puts its door. The sign alone
    would move the fix 2 m along the corridor; the walls in view say the robot is where
    the belief's hypothesis puts it, and the fix stays there."""
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.pose.belief import CorridorBelief
    from pmnav_bt.pose.glimpse import Glimpse
    from pmnav_bt.seams import Entity

    plan, field = hospital
    pm = parse_building(load_building(HOSPITAL_MAP.parent / "building.yaml"))
    truth = (-5.98, -23.46, -math.pi / 2)
    rays = tuple((truth[2] + a, f) for a, f in look_round(plan.occupancy() != 0, plan, truth))
    odom = Pose2D(*truth)  # odometry starts out as the map here
    seen = {Entity.room("room19"): (-7.58, -20.77)}
    belief = CorridorBelief(pm, walls=wall_source("grid", plan))
    belief.observe(Glimpse(odom, seen, free=rays), axis_odom=truth[2])
    tf, _ = belief.fix()
    assert math.dist(tf[:2], (0.0, 0.0)) < 0.5 and abs(tf[2]) < math.radians(5.0)
