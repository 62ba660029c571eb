"""The lead: where the corridor belief says to drive next, and whether signs are in reach.

The belief's hypotheses each put the robot somewhere on the corridors; the lead is one
of the ways out along the corridor axis (or across it at a junction), weighed over all of
them: how much of the belief says that way is open, and how far it expects signs (or,
with a ``target``, the whole trip to the target by way of signs) that way. When the
belief is split between a few clusters, a telling place comes first (``pose.telling``).

The ways are numbered 0-3 counter-clockwise from the corridor axis at the reference (in
the belief's straightened odometry); the belief remembers the way it chose last, so that
it explores one way to the end, then the other (``choose_lead`` takes and returns it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.pose.belief_view import BeliefView
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.telling import WALL_COST_M, telling_lead
from pmnav_bt.seams import Pose2D

BLOCKED_NEAR_M = 1.0  # a drive blocked this close to here: that way is shut from here
KEEP_WAY_MASS = 0.3  # keep exploring the same way while this much belief says it goes on
CROSS_WAY_MASS = 0.7  # turn into a side corridor only when this much belief says it is there
LOOK_SPACING_M = 6.0  # look round at least this far beyond an earlier look in the same way
JUNCTION_REACH_M = 1.0  # side corridors of a junction this close are the robot's
DIFFUSE_MASS = 0.3  # below this (best cluster), the belief is diffuse: look close by first
NEAR_JUNCTION_M = 6.0  # ... at a junction or corridor end this close (its shape tells much)
FIRST_JUNCTION_QUANTILE = 0.2  # diffuse, first drive: stop where this share puts a junction
LEAD_QUANTILE = 0.25  # drive to where this share of the belief has signs in reach
SWITCH_COST_RATIO = 2.0  # turn back when the other way is expected this much shorter


@dataclass(frozen=True)
class Lead:
    """Which way to go: an odometry heading, how far, and the share of belief behind it."""

    heading: float
    distance: float
    support: float


def choose_lead(
    b: BeliefView, odom: Pose2D, max_distance: float, last_way: int | None
) -> tuple[Lead | None, int | None]:
    """Where to drive from ``odom`` and the way (0-3) that is, given the way chosen last.

    It keeps ``last_way`` while enough of the belief says that way goes on (so it explores
    one way to the end, then the other), else the open way with the least expected
    corridor distance to where the map says two signs are readable (with a ``target``: to
    the target by way of such signs, so the search for signs heads where the robot is
    going), as far as where a quarter of the belief has signs in reach. The drive stops at
    the next junction, where half the belief puts it (on the first drive from a diffuse
    belief, where a fifth does: from a bare corridor the median junction is far, and a
    nearer one passed unlooked-at is the place that would have told the position)."""
    dist, _ = b.goal.towards_signs
    if not dist:
        return None, last_way
    blocked = blocked_ways(b, odom)
    told = telling_lead(b, odom, max_distance, JUNCTION_REACH_M)
    if told is not None and told[3] not in blocked:
        return Lead(*told[:3]), told[3]
    # (its way is shut from here: choose as if it had none)
    w = b.weights()
    tfs = b.map_T_odoms()
    live = np.nonzero(w > 1e-4 * w.max())[0]
    p = b.straighten((odom.x, odom.y))
    here = apply_many(tfs[live], (p[0], p[1]))
    near, _ = b.vis.nearest_many(here)
    axis = b.axis()
    open_mass = np.zeros(4)  # belief that each way (along/across the axis) is open
    cost = np.zeros(4)  # expected distance to signs each way
    trip = np.zeros(4)  # ... and to the target by way of signs (the whole trip)
    onward = None if b.target is None else b.goal.exits_to(b.target)
    run = [[] for _ in range(4)]  # (weight, distance to the next junction) per way
    reads = [[] for _ in range(4)]  # (weight, distance to signs) per way
    side_mass = 0.0  # belief that the robot is at a junction with a side corridor
    # Side corridors of a junction within reach count (it is easy to stop a little off
    # its centre); along the axis only the nearest point's ways (a dead end stays one).
    pairs = b.vis.lattice_within(here, JUNCTION_REACH_M)
    reach: dict[int, list[int]] = {}
    for a, c in pairs.T:
        reach.setdefault(int(a), []).append(int(c))
    for n, (i, j) in enumerate(zip(live, near, strict=True)):
        ways: dict[int, tuple[float, float, float]] = {}
        for m in {j, *reach.get(n, ())}:
            for h_map, d in b.goal.exits[m]:
                k = int(round(wrap_angle(h_map - tfs[i][2] - axis) / (math.pi / 2))) % 4
                if m != j and k % 2 == 0:
                    continue
                r = b.goal.run_lengths[m].get(h_map, 0.0)
                t = d if onward is None else onward[m].get(h_map, math.inf)
                if k not in ways or d < ways[k][0]:
                    ways[k] = (d, r, t)
        if 1 in ways or 3 in ways:
            side_mass += w[i]
        for k, (d, r, t) in ways.items():
            open_mass[k] += w[i]
            cost[k] += w[i] * min(d, WALL_COST_M)
            trip[k] += w[i] * min(t, 2.0 * WALL_COST_M)
            run[k].append((w[i], r))
            reads[k].append((w[i], min(d, WALL_COST_M)))
    total = float(w[live].sum())
    open_mass /= total
    side_mass /= total
    cost = np.where(open_mass > 0, cost / np.maximum(open_mass * total, 1e-12), np.inf)
    trip = np.where(open_mass > 0, trip / np.maximum(open_mass * total, 1e-12), np.inf)
    # Across the axis only where the belief is sure of a junction (it is easy to be a
    # metre or two short of one); along it while a third of the belief says it goes on,
    # except at a junction, where the way is chosen afresh.
    cross = CROSS_WAY_MASS if side_mass < CROSS_WAY_MASS else KEEP_WAY_MASS
    need = np.array([KEEP_WAY_MASS, cross, KEEP_WAY_MASS, cross])
    ends = np.full(4, np.inf)  # weighted median distance to the next junction or end
    for j, r in enumerate(run):
        if r:
            ends[j] = weighted_quantile(*np.array(r).T, 0.5)
    open_mass[list(blocked)] = 0.0  # not into the wall this spot's drive just met
    ok = np.nonzero(open_mass >= need)[0]
    k = last_way
    if k is not None and open_mass[k] >= need[k] and side_mass < CROSS_WAY_MASS:
        # Keep the way, unless the other way is expected much shorter (after what was
        # seen on this one): a search that doubles back instead of going on forever.
        back = (k + 2) % 4
        if back in ok and SWITCH_COST_RATIO * cost[back] < cost[k]:
            k = back
    elif len(ok):
        k = int(ok[np.argmin(trip[ok])])
        _, mass = b.best_cluster()
        near = [j for j in ok if ends[j] <= NEAR_JUNCTION_M]
        if mass < DIFFUSE_MASS and near and len(b.glimpses) <= 1:
            # Nothing tells the ways apart yet: first the junction or end close by.
            k = int(min(near, key=lambda j: ends[j]))
    else:
        k = int(np.argmax(open_mass[::2]) * 2)
    # As far as where a share of the belief has signs in reach: the mean distance of a
    # split belief (signs 3 m on under some hypotheses, 30 m under others) is where
    # none has any.
    go = 1.0
    if reads[k]:
        near_signs = weighted_quantile(*np.array(reads[k]).T, LEAD_QUANTILE)
        go = float(np.clip(near_signs + 1.0, 1.0, max_distance))
    # Drive past the places already looked round from in that direction.
    h = axis + k * math.pi / 2
    u = np.array([math.cos(h), math.sin(h)])
    ahead = [float((np.array([g.odom.x, g.odom.y]) - p) @ u) for g in b.glimpses]
    seen_to = max([a for a in ahead if a > 0.0], default=0.0)
    if seen_to > 0.0:
        go = float(min(max(go, seen_to + LOOK_SPACING_M), 2.0 * max_distance))
    # Stop at the next junction (most of the belief agrees where): look round there.
    if run[k]:
        # Where most of the belief puts it; on the first drive from a diffuse belief
        # (a bare corridor), where a share of it already does: a drive past a
        # junction not looked round at skips the place that tells most.
        _, mass = b.best_cluster()
        first = mass < DIFFUSE_MASS and len(b.glimpses) <= 1
        q = FIRST_JUNCTION_QUANTILE if first else 0.5
        to_junction = weighted_quantile(*np.array(run[k]).T, q)
        at = p + u * to_junction
        looked = any(math.hypot(g.odom.x - at[0], g.odom.y - at[1]) < 3.0 for g in b.glimpses)
        if 1.0 < to_junction < go and not looked:
            go = to_junction
    heading = wrap_angle(h + b.drift)  # back to odometry
    return Lead(heading, go, float(open_mass[k])), k


def blocked_ways(b: BeliefView, odom: Pose2D) -> set[int]:
    """The ways (0-3 from the axis) that a drive from within ``BLOCKED_NEAR_M`` of
    ``odom`` met a wall on: whatever the hypotheses say, that way is shut from here (a
    belief that puts the robot at the wrong junction would drive into it again)."""
    p = b.straighten((odom.x, odom.y))
    axis = b.axis()
    return {
        int(round(wrap_angle(g.blocked - axis) / (math.pi / 2))) % 4
        for g in b.glimpses
        if g.blocked is not None and math.hypot(g.odom.x - p[0], g.odom.y - p[1]) < BLOCKED_NEAR_M
    }


def sign_in_reach(b: BeliefView, odom: Pose2D) -> float:
    """The share of the belief under which the map puts a sign within reliable reading
    range of ``odom`` (1 with no glimpse yet): near 0 in a bare stretch, where looking
    harder round the same spot reads nothing. A drive just blocked here counts (a
    dead end is no junction with signs round it)."""
    if b.ref is None:
        return 1.0
    w = b.weights()
    p = b.straighten((odom.x, odom.y))
    tfs = b.map_T_odoms()
    if b.pending_blocked is not None:  # the drive here just met a wall: count it
        w = w * np.exp(b.evidence.floor.blocked_log(tfs, p, b.pending_blocked - b.drift))
        w = w / w.sum()
    near, _ = b.goal.nearest_many(apply_many(tfs, (p[0], p[1])))
    pts = b.goal.lattice_points
    return float(w[np.array([bool(pts[j].readable) for j in near])].sum())


def weighted_quantile(w: np.ndarray, x: np.ndarray, q: float) -> float:
    """The ``q`` quantile of the values ``x`` weighed by ``w``."""
    order = np.argsort(x)
    c = np.cumsum(w[order])
    return float(x[order][min(len(x) - 1, int(np.searchsorted(c, q * c[-1])))])
