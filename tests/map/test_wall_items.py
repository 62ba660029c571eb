"""What hangs on the annotated walls: a wall too short for its item, two items on one
stretch of wall. ``pmnav validate`` warns of both, from the placer the simulator hangs
its items with (tests/sim/test_world.py checks that the two report the same)."""

from __future__ import annotations

import yaml
from typer.testing import CliRunner

from pmnav_bt.cli import app
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.checks import building_warnings
from pmnav_bt.map.free_space import free_space_polygon
from pmnav_bt.map.wall_items import DOOR_SPAN_M, WallPlacer, annotated_walls, wall_item_warnings


def corridor(rooms=(), landmarks=(), width=2.4, length=20.0) -> dict:
    """A straight corridor from (0, 0) east, its north wall at y = width / 2."""
    return {
        "schema_version": 1,
        "name": "one",
        "corridor_width": width,
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
            {"id": "end1", "kind": "end", "pos": [length, 0.0]},
        ],
        "edges": [["start", "end1"]],
        "rooms": list(rooms),
        "landmarks": list(landmarks),
    }


def sign(ident: str, x: float, kind: str = "sign") -> dict:
    return {"id": ident, "kind": kind, "pos": [x, 1.2], "sign": ident.title()}


def test_two_landmarks_at_one_spot_of_a_wall_warn():
    b = building_from_data(corridor(landmarks=[sign("signa", 10.0), sign("signb", 10.0)]))
    (w,) = wall_item_warnings(b)
    assert w.field == "landmarks[1].pos"
    assert "overlaps landmark 'signa' on the same wall by 0.82 m" in w.message
    assert w in building_warnings(b)


def test_items_apart_on_one_wall_or_facing_do_not_warn():
    apart = [sign("signa", 10.0), sign("signb", 10.0 + 0.82)]  # plate beside plate
    facing = [sign("signa", 10.0), {**sign("signb", 10.0), "pos": [10.0, -1.2]}]
    for lms in (apart, facing):
        assert wall_item_warnings(building_from_data(corridor(landmarks=lms))) == []


def test_an_item_overlaps_by_its_kind_s_width():
    door = {"id": "room1", "door": [10.0, 1.2], "sign": "101"}
    lift = sign("lift1", 10.0 + DOOR_SPAN_M / 2 + 1.0, kind="Lift")  # 2.14 m: 0.07 m over
    (w,) = wall_item_warnings(building_from_data(corridor([door], [lift])))
    assert w.field == "landmarks[0].pos"
    assert "overlaps the door of 'room1' on the same wall by 0.07 m" in w.message
    plate = sign("exit1", 10.0 + DOOR_SPAN_M / 2 + 0.45)  # a 0.82 m plate fits beside it
    assert wall_item_warnings(building_from_data(corridor([door], [plate]))) == []


def test_a_door_on_a_wall_too_short_for_it_warns():
    # A corridor 1 m wide: the wall closing its dead end is 1 m long, the door 1.16 m.
    door = {"id": "room1", "door": [20.5, 0.0], "sign": "101"}
    (w,) = wall_item_warnings(building_from_data(corridor([door], width=1.0)))
    assert w.field == "rooms[0].door"
    assert "needs 1.16 m of wall, but the wall it is on (centre (20.50, 0.00)) is 1.00 m" in (
        w.message
    )


def test_the_placer_keeps_items_within_their_wall_and_shares_a_real_wall_s_stretches():
    placer = WallPlacer(annotated_walls(free_space_polygon(building_from_data(corridor()))))
    at = placer.place("a", (-1.1, 1.2), 0.5)  # 0.1 m from the corner: pushed along the wall
    wall = placer.walls[at.wall]
    assert at.problems == () and wall.normal == (0.0, -1.0)  # the north wall, facing in
    assert abs(wall.point(at.s)[0] - (-1.2 + 0.5)) < 1e-9
    placer.walls.append(wall)  # a real wall it hangs on (the simulator's grid walls)
    placer.share(len(placer.walls) - 1, at.wall)
    assert not placer.fits(len(placer.walls) - 1, at.s, at.s + 0.2)
    assert placer.fits(len(placer.walls) - 1, at.s - 0.7, at.s - 0.5)
    assert placer.nearest((-1.1, 1.2))[0] == at.wall  # never a wall beyond the annotated


def test_validate_prints_the_overlap(tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text(yaml.safe_dump(corridor(landmarks=[sign("signa", 10.0), sign("signb", 10.0)])))
    r = CliRunner().invoke(app, ["validate", str(f)])
    assert r.exit_code == 0 and "warning: landmarks[1].pos: landmark 'signb'" in r.output
    assert CliRunner().invoke(app, ["validate", "--strict", str(f)]).exit_code == 1
