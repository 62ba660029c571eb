"""The paper's Table 3 as a study: the localization subtree alone, from start poses classed
by how many landmarks are readable there (redundant > 2, minimal = 2, scarce 0-1).

Start poses are points of the corridor centre lines, facing along the corridor (either
way, seeded), at least ``START_CLEARANCE_M`` from key waypoints; the class comes from the
priori-map's readability model (``pmnav_bt.pose.visibility``: line of sight within the
corridors) with the read range of the perception under test: the OCR reader's reliable
range per plate kind (``read_range.landmark_ranges``: a sign 6 m away that it cannot read
is not a landmark the robot has), or ``READ_RANGE_M`` for the oracle and for the
map's-range classes of earlier rounds (``ranges=None``). A run succeeds when the subtree
ends in SUCCESS with the estimated pose within ``SUCCESS_POS_M`` and ``SUCCESS_YAW_DEG``
of the truth; d is the number of panoramas it took (``fix_attempts``), and
SDF = S * 2 / max(2, d).

Imports the simulator and the tree lazily (the experiments layer joins them).
"""

from __future__ import annotations

import json
import math
import random
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from pmnav_bt.config import Config
from pmnav_bt.eval.metrics import sdf_term
from pmnav_bt.perception.read_range import entity_plate_kind
from pmnav_bt.pose.visibility import LandmarkDensity, Visibility, density_class, entity_xy

SUCCESS_POS_M = 1.0
SUCCESS_YAW_DEG = 15.0
START_CLEARANCE_M = 1.5
MAX_CLOCK_S = 600.0  # sim seconds for one localization run
PAPER = {  # PM-Nav, Table 3: (SR, SDF)
    LandmarkDensity.REDUNDANT: (93.8, 90.4),
    LandmarkDensity.MINIMAL: (91.7, 82.6),
    LandmarkDensity.SCARCE: (63.3, 25.0),
}


@dataclass(frozen=True)
class LocStart:
    building: str
    x: float
    y: float
    yaw: float
    density: str
    readable: int
    seed: int


@dataclass
class LocResult:
    start: LocStart
    success: bool
    attempts: int
    position_error: float | None
    yaw_error_deg: float | None
    driven: float
    failure: str | None
    wall_time: float

    @property
    def sdf(self) -> float:
        return sdf_term(self.success, max(1, self.attempts))


def classified_starts(
    building: str, n: int, seed: int = 0, ranges: Mapping[str, float] | None = None
) -> list[LocStart]:
    """Up to ``n`` start poses of each landmark-density class in ``building`` (seeded),
    counting the landmarks readable within ``ranges`` (m per plate kind, as
    ``read_range.landmark_ranges``; None: ``READ_RANGE_M`` for every plate)."""
    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building

    b = load_building(building)
    pm = parse_building(b)
    vis = Visibility.of(pm, None if ranges is None else max(ranges.values()))
    keys = np.array([pm.node_xy(w.id) for w in pm.key_waypoints])
    rng = random.Random(f"{building}:{seed}")
    by_class: dict[LandmarkDensity, list] = {c: [] for c in LandmarkDensity}
    for p in vis.lattice_points:
        if np.min(np.linalg.norm(keys - np.array(p.xy), axis=1)) < START_CLEARANCE_M:
            continue
        readable = _within(b, pm, p, ranges)
        by_class[density_class(readable)].append((p, readable))
    out = []
    for cls, pts in by_class.items():
        for i, (p, readable) in enumerate(rng.sample(pts, min(n, len(pts)))):
            h = pm.segments[p.segment - 1].heading + (math.pi if rng.random() < 0.5 else 0.0)
            out.append(
                LocStart(building, p.xy[0], p.xy[1], h, cls.value, readable, seed * 1000 + i)
            )
    return out


def _within(building, pm, point, ranges: Mapping[str, float] | None) -> int:
    """How many of the signs in sight of a lattice point are within their kind's range."""
    if ranges is None:
        return len(point.readable)
    return sum(
        math.dist(entity_xy(pm, e), point.xy) <= ranges[entity_plate_kind(building, e)]
        for e in point.readable
    )


def run_localization(
    start: LocStart, config: Config, watch: Callable[[object, object], None] | None = None
) -> LocResult:
    """The localization subtree alone, from ``start``, in a fresh world. ``watch(ctx,
    body)``, when given, is called after every tick with the tree's context and the
    simulated body (its ``pose()`` is the truth), e.g. to draw the belief as it goes
    (``experiments/belief_show.py``)."""
    import py_trees

    from pmnav_bt.behaviours.common import NAMESPACE
    from pmnav_bt.map.catalogue import load_building, resolve_building_path
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.pose.evidence.floor_model import building_grid
    from pmnav_bt.seams import Pose2D
    from pmnav_bt.sim.odometry import simulated_robot
    from pmnav_bt.sim.world import SimWorld
    from pmnav_bt.trees.localize import active_localize_subtree
    from pmnav_bt.trees.runner import make_context

    t0 = time.perf_counter()
    b = load_building(start.building)
    folder = resolve_building_path(start.building).parent
    pm = parse_building(b)
    pose = Pose2D(start.x, start.y, start.yaw)
    with SimWorld(b, walls=config.sim.walls, base_dir=folder) as world:
        inner, base = simulated_robot(world, config.sim, pose, start.seed)
        # The grid is the map of the walls where the world is built from it (evaluation).
        grid = building_grid(b, folder) if config.sim.walls == "grid" else None
        ctx = make_context(base, pm, config, seed=start.seed, deferred_work=True, grid=grid)
        py_trees.blackboard.Blackboard.clear()
        tree = py_trees.trees.BehaviourTree(active_localize_subtree(ctx))
        period = 1.0 / config.tree.tick_hz
        status = py_trees.common.Status.RUNNING
        try:
            tree.setup()
            while ctx.now() < MAX_CLOCK_S:
                tree.tick()
                ctx.odometer.update(ctx.base.pose())
                if watch is not None:
                    watch(ctx, inner)
                status = tree.root.status
                if status != py_trees.common.Status.RUNNING:
                    break
                ctx.worker.drain()
                base.clock.wait(period)
        finally:
            base.stop()
            tree.interrupt()
            ctx.worker.shutdown()
        store = py_trees.blackboard.Blackboard.storage
        tf = store.get(f"{NAMESPACE}/map_T_odom")
        attempts = store.get(f"{NAMESPACE}/fix_attempts") or 0
        failure = store.get(f"{NAMESPACE}/failure")
        truth, odom = inner.pose(), ctx.base.pose()  # the tree's (calibrated) odometry
        driven = inner.stats.path_length
    pos_err = yaw_err = None
    ok = status == py_trees.common.Status.SUCCESS and tf is not None
    if tf is not None:
        c, s = math.cos(tf[2]), math.sin(tf[2])
        ex, ey = tf[0] + c * odom.x - s * odom.y, tf[1] + s * odom.x + c * odom.y
        pos_err = math.hypot(ex - truth.x, ey - truth.y)
        dyaw = math.remainder(tf[2] + odom.yaw - truth.yaw, 2 * math.pi)
        yaw_err = abs(math.degrees(dyaw))
        ok = ok and pos_err <= SUCCESS_POS_M and yaw_err <= SUCCESS_YAW_DEG
    why = None
    if not ok:
        why = (
            f"wrong fix: {pos_err:.2f} m, {yaw_err:.1f} deg off"
            if tf is not None and status == py_trees.common.Status.SUCCESS
            else str(failure)
            if failure is not None
            else f"no fix in {MAX_CLOCK_S:.0f} s"
        )
    return LocResult(start, ok, attempts, pos_err, yaw_err, driven, why, time.perf_counter() - t0)


def _crashed(start: LocStart, error: str) -> dict:
    r = LocResult(start, False, 0, None, None, 0.0, f"error: {error}", 0.0)
    return {**asdict(r), "start": asdict(start)}


def _run_one(args) -> dict:
    """One start in a worker; a crash becomes a failed run that says so."""
    start, config_json = args
    try:
        r = run_localization(start, Config.model_validate_json(config_json))
    except Exception as err:  # noqa: BLE001 - reported in the results, with its type
        return _crashed(start, f"{type(err).__name__}: {err}")
    d = asdict(r)
    d["start"] = asdict(start)
    return d


def run_study(
    starts: list[LocStart],
    config: Config,
    jobs: int = 1,
    progress=None,
    ray: str | None = None,
    done: dict[int, dict] | None = None,
    on_row=None,
    finished: list | None = None,
):
    """Every start once (in the pool or on Ray); results in the order of ``starts``.

    ``done`` maps indices of ``starts`` to rows already on disk (``--resume``): they are
    not run again. ``on_row(index, row)`` is called as each new run ends; ``finished``
    (when given) collects ``(index, row)`` as they arrive, for an interruption."""
    from pmnav_bt.experiments.executors import TaskCrash, run_tasks

    done = dict(done or {})
    blob = config.model_dump_json()
    todo = [i for i in range(len(starts)) if i not in done]
    got = finished if finished is not None else []
    got.extend(done.items())
    for k, row in run_tasks(_run_one, [(starts[i], blob) for i in todo], jobs=jobs, ray=ray):
        i = todo[k]
        if isinstance(row, TaskCrash):
            row = _crashed(starts[i], row.message)
        got.append((i, row))
        if on_row:
            on_row(i, row)
        if progress:
            progress(len(got), len(starts))
    return [result_of_row(r) for _, r in sorted(got, key=lambda p: p[0])]


def result_of_row(row: dict) -> LocResult:
    """A LocResult from its stored row (extra keys, such as the store's, ignored)."""
    names = {f.name for f in fields(LocResult)}
    r = {k: v for k, v in row.items() if k in names}
    return LocResult(**{**r, "start": LocStart(**row["start"])})


def start_key(start: LocStart) -> str:
    """A start's identity in results.jsonl."""
    return f"{start.building}-{start.density}-{start.seed}"


def table(results: list[LocResult], title: str = "") -> str:
    """SR and SDF per landmark-density class beside the paper's Table 3."""
    lines = [
        f"{title}" if title else "",
        "| landmarks | n | SR | SDF | mean panoramas | mean driven (m) | paper SR | paper SDF |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for cls in LandmarkDensity:
        rs = [r for r in results if r.start.density == cls.value]
        if not rs:
            lines.append(f"| {cls.value} | 0 | - | - | - | - | {PAPER[cls][0]} | {PAPER[cls][1]} |")
            continue
        sr = 100.0 * np.mean([r.success for r in rs])
        sdf = 100.0 * np.mean([r.sdf for r in rs])
        lines.append(
            f"| {cls.value} | {len(rs)} | {sr:.1f} | {sdf:.1f} | "
            f"{np.mean([r.attempts for r in rs]):.2f} | {np.mean([r.driven for r in rs]):.1f} | "
            f"{PAPER[cls][0]} | {PAPER[cls][1]} |"
        )
    return "\n".join(x for x in lines if x is not None)


def save(results: list[LocResult], out_dir: Path, header: str) -> Path:
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = []
    for r in results:
        d = asdict(r)
        d["sdf"] = r.sdf
        rows.append(d)
    (out_dir / "results.json").write_text(json.dumps(rows, indent=1), encoding="utf-8")
    md = out_dir / "results.md"
    md.write_text(header + "\n\n" + table(results) + "\n", encoding="utf-8")
    return md
