"""The priori-map of a site: one semantic priori-map per level and the lifts that join them.

Each level is parsed as a building is (``priori_map.parse_building``): its own segments,
key waypoints and places, numbered as in its own file. The site adds what joins them:
for each lift, its lobby on each level (the lobby landmark, its node and segment), and
the same for stairs, which are shown but never planned over. The text form is what a
planner or a VLM reads: the levels, the lifts with their lobbies, then each level's
priori-map under its name. A one-level site's text is its building's, unchanged.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

from pmnav_bt.map.corridor_search import LobbyTree
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.map.site import LiftLink, Site


@dataclass
class SiteMap:
    """The priori-map of every level of a site (``maps``: level name -> its map)."""

    site: Site
    maps: dict[str, PrioriMap]
    _lobby_trees: dict[tuple[str, str], LobbyTree] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def level_map(self, level: str) -> PrioriMap:
        """The priori-map of ``level`` (a name as typed: case is ignored)."""
        return self.maps[self.site.level(level).name]

    @property
    def single(self) -> bool:
        """True for a one-level site (a building): it plans and prints as the building."""
        return len(self.site.levels) == 1

    @cached_property
    def lobby_nodes(self) -> dict[tuple[str, str], str]:
        """(lift id, level) -> the map node of the lift's lobby on that level."""
        return {
            (lift.id, level): self.maps[level].places[lobby].node
            for lift in self.site.lifts
            for level, lobby in lift.lobbies.items()
        }

    def lobby_tree(self, lift: str, level: str) -> LobbyTree:
        """The shortest ways from every node of ``level`` to ``lift``'s lobby there: one
        search of the level, the first time it is asked for, kept for every later plan
        (``corridor_search``)."""
        key = (lift, level)
        tree = self._lobby_trees.get(key)
        if tree is None:
            tree = self._lobby_trees[key] = LobbyTree.grow(self.maps[level], self.lobby_nodes[key])
        return tree

    def link_line(self, link: LiftLink) -> str:
        """One lift (or stairs) for the text: its lobby on each level, where it is seen."""
        parts = []
        for lv, lobby in link.lobbies.items():
            pm = self.maps[lv]
            p = pm.places[lobby]
            seg = pm.segments[p.segment - 1]
            node = f"at node {p.node}, " if p.node != lobby else ""
            parts.append(
                f"{lv} at {lobby} ({node}on the {p.side} of {seg.short} going {seg.a}->{seg.b})"
            )
        return f"- {link.id} \"{link.display_name}\": " + "; ".join(parts)

    def links_text(self) -> str:
        """The lifts and stairs section: each one's lobby on each level."""
        site = self.site
        lines = ["## Lifts (id \"name\": the lobby landmark on each level)"]
        lines += [self.link_line(lift) for lift in site.lifts] or ["- (none)"]
        if site.stairs:
            lines += ["", "## Stairs (never taken: the robot cannot climb them)"]
            lines += [self.link_line(s) for s in site.stairs]
        return "\n".join(lines)

    def overview_text(self) -> str:
        """The site's levels (lowest first) and the lifts and stairs that join them."""
        site = self.site
        lines = [f"# Site {site.name}: {len(site.levels)} levels joined by lifts"]
        if site.description:
            lines.append(site.description)
        lines += ["", "## Levels (lowest first)"]
        for lv in sorted(site.levels, key=lambda lv: site.rank(lv.name)):
            b = lv.building
            lifts = ", ".join(lift.id for lift in site.lifts_at(lv.name)) or "none"
            lines.append(
                f"- {lv.name}: elevation {lv.elevation:.1f} m, {b.name}, {len(b.rooms)} rooms; "
                f"lifts {lifts}"
            )
        lines += ["", self.links_text()]
        return "\n".join(lines) + "\n"

    def to_text(self, level: str | None = None) -> str:
        """The structured text a planner or VLM reads: the levels and lifts, then each
        level's priori-map (only ``level``'s with a level named). One level: the
        building's text."""
        if self.single:
            return next(iter(self.maps.values())).to_text()
        site = self.site
        names = [site.level(level).name] if level is not None else list(site.level_names)
        lines = [self.overview_text()]
        for name in names:
            lines += [f"# Level {name}", "", self.maps[name].to_text().rstrip(), ""]
        return "\n".join(lines).rstrip() + "\n"

    def to_dict(self) -> dict:
        """JSON-ready data: the levels (each its priori-map's dict), the lifts, the stairs."""
        site = self.site

        def links(group) -> list[dict]:
            return [
                {"id": k.id, "name": k.display_name, "lobbies": dict(k.lobbies)} for k in group
            ]

        return {
            "site": site.name,
            "levels": [
                {"name": lv.name, "elevation_m": lv.elevation, "map": self.maps[lv.name].to_dict()}
                for lv in site.levels
            ],
            "lifts": links(site.lifts),
            "stairs": links(site.stairs),
        }


def parse_site(site: Site) -> SiteMap:
    """The priori-map of every level of a (validated) site."""
    return SiteMap(site, {lv.name: parse_building(lv.building) for lv in site.levels})
