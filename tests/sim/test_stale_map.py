"""Stale-map worlds: one change on the route, drawn from the seed, and a run that notices it
writes the disagreement with the right kind."""

from __future__ import annotations

import networkx as nx
import pytest

from pmnav_bt.config import WorldConfig, load_config
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.signage import split_number
from pmnav_bt.sim.episodes import generate_episodes
from pmnav_bt.sim.scene.stale_map import MOVE_M, stale_world


def _stale(building, tier, kinds, n=4):
    pm = parse_building(load_building(building))
    world = WorldConfig(stale_map=1.0, stale_kinds=kinds)
    eps = generate_episodes(building, tier, n, seed=0)
    return pm, [(e, stale_world(pm, world, e.seed, e.route, e.goal)) for e in eps]


def test_a_world_without_stale_map_is_the_maps_building():
    pm = parse_building(load_building("fig2_hospital"))
    for preset in ("clean", "realistic"):
        s = stale_world(pm, WorldConfig(preset=preset), 3, ("turn2", "room8"), "room15")
        assert s.building is pm.building and s.closed == () and s.changes == ()


def test_a_renamed_room_is_passed_on_the_way_keeps_its_number_and_nothing_else_changes():
    pm, runs = _stale("fig2_hospital", "hard", ["renamed"])
    for ep, s in runs:
        (c,) = s.changes
        assert c.kind == "renamed" and c.update_kind == "sign_text"
        assert c.subject in ep.route and c.subject != ep.goal
        assert split_number(c.after)[0] == split_number(c.before)[0] and c.after != c.before
        after = {r.id: r for r in s.building.rooms}
        assert after[c.subject].sign_text == c.after
        assert [r for r in pm.building.rooms if r.id != c.subject] == [
            r for r in s.building.rooms if r.id != c.subject
        ]
        building_from_data(s.building.to_dict())  # the world's building is a valid one


def test_a_moved_landmark_is_on_the_route_and_moved_along_its_corridor():
    pm, runs = _stale("fig2_hospital", "hard", ["moved"])
    moved = [(ep, s) for ep, s in runs if s.changes]
    assert moved
    for ep, s in moved:
        (c,) = s.changes
        assert c.update_kind == "moved" and c.subject in ep.route
        old = pm.building.landmark(c.subject).pos
        new = s.building.landmark(c.subject).pos
        d = ((old[0] - new[0]) ** 2 + (old[1] - new[1]) ** 2) ** 0.5
        assert MOVE_M[0] - 0.01 <= d <= MOVE_M[1] + 0.01


def test_a_closed_corridor_leaves_another_way_to_the_goal():
    pm, runs = _stale("loop_school", "hard", ["closed"])
    for ep, s in runs:
        (c,) = s.changes
        assert s.closed == (c.subject,) and c.update_kind == "corridor_blocked"
        seg = pm.segment(c.subject)
        legs = {frozenset(leg) for leg in zip(ep.route, ep.route[1:], strict=False)}
        assert frozenset((seg.a, seg.b)) in legs
        g = pm.graph.copy()
        g.remove_edge(seg.a, seg.b)
        assert nx.has_path(g, ep.route[0], ep.goal)


def test_a_building_without_a_loop_closes_no_corridor_and_the_seed_decides():
    _, runs = _stale("fig2_hospital", "hard", ["closed"])
    assert all(s.changes == () for _, s in runs)
    _, again = _stale("fig2_hospital", "hard", ["renamed", "moved"])
    _, once_more = _stale("fig2_hospital", "hard", ["renamed", "moved"])
    assert [s.changes for _, s in again] == [s.changes for _, s in once_more]


@pytest.mark.xfail(
    strict=True,
    reason="regressed when this stop's reading, belief and costmap branches were merged: "
    "the run writes no update at all; cause not found yet (issue 38)",
)
@pytest.mark.timeout(300)
def test_a_renamed_room_on_the_route_is_written_as_a_sign_text_update(tmp_path):
    """The real stack (OCR) in the clean world, a room on the route renamed: the run's
    updates file holds a sign_text update for that room, with what its plate reads."""
    pytest.importorskip("rapidocr_onnxruntime")
    from pmnav_bt.experiments.evaluation import run_episode
    from pmnav_bt.map.updates import load_updates

    cfg = load_config(None, ["world.stale_map=1", "world.stale_kinds=[renamed]"])
    pm = parse_building(load_building("fig2_hospital"))
    ep = next(
        e for e in generate_episodes("fig2_hospital", "medium", 4, seed=0)
        if stale_world(pm, cfg.world, e.seed, e.route, e.goal).changes
    )  # fmt: skip
    (change,) = stale_world(pm, cfg.world, ep.seed, ep.route, ep.goal).changes
    run = run_episode(ep, cfg, out_dir=tmp_path, plot=False)
    log = load_updates(run.map_updates)
    assert log.building == "fig2_hospital"
    written = [(u.kind, u.subject, u.seen) for u in log.updates]
    assert ("sign_text", change.subject, change.after) in written
    crop = next(u.evidence.crop for u in log.updates if u.subject == change.subject)
    assert (tmp_path / crop).exists()
