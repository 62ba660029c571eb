"""``pmnav map import-rmf`` without ``--level``: every level of a multi-level RMF building
as a site file joined by the RMF lifts."""

from __future__ import annotations

import pytest
import yaml

from pmnav_bt.experiments.cli import main
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.free_space import free_space_polygon
from pmnav_bt.map.landmark_kinds import ELEVATOR
from pmnav_bt.map.rmf_import import RmfImportError
from pmnav_bt.map.rmf_site import import_rmf_site
from pmnav_bt.map.site import read_site_file
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.map.wall_items import WallPlacer, annotated_walls, landmark_item
from pmnav_bt.planning.site_plan import SitePlanner
from pmnav_bt.testing.rmf_example import (
    LIFT_DOOR,
    example_rmf,
    example_rmf_lane_into_lift,
    example_rmf_two_levels,
    write_example_rmf,
)


def run(capsys, *argv) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return info.value.code or 0, out, err


def test_every_level_and_the_lift_come_across(tmp_path):
    rmf = write_example_rmf(tmp_path, example_rmf_two_levels())
    imported = import_rmf_site(rmf, tmp_path / "site.yaml")
    site = read_site_file(tmp_path / "site.yaml")
    assert site == imported.site
    assert site.level_names == ("L1", "L2")
    assert [lv.elevation for lv in site.levels] == [0.0, 4.0]
    assert site.level("L2").path == tmp_path / "site_L2.yaml"
    assert [r.id for r in site.level("L2").building.rooms] == ["office_2"]
    (lift,) = site.lifts
    assert lift.id == "lift_a" and set(lift.lobbies) == {"L1", "L2"}
    for level, lobby in lift.lobbies.items():
        lm = site.level(level).building.landmark(lobby)
        assert lm.kind == "elevator" and lm.pos == pytest.approx(LIFT_DOOR)


def test_the_imported_site_plans_across_levels(tmp_path):
    rmf = write_example_rmf(tmp_path, example_rmf_two_levels())
    sm = parse_site(import_rmf_site(rmf, tmp_path / "site.yaml").site)
    p = SitePlanner().plan(sm, "L1", "start", "office_2")
    assert [(r.lift, r.to_level) for r in p.rides] == [("lift_a", "L2")]


def test_a_lift_on_one_level_joins_nothing_and_the_level_is_refused(tmp_path):
    data = example_rmf_two_levels()
    data["lifts"]["lift_a"]["level_doors"] = {"L1": ["door_a"]}
    rmf = write_example_rmf(tmp_path, data)
    with pytest.raises(RmfImportError) as info:
        import_rmf_site(rmf, tmp_path / "site.yaml")
    msg = str(info.value)
    assert "levels[0]: level 'L1' has no way from its corridors to any lift" in msg
    assert "(lift 'lift_a': its door is on a corridor on L1 only; it joins nothing)" in msg


def test_cli_without_level_writes_the_site(tmp_path, capsys):
    rmf = write_example_rmf(tmp_path, example_rmf_two_levels())
    out = tmp_path / "ex.yaml"
    image = tmp_path / "ex.png"
    code, text, err = run(capsys, "map", "import-rmf", rmf, "-o", out, "--image", image)
    assert code == 0, err
    assert f"wrote {out}: site example, 2 levels, lifts lift_a (L1, L2)" in text
    assert (tmp_path / "ex_L1.png").is_file() and (tmp_path / "ex_L2.png").is_file()
    assert yaml.safe_load(out.read_text())["site_version"] == 1
    code, text, err = run(capsys, "validate", out)
    assert code == 0 and "OK: site example: 2 levels, 1 lift" in text


def test_cli_with_a_level_or_one_level_writes_a_building(tmp_path, capsys):
    rmf = write_example_rmf(tmp_path, example_rmf_two_levels())
    code, _, err = run(capsys, "map", "import-rmf", rmf, "--level", "L2", "-o", tmp_path / "b.yaml")
    assert code == 0, err
    assert load_building(tmp_path / "b.yaml").rooms[0].id == "office_2"
    one = tmp_path / "one"
    one.mkdir()
    code, _, err = run(
        capsys, "map", "import-rmf", write_example_rmf(one, example_rmf()), "-o", one / "o.yaml"
    )
    assert code == 0, err
    assert "schema_version" in yaml.safe_load((one / "o.yaml").read_text())


def test_the_rmf_clinic_imports_as_a_site_of_two_levels(rmf_maps, tmp_path, capsys):
    out = tmp_path / "clinic.yaml"
    code, text, err = run(capsys, "map", "import-rmf", rmf_maps / "clinic" / "clinic.building.yaml",
                          "-o", out)
    assert code == 0, err
    site = read_site_file(out)
    assert site.level_names == ("L1", "L2") and len(site.lifts) >= 2
    assert all(set(lift.lobbies) == {"L1", "L2"} for lift in site.lifts)
    code, text, err = run(capsys, "validate", out)
    assert code == 0, err
    sm = parse_site(site)
    room = sm.maps["L2"].building.rooms[0].id
    p = SitePlanner().plan(sm, "L1", "start", f"L2/{room}")
    assert len(p.rides) == 1 and p.legs[-1].plan.goal == room


def lift_walls(site) -> list[tuple[str, str, float, tuple[str, ...]]]:
    """(level, lift, distance from its point to the wall it hangs on, what is wrong there)
    for every lift lobby of ``site``, hung as the simulator hangs it."""
    out = []
    for lift in site.lifts:
        for level, lobby in lift.lobbies.items():
            b = site.level(level).building
            walls = annotated_walls(free_space_polygon(b))
            lm = b.landmark(lobby)
            placed = WallPlacer(walls).place(
                landmark_item(lobby), lm.pos, ELEVATOR.span_m / 2.0, at_foot=True
            )
            foot = walls[placed.wall].point(placed.s)
            gap = float(((foot[0] - lm.pos[0]) ** 2 + (foot[1] - lm.pos[1]) ** 2) ** 0.5)
            out.append((level, lift.id, gap, placed.problems))
    return out


def test_a_lane_on_into_the_lift_leaves_its_door_on_a_straight_corridor_wall(tmp_path):
    """RMF lanes run on through a lift's door to its cabin's middle; the cabin is the
    lift's shaft, not a corridor, so the lift's doors and frame hang on the corridor's
    wall at the drawing's door, with wall enough either side (no notch of a corridor
    run into the shaft)."""
    rmf = write_example_rmf(tmp_path, example_rmf_lane_into_lift())
    site = import_rmf_site(rmf, tmp_path / "site.yaml").site
    for level, lift, gap, problems in lift_walls(site):
        assert gap < 0.2 and problems == (), (level, lift, gap, problems)

