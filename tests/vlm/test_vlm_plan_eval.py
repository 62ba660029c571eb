"""The Table 2 harness end to end against the scripted server, and its replay."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pmnav_bt.experiments.cli import main
from pmnav_bt.vlm.prompts import template
from pmnav_bt.vlm.scripted_server import ChatServer, PlanningResponder

ROOT = Path(__file__).resolve().parents[2]
tomllib = pytest.importorskip("tomllib")  # Python 3.11+


def run(*argv) -> None:
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    assert not info.value.code


def test_plan_eval_then_replay_give_the_same_table(tmp_path, capsys):
    out = tmp_path / "eval"
    with ChatServer(PlanningResponder(wrong=0.5, seed=1)) as s:
        run(
            "plan", "eval", "--endpoint", s.base_url, "--model", "scripted",
            "--inputs", "o-em,h-pm", "--building", "fig2_hospital", "--tier", "all",
            "-n", "2", "--tries", "2", "--out", str(out),
        )  # fmt: skip
    first = capsys.readouterr().out
    data = json.loads((out / "results.json").read_text())
    rows = data["results"]
    assert len(rows) == 2 * 3 * 2  # inputs x tiers x n
    assert {r["inputs"] for r in rows} == {"o-em", "h-pm"}
    assert any(r["correct"] for r in rows) and not all(r["correct"] for r in rows)
    assert any(r["correct_after_repair"] and not r["correct"] for r in rows)
    transcripts = sorted((out / "transcripts").glob("*/*.json"))
    assert len(transcripts) == len(rows)
    t = json.loads(transcripts[0].read_text())
    assert t["turns"][0]["role"] == "user" and t["turns"][0]["images"][0]["sha256"]
    md = (out / "results.md").read_text()
    assert "A plan is correct when" in md and "Episode tiers" in md

    run("plan", "eval", "--replay", str(out))
    again = capsys.readouterr().out
    table = [line for line in first.splitlines() if line.startswith("|")]
    assert table and table == [line for line in again.splitlines() if line.startswith("|")]


def test_route_is_still_the_default_plan_command(capsys):
    run("plan", "fig2_hospital", "--from", "seg13", "--to", "room17")
    assert "{room17: arrive}" in capsys.readouterr().out


def test_the_prompt_templates_are_package_data():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert "prompts/*.txt" in cfg["package-data"]["pmnav_bt.vlm"]
    for name in ("h_cot", "ordinary", "repair", "coarse", "priori_map_section"):
        assert template(name).template.strip()
