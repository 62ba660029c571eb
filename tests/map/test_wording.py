"""A way found shut at a fire door is named by that door: where its leaves cross the
corridor (its node on the centre line), whichever wall its point is on."""

from __future__ import annotations

from building_kit import with_landmark

from pmnav_bt.map.building import Landmark
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.wording import fire_door_at


def test_a_fire_door_is_named_from_where_it_crosses_a_wide_corridor():
    b = load_building("straight_office").model_copy(update={"corridor_width": 4.0})
    door = Landmark(id="fd1", kind="fire_door", name="FD-1", pos=(15.25, 2.0))  # on a wall
    pm = parse_building(with_landmark(b, door))
    assert fire_door_at(pm, (15.0, 0.0)) == "fire door FD-1 at fd1"  # 2 m from its pos
    assert fire_door_at(pm, (18.0, 0.0)) is None
