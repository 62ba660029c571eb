"""The ``vlm`` planner back end: ask a VLM, check its plan against the map, re-prompt with
the problems found, and fall back to the graph planner; the tree never runs an invalid plan.

Each ``plan`` call is one conversation: the planning prompt (``vlm.prompt``: h-pm, h-em or
o-em), then up to ``vlm.plan_tries - 1`` re-prompts that quote the validation issues. A
valid answer's node route becomes a Plan through ``graph_planner.build_plan``. When no
answer is valid, or the server fails, the graph planner plans instead (``vlm.fallback``),
or the call raises VlmError (the tree's VLM_ERROR). ``stats`` counts plans, repairs,
fallbacks and issues by kind, for the evaluation to report; ``transcripts`` keeps the last
conversations (texts and image digests, never the API key).
"""

from __future__ import annotations

import hashlib
import json
import logging
import threading
from collections import Counter, deque
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from pmnav_bt.errors import VlmError
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.planning.graph_planner import GraphPlanner, build_plan
from pmnav_bt.planning.plan import MAX_GAP_M, Plan
from pmnav_bt.planning.resolve import StartPoint, resolve_room, resolve_start
from pmnav_bt.seams import PlanConstraints, Pose2D
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.parse import ParseFailure, parse_plan
from pmnav_bt.vlm.prompts import PLAN_INPUTS, plan_messages, repair_text
from pmnav_bt.vlm.validate import NO_CONSTRAINTS, CheckedRoute, IssueKind, PlanIssue, check_plan

log = logging.getLogger(__name__)


def start_point(pm: PrioriMap, start: Pose2D | str | StartPoint) -> StartPoint:
    """A plan start from an estimated pose, a name a person typed, or a resolved start."""
    if isinstance(start, StartPoint):
        return start
    if isinstance(start, Pose2D):
        loc = pm.locate(start.x, start.y)
        return StartPoint(f"pose ({start.x:.1f}, {start.y:.1f})", loc.segment, loc.t, start.yaw)
    return resolve_start(pm, start)


@dataclass
class Conversation:
    """One planning conversation: every turn, the issues of each answer, the outcome."""

    inputs: str
    turns: list[dict[str, Any]] = field(default_factory=list)
    answers: list[str] = field(default_factory=list)
    issues: list[list[PlanIssue]] = field(default_factory=list)
    route: CheckedRoute | None = None
    error: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "inputs": self.inputs,
            "turns": self.turns,
            "issues": [
                [{"kind": i.kind.value, "step": i.step, "message": i.message} for i in a]
                for a in self.issues
            ],
            "valid_on_try": len(self.answers) if self.route is not None else None,
            "error": self.error,
        }


def converse(
    client: VlmClient,
    pm: PrioriMap,
    sp: StartPoint,
    goal_id: str,
    inputs: str = "h-pm",
    tries: int = 1,
    constraints: PlanConstraints = NO_CONSTRAINTS,
    image_px: int = 1280,
    cancelled: threading.Event | None = None,
    max_detour: float | None = None,
) -> Conversation:
    """Ask for a plan; re-prompt with the issues up to ``tries`` answers in all.

    ``max_detour``: a valid route longer than the shortest by more than this fraction is
    an issue too (None: any length)."""
    conv = Conversation(inputs)
    messages = plan_messages(pm, sp, goal_id, inputs, image_px)
    conv.turns.append(_turn_record(messages[0]))
    for attempt in range(tries):
        try:
            reply = client.chat(messages, purpose=f"plan:{inputs}", cancelled=cancelled)
        except VlmError as err:
            conv.error = str(err)
            conv.turns.append({"role": "error", "text": str(err)})
            return conv
        conv.answers.append(reply.text)
        conv.turns.append(
            {
                "role": "assistant",
                "text": reply.text,
                "finish_reason": reply.finish_reason,
                "usage": {
                    "prompt_tokens": reply.usage.prompt_tokens,
                    "completion_tokens": reply.usage.completion_tokens,
                    "latency_s": reply.usage.latency_s,
                    "attempts": reply.usage.attempts,
                },
            }
        )
        route, issues = score_answer(pm, sp, goal_id, reply.text, constraints, max_detour)
        conv.issues.append(issues)
        if route is not None:
            conv.route = route
            return conv
        if attempt + 1 < tries:
            text = repair_text([str(i) for i in issues], goal_id)
            messages = [*messages, {"role": "assistant", "content": reply.text}]
            messages.append({"role": "user", "content": text})
            conv.turns.append({"role": "user", "text": text, "images": []})
    return conv


def score_answer(
    pm: PrioriMap,
    sp: StartPoint,
    goal_id: str,
    text: str,
    constraints: PlanConstraints = NO_CONSTRAINTS,
    max_detour: float | None = None,
) -> tuple[CheckedRoute | None, list[PlanIssue]]:
    """Parse and check one answer: its route, or the issues (``max_detour``: see converse)."""
    try:
        raw = parse_plan(text)
    except ParseFailure as err:
        return None, [PlanIssue(IssueKind(err.kind), err.message)]
    route, issues = check_plan(pm, sp, goal_id, raw, constraints)
    if route is None or max_detour is None:
        return route, issues
    best = graph_plan(pm, sp, goal_id, constraints, max_gap=1e9)
    if route.length > best.length * (1.0 + max_detour) + 1e-6:
        way = ", ".join(s.landmark for s in best.steps)
        return None, [
            PlanIssue(
                IssueKind.DETOUR,
                f"the route is {route.length:.1f} m long, more than {max_detour:.0%} longer "
                f"than the shortest ({best.length:.1f} m, by {way}); take a shorter way",
            )
        ]
    return route, []


def _turn_record(message: dict[str, Any]) -> dict[str, Any]:
    """A user turn for a transcript: its text, and each image as a digest (not the bytes)."""
    content = message["content"]
    if isinstance(content, str):
        return {"role": message["role"], "text": content, "images": []}
    text = "".join(p["text"] for p in content if p["type"] == "text")
    images = []
    for p in content:
        if p["type"] == "image_url":
            url = p["image_url"]["url"]
            images.append({"sha256": hashlib.sha256(url.encode()).hexdigest(), "chars": len(url)})
    return {"role": message["role"], "text": text, "images": images}


@dataclass
class PlanStats:
    """What the VLM planner did, for the evaluation to report."""

    plans: int = 0  # plan() calls
    valid_first: int = 0  # the first answer was valid
    repaired: int = 0  # valid after one or more re-prompts
    fallbacks: int = 0  # planned by the graph planner instead
    server_errors: int = 0  # conversations ended by a server failure
    reprompts: int = 0
    issues: Counter = field(default_factory=Counter)  # by IssueKind value

    def to_dict(self) -> dict[str, Any]:
        return {
            "plans": self.plans,
            "valid_first": self.valid_first,
            "repaired": self.repaired,
            "fallbacks": self.fallbacks,
            "server_errors": self.server_errors,
            "reprompts": self.reprompts,
            "issues": dict(sorted(self.issues.items())),
        }


class VlmPlanner:
    """Planner back end ``vlm``: a VLM's plan, checked against the map, or the graph's."""

    name = "vlm"

    def __init__(
        self,
        client: VlmClient,
        inputs: str = "h-pm",
        tries: int = 3,
        fallback: bool = True,
        max_gap: float = MAX_GAP_M,
        max_detour: float | None = 0.5,
        image_px: int = 1280,
        keep_transcripts: int = 20,
        plan_log: str | Path | None = None,
    ):
        if inputs not in PLAN_INPUTS:
            raise ValueError(f"inputs must be one of {PLAN_INPUTS}, got {inputs!r}")
        self.client = client
        self.inputs = inputs
        self.tries = tries
        self.fallback = fallback
        self.max_detour = max_detour
        self.max_gap = max_gap
        self.image_px = image_px
        self.stats = PlanStats()
        self.transcripts: deque[dict[str, Any]] = deque(maxlen=keep_transcripts)
        self.plan_log = Path(plan_log) if plan_log else None
        self._lock = threading.Lock()

    def plan(
        self,
        pm: PrioriMap,
        start: Pose2D | str,
        goal: str,
        constraints: PlanConstraints = NO_CONSTRAINTS,
    ) -> Plan:
        goal_id = resolve_room(pm, goal)
        sp = start_point(pm, start)
        conv = converse(
            self.client,
            pm,
            sp,
            goal_id,
            self.inputs,
            self.tries,
            constraints,
            self.image_px,
            max_detour=self.max_detour,
        )
        self._count(conv)
        self.transcripts.append({"goal": goal_id, "start": sp.description, **conv.to_dict()})
        if conv.route is not None:
            r = conv.route
            plan = build_plan(
                pm,
                sp,
                goal_id,
                list(r.nodes),
                r.length,
                np.asarray(r.start_xy),
                self.max_gap,
                self.name,
                constraints.avoid_landmarks,
            )
            note = f"vlm ({self.inputs}): valid on answer {len(conv.answers)}"
            return replace(plan, notes=(*plan.notes, note))
        why = conv.error or "; ".join(str(i) for i in conv.issues[-1][:3])
        n = len(conv.answers)
        what = "the VLM failed" if conv.error else f"no valid VLM plan in {n} answers"
        if not self.fallback:
            raise VlmError(f"{what}: {why}")
        log.warning("%s (%s); planning with the graph planner", what, why)
        plan = graph_plan(pm, sp, goal_id, constraints, self.max_gap, "vlm->graph")
        return replace(plan, notes=(*plan.notes, f"fallback to the graph planner: {what}: {why}"))

    def _count(self, conv: Conversation) -> None:
        outcome = (
            "fallback" if conv.route is None and self.fallback
            else "failed" if conv.route is None
            else "valid_first" if len(conv.answers) == 1
            else "repaired"
        )  # fmt: skip
        with self._lock:
            if self.plan_log is not None:
                line = {
                    "outcome": outcome,
                    "answers": len(conv.answers),
                    "issues": [i.kind.value for a in conv.issues for i in a],
                    "server_error": conv.error,
                }
                with open(self.plan_log, "a", encoding="utf-8") as f:
                    f.write(json.dumps(line) + "\n")
            s = self.stats
            s.plans += 1
            s.reprompts += max(0, len(conv.answers) - 1)
            for answer in conv.issues:
                s.issues.update(i.kind.value for i in answer)
            if conv.error:
                s.server_errors += 1
                s.issues[IssueKind.SERVER_ERROR.value] += 1
            if conv.route is None:
                s.fallbacks += int(self.fallback)
            elif len(conv.answers) == 1:
                s.valid_first += 1
            else:
                s.repaired += 1


def graph_plan(
    pm: PrioriMap,
    sp: StartPoint,
    goal_id: str,
    constraints: PlanConstraints,
    max_gap: float,
    name: str = "graph",
) -> Plan:
    """The graph planner's plan (shortest route, constraints kept), named ``name``."""
    return replace(GraphPlanner(max_gap=max_gap).plan(pm, sp, goal_id, constraints), planner=name)


def build(deps) -> VlmPlanner:
    """Factory of the ``vlm`` planner back end (registry)."""
    cfg = deps.config.vlm
    return VlmPlanner(
        VlmClient.from_config(cfg),
        inputs=cfg.prompt,
        tries=cfg.plan_tries,
        fallback=cfg.fallback,
        max_gap=deps.config.planner.max_gap,
        max_detour=cfg.max_detour,
        image_px=cfg.image_px,
        plan_log=cfg.plan_log or None,
    )


def summarise_plan_log(path: str | Path) -> dict[str, Any]:
    """Counts of a plan log (written by planners in any number of processes)."""
    out: dict[str, Any] = {"plans": 0, "issues": Counter()}
    for line in Path(path).read_text(encoding="utf-8").splitlines():
        d = json.loads(line)
        out["plans"] += 1
        out[d["outcome"]] = out.get(d["outcome"], 0) + 1
        out["issues"].update(d["issues"])
    out["issues"] = dict(sorted(out["issues"].items()))
    return out
