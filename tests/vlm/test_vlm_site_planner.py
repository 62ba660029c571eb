"""The VLM planner across levels: the H-CoT prompt per level with the lifts, answers
checked level by level (rides too), re-prompts, and the graph fallback across levels."""

from __future__ import annotations

import json

import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.site import load_site
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.planning.resolve import resolve_start
from pmnav_bt.planning.site_plan import SitePlanner
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.parse import RawStep
from pmnav_bt.vlm.planner import VlmPlanner
from pmnav_bt.vlm.scripted_server import ChatServer, Reply, Script
from pmnav_bt.vlm.site_planner import SiteVlmPlanner, check_site_plan, site_plan_text
from pmnav_bt.vlm.validate import IssueKind


@pytest.fixture(scope="module")
def sm():
    return parse_site(load_site("hospital_2l"))


@pytest.fixture(scope="module")
def best(sm):
    return SitePlanner().plan(sm, "L1", "start", "Laboratory")


def good_steps(plan) -> list[tuple[str, str]]:
    """The graph planner's plan across levels as an answer's steps."""
    out = []
    for i, leg in enumerate(plan.legs):
        out += [(s.landmark, s.action.value) for s in leg.plan.steps]
        if i < len(plan.rides):
            r = plan.rides[i]
            out.append((r.lift, f"take the lift to level {r.to_level}"))
    return out


def answer(steps) -> str:
    body = json.dumps({"plan": [{"landmark": n, "action": a} for n, a in steps]})
    return f"Step 1: lift A is nearer.\n```json\n{body}\n```"


def planner(server, **kw) -> SiteVlmPlanner:
    kw.setdefault("tries", 1)
    client = VlmClient(server.base_url, "m", timeout_s=5.0, retries=0)
    return SiteVlmPlanner(VlmPlanner(client, **kw))


def raw(steps) -> list[RawStep]:
    return [RawStep(n, a) for n, a in steps]


def test_the_graph_plan_as_an_answer_is_valid(sm, best):
    sp = resolve_start(sm.maps["L1"], "start")
    checked, issues = check_site_plan(sm, "L1", sp, "L2", "room208", raw(good_steps(best)))
    assert issues == []
    legs, rides = checked
    assert [leg.level for leg in legs] == ["L1", "L2"] and legs[0].goal == "lift_a"
    assert [(r.lift, r.to_level) for r in rides] == [("lift1", "L2")]
    assert [leg.route.nodes for leg in legs] == [leg.plan.nodes for leg in best.legs]


@pytest.mark.parametrize(
    "change, kind, words",
    [
        (
            lambda s, k: s[:k] + [("lift9", s[k][1])] + s[k + 1 :],
            IssueKind.WRONG_LIFT,
            "not a lift",
        ),
        (
            lambda s, k: s[:k] + [(s[k][0], "take the lift to level L7")] + s[k + 1 :],
            IssueKind.WRONG_LIFT,
            "'L7' is not a level",
        ),
        (lambda s, k: s[:k], IssueKind.WRONG_GOAL, "ends on level L1, but room208 is on level L2"),
        (lambda s, k: s[: k - 1] + s[k:], IssueKind.WRONG_GOAL, "not at the goal lift_a"),
    ],
    ids=["unknown lift", "unknown level", "no ride", "no arrive at the lobby"],
)
def test_wrong_answers_are_caught_with_their_step(sm, best, change, kind, words):
    steps = good_steps(best)
    k = next(i for i, (_, a) in enumerate(steps) if a.startswith("take the lift"))
    sp = resolve_start(sm.maps["L1"], "start")
    checked, issues = check_site_plan(sm, "L1", sp, "L2", "room208", raw(change(steps, k)))
    assert checked is None
    assert issues[0].kind is kind and words in issues[0].message, issues


def test_a_wrong_step_on_the_second_level_is_numbered_in_the_whole_answer(sm, best):
    steps = good_steps(best)
    steps[-1] = ("room209", "arrive")
    sp = resolve_start(sm.maps["L1"], "start")
    _, issues = check_site_plan(sm, "L1", sp, "L2", "room208", raw(steps))
    assert issues[0].kind is IssueKind.WRONG_GOAL and issues[0].step == len(steps)


def test_a_valid_answer_becomes_the_plan_across_levels(sm, best):
    with ChatServer(Script([Reply(answer(good_steps(best)))])) as s:
        p = planner(s, fallback=False).plan(sm, "L1", "start", "Laboratory")
    assert [leg.plan.planner for leg in p.legs] == ["vlm", "vlm"]
    assert [leg.plan.nodes for leg in p.legs] == [leg.plan.nodes for leg in best.legs]
    assert p.step_texts() == best.step_texts()
    assert p.legs[-1].plan.notes[-1] == "vlm (h-pm) across levels: valid on answer 1"
    content = s.requests[0]["messages"][0]["content"]
    text = content[0]["text"]
    assert "Step 1. Which levels does the route pass" in text
    assert "# Level L1" in text and "# Level L2" in text and '- lift1 "Lift A"' in text
    assert "Robot position (level L1): on seg1(start-reception)" in text
    assert sum(part["type"] == "image_url" for part in content) == 2  # one map per level


def test_a_wrong_ride_is_reprompted_and_repaired(sm, best):
    steps = good_steps(best)
    k = next(i for i, (_, a) in enumerate(steps) if a.startswith("take the lift"))
    wrong = steps[:k] + [("lift2", steps[k][1])] + steps[k + 1 :]
    with ChatServer(Script([Reply(answer(wrong)), Reply(answer(steps))])) as s:
        vp = planner(s, tries=2, fallback=False)
        p = vp.plan(sm, "L1", "start", "Laboratory")
        repair = s.requests[1]["messages"][-1]["content"]
    assert p.rides[0].lift == "lift1"
    assert "the plan ends at lift_a, not at the goal lift_b" in repair
    assert vp.stats.repaired == 1 and vp.stats.issues["wrong_goal"] == 1


def test_no_valid_answer_falls_back_to_the_graph_across_levels(sm, best):
    with ChatServer(Script([Reply("Take the lift.")])) as s:
        vp = planner(s)
        p = vp.plan(sm, "L1", "start", "Laboratory")
    assert p.step_texts() == best.step_texts()
    assert p.legs[-1].plan.planner == "vlm->graph"
    assert "fallback to the graph planner" in p.legs[-1].plan.notes[-1]
    assert vp.stats.fallbacks == 1


def test_a_goal_on_the_start_level_is_the_one_level_vlm_plan(sm):
    g = SitePlanner().plan(sm, "L2", "start", "Laboratory")
    steps = [(s.landmark, s.action.value) for s in g.legs[0].plan.steps]
    with ChatServer(Script([Reply(answer(steps))])) as s:
        p = planner(s, fallback=False).plan(sm, "L2", "start", "Laboratory")
        text = s.requests[0]["messages"][0]["content"][0]["text"]
    assert not p.rides and p.legs[0].plan.planner == "vlm"
    assert "# Level" not in text and "Step 1. Where is the robot" in text


def test_the_ordinary_prompt_does_not_plan_across_levels(sm):
    sp = resolve_start(sm.maps["L1"], "start")
    with pytest.raises(PmNavError, match="'o-em' cannot plan across levels"):
        site_plan_text(sm, ["L1", "L2"], "L1", sp, "L2", "room208", "o-em", 14.0)
