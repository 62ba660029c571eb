"""Navigation episodes: tiers, geodesic paths, a seeded generator, and the JSON episode file.

An episode is a start pose on a corridor centre line (yaw along the corridor) and a goal
room. Its geodesic is the corridor-graph path from the start to the goal room's node on
the centre line, then straight to the goal *stop point*, ``STOP_OFFSET_M`` from the door
point towards the corridor centre. Success is stopping within ``SUCCESS_RADIUS_M`` of the
door point (:mod:`pmnav_bt.eval.metrics`).

The tiers (paper RQ1) are defined once, in ``TIERS``, by structure (goal visible from the
start, turns and forks on the path) and path length in paper "steps" of ``STEP_M``;
``tier_definition()`` prints them.
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

from pmnav_bt.errors import PmNavError, Problem
from pmnav_bt.eval.metrics import SUCCESS_RADIUS_M, EpisodeResult, spl, success
from pmnav_bt.geometry import Action, heading, point_towards, relative_action, wrap_angle
from pmnav_bt.loading import InputFileError, atomic_write_text, load_json
from pmnav_bt.map.building import Building, load_building
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.seams import FORWARD_STEP_M, Pose2D

__all__ = [
    "EPISODES_SCHEMA_VERSION",
    "START_CLEARANCE_M",
    "STEP_BUDGET",
    "STEP_M",
    "STOP_OFFSET_M",
    "SUCCESS_RADIUS_M",
    "TIERS",
    "VISIBLE_HALF_FOV_DEG",
    "VISIBLE_RANGE_M",
    "Episode",
    "EpisodeFileError",
    "EpisodeGenerationError",
    "PathFacts",
    "TierSpec",
    "classify",
    "generate_episodes",
    "geodesic_length",
    "goal_door",
    "goal_stop_point",
    "load_episodes",
    "path_facts",
    "save_episodes",
    "shortest_path_points",
    "step_budget",
    "tier_definition",
]

# -- the numbers, in one place ------------------------------------------------------------

STEP_M = 1.0  # one paper "step" (RQ1 step counts fit moves of about a metre)
STOP_OFFSET_M = 0.6  # stop point: this far from the door point towards the corridor centre
VISIBLE_RANGE_M = 10.0  # a door sign is readable up to this distance
VISIBLE_HALF_FOV_DEG = 25.0  # door centre within +-this of the start heading (60 deg camera)
START_CLEARANCE_M = 1.5  # starts at least this far from any key waypoint (junction, end)
STEP_BUDGET = 500  # actions per episode (Habitat ObjectNav), scaled up for long paths
_GRID_M = 0.05  # spacing of candidate start points along the centre lines

EPISODES_SCHEMA_VERSION = 1


@dataclass(frozen=True)
class TierSpec:
    """One difficulty tier: path length in steps and the structure the path must have."""

    name: str
    min_steps: int
    max_steps: int
    goal_visible: bool | None  # required value; None: either
    min_turns: int
    max_turns: int | None
    min_forks: int
    max_forks: int | None
    paper: str  # the paper's words (RQ1)

    @property
    def length_band(self) -> tuple[float, float]:
        """Geodesic length band in metres, [lo, hi): step counts rounded to the nearest step."""
        return (self.min_steps - 0.5) * STEP_M, (self.max_steps + 0.5) * STEP_M

    def accepts(self, facts: PathFacts) -> bool:
        lo, hi = self.length_band
        return (
            lo <= facts.length < hi
            and (self.goal_visible is None or facts.goal_visible == self.goal_visible)
            and _within(facts.turns, self.min_turns, self.max_turns)
            and _within(facts.forks, self.min_forks, self.max_forks)
        )

    def describe(self) -> str:
        lo, hi = self.length_band
        vis = {True: "goal visible", False: "goal not visible", None: "goal visible or not"}
        return (
            f"{self.name}: {vis[self.goal_visible]}; turns {_range(self.min_turns, self.max_turns)}"
            f"; forks {_range(self.min_forks, self.max_forks)}; "
            f"{self.min_steps}-{self.max_steps} steps (geodesic {lo:.1f} <= l < {hi:.1f} m)"
            f"  [paper: {self.paper}]"
        )


def _within(v: int, lo: int, hi: int | None) -> bool:
    return v >= lo and (hi is None or v <= hi)


def _range(lo: int, hi: int | None) -> str:
    if hi is None:
        return f">= {lo}"
    return f"= {lo}" if lo == hi else f"{lo}-{hi}"


TIERS: dict[str, TierSpec] = {
    t.name: t
    for t in (
        TierSpec(
            name="easy",
            min_steps=3,
            max_steps=5,
            goal_visible=True,
            min_turns=0,
            max_turns=0,
            min_forks=0,
            max_forks=0,
            paper="goal in view, reachable in 3-5 steps",
        ),
        TierSpec(
            name="medium",
            min_steps=6,
            max_steps=10,
            goal_visible=False,
            min_turns=1,
            max_turns=None,
            min_forks=0,
            max_forks=0,
            paper="goal not visible, at least one turn, 6-10 steps",
        ),
        TierSpec(
            name="hard",
            min_steps=11,
            max_steps=60,
            goal_visible=False,
            min_turns=2,
            max_turns=None,
            min_forks=1,
            max_forks=None,
            paper="several turns and fork selections, more than 10 steps",
        ),
    )
}


def tier_definition() -> str:
    """The tier definitions as text, to print with results."""
    lines = [
        "Episode tiers (PM-Nav RQ1), by structure and geodesic length l from the start to the "
        f"goal stop point ({STOP_OFFSET_M:g} m from the door towards the corridor centre); "
        f"1 step = {STEP_M:g} m:",
    ]
    lines += [f"- {t.describe()}" for t in TIERS.values()]
    lines += [
        f"Goal visible: the goal door is on the start's straight corridor (no key waypoint "
        f"between), within {VISIBLE_RANGE_M:g} m and +-{VISIBLE_HALF_FOV_DEG:g} deg of the "
        "start heading. Turn: the path bends by more than 30 deg at a waypoint. Fork: the path "
        "passes a branch waypoint (3+ corridors meet). The hard tier is capped at "
        f"{TIERS['hard'].max_steps} steps. Starts lie on a corridor centre line, at least "
        f"{START_CLEARANCE_M:g} m from any key waypoint, facing along the corridor. "
        f"Success: stop within {SUCCESS_RADIUS_M:g} m of the door point. Step budget: "
        f"{STEP_BUDGET} actions, or twice the forward steps of the geodesic if more.",
    ]
    return "\n".join(lines)


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


# -- episodes -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Episode:
    """One navigation task: start pose, goal room and the facts of its geodesic."""

    id: str
    building: str
    tier: str
    start_x: float
    start_y: float
    start_yaw: float  # rad, CCW from +x
    goal: str  # room id
    geodesic_length: float  # metres, start to the goal stop point
    seed: int  # for everything random inside the episode (noise, detector misses)
    goal_visible: bool
    turns: int
    forks: int
    route: tuple[str, ...] = ()  # priori-map nodes of the geodesic, ending at the goal node
    step_budget: int = STEP_BUDGET

    @property
    def start_pose(self) -> Pose2D:
        return Pose2D(self.start_x, self.start_y, self.start_yaw)

    @property
    def steps(self) -> int:
        """Path length in paper steps of ``STEP_M``."""
        return int(round(self.geodesic_length / STEP_M))

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["route"] = list(self.route)
        return d


_FIELD_TYPES: dict[str, tuple[type, ...]] = {
    "id": (str,),
    "building": (str,),
    "tier": (str,),
    "start_x": (int, float),
    "start_y": (int, float),
    "start_yaw": (int, float),
    "goal": (str,),
    "geodesic_length": (int, float),
    "seed": (int,),
    "goal_visible": (bool,),
    "turns": (int,),
    "forks": (int,),
    "route": (list,),
    "step_budget": (int,),
}
_OPTIONAL = {"route", "step_budget"}
# Plausible magnitudes: a building fits in 1 km; text is short; budgets stay finite.
_LIMITS: dict[str, tuple[float, float]] = {
    "id": (1, 200),
    "building": (1, 4096),
    "goal": (1, 64),
    "start_x": (-1000.0, 1000.0),
    "start_y": (-1000.0, 1000.0),
    "start_yaw": (-100.0, 100.0),
    "geodesic_length": (0.0, 100_000.0),
    "seed": (0, 2**63 - 1),
    "turns": (0, 10_000),
    "forks": (0, 10_000),
    "route": (0, 10_000),
    "step_budget": (1, 1_000_000),
}
_LENGTHS = {"id", "building", "goal", "route"}
MAX_EPISODES = 100_000


def _in_limits(key: str, v: Any) -> bool:
    lo, hi = _LIMITS[key]
    return lo <= (len(v) if key in _LENGTHS else v) <= hi


def _episode_from_dict(d: Any, where: str) -> tuple[Episode | None, list[Problem]]:
    if not isinstance(d, dict):
        return None, [Problem(where, f"expected an object, got {type(d).__name__}")]
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
        if ok and k == "route":
            ok = all(isinstance(x, str) for x in v)
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
    if not problems and d["geodesic_length"] < 0:
        problems.append(Problem(f"{where}.geodesic_length", "must be non-negative"))
    if problems:
        return None, problems
    kw = dict(d)
    kw["route"] = tuple(kw.get("route", ()))
    for k in ("start_x", "start_y", "start_yaw", "geodesic_length"):
        kw[k] = float(kw[k])
    return Episode(**kw), []


def save_episodes(episodes: Sequence[Episode], path: str | Path) -> Path:
    """Write episodes to a JSON file (with the tier definition, for the reader)."""
    path = Path(path)
    data = {
        "format": "pmnav-episodes",
        "schema_version": EPISODES_SCHEMA_VERSION,
        "tier_definition": tier_definition(),
        "episodes": [e.to_dict() for e in episodes],
    }
    return atomic_write_text(path, json.dumps(data, indent=1) + "\n")


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
                    f"this version of pmnav reads {EPISODES_SCHEMA_VERSION}, not {version!r}",
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


def goal_stop_point(pm: PrioriMap, room: str) -> tuple[float, float]:
    """``STOP_OFFSET_M`` from the room's door point towards the corridor centre line."""
    door = goal_door(pm, room)
    return point_towards(door, pm.locate(*door).point(pm), STOP_OFFSET_M)


@dataclass(frozen=True)
class PathFacts:
    """The geodesic from a start pose to a goal room, and its structural facts."""

    length: float
    turns: int
    forks: int
    goal_visible: bool
    route: tuple[str, ...]  # priori-map nodes, ending at the goal node
    points: tuple[tuple[float, float], ...]  # polyline: start ... goal node, stop point


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


def geodesic_length(pm: PrioriMap, start_xy: Sequence[float], goal: str) -> float:
    """Corridor-graph distance from ``start_xy`` to room ``goal``'s stop point (metres)."""
    return path_facts(pm, tuple(start_xy[:2]), goal).length


def shortest_path_points(
    pm: PrioriMap, start_xy: Sequence[float], goal_room: str
) -> list[tuple[float, float]]:
    """The geodesic as a polyline: start, (its projection), map nodes, goal stop point."""
    return list(path_facts(pm, tuple(start_xy[:2]), goal_room).points)


def classify(facts: PathFacts) -> str | None:
    """The tier whose definition the path meets, or None."""
    return next((t.name for t in TIERS.values() if t.accepts(facts)), None)


def step_budget(geodesic: float) -> int:
    """``STEP_BUDGET``, or twice the forward steps the geodesic alone needs if more."""
    return max(STEP_BUDGET, 2 * math.ceil(geodesic / FORWARD_STEP_M))


# -- generation ----------------------------------------------------------------------------


def _as_map(b: Building | PrioriMap | str | Path) -> PrioriMap:
    if isinstance(b, PrioriMap):
        return b
    if not isinstance(b, Building):
        b = load_building(b)
    return parse_building(b)


def _candidates(pm: PrioriMap) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Start candidates on the centre lines: xy (N,2), segment index (N,), s along it (N,)."""
    keys = np.array([n.pos for n in pm.key_waypoints], dtype=float)
    xy, seg, ss = [], [], []
    for k, sg in enumerate(pm.segments):
        a, b = pm.node_xy(sg.a), pm.node_xy(sg.b)
        s = np.arange(0.0, sg.length + 1e-9, _GRID_M)
        p = a + (s / max(sg.length, 1e-9))[:, None] * (b - a)
        clear = np.linalg.norm(p[:, None, :] - keys[None], axis=2).min(axis=1)
        ok = clear >= START_CLEARANCE_M
        xy.append(p[ok])
        seg.append(np.full(int(ok.sum()), k))
        ss.append(s[ok])
    return np.concatenate(xy), np.concatenate(seg), np.concatenate(ss)


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
    pm = _as_map(building)
    name = pm.building.name
    # Episodes name their building so it loads again: a file by its path, a built-in by name.
    source = str(building) if isinstance(building, (str, Path)) else name
    rng = np.random.default_rng([seed, zlib.crc32(name.encode()), list(TIERS).index(tier)])
    xy, seg_idx, s_along = _candidates(pm)
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
                building=source,
                tier=tier,
                start_x=x,
                start_y=y,
                start_yaw=yaw,
                goal=room,
                geodesic_length=facts.length,
                seed=int(rng.integers(2**31 - 1)),
                goal_visible=facts.goal_visible,
                turns=facts.turns,
                forks=facts.forks,
                route=facts.route,
                step_budget=step_budget(facts.length),
            )
        )
    return episodes


def _route_fits(pm: PrioriMap, gf: _GoalField, spec: TierSpec, xy, end: str) -> bool:
    """Whether routes leaving a segment through ``end`` meet the tier's turn/fork counts."""
    f = _facts(pm, gf, xy, None, end)
    ok = _within(f.turns, spec.min_turns, spec.max_turns) and _within(
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
    path_length: float,
    steps: int,
    collisions: int,
    wall_time: float,
    failure: str | None = None,
    trace: list | None = None,
) -> EpisodeResult:
    """Score a run that stopped at ``stop_xy``: success within the radius of the goal door
    (and no ``failure`` reported), SPL against the episode's geodesic."""
    door = goal_door(pm, episode.goal)
    dist = math.dist((float(stop_xy[0]), float(stop_xy[1])), door)
    ok = failure is None and success(stop_xy, door)
    reason = failure
    if failure is None and not ok:
        reason = f"STOPPED_AWAY: stopped {dist:.2f} m from the door"
    return EpisodeResult(
        episode_id=episode.id,
        tier=episode.tier,
        success=ok,
        spl=spl(ok, episode.geodesic_length, path_length),
        path_length=path_length,
        steps=steps,
        collisions=collisions,
        wall_time=wall_time,
        failure_reason=reason,
        shortest_path_length=episode.geodesic_length,
        distance_to_goal=dist,
        building=episode.building,
        trace=trace,
    )
