"""The paper's Table 2 harness: planning SR per input (O-EM, H-EM, H-PM) and tier.

Plan tasks are the episodes of the simulator's tiers (``pmnav_bt.sim.episodes``: the
same seeded starts, goals and tier definitions as ``pmnav sim eval``), one VLM
conversation per task and input. Every conversation is saved as a transcript (texts,
answers, usage, image digests; never the API key), and ``replay`` re-scores saved
transcripts with no server, giving the same table.

A plan counts as correct when (``CORRECT_RULE``) its answer parses, passes every check
of ``pmnav_bt.vlm.validate`` (landmarks exist, consecutive steps connected, actions
agree with the headings, ends at the goal with arrive), and its route is no longer than
the shortest route from the same start by more than the margin.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import cv2

from pmnav_bt.errors import PmNavError
from pmnav_bt.loading import load_json
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import PrioriMap, parse_building
from pmnav_bt.planning.graph_planner import shortest_route
from pmnav_bt.planning.resolve import StartPoint
from pmnav_bt.seams import Pose2D
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.planner import converse, score_answer, start_point
from pmnav_bt.vlm.prompts import INPUT_NAMES, PLAN_INPUTS, map_image

TRANSCRIPT_VERSION = 1
TIERS = ("easy", "medium", "hard")
PAPER_TABLE2 = {"o-em": (31.3, 10.4, 0.0), "h-em": (91.6, 85.4, 75.0), "h-pm": (95.8, 89.5, 83.3)}


def correct_rule(margin: float) -> str:
    return (
        "A plan is correct when its first answer parses, names only map landmarks, joins "
        "consecutive steps by one stretch of corridor (every turn and branch passed is a "
        "step), gives at each step the action the headings call for, ends at the goal with "
        f"'arrive', and its route is at most {margin:.0%} longer than the shortest route "
        "from the same start. 'after repair': the same, for the first valid answer within "
        "the re-prompts that quote the validator's errors."
    )


@dataclass(frozen=True)
class PlanTask:
    """One planning task: an episode's start and goal."""

    id: str
    building: str
    tier: str
    start: tuple[float, float, float]  # x, y, yaw (rad)
    goal: str


@dataclass
class TaskResult:
    task: str
    building: str
    tier: str
    inputs: str
    goal: str
    correct: bool  # the first answer
    correct_after_repair: bool
    answers: int
    valid_on_answer: int | None
    route_m: float | None
    shortest_m: float
    issues: list[str]
    error: str = ""


def plan_tasks(buildings: Iterable[str], tiers: Iterable[str], n: int, seed: int):
    """Episodes as plan tasks (tiers a building cannot pose are skipped, with a note)."""
    from pmnav_bt.sim.episodes import EpisodeGenerationError, generate_episodes

    tasks, notes = [], []
    for b in buildings:
        for tier in tiers:
            try:
                eps = generate_episodes(b, tier, n, seed=seed)
            except EpisodeGenerationError as err:
                notes.append(str(err))
                continue
            tasks += [
                PlanTask(e.id, e.building, e.tier, (e.start_x, e.start_y, e.start_yaw), e.goal)
                for e in eps
            ]
    return tasks, notes


class _Maps:
    def __init__(self) -> None:
        self._maps: dict[str, PrioriMap] = {}

    def __call__(self, name: str) -> PrioriMap:
        if name not in self._maps:
            self._maps[name] = parse_building(load_building(name))
        return self._maps[name]


def _start(pm: PrioriMap, task_start) -> StartPoint:
    x, y, yaw = task_start
    return start_point(pm, Pose2D(x, y, yaw))


def score_transcript(pm: PrioriMap, t: dict[str, Any], margin: float) -> TaskResult:
    """Re-score one saved conversation from its answers alone."""
    sp = _start(pm, t["start"])
    _, shortest, _ = shortest_route(pm, sp, pm.places[t["goal"]].node)
    answers = [turn["text"] for turn in t["turns"] if turn["role"] == "assistant"]
    error = next((turn["text"] for turn in t["turns"] if turn["role"] == "error"), "")
    ok: list[bool] = []
    issues: list[str] = []
    route_m = None
    for text in answers:
        route, found = score_answer(pm, sp, t["goal"], text, max_detour=margin)
        issues += [i.kind.value for i in found]
        ok.append(route is not None)
        if route is not None:
            route_m = round(route.length, 2)
            break  # the conversation ended at its first valid answer
    first_ok = next((i + 1 for i, g in enumerate(ok) if g), None)
    return TaskResult(
        task=t["task"],
        building=t["building"],
        tier=t["tier"],
        inputs=t["inputs"],
        goal=t["goal"],
        correct=bool(ok and ok[0]),
        correct_after_repair=first_ok is not None,
        answers=len(answers),
        valid_on_answer=first_ok,
        route_m=route_m,
        shortest_m=round(shortest, 2),
        issues=issues,
        error=error,
    )


def run_plan_eval(
    client: VlmClient,
    tasks: list[PlanTask],
    inputs: list[str],
    out: Path,
    tries: int = 1,
    margin: float = 0.1,
    image_px: int = 1280,
    progress: Callable[[int, int], None] | None = None,
) -> list[TaskResult]:
    """Ask the VLM every task under every input; save transcripts; score them."""
    for i in inputs:
        if i not in PLAN_INPUTS:
            raise PmNavError(f"--inputs: unknown input {i!r}; choose from {', '.join(PLAN_INPUTS)}")
    maps = _Maps()
    (out / "transcripts").mkdir(parents=True, exist_ok=True)
    (out / "images").mkdir(parents=True, exist_ok=True)
    results, done = [], 0
    for inp in inputs:
        for task in tasks:
            pm = maps(task.building)
            img_path = out / "images" / f"{task.building}_{'pm' if inp == 'h-pm' else 'em'}.png"
            if not img_path.exists():
                cv2.imwrite(str(img_path), map_image(pm, inp, image_px))
            sp = _start(pm, task.start)
            conv = converse(
                client, pm, sp, task.goal, inp, tries, image_px=image_px, max_detour=margin
            )
            t = {
                "version": TRANSCRIPT_VERSION,
                "task": task.id,
                "building": task.building,
                "tier": task.tier,
                "start": list(task.start),
                "goal": task.goal,
                "model": client.model,
                "image": str(img_path.relative_to(out)),
                **conv.to_dict(),
            }
            path = out / "transcripts" / inp / f"{task.id}.json"
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(json.dumps(t, indent=1), encoding="utf-8")
            results.append(score_transcript(pm, t, margin))
            done += 1
            if progress:
                progress(done, len(tasks) * len(inputs))
    return results


def replay(folder: Path, margin: float = 0.1) -> list[TaskResult]:
    """Re-score every transcript under ``folder/transcripts`` (no server)."""
    files = sorted((folder / "transcripts").glob("*/*.json"))
    if not files:
        raise PmNavError(f"{folder}: no transcripts under {folder / 'transcripts'}")
    maps = _Maps()
    out = []
    for f in files:
        t = load_json(f, "transcript")
        if not isinstance(t, dict) or t.get("version") != TRANSCRIPT_VERSION:
            raise PmNavError(
                f"{f}: not a version {TRANSCRIPT_VERSION} transcript of pmnav plan eval"
            )
        out.append(score_transcript(maps(t["building"]), t, margin))
    order = {k: i for i, k in enumerate(PLAN_INPUTS)}
    return sorted(out, key=lambda r: (order.get(r.inputs, 9), r.task))


def table_markdown(results: list[TaskResult], with_paper: bool = True) -> str:
    """SR (%) per input and tier, first answer and after repair, with the paper's Table 2."""
    inputs = [i for i in PLAN_INPUTS if any(r.inputs == i for r in results)]
    head = "| input | " + " | ".join(f"{t} SR (n)" for t in TIERS) + " | all SR (n) |"
    head += " after repair (all) | paper (easy/medium/hard) |" if with_paper else ""
    lines = [head, "|---" * (len(TIERS) + 2 + (2 if with_paper else 0)) + "|"]
    for inp in inputs:
        rows = [r for r in results if r.inputs == inp]
        cells = []
        for t in [*TIERS, None]:
            sel = [r for r in rows if t is None or r.tier == t]
            cells.append(_sr(sel, "correct"))
        line = f"| {INPUT_NAMES[inp]} | " + " | ".join(cells) + " |"
        if with_paper:
            paper = "/".join(f"{v:g}" for v in PAPER_TABLE2[inp])
            line += f" {_sr(rows, 'correct_after_repair')} | {paper} |"
        lines.append(line)
    return "\n".join(lines)


def _sr(rows: list[TaskResult], attr: str) -> str:
    if not rows:
        return "-"
    k = sum(getattr(r, attr) for r in rows)
    return f"{100.0 * k / len(rows):.1f} ({len(rows)})"


def issue_counts(results: list[TaskResult]) -> dict[str, dict[str, int]]:
    out: dict[str, dict[str, int]] = {}
    for r in results:
        d = out.setdefault(r.inputs, {})
        for k in r.issues + (["server_error"] if r.error else []):
            d[k] = d.get(k, 0) + 1
    return out


def save_results(results: list[TaskResult], out: Path, header: str, name: str = "results"):
    """Write ``name``.json (every task) and ``name``.md (the table); return the .md path."""
    out.mkdir(parents=True, exist_ok=True)
    data = {
        "header": header,
        "issues": issue_counts(results),
        "results": [asdict(r) for r in results],
    }
    (out / f"{name}.json").write_text(json.dumps(data, indent=1), encoding="utf-8")
    md = out / f"{name}.md"
    counts = issue_counts(results)
    issue_lines = "\n".join(
        f"- {INPUT_NAMES[i]}: " + (", ".join(f"{k} {v}" for k, v in sorted(c.items())) or "none")
        for i, c in counts.items()
    )
    md.write_text(
        f"{header}\n\n{table_markdown(results)}\n\nIssues found by the validator:\n{issue_lines}\n",
        encoding="utf-8",
    )
    return md
