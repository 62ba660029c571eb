"""Draft extraction: grids rasterised from the built-in buildings give back their corridors."""

from __future__ import annotations

import numpy as np
import pytest

from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.draft import DraftError, draft_building
from pmnav_bt.map.floorplan import FloorPlanImage, load_ros_map, rasterize_building, save_ros_map


def _draft(name, tmp_path):
    truth = load_building(name)
    grid = save_ros_map(rasterize_building(truth), tmp_path / f"{name}.yaml")
    drafted, draft, text = draft_building(grid, tmp_path / "out" / "building.yaml")
    return truth, drafted, draft, text


@pytest.mark.parametrize("name", builtin_buildings())
def test_draft_recovers_builtin_building(name, tmp_path):
    truth, got, _, _ = _draft(name, tmp_path)
    dp = {w.id: np.array(w.pos) for w in got.waypoints}
    match = {}
    for w in truth.waypoints:
        near = min(dp, key=lambda k: np.linalg.norm(dp[k] - w.pos))
        assert np.linalg.norm(dp[near] - w.pos) <= 0.5, f"{w.id} at {w.pos}: nearest {near}"
        match[w.id] = near
    assert len(set(match.values())) == len(truth.waypoints) == len(got.waypoints)
    want = {frozenset((match[e.a], match[e.b])): truth.edge_width(e) for e in truth.edges}
    have = {frozenset((e.a, e.b)): got.edge_width(e) for e in got.edges}
    assert set(want) == set(have), "corridor graph topology differs"
    for k, w in want.items():
        assert abs(have[k] - w) <= 0.3, f"width of {sorted(k)}: {have[k]} vs {w}"
    for w in truth.waypoints:
        assert got.waypoint(match[w.id]).kind.value in (w.kind.value, "start", "end") or (
            w.kind.value in ("start", "end")
        )
    t = np.array([r.door for r in truth.rooms])
    d = np.array([r.door for r in got.rooms]).reshape(-1, 2)
    dist = np.linalg.norm(t[:, None] - d[None], axis=2)
    recall = (dist.min(axis=1) < 0.5).mean()
    precision = (dist.min(axis=0) < 0.5).mean() if len(d) else 0.0
    assert recall >= 0.9 and precision >= 0.9, (precision, recall)


def test_doors_lie_exactly_on_the_annotated_wall(tmp_path):
    _, got, _, _ = _draft("t_school", tmp_path)
    from pmnav_bt.map.floorplan import door_frames

    for f in door_frames(got):
        off = np.dot(np.subtract(f.door, f.foot), f.out)
        assert off == pytest.approx(f.wall, abs=0.011)


def test_draft_marks_what_a_person_must_add(tmp_path):
    _, got, _, text = _draft("l_hospital", tmp_path)
    assert "todo: name, sign" in text
    assert got.floor_plan.ros_map == "../l_hospital.yaml"  # relative to the output file
    assert sum(w.kind.value == "start" for w in got.waypoints) == 1
    assert all(r.name == "" for r in got.rooms)


def test_open_area_is_flagged_not_made_a_corridor(tmp_path):
    b = load_building("straight_office")
    plan = rasterize_building(b)
    # Carve a 10 m x 10 m hall at the west end.
    xy = plan.world_to_pixel([[b.waypoints[0].pos[0] - 1, -5], [b.waypoints[0].pos[0] + 9, 5]])
    (c0, r1), (c1, r0) = np.round(xy).astype(int)
    plan.image[max(r0, 0) : r1, max(c0, 0) : c1] = 254
    grid = save_ros_map(plan, tmp_path / "hall.yaml")
    got, draft, text = draft_building(grid, tmp_path / "b.yaml")
    assert len(draft.open_areas) == 1
    assert "open area 1" in text
    a = draft.open_areas[0]
    for w in got.waypoints:  # no corridor waypoint deep inside the hall
        inside = a.xmin + 1 < w.pos[0] < a.xmax - 1 and a.ymin + 1 < w.pos[1] < a.ymax - 1
        assert not inside, w


def test_a_grid_without_corridors_is_a_draft_error(tmp_path):
    img = np.full((40, 40), 205, np.uint8)
    grid = save_ros_map(FloorPlanImage(img, 0.05, (0.0, 0.0, 0.0)), tmp_path / "empty.yaml")
    with pytest.raises(DraftError, match="no free cells"):
        draft_building(grid, tmp_path / "b.yaml")


def test_draft_of_the_real_hospital_map_is_valid(hospital_grid, tmp_path):
    got, draft, text = draft_building(hospital_grid, tmp_path / "hospital.yaml")
    assert len(got.edges) >= 10 and len(got.rooms) >= 10
    assert draft.open_areas  # the lobby is flagged, not made a corridor
    assert got.floor_plan.ros_map.endswith("hospital.yaml")


def test_example_hospital_building_warns_only_about_its_pillar_and_the_lobby_door():
    from pathlib import Path

    from pmnav_bt.map.checks import building_warnings

    f = Path(__file__).resolve().parents[2] / "examples" / "hospital" / "building.yaml"
    w = building_warnings(load_building(f), f.parent)
    assert len(w) == 2 and "branch4-branch5 runs into an obstacle" in w[0].message
    assert w[1].field == "rooms[0].door" and "no stretch of the grid's wall" in w[1].message


def test_pmnav_map_draft_command(tmp_path, capsys):
    from pmnav_bt.cli import main

    grid = save_ros_map(rasterize_building(load_building("l_hospital")), tmp_path / "g.yaml")
    out = tmp_path / "new" / "b.yaml"
    with pytest.raises(SystemExit) as ex:
        main(["map", "draft", str(grid), "-o", str(out), "--image", str(tmp_path / "s.png")])
    assert ex.value.code == 0
    assert load_building(out).floor_plan.ros_map == "../g.yaml"
    assert (tmp_path / "s.png").is_file()
    assert "3 key waypoints, 2 corridors, 31 door candidates" in capsys.readouterr().out


def _grid(tmp_path, rects, size=(34.0, 16.0), res=0.05, name="g"):
    """A map_server grid: unknown everywhere but the free rectangles (x0, y0, x1, y1)."""
    w, h = round(size[0] / res), round(size[1] / res)
    img = np.full((h, w), 205, np.uint8)
    for x0, y0, x1, y1 in rects:
        img[h - round(y1 / res) : h - round(y0 / res), round(x0 / res) : round(x1 / res)] = 254
    return save_ros_map(FloorPlanImage(img, res, (0.0, 0.0, 0.0)), tmp_path / f"{name}.yaml")


def _near(b, xy, tol=1.0):
    return any(np.hypot(w.pos[0] - xy[0], w.pos[1] - xy[1]) <= tol for w in b.waypoints)


def test_a_narrow_corridor_between_wide_ones_is_a_corridor(tmp_path):
    # Two 2.4 m corridors joined by a 1.2 m one, narrower than a wide door: the draft used
    # to cut it away with the rooms, and the second wide corridor with it.
    grid = _grid(tmp_path, [(2, 2, 30, 4.4), (2, 12, 30, 14.4), (15.4, 4.4, 16.6, 12)])
    b, d, _ = draft_building(grid, tmp_path / "b.yaml")
    for xy in ((2.5, 3.2), (29.5, 3.2), (2.5, 13.2), (29.5, 13.2)):
        assert _near(b, xy), xy
    pos = {w.id: np.array(w.pos) for w in b.waypoints}
    narrow = [e for e in b.edges if abs((pos[e.a] + pos[e.b])[0] / 2 - 16.0) < 0.3]
    assert narrow and all(abs(b.edge_width(e) - 1.2) <= 0.2 for e in narrow)
    assert not d.warnings


def test_a_corridor_part_beyond_a_doorway_is_joined(tmp_path):
    # A fire door 0.9 m wide parts a 28 m corridor in two: both halves stay, joined.
    grid = _grid(tmp_path, [(2, 6, 15.8, 8.4), (16.2, 6, 30, 8.4), (15.8, 6.75, 16.2, 7.65)])
    b, d, _ = draft_building(grid, tmp_path / "b.yaml")
    assert _near(b, (2.5, 7.2)) and _near(b, (29.5, 7.2))
    assert not d.warnings


def test_a_part_that_cannot_be_joined_is_named_by_draft_and_validate(tmp_path):
    from pmnav_bt.map.unreached import unreached_warnings

    # The second corridor is reached only by a 0.8 m passage with a bend: no corridor,
    # and no straight way.
    rects = [(2, 2, 30, 4.4), (2, 12, 30, 14.4), (30, 2, 30.8, 9), (22, 8.2, 30.8, 9),
             (22, 8.2, 22.8, 12)]
    grid = _grid(tmp_path, rects)
    b, d, text = draft_building(grid, tmp_path / "b.yaml")
    assert len(d.warnings) == 1 and "no free straight way" in d.warnings[0]
    assert "# warning: a corridor part of 2" in text
    assert not _near(b, (16.0, 13.2), 2.0)
    w = unreached_warnings(b, load_ros_map(grid))
    assert len(w) == 1 and "no corridor reaches" in w[0].message


def test_map_draft_options_set_the_thresholds(tmp_path, capsys):
    from pmnav_bt.cli import main

    grid = _grid(tmp_path, [(2, 2, 30, 4.4), (2, 12, 30, 14.4), (15.4, 4.4, 16.6, 12)])

    def run(*opts):
        with pytest.raises(SystemExit) as ex:
            main(["map", "draft", str(grid), "-o", str(tmp_path / "b.yaml"), *opts])
        return ex.value.code, capsys.readouterr()

    # A 1.2 m corridor is a sliver when corridors are at least 1.5 m: the far corridor is
    # then a part apart, 10 m away centre line to centre line: too far to join by default ...
    code, out = run("--corridor-min", "1.5")
    assert code == 0 and "has no free straight way to the rest within 6.0 m" in out.err
    # ... and joined when links may be longer.
    code, out = run("--corridor-min", "1.5", "--link-max", "11")
    assert code == 0 and "warning" not in out.err
    code, out = run("--link-max", "0")
    assert code == 2 and "--link-max must be a positive number of metres" in out.err


def test_a_short_wide_dead_end_off_a_corridor_is_a_room_not_a_corridor(tmp_path):
    from pmnav_bt.map.draft import DraftParams

    # A 28 m corridor with, on its north side, a room 4 m wide and 6 m deep open across
    # its whole front (a glass front the scan did not see) and a stub corridor 1.4 m wide
    # and 7 m long (five times longer than wide).
    rects = [(2, 2, 30, 4.4), (8, 4.4, 12, 10.4), (22, 4.4, 23.4, 11.4)]
    grid = _grid(tmp_path, rects)
    b, _, _ = draft_building(grid, tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert not any(w.pos[1] > 6.0 and 7.5 < w.pos[0] < 12.5 for w in b.waypoints)
    assert _near(b, (22.7, 10.8), 1.2)
    # With a corridor only as long as it is wide, the room is drafted as a corridor.
    loose, _, _ = draft_building(grid, tmp_path / "c.yaml", params=DraftParams(corridor_ratio=1.0))
    assert any(w.pos[1] > 6.0 and 7.5 < w.pos[0] < 12.5 for w in loose.waypoints)


def _walled_grid(tmp_path, rects, unseen, size=(34.0, 16.0), res=0.05):
    """A grid of free rectangles, walled (black) but along the ``unseen`` rectangles'
    borders, which stay the never-seen grey: rays through a door into space not mapped."""
    import cv2

    w, h = round(size[0] / res), round(size[1] / res)
    free = np.zeros((h, w), np.uint8)
    for x0, y0, x1, y1 in [*rects, *unseen]:
        free[h - round(y1 / res) : h - round(y0 / res), round(x0 / res) : round(x1 / res)] = 1
    img = np.full((h, w), 205, np.uint8)
    img[cv2.dilate(free, np.ones((5, 5), np.uint8)) > 0] = 0
    for x0, y0, x1, y1 in unseen:  # no wall seen round the fan, only its rays
        r0, r1 = h - round(y1 / res) - 3, h - round(y0 / res) + 3
        img[r0:r1, round(x0 / res) - 3 : round(x1 / res) + 3] = 205
    img[free > 0] = 254
    return save_ros_map(FloorPlanImage(img, res, (0.0, 0.0, 0.0)), tmp_path / "w.yaml")


def test_a_dead_end_bordered_by_unseen_space_is_a_laser_fan(tmp_path):
    # A walled 28 m corridor with two dead ends north, 1.4 m wide and 7 m long: one
    # walled (a corridor), one with no wall seen round it (rays through a door).
    corridor, stub = (2, 2, 30, 4.4), (8, 4.4, 9.4, 11.4)
    fan = (22, 4.4, 23.4, 11.4)
    grid = _walled_grid(tmp_path, [corridor, stub], [fan])
    b, d, _ = draft_building(grid, tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert _near(b, (8.7, 10.8), 1.2)
    # The fan is corridor-shaped (its skeleton is drafted) but no corridor goes up it.
    plan = load_ros_map(grid)
    col = plan.world_to_pixel([[22.7, 8.0]]).round().astype(int)[0][0]
    assert d.skeleton[:, col - 3 : col + 4].any()
    assert not any(w.pos[1] > 6.0 and w.pos[0] > 20 for w in b.waypoints)


def _seen_grid(tmp_path, free_rects, wall_rects, size=(34.0, 16.0), res=0.05):
    """Never-seen grey with the free rectangles (x0, y0, x1, y1), and walls (black) drawn
    only as the ``wall_rects``: what a scanner saw."""
    w, h = round(size[0] / res), round(size[1] / res)
    img = np.full((h, w), 205, np.uint8)

    def cells(x0, y0, x1, y1):
        return np.s_[h - round(y1 / res) : h - round(y0 / res), round(x0 / res) : round(x1 / res)]

    for r in wall_rects:
        img[cells(*r)] = 0
    for r in free_rects:
        img[cells(*r)] = 254
    return save_ros_map(FloorPlanImage(img, res, (0.0, 0.0, 0.0)), tmp_path / "s.yaml")


def test_a_walled_dead_end_that_ends_in_fans_is_a_corridor(tmp_path):
    # A walled 28 m corridor, and off it north a walled corridor 3 m wide and 9 m long
    # whose far end opens into a wide fan of rays with no wall seen round it (Stata's
    # north corridor). Most of the dead end's border, counted round its end, is space
    # never seen; its sides are walls: it is a corridor, and only the fan goes.
    free = [(2, 2, 30, 4.4), (10, 4.4, 13, 13.4), (5, 13.4, 18, 15.6)]
    walls = [(1.8, 1.8, 30.2, 2), (1.8, 4.4, 10, 4.6), (13, 4.4, 30.2, 4.6),
             (1.8, 1.8, 2, 4.6), (30, 1.8, 30.2, 4.6),
             (9.8, 4.4, 10, 13.4), (13, 4.4, 13.2, 13.4)]
    b, _, _ = draft_building(_seen_grid(tmp_path, free, walls), tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert any(w.pos[1] > 10.0 and 10 < w.pos[0] < 13 for w in b.waypoints), b.waypoints
    assert not any(w.pos[1] > 13.0 and not 10 < w.pos[0] < 13 for w in b.waypoints)


def test_a_dead_end_walled_on_one_side_only_is_a_room_seen_through_its_doorway(tmp_path):
    # Off a walled corridor, a dead end 1.6 m wide and 7 m long whose west side is a wall
    # and whose east side fades into space never seen (a room the scanner saw only through
    # its doorway). Half its border is wall, but no wall stands on its east side anywhere.
    free = [(2, 2, 30, 4.4), (8, 4.4, 9.6, 11.4)]
    walls = [(1.8, 1.8, 30.2, 2), (1.8, 4.4, 8, 4.6), (9.6, 4.4, 30.2, 4.6),
             (1.8, 1.8, 2, 4.6), (30, 1.8, 30.2, 4.6), (7.8, 4.4, 8, 11.6), (7.8, 11.4, 9.6, 11.6)]
    b, _, _ = draft_building(_seen_grid(tmp_path, free, walls), tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert not any(w.pos[1] > 6.0 for w in b.waypoints), b.waypoints


def test_a_fan_whose_rays_close_a_loop_is_a_fan_once_the_loop_is_cut(tmp_path):
    # Off a walled corridor, rays with no wall seen round them: a strip north, a band
    # across its top and a wedge widening from a second opening up to the band (Willow's
    # big fan north of its west office, whose rays met again). The skeleton runs round
    # the loop; the lined rule cuts the wedge (its sides diverge), which leaves the strip
    # and the band a dead end bordered by space never seen: a fan, judged after the cut.
    import cv2

    res, (w, h) = 0.05, (680, 320)

    def px(poly):
        return np.array([[round(x / res), h - round(y / res)] for x, y in poly], np.int32)

    free = np.zeros((h, w), np.uint8)
    cv2.fillPoly(free, [px([(2, 2), (30, 2), (30, 4.4), (2, 4.4)])], 1)
    img = np.full((h, w), 205, np.uint8)
    img[cv2.dilate(free, np.ones((5, 5), np.uint8)) > 0] = 0
    rays = [
        [(20, 4.3), (21.8, 4.3), (21.8, 12), (20, 12)],
        [(20, 10.4), (28.5, 10.4), (28.5, 12), (20, 12)],
        [(24, 4.3), (26, 4.3), (28.5, 10.5), (21.8, 10.5)],
    ]
    for p in rays:  # one at a time: polygons filled together leave their overlaps out
        cv2.fillPoly(free, [px(p)], 1)
    img[free > 0] = 254
    grid = save_ros_map(FloorPlanImage(img, res, (0.0, 0.0, 0.0)), tmp_path / "fan.yaml")
    b, _, _ = draft_building(grid, tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert not any(wp.pos[1] > 5.0 for wp in b.waypoints), b.waypoints


def test_walls_saved_as_grey_likelihoods_are_seen_and_unknown_is_not():
    from pmnav_bt.map.grid import seen_mask

    # map_saver's never-seen grey (205) everywhere, free cells, and walls in a grey the
    # trinary thresholds read as unknown too (the Willow Garage map's walls).
    img = np.full((40, 60), 205, np.uint8)
    img[10:30, 10:50] = 254
    img[9, 10:50] = 150
    seen = seen_mask(FloorPlanImage(img, 0.1, (0.0, 0.0, 0.0)))
    assert seen[9, 10:50].all() and seen.sum() == 40
    img[img == 205] = 0  # no unknown at all: every non-free cell is a wall
    assert seen_mask(FloorPlanImage(img, 0.1, (0.0, 0.0, 0.0))).sum() == 60 * 40 - 20 * 40


@pytest.mark.parametrize(
    "option, says",
    [
        ("--wall-min", "a share of a dead end's length, 0 to 1"),
        ("--lined-min", "a share of a corridor's"),
    ],
)
def test_map_draft_shares_are_shares(tmp_path, capsys, option, says):
    from pmnav_bt.cli import main

    grid = _grid(tmp_path, [(2, 2, 30, 4.4)])
    with pytest.raises(SystemExit) as ex:
        main(["map", "draft", str(grid), "-o", str(tmp_path / "b.yaml"), option, "2"])
    assert ex.value.code == 2 and f"{option} is {says}" in capsys.readouterr().err


def test_an_alcove_goes_unless_it_points_at_another_dead_end():
    import networkx as nx

    from pmnav_bt.map.draft import prune_alcoves
    from pmnav_bt.map.draft_links import straight_path

    def graph(with_facing_end: bool) -> nx.Graph:
        # A corridor L-J-R 20 px wide, and a dead end J-A 30 px long off it (short for
        # its width); with B-C, another dead end points back at A across an 18 px gap.
        pts = {"J": (50, 50), "L": (50, 0), "R": (50, 110), "A": (20, 50)}
        edges = [("J", "L"), ("J", "R"), ("J", "A")]
        if with_facing_end:
            pts |= {"B": (2, 50), "C": (2, 110)}
            edges.append(("B", "C"))
        h = nx.Graph()
        for n, rc in pts.items():
            h.add_node(n, rc=np.array(rc, float))
        for a, b in edges:
            h.add_edge(a, b, path=straight_path(h.nodes[a]["rc"], h.nodes[b]["rc"]))
        return h

    dist = np.full((60, 120), 10.0)
    alone = graph(False)
    assert prune_alcoves(alone, dist, 3.0) == 1 and "A" not in alone
    broken = graph(True)
    assert prune_alcoves(broken, dist, 3.0) == 0 and "A" in broken


def _greyed_grid(tmp_path, free_thresh: float):
    """A walled 28 m corridor whose north wall is missing for 10 m, where map_saver's
    never-seen grey (205) lies beyond, 7.6 m deep: a room the scanner never entered."""
    import cv2

    res, (w, h) = 0.05, (680, 320)
    img = np.full((h, w), 205, np.uint8)
    corridor = np.zeros((h, w), np.uint8)
    corridor[h - 88 : h - 40, 40:600] = 1  # x 2..30 m, y 2..4.4 m
    img[cv2.dilate(corridor, np.ones((5, 5), np.uint8)) > 0] = 0
    img[h - 240 : h - 85, 200:400] = 205  # x 10..20 m, y 4.25..12 m: no wall, never seen
    img[corridor > 0] = 254
    plan = FloorPlanImage(img, res, (0.0, 0.0, 0.0), free_thresh=free_thresh)
    return save_ros_map(plan, tmp_path / f"g{free_thresh}.yaml")


def test_never_seen_grey_read_as_free_is_no_floor_for_the_draft(tmp_path):
    from pmnav_bt.map.grid import free_mask, never_seen_free

    # map_server with free_thresh 0.25 (the hospital's) reads the grey free: the corridor
    # and the room never entered make one wide space.
    loose = load_ros_map(_greyed_grid(tmp_path, 0.25))
    assert free_mask(loose)[100, 300] and never_seen_free(loose)[100, 300]
    assert not free_mask(loose, seen_only=True)[100, 300]
    b, _, _ = draft_building(_greyed_grid(tmp_path, 0.25), tmp_path / "b.yaml")
    assert _near(b, (2.5, 3.2)) and _near(b, (29.5, 3.2))
    assert all(w.pos[1] < 4.4 for w in b.waypoints), [w.pos for w in b.waypoints]
    # With map_saver's own threshold the grey is unknown already: nothing to leave out.
    strict = load_ros_map(_greyed_grid(tmp_path, 0.196))
    assert not never_seen_free(strict).any()
    # A map drawn all in that grey (no lighter free cell) is left as it reads.
    flat = FloorPlanImage(np.full((40, 60), 205, np.uint8), 0.1, (0.0, 0.0, 0.0), free_thresh=0.25)
    assert not never_seen_free(flat).any()


def test_a_waypoint_moves_to_its_corridors_crossing_only_along_free_space():
    import networkx as nx

    from pmnav_bt.map.draft import _place_nodes

    # Two corridors meet at J, drafted 1 m short of where their lines cross, (0, 0):
    # J moves there, unless the way there is walled (a room's skeleton bending
    # whose lines cross beyond its wall).
    h = nx.Graph([("J", "A"), ("J", "B")])
    world = {"J": np.array([1.0, 0.0]), "A": np.array([10.0, 0.0]), "B": np.array([0.0, 10.0])}
    lines = {}
    for m, c, d in (("A", (5.0, 0.0), (1.0, 0.0)), ("B", (0.0, 5.0), (0.0, 1.0))):
        lines[("J", m)] = lines[(m, "J")] = (np.array(c), np.array(d))
    moved = _place_nodes(h, world, lines, lambda a, b: True)
    assert np.allclose(moved["J"], (0.0, 0.0), atol=1e-6)
    kept = _place_nodes(h, world, lines, lambda a, b: False)
    assert np.allclose(kept["J"], (1.0, 0.0))


def test_the_draft_of_the_rmf_office_walls_grid_loads(rmf_maps, tmp_path):
    from pmnav_bt.map.rmf_import import import_rmf, write_import

    # The draft kept a door 1.4996 m from its corridor (reachable: at most 1.50 m) that
    # its own file, with the waypoints rounded to 1 cm, put 1.51 m away: an error
    # instead of a draft.
    out = tmp_path / "office.yaml"
    write_import(import_rmf(rmf_maps / "office" / "office.building.yaml", out, None), out)
    b, _, _ = draft_building(tmp_path / "office_walls.yaml", tmp_path / "draft.yaml")
    assert len(b.edges) >= 5 and b.rooms
