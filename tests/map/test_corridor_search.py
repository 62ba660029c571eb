"""Shortest ways along a level's corridors: the lobby trees a site map keeps, and the
search a blocked start level gets, against networkx on the same graph."""

from __future__ import annotations

from itertools import pairwise

import networkx as nx
import pytest

from pmnav_bt.map.corridor_search import CorridorSearch, LobbyTree
from pmnav_bt.map.generate import generate_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.site import load_site
from pmnav_bt.map.site_map import parse_site


@pytest.fixture(scope="module")
def level():
    return parse_building(generate_building(150, seed=4))


def test_a_lobby_tree_holds_every_nodes_shortest_way_to_the_lobby(level):
    lobby = next(lm.id for lm in level.building.landmarks if lm.kind == "elevator")
    node = level.places[lobby].node
    tree = LobbyTree.grow(level, node)
    want = nx.single_source_dijkstra_path_length(level.graph, node, weight="length")
    assert tree.dist.keys() == want.keys()
    for n, d in want.items():
        assert tree.dist[n] == pytest.approx(d)
        way = tree.way(n)
        assert way[0] == n and way[-1] == node
        metres = sum(level.graph.edges[a, b]["length"] for a, b in pairwise(way))
        assert metres == pytest.approx(d)


def test_a_search_never_crosses_a_blocked_segment_and_stops_at_its_targets(level):
    graph = level.graph
    source = level.segments[0].a
    blocked = frozenset(range(2, len(level.segments), 5))
    open_graph = nx.subgraph_view(
        graph, filter_edge=lambda u, v: graph.edges[u, v]["segment"] not in blocked
    )
    want = nx.single_source_dijkstra_path_length(open_graph, source, weight="length")
    far = max(want, key=want.get)
    search = CorridorSearch(level, {source: (0.0, 0.0)}, blocked).run({far})
    assert search.dist[far] == pytest.approx(want[far])
    assert set(search.dist) <= set(want)  # nothing behind a blocked segment
    way = search.path(far)[::-1]
    assert way[0] == source
    assert all(graph.edges[a, b]["segment"] not in blocked for a, b in pairwise(way))
    # an open search stops once it has its target: it does not settle the whole level
    near = min((n for n in want if n != source), key=want.get)
    reached = CorridorSearch(level, {source: (0.0, 0.0)}).run({near}).dist
    assert reached[near] <= want[near] + 1e-9  # open ways are never longer
    assert len(reached) < graph.number_of_nodes()


def test_the_site_map_keeps_each_lobby_tree():
    sm = parse_site(load_site("hospital_2l"))
    lift = sm.site.lifts[0]
    for lv in lift.lobbies:
        tree = sm.lobby_tree(lift.id, lv)
        assert tree.node == sm.lobby_nodes[(lift.id, lv)] and tree.dist[tree.node] == 0.0
        assert sm.lobby_tree(lift.id, lv) is tree
