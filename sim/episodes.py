"""Navigation episodes: a seeded generator, corridor routes, the JSON episode file, scoring.

An episode is a start pose on a corridor centre line (yaw along the corridor), a goal
room and the building file it was made for (its absolute path and sha256: running an
episode re-checks that the file has not changed). Its *route* is the corridor-graph path
from the start to the goal room's node on the centre line, then straight to the goal
*stop point*, ``STOP_OFFSET_M`` from the door point towards the corridor centre; the
tiers (:mod:`pmnav_bt.eval.tiers`) and the action budget (:mod:`pmnav_bt.eval.task`)
are judged on it. SPL's shortest path is not the route but the free-space geodesic to
the success disc (:func:`goal_geodesic`), which a driven robot can match.
"""

from __future__ import annotations

import json
import math
import zlib
from collections.abc import Sequence
from dataclasses import asdict, dataclass, fields
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np

from pmnav_bt.errors import PmNavError, Problem, UnknownNameError
from pmnav_bt.eval.geodesic import GeodesicField
from pmnav_bt.eval.metrics import EpisodeResult, soft_spl, spl, success
from pmnav_bt.eval.task import STOP_OFFSET_M, SUCCESS_RADIUS_M, action_budget
from pmnav_bt.eval.tiers import (
    START_CLEARANCE_M,
    STEP_M,
    TIERS,
    VISIBLE_HALF_FOV_DEG,
    VISIBLE_RANGE_M,
    PathFacts,
    TierSpec,
    classify,
    start_candidates,
    tier_definition,
    within,
)
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import Action, heading, point_towards, relative_action, wrap_angle
from pmnav_bt.loading import InputFileError, atomic_write_text, load_json
from pmnav_bt.map.building import Building
from pmnav_bt.map.catalogue import (
    building_sha256,
    builtin_buildings,
    is_generated_name,
    load_building,
    open_building,
    resolve_building_path,
)
from pmnav_bt.map.free_space import free_space_polygon
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.planning.resolve import resolve_room, resolve_start
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D

__all__ = [
    "EPISODES_SCHEMA_VERSION",
    "START_CLEARANCE_M",
    "STEP_M",
    "STOP_OFFSET_M",
    "SUCCESS_RADIUS_M",
    "TIERS",
    "VISIBLE_HALF_FOV_DEG",
    "VISIBLE_RANGE_M",
    "Episode",
    "EpisodeFileError",
    "EpisodeGenerationError",
    "EpisodeBuildingError",
    "PathFacts",
    "TierSpec",
    "classify",
    "episode_building",
    "episode_building_file",
    "episode_map",
    "episodes_json",
    "generate_episodes",
    "goal_door",
    "goal_door_in_world",
    "goal_geodesic",
    "goal_stop_point",
    "load_episodes",
    "path_facts",
    "route_length",
    "save_episodes",
    "score_episode",
    "shortest_path_points",
    "tier_definition",
]


EPISODES_SCHEMA_VERSION = 2


# -- errors ---------------------------------------------------------------------------------


class EpisodeFileError(PmNavError):
    """An episode file could not be read or is invalid; ``problems`` lists every problem."""

    def __init__(self, path: str, problems: Sequence[Problem]):
        self.path = str(path)
        self.problems = list(problems) or [Problem("", "invalid episode file")]
        more = len(self.problems) - 1
        tail = f" (and {more} more)" if more else ""
        super().__init__(f"{self.path}: {self.problems[0]}{tail}")


class EpisodeGenerationError(PmNavError):
    """No episodes of the asked tier fit the building (or the tier name is unknown)."""


class EpisodeBuildingError(PmNavError):
    """An episode's building file is missing or has changed since the episode was made."""


# -- episodes -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Episode:
    """One navigation task: start pose, goal room, its building file and route facts.

    ``building`` is the building's name; ``building_path`` its file (absolute) and
    ``building_sha256`` the file's content hash, checked when the episode is run.
    """

    id: str
    building: str
    tier: str
    start_x: float
    start_y: float
    start_yaw: float  # rad, CCW from +x
    goal: str  # room id
    route_length: float  # metres along the corridor route, start to the goal stop point
    seed: int  # for everything random inside the episode (noise, detector misses)
    goal_visible: bool
    turns: int
    forks: int
    route: tuple[str, ...] = ()  # priori-map nodes of the route, ending at the goal node
    step_budget: int = 0  # actions under the default budget rule; 0: compute it
    building_path: str = ""  # absolute path of the building file ("" : find ``building``)
    building_sha256: str = ""  # of the building file's bytes ("" : not checked)
    blocked: tuple[str, ...] = ()  # priori-map segments closed by a barrier (scene.blocking)

    def __post_init__(self) -> None:
        if self.step_budget <= 0:
            object.__setattr__(self, "step_budget", action_budget(self.route_length))

    @property
    def start_pose(self) -> Pose2D:
        return Pose2D(self.start_x, self.start_y, self.start_yaw)

    @property
    def steps(self) -> int:
        """Route length in paper steps of ``STEP_M``."""
        return int(round(self.route_length / STEP_M))

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["route"] = list(self.route)
        d["blocked"] = list(self.blocked)
        if not self.blocked:
            del d["blocked"]  # files of episodes that block nothing stay as they were
        return d


_FIELD_TYPES: dict[str, tuple[type, ...]] = {
    "id": (str,),
    "building": (str,),
    "tier": (str,),
    "start_x": (int, float),
    "start_y": (int, float),
    "start_yaw": (int, float),
    "goal": (str,),
    "route_length": (int, float),
    "seed": (int,),
    "goal_visible": (bool,),
    "turns": (int,),
    "forks": (int,),
    "route": (list,),
    "step_budget": (int,),
    "building_path": (str,),
    "building_sha256": (str,),
    "blocked": (list,),
}
_OPTIONAL = {"route", "step_budget", "building_path", "building_sha256", "blocked"}
# Plausible magnitudes: a building fits in 1 km; text is short; budgets stay finite.
_LIMITS: dict[str, tuple[float, float]] = {
    "id": (1, 200),
    "building": (1, 4096),
    "goal": (1, 64),
    "start_x": (-1000.0, 1000.0),
    "start_y": (-1000.0, 1000.0),
    "start_yaw": (-100.0, 100.0),
    "route_length": (0.0, 100_000.0),
    "seed": (0, 2**63 - 1),
    "turns": (0, 10_000),
    "forks": (0, 10_000),
    "route": (0, 10_000),
    "step_budget": (1, 1_000_000),
    "building_path": (0, 4096),
    "building_sha256": (0, 64),
    "blocked": (0, 100),
}
_LENGTHS = {"id", "building", "goal", "route", "building_path", "building_sha256", "blocked"}
MAX_EPISODES = 100_000


def _in_limits(key: str, v: Any) -> bool:
    lo, hi = _LIMITS[key]
    return lo <= (len(v) if key in _LENGTHS else v) <= hi


def _episode_from_dict(d: Any, where: str) -> tuple[Episode | None, list[Problem]]:
    if not isinstance(d, dict):
        return None, [Problem(where, f"expected an object, got {type(d).__name__}")]
    if "site" in d:  # an episode across the levels of a site (tier cross_level)
        from pmnav_bt.sim.site_episodes import site_episode_from_dict  # it imports this module

        return site_episode_from_dict(d, where)
    problems = []
    known = {f.name for f in fields(Episode)}
    for k in d:
        if k not in known:
            problems.append(Problem(f"{where}.{k}", "unknown key"))
    for k, types in _FIELD_TYPES.items():
        if k not in d:
            if k not in _OPTIONAL:
                problems.append(Problem(f"{where}.{k}", "required key is missing"))
            continue
        v = d[k]
        ok = isinstance(v, types) and (bool in types or not isinstance(v, bool))
        if ok and isinstance(v, float) and not math.isfinite(v):
            ok = False
        if ok and k in ("route", "blocked"):
            ok = all(isinstance(x, str) and len(x) <= 200 for x in v)
        if not ok:
            want = " or ".join(t.__name__ for t in types)
            shown = repr(v) if len(repr(v)) <= 60 else repr(v)[:57] + "..."
            problems.append(Problem(f"{where}.{k}", f"expected {want}, got {shown}"))
        elif (
            k in _LIMITS and not _LIMITS[k][0] <= (len(v) if k in _LENGTHS else v) <= _LIMITS[k][1]
        ):
            lo, hi = _LIMITS[k]
            what = "length" if k in _LENGTHS else "value"
            problems.append(Problem(f"{where}.{k}", f"{what} must be from {lo} to {hi}"))
    if not problems and d["tier"] not in TIERS:
        problems.append(
            Problem(f"{where}.tier", f"unknown tier {d['tier']!r}; known: {', '.join(TIERS)}")
        )
    if not problems and d["route_length"] < 0:
        problems.append(Problem(f"{where}.route_length", "must be non-negative"))
    if problems:
        return None, problems
    kw = dict(d)
    kw["route"] = tuple(kw.get("route", ()))
    kw["blocked"] = tuple(kw.get("blocked", ()))
    for k in ("start_x", "start_y", "start_yaw", "route_length"):
        kw[k] = float(kw[k])
    return Episode(**kw), []


def episodes_json(episodes: Sequence[Episode]) -> str:
    """Episodes as the JSON text of an episode file (with the tier definition)."""
    data = {
        "format": "pmnav-episodes",
        "schema_version": EPISODES_SCHEMA_VERSION,
        "tier_definition": tier_definition(),
        "episodes": [e.to_dict() for e in episodes],
    }
    return json.dumps(data, indent=1) + "\n"


def save_episodes(episodes: Sequence[Episode], path: str | Path) -> Path:
    """Write episodes to a JSON file (with the tier definition, for the reader)."""
    return atomic_write_text(path, episodes_json(episodes))


def episode_building_file(episode: Episode) -> Path:
    """The building file an episode was made for, checked against its recorded sha256.

    A recorded path that no longer exists falls back to the built-in (or generated)
    building of the episode's name when its content is the same (episode files of
    built-ins travel; a Ray node regenerates a generated building in its own cache).
    """
    path = episode.building_path
    if not path:
        return resolve_building_path(episode.building)
    if not Path(path).is_file():
        if episode.building in builtin_buildings() or is_generated_name(episode.building):
            builtin = resolve_building_path(episode.building)
            if not episode.building_sha256 or building_sha256(builtin) == episode.building_sha256:
                return builtin
        raise EpisodeBuildingError(
            f"episode {episode.id}: building file {path} not found; the episodes were made "
            "for it (regenerate them with 'pmnav sim episodes')"
        )
    if episode.building_sha256:
        now = building_sha256(path)
        if now != episode.building_sha256:
            raise EpisodeBuildingError(
                f"episode {episode.id}: building file {path} has changed since the episodes "
                f"were made (sha256 {now[:12]}..., episodes recorded "
                f"{episode.building_sha256[:12]}...); regenerate them with 'pmnav sim episodes'"
            )
    return Path(path)


def episode_building(episode: Episode) -> Building:
    """The building of ``episode`` (see :func:`episode_building_file`), checked to be the
    one the episode names (see :func:`episode_map`)."""
    return _named_building(episode, episode_building_file(episode))


def episode_map(episode: Episode) -> tuple[Path, PrioriMap]:
    """The building file of ``episode`` and its priori-map, the episode checked against
    them before anything runs: the file holds the building the episode names, and the
    start is in one of its corridors, by the rule ``--start`` is held to
    (``planning.resolve``: within half the corridor's width and 1 m of its centre line).
    A start outside the building would spend the run's whole budget going nowhere."""
    file = episode_building_file(episode)
    pm = parse_building(_named_building(episode, file))
    try:
        resolve_start(pm, episode.start_pose)
    except UnknownNameError as err:
        raise EpisodeBuildingError(f"episode {episode.id}: start_x, start_y: {err}") from None
    return file, pm


def _named_building(episode: Episode, file: Path) -> Building:
    """The building in ``file``, which must be the one named by the episode's
    ``building``: a ``building_path`` to another building is an error naming both (one of
    the two is wrong, and running either would be a guess)."""
    b = load_building(file)
    if episode.building_path and b.name != episode.building:
        raise EpisodeBuildingError(
            f"episode {episode.id}: building is {episode.building!r} but building_path "
            f"{file} holds building {b.name!r}; correct one of them (or regenerate the "
            "episodes with 'pmnav sim episodes')"
        )
    return b


def load_episodes(path: str | Path) -> list[Episode]:
    """Read an episode file written by ``save_episodes``; raise EpisodeFileError if invalid."""
    path = Path(path)
    try:
        data = load_json(path, "episodes")
    except InputFileError as err:
        raise EpisodeFileError(str(path), [Problem(err.field, err.message)]) from None
    if isinstance(data, list):  # a bare list of episodes is accepted too
        data = {"schema_version": EPISODES_SCHEMA_VERSION, "episodes": data}
    if not isinstance(data, dict) or "episodes" not in data:
        raise EpisodeFileError(
            str(path),
            [
                Problem(
                    "",
                    "expected an object with an 'episodes' list "
                    "(write it with 'pmnav sim episodes')",
                )
            ],
        )
    version = data.get("schema_version")
    if version != EPISODES_SCHEMA_VERSION:
        raise EpisodeFileError(
            str(path),
            [
                Problem(
                    "schema_version",
                    f"this version of pmnav reads {EPISODES_SCHEMA_VERSION}, not {version!r}; "
                    "regenerate the file with 'pmnav sim episodes'",
                )
            ],
        )
    items = data["episodes"]
    if not isinstance(items, list):
        raise EpisodeFileError(str(path), [Problem("episodes", "expected a list")])
    if len(items) > MAX_EPISODES:
        raise EpisodeFileError(
            str(path), [Problem("episodes", f"{len(items)} episodes; at most {MAX_EPISODES}")]
        )
    episodes, problems = [], []
    for i, d in enumerate(items):
        ep, probs = _episode_from_dict(d, f"episodes[{i}]")
        problems += probs
        if ep is not None:
            episodes.append(ep)
    seen: dict[str, int] = {}
    for i, ep in enumerate(episodes):
        if ep.id in seen:
            problems.append(Problem(f"episodes[{i}].id", f"duplicate id {ep.id!r}"))
        seen.setdefault(ep.id, i)
    if problems:
        raise EpisodeFileError(str(path), problems)
    return episodes


# -- geodesics ------------------------------------------------------------------------------


def goal_door(pm: PrioriMap, room: str) -> tuple[float, float]:
    """The door point of a room (id, name or alias)."""
    r = pm.building.room(resolve_room(pm, room))
    return float(r.door[0]), float(r.door[1])


def goal_door_in_world(world, pm: PrioriMap, room: str) -> tuple[float, float]:
    """The door point of a room where ``world`` (a SimWorld) has the door: with grid walls,
    the centre of the door the simulator hung on the grid's real wall
    (``SimWorld.moved_items``); else the file's door point. Success is measured here: a
    person judging the run stands at the door the building has, not at the annotation.
    (Not the file's point moved by the door's shift off its annotated wall: a door point
    already in the real wall, as an imported RMF door's is, would move as far again,
    behind the wall, by the gap between the annotated wall and the real one.)"""
    rid = resolve_room(pm, room)
    for m in world.moved_items:
        if m.kind == "door" and m.id == rid:
            return m.placed
    return goal_door(pm, room)


def goal_stop_point(pm: PrioriMap, room: str) -> tuple[float, float]:
    """``STOP_OFFSET_M`` from the room's door point towards the corridor centre line."""
    door = goal_door(pm, room)
    return point_towards(door, pm.locate(*door).point(pm), STOP_OFFSET_M)


class _GoalField:
    """Shortest paths from every map node to one goal room's node (one Dijkstra)."""

    def __init__(self, pm: PrioriMap, room: str):
        self.room = room
        self.node = pm.places[room].node
        self.dist, paths = nx.single_source_dijkstra(pm.graph, self.node, weight="length")
        self.paths = {n: tuple(reversed(p)) for n, p in paths.items()}
        self.stop = goal_stop_point(pm, room)
        self.door = goal_door(pm, room)
        self.tail = math.dist(pm.nodes[self.node].pos, self.stop)

    def via(self, seg_a: str, seg_b: str, s: float, length: float) -> tuple[str, float]:
        """(end node, distance to the goal node) for a point ``s`` along segment a->b."""
        da = s + self.dist.get(seg_a, math.inf)
        db = (length - s) + self.dist.get(seg_b, math.inf)
        return (seg_a, da) if da <= db else (seg_b, db)


def _facts(
    pm: PrioriMap, gf: _GoalField, xy, yaw: float | None, end: str | None = None
) -> PathFacts:
    """Facts of the geodesic from ``xy``; ``end`` forces the way off the start's segment."""
    loc = pm.locate(float(xy[0]), float(xy[1]))
    seg = loc.segment
    proj = loc.point(pm)
    s = loc.t * seg.length
    end, d = (
        gf.via(seg.a, seg.b, s, seg.length)
        if end is None
        else (end, (s if end == seg.a else seg.length - s) + gf.dist.get(end, math.inf))
    )
    if not math.isfinite(d):
        raise EpisodeGenerationError(f"room {gf.room!r} cannot be reached from {tuple(xy)}")
    route = gf.paths[end]
    pts: list[tuple[float, float]] = [(float(xy[0]), float(xy[1]))]
    if loc.offset > 0.01:
        pts.append((float(proj[0]), float(proj[1])))
    for n in route:
        p = pm.nodes[n].pos
        if math.dist(p, pts[-1]) > 1e-6:
            pts.append((float(p[0]), float(p[1])))
    pts.append(gf.stop)
    length = loc.offset + d + gf.tail
    # Turns at the vertices between the start's centre-line point and the goal node.
    first = 2 if loc.offset > 0.01 else 1
    turns = 0
    for i in range(first, len(pts) - 2):  # pts[-2] is the goal node
        a = relative_action(heading(pts[i - 1], pts[i]), heading(pts[i], pts[i + 1]))
        turns += a != Action.GO_STRAIGHT
    forks = sum(pm.nodes[n].kind == "branch" for n in route[:-1])
    keys_between = any(pm.nodes[n].is_key for n in route[:-1])
    visible = False
    if yaw is not None and not keys_between:
        dist_door = math.dist(pts[0], gf.door)
        bearing = wrap_angle(heading(pts[0], gf.door) - yaw)
        visible = dist_door <= VISIBLE_RANGE_M and abs(bearing) <= math.radians(
            VISIBLE_HALF_FOV_DEG
        )
    return PathFacts(float(length), int(turns), int(forks), visible, tuple(route), tuple(pts))


def path_facts(pm: PrioriMap, start: Pose2D | Sequence[float], goal: str) -> PathFacts:
    """The geodesic from ``start`` ((x, y[, yaw]) or a Pose2D) to room ``goal`` and its facts.

    Without a yaw, ``goal_visible`` is False.
    """
    if isinstance(start, Pose2D):
        xy, yaw = (start.x, start.y), start.yaw
    else:
        xy, yaw = start[:2], (float(start[2]) if len(start) > 2 else None)
    return _facts(pm, _GoalField(pm, resolve_room(pm, goal)), xy, yaw)


def route_length(pm: PrioriMap, start_xy: Sequence[float], goal: str) -> float:
    """Corridor-route distance from ``start_xy`` to room ``goal``'s stop point (metres)."""
    return path_facts(pm, tuple(start_xy[:2]), goal).length


def shortest_path_points(
    pm: PrioriMap, start_xy: Sequence[float], goal_room: str
) -> list[tuple[float, float]]:
    """The corridor route as a polyline: start, (its projection), map nodes, stop point."""
    return list(path_facts(pm, tuple(start_xy[:2]), goal_room).points)


def goal_geodesic(
    pm: PrioriMap,
    room: str,
    obstacles: Sequence = (),
    robot_radius: float = CREATE3_RADIUS_M,
    radius: float = SUCCESS_RADIUS_M,
    floor=None,
    door: tuple[float, float] | None = None,
) -> GeodesicField:
    """SPL's shortest paths to room ``room``: the geodesic through the open floor (the
    corridors unless ``floor`` says otherwise, e.g. ``SimWorld.floor_space()`` with grid
    walls), less the robot's radius and the footprints of ``obstacles``, to the success
    disc of the door (the file's door point unless ``door`` says where the world has it,
    :func:`goal_door_in_world`)."""
    return GeodesicField(
        free_space_polygon(pm.building) if floor is None else floor,
        goal_door(pm, room) if door is None else door,
        radius,
        robot_radius=robot_radius,
        obstacles=obstacles,
    )


# -- generation ----------------------------------------------------------------------------


def _as_map(b: Building | PrioriMap | str | Path) -> tuple[PrioriMap, str, str]:
    """The priori-map, the building file's absolute path and its sha256 ("" if unknown)."""
    if isinstance(b, PrioriMap):
        return b, "", ""
    if isinstance(b, Building):
        return parse_building(b), "", ""
    path = resolve_building_path(b).resolve()
    return parse_building(open_building(path)), str(path), building_sha256(path)


def _structure_hint(pm: PrioriMap) -> str:
    kinds = [n.kind for n in pm.key_waypoints]
    cyc = len(nx.cycle_basis(pm.building.corridor_graph()))
    return (
        f"{pm.building.name} has {kinds.count('turn')} turn and {kinds.count('branch')} "
        f"branch waypoints{' and a loop' if cyc else ''}"
    )


def generate_episodes(
    building: Building | PrioriMap | str | Path, tier: str, n: int, seed: int = 0
) -> list[Episode]:
    """``n`` episodes of ``tier`` in a building (object, priori-map, file or built-in name).

    Seeded: the same building, tier, n and seed give the same episodes. Goals are drawn
    uniformly over the rooms that have a start fitting the tier, then starts uniformly
    over the fitting centre-line points, then the yaw (either way along the corridor).
    """
    if tier not in TIERS:
        raise EpisodeGenerationError(f"unknown tier {tier!r}: choose {', '.join(TIERS)}")
    if n < 0:
        raise EpisodeGenerationError(f"the number of episodes must be >= 0, not {n}")
    spec = TIERS[tier]
    pm, building_path, sha = _as_map(building)
    name = pm.building.name
    rng = np.random.default_rng([seed, zlib.crc32(name.encode()), list(TIERS).index(tier)])
    xy, seg_idx, s_along = start_candidates(pm)
    lo, hi = spec.length_band

    # Per goal: the candidate starts whose length and route structure fit the tier.
    fits: dict[str, tuple[_GoalField, np.ndarray]] = {}
    for room in sorted(r.id for r in pm.building.rooms):
        gf = _GoalField(pm, room)
        ok = np.zeros(len(xy), dtype=bool)
        for k, sg in enumerate(pm.segments):
            m = np.nonzero(seg_idx == k)[0]
            if not len(m):
                continue
            s = s_along[m]
            da = s + gf.dist.get(sg.a, math.inf)
            db = sg.length - s + gf.dist.get(sg.b, math.inf)
            length = np.minimum(da, db) + gf.tail
            band = (length >= lo) & (length < hi)
            for end, mask in ((sg.a, da <= db), (sg.b, da > db)):
                sel = m[band & mask]
                if len(sel) and _route_fits(pm, gf, spec, xy[sel[0]], end):
                    ok[sel] = True
        if ok.any():
            fits[room] = (gf, np.nonzero(ok)[0])
    if not fits and n > 0:
        raise EpisodeGenerationError(
            f"no {tier} episodes fit {name}: {spec.describe().split('  [')[0]}; "
            f"{_structure_hint(pm)}"
        )

    episodes: list[Episode] = []
    seen: set[tuple] = set()
    goals = sorted(fits)
    attempts = 0
    while len(episodes) < n:
        attempts += 1
        if attempts > 200 * n + 2000:
            raise EpisodeGenerationError(
                f"found only {len(episodes)} distinct {tier} episodes in {name} "
                f"(asked for {n}); ask for fewer"
            )
        room = goals[int(rng.integers(len(goals)))]
        gf, cand = fits[room]
        i = int(cand[int(rng.integers(len(cand)))])
        sg = pm.segments[int(seg_idx[i])]
        yaw = wrap_angle(sg.heading + (math.pi if rng.random() < 0.5 else 0.0))
        x, y = round(float(xy[i, 0]), 3), round(float(xy[i, 1]), 3)
        key = (room, x, y, round(yaw, 3))
        if key in seen:
            continue
        facts = _facts(pm, gf, (x, y), yaw)
        if not spec.accepts(facts):
            continue
        seen.add(key)
        episodes.append(
            Episode(
                id=f"{name}-{tier}-s{seed}-{len(episodes):03d}",
                building=name,
                tier=tier,
                start_x=x,
                start_y=y,
                start_yaw=yaw,
                goal=room,
                route_length=facts.length,
                seed=int(rng.integers(2**31 - 1)),
                goal_visible=facts.goal_visible,
                turns=facts.turns,
                forks=facts.forks,
                route=facts.route,
                step_budget=action_budget(facts.length),
                building_path=building_path,
                building_sha256=sha,
            )
        )
    return episodes


def _route_fits(pm: PrioriMap, gf: _GoalField, spec: TierSpec, xy, end: str) -> bool:
    """Whether routes leaving a segment through ``end`` meet the tier's turn/fork counts."""
    f = _facts(pm, gf, xy, None, end)
    ok = within(f.turns, spec.min_turns, spec.max_turns) and within(
        f.forks, spec.min_forks, spec.max_forks
    )
    if spec.goal_visible:  # needs a straight run with no key waypoint between
        ok = ok and not any(pm.nodes[k].is_key for k in f.route[:-1])
    return ok


def score_episode(
    pm: PrioriMap,
    episode: Episode,
    stop_xy: Sequence[float],
    *,
    geodesic: GeodesicField,
    path_length: float,
    steps: int,
    collisions: int,
    people_contacts: int,
    wall_time: float,
    failure: str | None = None,
    trace: list | None = None,
    door: tuple[float, float] | None = None,
) -> EpisodeResult:
    """Score a run that stopped at ``stop_xy``: success within the radius of the goal door
    (the file's door point unless ``door`` says where the world has it,
    :func:`goal_door_in_world`; and no ``failure`` reported); SPL and soft SPL against the
    free-space ``geodesic`` (:func:`goal_geodesic`) from the start to the success disc."""
    door = goal_door(pm, episode.goal) if door is None else door
    stop = (float(stop_xy[0]), float(stop_xy[1]))
    dist = math.dist(stop, door)
    ok = failure is None and success(stop, door)
    reason = failure
    if failure is None and not ok:
        reason = f"{FailureCode.STOPPED_AWAY.value}: stopped {dist:.2f} m from the door"
    shortest = geodesic.distance((episode.start_x, episode.start_y))
    to_goal = 0.0 if ok else geodesic.distance(stop)
    return EpisodeResult(
        episode_id=episode.id,
        tier=episode.tier,
        success=ok,
        spl=spl(ok, shortest, path_length),
        path_length=path_length,
        steps=steps,
        collisions=collisions,
        people_contacts=people_contacts,
        wall_time=wall_time,
        failure_reason=reason,
        shortest_path_length=shortest,
        distance_to_goal=to_goal,
        building=episode.building,
        trace=trace,
        soft_spl=soft_spl(shortest, to_goal, path_length) if math.isfinite(to_goal) else 0.0,
        distance_to_door=dist,
        route_length=episode.route_length,
    )
