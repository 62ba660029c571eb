"""The VLM planner against a real local server: correct plans, each wrong plan class caught
by the validator, re-prompts that quote the errors, the graph fallback, counters."""

from __future__ import annotations

import json
import logging

import pytest

from pmnav_bt.errors import VlmError
from pmnav_bt.geometry import Action
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.planning.resolve import resolve_start
from pmnav_bt.seams import PlanConstraints, Pose2D
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.parse import parse_plan
from pmnav_bt.vlm.planner import VlmPlanner, start_point
from pmnav_bt.vlm.scripted_server import ChatServer, PlanningResponder, Reply, Script
from pmnav_bt.vlm.validate import IssueKind, check_plan

# fig2_hospital, from seg13 (between room14 and room7, facing east) to room17.
GOOD = [
    ("room7", "go straight"),
    ("room15", "go straight"),
    ("room8", "go straight"),
    ("turn2", "turn left"),
    ("elevator1", "go straight"),
    ("room16", "go straight"),
    ("branch1", "turn right"),
    ("room19", "go straight"),
    ("room17", "arrive"),
]
START = Pose2D(22.0, 0.0, 0.0)


def answer(steps) -> str:
    body = json.dumps({"plan": [{"landmark": n, "action": a} for n, a in steps]})
    return f"Step 1: east of room14, room17 lies north-east.\n```json\n{body}\n```"


def replace(steps, i, step):
    out = list(steps)
    out[i] = step
    return out


WRONG = {
    "wrong landmark": (replace(GOOD, 5, ("room99", "go straight")), IssueKind.UNKNOWN_LANDMARK),
    "unconnected step": ([s for s in GOOD if s[0] != "turn2"], IssueKind.NOT_CONNECTED),
    "wrong turn": (replace(GOOD, 3, ("turn2", "turn right")), IssueKind.WRONG_ACTION),
    "wrong goal": (GOOD[:-2] + [("room18", "arrive")], IssueKind.WRONG_GOAL),
    "goal not arrive": (replace(GOOD, 8, ("room17", "go straight")), IssueKind.WRONG_GOAL),
    "stops short": (GOOD[:-1], IssueKind.WRONG_GOAL),
    "unknown action": (replace(GOOD, 0, ("room7", "fly")), IssueKind.UNKNOWN_ACTION),
    "prose": ("Go east, then ask at the lift.", IssueKind.NO_PLAN),
    "truncated JSON": (answer(GOOD)[:150], IssueKind.MALFORMED_JSON),
}


def planner(server, **kw) -> VlmPlanner:
    kw.setdefault("tries", 1)
    return VlmPlanner(VlmClient(server.base_url, "m", timeout_s=5.0, retries=0), **kw)


def test_a_correct_answer_is_the_graph_planners_plan(fig2_map):
    with ChatServer(Script([Reply(answer(GOOD))])) as s:
        p = planner(s, fallback=False).plan(fig2_map, START, "room17")
    g = GraphPlanner(max_gap=8.0).plan(fig2_map, "22,0,0", "room17")
    assert p.planner == "vlm"
    assert p.nodes == g.nodes and p.length == pytest.approx(g.length)
    assert [x.text() for x in p.steps] == [x.text() for x in g.steps]
    assert p.notes[-1] == "vlm (h-pm): valid on answer 1"
    # The request carried the H-CoT prompt, the priori-map text and the annotated map.
    content = s.requests[0]["messages"][0]["content"]
    text = content[0]["text"]
    assert "Step 1." in text and "Step 3." in text and "seg13(room14-room7)" in text
    assert "from start to turn1, the direction is south" in text
    assert "Robot position: on seg13(room14-room7) at (22.00, 0.00), facing east" in text
    assert content[1]["image_url"]["url"].startswith("data:image/png;base64,")


@pytest.mark.parametrize("case", sorted(WRONG))
def test_each_wrong_plan_class_is_caught_by_the_validator(fig2_map, case):
    text, kind = WRONG[case]
    text = text if isinstance(text, str) else answer(text)
    with ChatServer(Script([Reply(text)])) as s:
        pl = planner(s, fallback=False)
        with pytest.raises(VlmError, match="no valid VLM plan in 1 answers"):
            pl.plan(fig2_map, START, "room17")
    issues = pl.transcripts[-1]["issues"][0]
    assert kind.value in [i["kind"] for i in issues]
    assert pl.stats.issues[kind.value] >= 1


def test_the_validator_names_the_problem(fig2_map):
    sp = resolve_start(fig2_map, "22,0,0")
    _, issues = check_plan(fig2_map, sp, "room17", parse_plan(answer(WRONG["wrong turn"][0])))
    assert [str(i) for i in issues] == [
        "step 4: at turn2 the robot arrives heading east and leaves heading north towards "
        "elevator1: that is 'turn left', not 'turn right'"
    ]
    _, issues = check_plan(fig2_map, sp, "room17", parse_plan(answer(WRONG["unconnected step"][0])))
    assert "room8 -> elevator1: no single stretch of corridor joins them" in str(issues[0])


def test_the_paper_notation_is_accepted(fig2_map):
    text = "{room8: go straight} -> {turn2: turn left}\n"
    text += "{turn2: turn left} -> {elevator1: go straight}"
    text += " -> {branch1: turn right} -> {room17: arrive}"
    with ChatServer(Script([Reply(text)])) as s:
        p = planner(s, fallback=False).plan(fig2_map, START, "room17")
    assert p.steps[-1].landmark == "room17" and p.planner == "vlm"


def test_a_reprompt_quotes_the_errors_and_a_repair_is_counted(fig2_map):
    bad = answer(WRONG["wrong turn"][0])
    with ChatServer(Script([Reply(bad), Reply(answer(GOOD))])) as s:
        pl = planner(s, tries=3)
        p = pl.plan(fig2_map, START, "room17")
    assert p.planner == "vlm" and p.notes[-1] == "vlm (h-pm): valid on answer 2"
    msgs = s.requests[1]["messages"]
    assert [m["role"] for m in msgs] == ["user", "assistant", "user"]
    assert msgs[1]["content"] == bad
    assert "that is 'turn left', not 'turn right'" in msgs[2]["content"]
    assert pl.stats.repaired == 1 and pl.stats.reprompts == 1 and pl.stats.fallbacks == 0


def test_no_valid_answer_falls_back_to_the_graph_planner(fig2_map, caplog):
    with ChatServer(Script([Reply("no idea")])) as s:
        pl = planner(s, tries=2)
        with caplog.at_level(logging.WARNING):
            p = pl.plan(fig2_map, START, "room17")
    g = GraphPlanner(max_gap=8.0).plan(fig2_map, "22,0,0", "room17")
    assert p.planner == "vlm->graph" and p.nodes == g.nodes
    assert "fallback to the graph planner: no valid VLM plan in 2 answers" in p.notes[-1]
    assert pl.stats.to_dict() == {
        "plans": 1, "valid_first": 0, "repaired": 0, "fallbacks": 1, "server_errors": 0,
        "reprompts": 1, "issues": {"no_plan": 2},
    }  # fmt: skip
    assert "planning with the graph planner" in caplog.text


def test_a_server_that_times_out_falls_back_or_is_a_vlm_error(fig2_map):
    with ChatServer(Script([Reply(answer(GOOD), delay_s=3.0)])) as s:
        client = VlmClient(s.base_url, "m", timeout_s=0.3, retries=0)
        p = VlmPlanner(client).plan(fig2_map, START, "room17")
        assert p.planner == "vlm->graph" and "no answer within 0.3 s" in p.notes[-1]
        with pytest.raises(VlmError, match="the VLM failed: .*no answer within 0.3 s"):
            VlmPlanner(client, fallback=False).plan(fig2_map, START, "room17")


def test_constraints_reach_the_validator(fig2_map):
    sp = resolve_start(fig2_map, "22,0,0")
    avoid = PlanConstraints(avoid_landmarks=frozenset({"elevator1"}))
    _, issues = check_plan(fig2_map, sp, "room17", parse_plan(answer(GOOD)), avoid)
    assert [i.kind for i in issues] == [IssueKind.AVOIDED_LANDMARK]
    seg = fig2_map.graph.edges["elevator1", "room16"]["segment"]
    blocked = PlanConstraints(blocked_segments=frozenset({seg}))
    _, issues = check_plan(fig2_map, sp, "room17", parse_plan(answer(GOOD)), blocked)
    assert [i.kind for i in issues] == [IssueKind.BLOCKED_SEGMENT]


def test_the_start_may_be_a_pose_a_segment_or_a_room(fig2_map):
    assert start_point(fig2_map, START).heading == 0.0
    assert start_point(fig2_map, "seg13").segment.name == "seg13(room14-room7)"
    assert start_point(fig2_map, "room20").description == "room20"


@pytest.mark.parametrize("inputs", ["o-em", "h-em", "h-pm"])
def test_scripted_server_plans_are_valid_in_every_built_in(inputs):
    from pmnav_bt.map.catalogue import builtin_buildings, load_building
    from pmnav_bt.map.priori_map import parse_building

    with ChatServer(PlanningResponder(wrong=0.0)) as s:
        pl = planner(s, inputs=inputs, fallback=False)
        for name in builtin_buildings():
            pm = parse_building(load_building(name))
            for room in [r.id for r in pm.building.rooms][::4]:
                p = pl.plan(pm, pm.segments[len(pm.segments) // 2].name, room)
                assert p.planner == "vlm"
                assert p.steps[-1].action is Action.ARRIVE
    assert pl.stats.valid_first == pl.stats.plans > 20


def test_every_corruption_of_the_scripted_server_is_caught(fig2_map):
    resp = PlanningResponder(wrong=1.0, seed=3)
    with ChatServer(resp) as s:
        pl = planner(s, tries=1)
        for room in [r.id for r in fig2_map.building.rooms]:
            for seg in ("seg3", "seg13", "seg20", "seg25"):
                assert pl.plan(fig2_map, seg, room).planner == "vlm->graph"
    assert pl.stats.valid_first == 0 and pl.stats.fallbacks == pl.stats.plans == 80
    assert all(resp.counts[k] > 0 for k in resp.counts if k != "correct")


def test_the_plan_log_counts_outcomes_across_planners(fig2_map, tmp_path):
    from pmnav_bt.vlm.planner import summarise_plan_log

    log = tmp_path / "plans.jsonl"
    replies = [Reply("prose"), Reply(answer(GOOD)), Reply(answer(GOOD)), Reply("no")]
    with ChatServer(Script(replies)) as s:
        planner(s, tries=2, plan_log=log).plan(fig2_map, START, "room17")  # repaired
        planner(s, tries=1, plan_log=log).plan(fig2_map, START, "room17")  # valid first
        planner(s, tries=1, plan_log=log).plan(fig2_map, START, "room17")  # fallback
    assert summarise_plan_log(log) == {
        "plans": 3, "repaired": 1, "valid_first": 1, "fallback": 1, "issues": {"no_plan": 2},
    }  # fmt: skip


def test_a_detour_is_an_issue_when_a_limit_is_set(fig2_map):
    from pmnav_bt.vlm.planner import score_answer

    sp = resolve_start(fig2_map, "22,0,180")  # facing west, away from room17
    back = [("room14", "turn around")] + GOOD  # via room14, then back east: 4 m more
    route, issues = score_answer(fig2_map, sp, "room17", answer(back))
    assert route is not None and not issues
    route, issues = score_answer(fig2_map, sp, "room17", answer(back), max_detour=0.05)
    assert route is None and [i.kind for i in issues] == [IssueKind.DETOUR]
    assert "shorter way" in str(issues[0])
