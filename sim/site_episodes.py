"""Episodes across levels (issue 40): a start on one level of a site, a goal room on
another, reached by lift (the tier ``cross_level``).

A ``SiteEpisode`` names its site (a built-in or generated site by its name, so that an
episode file travels to another machine as the one-level episodes of built-ins do; any
other by its file's absolute path: ``site_ref``), the start level and
pose (that level's map frame, on a corridor centre line, along the corridor), the goal
room and its level. Its route is the ``SitePlan`` from the start (``planning/site_plan.py``):
``route_length`` is the corridor metres of its legs together, the rides not counted.
Generation is seeded: the same site, n and seed give the same episodes. They are written
to and read from the episode file of ``sim/episodes.py`` beside the one-level episodes (an
entry with a ``site`` key is a ``SiteEpisode``: ``site_episode_from_dict``).
"""

from __future__ import annotations

import math
import zlib
from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from pmnav_bt.errors import PmNavError, Problem
from pmnav_bt.eval.task import action_budget
from pmnav_bt.eval.tiers import CROSS_LEVEL, start_candidates
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.catalogue import generated_site_path, is_generated_site_name
from pmnav_bt.map.site import BUILTIN_SITES_DIR, Site, load_site
from pmnav_bt.map.site_map import SiteMap, parse_site
from pmnav_bt.planning.resolve import resolve_site_room, resolve_start
from pmnav_bt.planning.site_plan import SitePlan, SitePlanner
from pmnav_bt.seams import Pose2D

# The actions a lift ride adds to an episode's budget (eval/task.py's rule for the legs):
# to the lobby, into the cabin, round, out, and on arrival a localization from scratch
# (a panorama of 6-12 views and a fix, as at the start). One ride in hospital_2l's
# realistic world took 66 (the lobby to the fix on the next level).
RIDE_ACTIONS = 100


class SiteEpisodeError(PmNavError):
    """A site episode cannot be made: a one-level site, an unknown start or goal."""


@dataclass(frozen=True)
class SiteEpisode:
    """One task across levels (see the module)."""

    id: str
    site: str
    start_level: str
    start_x: float
    start_y: float
    start_yaw: float
    goal: str  # room id on ``goal_level``
    goal_level: str
    route_length: float
    seed: int
    rides: int
    tier: str = CROSS_LEVEL

    @property
    def building(self) -> str:
        """The site, where an evaluation names an episode's building (its results' rows)."""
        return self.site

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)

    @property
    def start_pose(self) -> Pose2D:
        return Pose2D(self.start_x, self.start_y, self.start_yaw)

    @property
    def step_budget(self) -> int:
        """The default budget rule on the legs' corridors, and ``RIDE_ACTIONS`` a ride."""
        return action_budget(self.route_length) + RIDE_ACTIONS * self.rides


def site_map(site: str | Site) -> SiteMap:
    """The priori-maps of a site of several levels (a name or a path, or a Site)."""
    s = site if isinstance(site, Site) else load_site(site)
    if len(s.levels) < 2:
        raise SiteEpisodeError(f"{s.name} has one level: its episodes are 'pmnav sim episodes'")
    return parse_site(s)


def site_ref(s: Site) -> str:
    """How an episode names its site: a built-in or a generated site (``hospital_site_3``)
    by its name, any other by its file."""
    if s.path is None:
        raise SiteEpisodeError(f"site {s.name} has no file: its episodes cannot name it")
    path = s.path.resolve()
    if path == (BUILTIN_SITES_DIR / f"{path.stem}.yaml").resolve():
        return path.stem
    if is_generated_site_name(path.stem) and path == generated_site_path(path.stem).resolve():
        return path.stem
    return str(path)


_TYPES: dict[str, tuple[type, ...]] = {
    "id": (str,),
    "site": (str,),
    "start_level": (str,),
    "start_x": (int, float),
    "start_y": (int, float),
    "start_yaw": (int, float),
    "goal": (str,),
    "goal_level": (str,),
    "route_length": (int, float),
    "seed": (int,),
    "rides": (int,),
    "tier": (str,),
}


def site_episode_from_dict(d: dict, where: str) -> tuple[SiteEpisode | None, list[Problem]]:
    """A ``SiteEpisode`` from its entry in an episode file, or the entry's problems (an
    unknown or missing key, a wrong type, a tier other than cross_level). The site itself
    is opened when the episode runs."""
    problems = [Problem(f"{where}.{k}", "unknown key") for k in d if k not in _TYPES]
    for k, types in _TYPES.items():
        if k not in d:
            if k != "tier":
                problems.append(Problem(f"{where}.{k}", "required key is missing"))
            continue
        v = d[k]
        ok = isinstance(v, types) and not isinstance(v, bool)
        if ok and isinstance(v, float) and not math.isfinite(v):
            ok = False
        if not ok:
            want = " or ".join(t.__name__ for t in types)
            problems.append(Problem(f"{where}.{k}", f"expected {want}, got {v!r:.60}"))
    if not problems and d.get("tier", CROSS_LEVEL) != CROSS_LEVEL:
        problems.append(Problem(f"{where}.tier", f"an episode with a site is {CROSS_LEVEL}"))
    if not problems and (d["rides"] < 1 or d["route_length"] < 0):
        problems.append(Problem(f"{where}.rides", "expected >= 1 ride, a route >= 0 m"))
    if problems:
        return None, problems
    kw = {f.name: d[f.name] for f in fields(SiteEpisode) if f.name in d}
    for k in ("start_x", "start_y", "start_yaw", "route_length"):
        kw[k] = float(kw[k])
    return SiteEpisode(**kw), []


def site_plan(sm: SiteMap, ep: SiteEpisode) -> SitePlan:
    """The route of ``ep`` across levels."""
    return SitePlanner().plan(sm, ep.start_level, ep.start_pose, f"{ep.goal_level}/{ep.goal}")


def custom_site_episode(
    site: str, goal: str, start: str | None = None, seed: int = 0
) -> SiteEpisode:
    """An episode for ``pmnav sim run`` in a site: ``goal`` as a person names it (on any
    level, qualified where it is on several: "L2/toilets"); ``start`` a start on a level
    ("L2/x,y,yaw_deg", "L2/start"; unqualified: on the first level), by default the first
    level's start waypoint, facing along its corridor."""
    sm = site_map(site)
    level, _, where = (start or "").rpartition("/")
    level = sm.site.level(level).name if level else sm.site.levels[0].name
    pm = sm.maps[level]
    sp = resolve_start(pm, where or _start_waypoint(sm, level))
    a, b = pm.node_xy(sp.segment.a), pm.node_xy(sp.segment.b)
    xy = a + sp.t * (b - a)
    yaw = sp.heading if sp.heading is not None else sp.segment.heading
    if not where:  # a little into the corridor, not against the end wall
        xy = xy + 0.5 * np.array([math.cos(yaw), math.sin(yaw)])
    goal_level, room = resolve_site_room(sm, goal)
    ident = f"{sm.site.name}-{goal_level}-{room}"
    return _episode(sm, ident, level, xy, yaw, goal_level, room, seed)


def _start_waypoint(sm: SiteMap, level: str) -> str:
    b = sm.maps[level].building
    w = next((w for w in b.waypoints if w.kind.value == "start"), b.waypoints[0])
    return w.id


def _episode(sm, ident, level, xy, yaw, goal_level, room, seed) -> SiteEpisode:
    pose = Pose2D(float(xy[0]), float(xy[1]), float(yaw))
    plan = SitePlanner().plan(sm, level, pose, f"{goal_level}/{room}")
    return SiteEpisode(
        id=ident,
        site=site_ref(sm.site),
        start_level=level,
        start_x=pose.x,
        start_y=pose.y,
        start_yaw=pose.yaw,
        goal=room,
        goal_level=goal_level,
        route_length=plan.length,
        seed=int(seed),
        rides=len(plan.rides),
    )


def generate_site_episodes(site: str | Site, n: int, seed: int = 0) -> list[SiteEpisode]:
    """``n`` episodes across levels: the start level, then a goal level other than it and a
    goal room there, then a start on the start level's centre lines (clear of junctions and
    ends, as the one-level tiers' starts) facing either way, all drawn from ``seed``."""
    if n < 0:
        raise SiteEpisodeError(f"the number of episodes must be >= 0, not {n}")
    sm = site_map(site)
    names = list(sm.site.level_names)
    rng = np.random.default_rng([seed, zlib.crc32(sm.site.name.encode()), 40])
    out: list[SiteEpisode] = []
    while len(out) < n:
        level = names[int(rng.integers(len(names)))]
        others = [lv for lv in names if lv != level]
        goal_level = others[int(rng.integers(len(others)))]
        rooms = sorted(r.id for r in sm.maps[goal_level].building.rooms)
        room = rooms[int(rng.integers(len(rooms)))]
        pm = sm.maps[level]
        xy, seg_idx, _ = start_candidates(pm)
        i = int(rng.integers(len(xy)))
        seg = pm.segments[int(seg_idx[i])]
        yaw = wrap_angle(seg.heading + (math.pi if rng.random() < 0.5 else 0.0))
        ident = f"{sm.site.name}-{CROSS_LEVEL}-s{seed}-{len(out):03d}"
        ep_seed = int(rng.integers(2**31 - 1))
        out.append(_episode(sm, ident, level, np.round(xy[i], 3), yaw, goal_level, room, ep_seed))
    return out
