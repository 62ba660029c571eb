"""``pmnav-ros`` in a building of several levels (``-p building:=hospital_2l -p
lifts:=true``): each goal runs the mission across levels (``trees/site.py``), riding the
building's lifts through the node's ``RosLiftClient``.

What the node knows before a goal, and what it assumes:

- the robot starts on ``start_level`` (a parameter; default the site's first level):
  its map is the one the node shows (markers, goal poses) and the one the mission
  localizes on; the blackboard's ``level`` says so from the first tick, so the action's
  feedback reports the level from the start;
- the lifts ridden are chosen when the goal's tree is built, from the start level's
  start waypoint (the node does not know where on the level the robot stands until it
  has localized; each leg then plans from the tree's own estimate, as in the simulator);
- the robot asks for lifts by the node's fully qualified name (``/robot1/pmnav``): Open-RMF
  lifts serve one session at a time, and a session must be unique among the requesters.

Each level's back ends (its grounder reads that level's signs) and occupancy grid are
built once, when the node starts; each goal makes a Context per level on them
(``trees.lift.level_context``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import py_trees

from pmnav_bt.backends import Backends
from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.config import Config
from pmnav_bt.errors import PmNavError, UnknownNameError
from pmnav_bt.map.building import Room
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.site import Site, load_site
from pmnav_bt.map.site_map import SiteMap, parse_site
from pmnav_bt.planning.resolve import resolve_site_room
from pmnav_bt.planning.site_plan import SitePlanner
from pmnav_bt.seams import Lift


class UnknownGoalError(PmNavError):
    """The goal names no room of the site (the node reports INVALID_GOAL)."""


@dataclass(frozen=True)
class _LevelParts:
    """What a goal's Context on one level is built on."""

    pm: PrioriMap
    backends: Backends
    grid: object  # the level's occupancy grid, or None


def site_of_levels(building: str) -> Site | None:
    """The site ``building`` names when it has several levels, else None: one floor, or
    no site (the node opens it as a building, and reports what is wrong with it then)."""
    try:
        site = load_site(building)
    except PmNavError:
        return None
    return site if len(site.levels) > 1 else None


class NodeSite:
    """The site a node runs on (see the module): its levels' maps, back ends and grids,
    and the start level."""

    def __init__(
        self, site: Site, start_level: str, config: Config, *, on_robot: bool, seed: int
    ) -> None:
        from pmnav_bt.pose.evidence.floor_model import building_grid
        from pmnav_bt.trees.runner import variant_backends

        if not site.lifts:
            raise PmNavError(f"parameter 'building': {site.name} has several levels, no lifts")
        try:
            self.start_level = site.level(start_level).name if start_level else site.levels[0].name
        except PmNavError as err:
            raise PmNavError(f"parameter 'start_level': {err}") from None
        self.sm: SiteMap = parse_site(site)
        self.seed, self.on_robot = seed, on_robot
        self.levels: dict[str, _LevelParts] = {}
        for lv in site.levels:
            pm = self.sm.maps[lv.name]
            base_dir = (lv.path or site.path).parent if (lv.path or site.path) else None
            self.levels[lv.name] = _LevelParts(
                pm,
                variant_backends(config, pm, on_robot=on_robot, seed=seed),
                building_grid(lv.building, base_dir) if base_dir else None,
            )

    @property
    def start(self) -> _LevelParts:
        return self.levels[self.start_level]

    @property
    def start_file(self) -> str:
        """How the web view, the tree record and the map updates find the start level's
        map again: its building file (the site's name for a level written inline)."""
        level = self.sm.site.level(self.start_level)
        return str(level.path) if level.path is not None else self.sm.site.name

    def room(self, goal: str) -> tuple[str, Room]:
        """The level and the room ``goal`` names (as ``resolve_site_room``), or
        UnknownGoalError."""
        try:
            level, room_id = resolve_site_room(self.sm, goal)
        except UnknownNameError as err:
            raise UnknownGoalError(str(err)) from None
        return level, self.sm.maps[level].building.room(room_id)

    def mission(
        self, ctx: Context, goal: str, lift: Lift, session: str
    ) -> tuple[Callable, Callable[[], Context]]:
        """For ``run_tree``: how to build the mission to ``goal`` (a room on any level, as a
        person names it; an unknown one is an UnknownGoalError now) from ``ctx`` (the start
        level's), and the Context of the level the run ended on."""
        from pmnav_bt.trees.lift import level_context

        level, room = self.room(goal)
        from pmnav_bt.trees.site import build_site_tree

        contexts = {self.start_level: ctx}
        for name, parts in self.levels.items():
            if name != self.start_level:
                contexts[name] = level_context(
                    ctx, parts.pm, self.seed, on_robot=self.on_robot, backends=parts.backends,
                    grid=parts.grid,
                )  # fmt: skip

        def build(_ctx: Context, _goal: str):
            start = self._start_waypoint()
            plan = SitePlanner().plan(self.sm, self.start_level, start, f"{level}/{room.id}")
            return build_site_tree(contexts, self.sm, plan, lift, session=session)

        def ended_on() -> Context:
            here = py_trees.blackboard.Blackboard.storage.get(f"{NAMESPACE}/level")
            return contexts.get(here or self.start_level, ctx)

        return build, ended_on

    def _start_waypoint(self) -> str:
        b = self.sm.maps[self.start_level].building
        return next((w for w in b.waypoints if w.kind.value == "start"), b.waypoints[0]).id
