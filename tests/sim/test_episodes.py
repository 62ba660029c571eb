"""Episodes: each generated episode meets its tier, seeds reproduce, the JSON file round-trips."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.catalogue import BUILTIN_DIR, builtin_buildings, load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.sim.episodes import (
    START_CLEARANCE_M,
    STOP_OFFSET_M,
    TIERS,
    EpisodeBuildingError,
    EpisodeFileError,
    EpisodeGenerationError,
    classify,
    episode_building,
    episode_building_file,
    episodes_json,
    generate_episodes,
    goal_door,
    goal_geodesic,
    goal_stop_point,
    load_episodes,
    path_facts,
    route_length,
    save_episodes,
    shortest_path_points,
    tier_definition,
)

# Tiers each built-in building's structure allows.
NO_TIER = {"straight_office": {"medium", "hard"}, "l_hospital": {"hard"}}


def _cases():
    for b in builtin_buildings():
        for t in TIERS:
            if t not in NO_TIER.get(b, set()):
                yield b, t


@pytest.fixture(scope="module")
def maps():
    return {b: parse_building(load_building(b)) for b in builtin_buildings()}


@pytest.mark.parametrize(("name", "tier"), list(_cases()))
def test_generated_episodes_meet_their_tier(maps, name, tier):
    pm = maps[name]
    spec = TIERS[tier]
    keys = [n.pos for n in pm.key_waypoints]
    for ep in generate_episodes(pm, tier, 8, seed=3):
        assert ep.tier == tier and ep.building == name
        facts = path_facts(pm, ep.start_pose, ep.goal)
        assert spec.accepts(facts) and classify(facts) == tier
        assert (facts.turns, facts.forks, facts.goal_visible) == (
            ep.turns,
            ep.forks,
            ep.goal_visible,
        )
        assert facts.route == ep.route
        assert ep.route_length == pytest.approx(facts.length, abs=1e-3)
        lo, hi = spec.length_band
        assert lo <= ep.route_length < hi
        # On a centre line, facing along the corridor, clear of junctions and ends.
        loc = pm.locate(ep.start_x, ep.start_y)
        assert loc.offset < 2e-3
        along = abs(wrap_angle(ep.start_yaw - loc.segment.heading))
        assert min(along, math.pi - along) < 1e-6
        assert min(math.dist((ep.start_x, ep.start_y), k) for k in keys) >= START_CLEARANCE_M
        if tier == "easy":
            assert ep.goal_visible and ep.turns == 0 and ep.forks == 0
        if tier == "medium":
            assert not ep.goal_visible and ep.turns >= 1 and ep.forks == 0
        if tier == "hard":
            assert ep.turns >= 2 and ep.forks >= 1 and ep.steps > 10


@pytest.mark.parametrize(("name", "tier"), [(b, t) for b, ts in NO_TIER.items() for t in ts])
def test_tiers_the_structure_cannot_hold_are_clear_errors(maps, name, tier):
    with pytest.raises(EpisodeGenerationError, match=name) as err:
        generate_episodes(maps[name], tier, 3)
    assert isinstance(err.value, PmNavError)


def test_unknown_tier_and_bad_n(maps):
    with pytest.raises(EpisodeGenerationError, match="unknown tier"):
        generate_episodes(maps["fig2_hospital"], "extreme", 3)
    with pytest.raises(EpisodeGenerationError):
        generate_episodes(maps["fig2_hospital"], "easy", -1)


def test_same_seed_same_episodes(maps):
    a = generate_episodes(maps["ring_school"], "hard", 10, seed=7)
    b = generate_episodes("ring_school", "hard", 10, seed=7)  # by built-in name
    c = generate_episodes(maps["ring_school"], "hard", 10, seed=8)
    assert a == [dataclasses.replace(e, building_path="", building_sha256="") for e in b]
    assert a != c
    assert generate_episodes(maps["ring_school"], "hard", 4, seed=7) == a[:4]  # a prefix
    assert len({e.id for e in a}) == 10
    assert generate_episodes(maps["ring_school"], "hard", 0) == []


def test_shortest_path_points_hand_case(maps):
    pm = maps["fig2_hospital"]
    # From (0, 25) on the start-turn1 corridor to room7 (door (24, 1.2)): down to turn1, east.
    pts = shortest_path_points(pm, (0.0, 25.0), "room7")
    assert pts[0] == (0.0, 25.0)
    assert pts[-1] == pytest.approx((24.0, 1.2 - STOP_OFFSET_M))
    assert (0.0, 0.0) in pts
    length = sum(math.dist(p, q) for p, q in zip(pts, pts[1:], strict=False))
    assert length == pytest.approx(25 + 24 + 0.6)
    assert route_length(pm, (0.0, 25.0), "room7") == pytest.approx(length)
    assert goal_door(pm, "room7") == (24.0, 1.2)
    assert math.dist(goal_stop_point(pm, "room7"), goal_door(pm, "room7")) == pytest.approx(
        STOP_OFFSET_M
    )
    # A start off the centre line goes to the line first.
    off = shortest_path_points(pm, (0.5, 25.0), "Consulting Room 7")  # names resolve too
    assert off[1] == pytest.approx((0.0, 25.0))


def test_facts_turns_and_forks(maps):
    pm = maps["fig2_hospital"]
    # start corridor -> turn1 -> turn2 -> branch1 -> east: three turns, one fork (the paper's
    # Fig. 2 task to room17, the One-Stop Service Centre).
    f = path_facts(pm, (0.0, 25.0, -math.pi / 2), "room17")
    assert (f.turns, f.forks, f.goal_visible) == (3, 1, False)
    # Facing a door 4 m ahead on the same corridor: visible; facing away: not.
    ahead = path_facts(pm, (0.0, 10.0, math.pi / 2), "room5")
    behind = path_facts(pm, (0.0, 10.0, -math.pi / 2), "room5")
    assert ahead.goal_visible and not behind.goal_visible
    assert classify(ahead) == "easy" and classify(behind) is None


def test_json_round_trip(tmp_path, maps):
    eps = generate_episodes(maps["t_school"], "medium", 5, seed=2)
    eps += generate_episodes(maps["t_school"], "hard", 5, seed=2)
    path = save_episodes(eps, tmp_path / "eps.json")
    assert load_episodes(path) == eps
    data = json.loads(path.read_text())
    assert data["schema_version"] == 2 and "tier_definition" in data
    assert json.loads(episodes_json(eps)) == data


def _write(tmp_path, data, name="bad.json"):
    p = tmp_path / name
    p.write_text(data if isinstance(data, str) else json.dumps(data))
    return p


@pytest.mark.parametrize(
    ("mutate", "needle"),
    [
        (lambda d: d["episodes"][0].pop("goal"), "episodes[0].goal: required key is missing"),
        (lambda d: d["episodes"][1].update(start_x="3"), "episodes[1].start_x: expected"),
        (lambda d: d["episodes"][0].update(turns=True), "episodes[0].turns"),
        (lambda d: d["episodes"][0].update(tier="extreme"), "unknown tier 'extreme'"),
        (lambda d: d["episodes"][0].update(colour="red"), "episodes[0].colour: unknown key"),
        (lambda d: d.update(schema_version=9), "schema_version"),
        (lambda d: d["episodes"][1].update(id=d["episodes"][0]["id"]), "duplicate id"),
        (lambda d: d.update(episodes={"a": 1}), "episodes: expected a list"),
    ],
)
def test_bad_episode_files_name_file_and_field(tmp_path, maps, mutate, needle):
    eps = generate_episodes(maps["fig2_hospital"], "easy", 2)
    data = json.loads(save_episodes(eps, tmp_path / "good.json").read_text())
    mutate(data)
    p = _write(tmp_path, data)
    with pytest.raises(EpisodeFileError) as err:
        load_episodes(p)
    assert str(p) in str(err.value) and needle in str(err.value)
    assert "\n" not in str(err.value)


def test_unreadable_and_non_json_files(tmp_path):
    with pytest.raises(EpisodeFileError, match="cannot read episodes file"):
        load_episodes(tmp_path / "missing.json")
    with pytest.raises(EpisodeFileError, match="line 1, column"):
        load_episodes(_write(tmp_path, "{not json"))
    with pytest.raises(EpisodeFileError, match="'episodes' list"):
        load_episodes(_write(tmp_path, {"rooms": []}))


def test_tier_definition_prints_the_numbers():
    text = tier_definition()
    for t in TIERS.values():
        assert t.describe() in text
    assert "1 m" in text and "0.6 m" in text


def test_an_off_centre_start_adds_no_turn(maps):
    pm = maps["fig2_hospital"]
    on = path_facts(pm, (0.0, 25.0, -math.pi / 2), "room17")
    off = path_facts(pm, (0.6, 25.0, -math.pi / 2), "room17")
    assert off.turns == on.turns and off.length == pytest.approx(on.length + 0.6)


def test_episodes_record_the_building_file_and_its_hash(tmp_path, monkeypatch):
    src = BUILTIN_DIR / "t_school.yaml"
    own = tmp_path / "plans" / "my_school.yaml"
    own.parent.mkdir()
    shutil.copy(src, own)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    eps = generate_episodes("../plans/my_school.yaml", "easy", 2, seed=1)  # relative to cwd
    assert all(e.building_path == str(own.resolve()) for e in eps)
    assert all(len(e.building_sha256) == 64 for e in eps)
    saved = save_episodes(eps, tmp_path / "eps.json")
    monkeypatch.chdir(tmp_path)  # another directory: the absolute path still finds it
    ep = load_episodes(saved)[0]
    assert episode_building_file(ep) == own.resolve()
    assert episode_building(ep).name == "t_school"
    own.write_text(own.read_text() + "\n# edited\n")
    with pytest.raises(EpisodeBuildingError, match="has changed since the episodes were made"):
        episode_building_file(ep)
    own.unlink()
    with pytest.raises(EpisodeBuildingError, match="not found"):
        episode_building_file(dataclasses.replace(ep, building="my_school"))


def test_builtin_episodes_travel_when_the_package_moves(maps):
    ep = generate_episodes("fig2_hospital", "easy", 1)[0]
    moved = dataclasses.replace(ep, building_path="/nowhere/fig2_hospital.yaml")
    assert episode_building_file(moved) == BUILTIN_DIR / "fig2_hospital.yaml"
    changed = dataclasses.replace(moved, building_sha256="0" * 64)
    with pytest.raises(EpisodeBuildingError):
        episode_building_file(changed)


def test_geodesic_is_shorter_than_the_route_and_zero_at_the_goal(maps):
    pm = maps["fig2_hospital"]
    for ep in generate_episodes(pm, "hard", 3, seed=4) + generate_episodes(pm, "easy", 3):
        field = goal_geodesic(pm, ep.goal)
        door = goal_door(pm, ep.goal)
        shortest = field.distance((ep.start_x, ep.start_y))
        # The route runs along centre lines to a stop point 0.6 m from the door; the
        # geodesic cuts corners and ends at the 1 m success disc: at least 0.4 m shorter.
        assert 0 < shortest <= ep.route_length - 0.39
        # ... and no shorter than the straight line to the disc.
        assert shortest >= math.dist((ep.start_x, ep.start_y), door) - 1.0 - 0.01
        assert field.distance(goal_stop_point(pm, ep.goal)) == 0.0
