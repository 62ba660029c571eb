"""The commands that take a building, given a site: validate, map and plan per level."""

from __future__ import annotations

import json

import cv2
import pytest
import yaml
from site_kit import two_level_site

from pmnav_bt.experiments.cli import main


def run(capsys, *argv) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    out, err = capsys.readouterr()
    return info.value.code or 0, out, err


def test_validate_reports_each_level(capsys):
    code, out, _ = run(capsys, "validate", "hospital_2l")
    lines = out.splitlines()
    assert code == 0
    assert lines[0].startswith("hospital_2l: level L1: OK: hospital_2l_L1: 19 rooms")
    assert lines[1].startswith("hospital_2l: level L2: OK: hospital_2l_L2: 18 rooms")
    assert lines[2] == "hospital_2l: OK: site hospital_2l: 2 levels, 2 lifts, 1 stairs"


def test_validate_one_level(capsys):
    code, out, _ = run(capsys, "validate", "hospital_2l", "--level", "L2")
    assert code == 0 and "level L1" not in out and "level L2: OK" in out


def test_validate_site_file_lists_every_problem(capsys, tmp_path):
    data = two_level_site()
    data["lifts"][0]["lobbies"]["L3"] = "lA"
    data["lifts"][1]["lobbies"] = {"L1": "lB"}
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(data))
    code, _, err = run(capsys, "validate", str(f))
    lines = err.strip().splitlines()
    assert code == 1 and lines[-1] == "2 problem(s)"
    assert lines[0].startswith(f"{f}: lifts[0].lobbies.L3: unknown level 'L3'")
    assert lines[1].startswith(f"{f}: lifts[1].lobbies: lift 'liftB' has a lobby on 1 level")


def test_unknown_level_is_one_line(capsys):
    code, _, err = run(capsys, "map", "hospital_2l", "--level", "L7")
    assert code == 2 and err.strip() == "pmnav: error: no level 'L7' in hospital_2l; levels: L1, L2"


def test_map_text_names_levels_and_lifts(capsys):
    code, out, _ = run(capsys, "map", "hospital_2l")
    assert code == 0
    assert "# Level L1" in out and "# Level L2" in out
    assert '- lift1 "Lift A": L1 at lift_a' in out
    code, out, _ = run(capsys, "map", "hospital_2l", "--level", "L2")
    assert "# Level L2" in out and "# Level L1" not in out and "- lift2" in out


def test_map_json_has_every_level(capsys):
    code, out, _ = run(capsys, "map", "hospital_2l", "--json")
    d = json.loads(out)
    assert [lv["name"] for lv in d["levels"]] == ["L1", "L2"]
    assert d["lifts"][0]["lobbies"] == {"L1": "lift_a", "L2": "lift_a"}


def test_map_image_per_level(capsys, tmp_path):
    out = tmp_path / "m.png"
    code, _, err = run(capsys, "map", "hospital_2l", "--image", str(out))
    assert code == 0
    for level in ("L1", "L2"):
        img = cv2.imread(str(tmp_path / f"m_{level}.png"))
        assert img is not None and img.shape[0] > 200
    code, _, _ = run(capsys, "map", "hospital_2l", "--level", "L2", "--image", str(out))
    assert cv2.imread(str(out)) is not None


def test_a_building_prints_as_before(capsys):
    _, before, _ = run(capsys, "map", "fig2_hospital")
    _, as_level, _ = run(capsys, "map", "fig2_hospital", "--level", "L1")
    assert as_level == before


def test_plan_across_levels(capsys):
    code, out, _ = run(capsys, "plan", "hospital_2l", "--from", "start", "--to", "Laboratory")
    assert code == 0
    assert "Level L1:" in out and "Level L2:" in out
    assert "ride: {lift1: take the lift to level L2}" in out


def test_plan_start_level_and_qualified_goal(capsys):
    argv = ["plan", "hospital_2l", "--start-level", "L2", "--from", "room213", "--json"]
    code, out, _ = run(capsys, *argv, "--to", "L1/Toilets")
    d = json.loads(out)
    assert code == 0 and d["start_level"] == "L2" and d["goal"]["room"] == "room113"
    assert d["rides"] == [
        {"lift": "lift2", "from": "L2", "to": "L1", "text": "{lift2: take the lift to level L1}"}
    ]


def test_plan_ambiguous_goal_is_one_line(capsys):
    code, _, err = run(capsys, "plan", "hospital_2l", "--from", "start", "--to", "toilets")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "is on 2 levels: L1" in err


def test_plan_of_a_building_with_start_level_is_unchanged(capsys):
    argv = ["plan", "fig2_hospital", "--from", "seg13", "--to", "room17"]
    _, before, _ = run(capsys, *argv)
    _, with_level, _ = run(capsys, *argv, "--start-level", "L1")
    assert with_level == before


def test_plan_across_levels_with_a_planner_that_cannot(capsys):
    argv = ["plan", "hospital_2l", "--from", "start", "--to", "Laboratory", "--planner", "nope"]
    code, _, err = run(capsys, *argv)
    assert code == 2
    assert err.strip().endswith("planner 'nope' cannot plan across levels: choose graph, vlm")


def test_plan_across_levels_with_the_vlm(capsys):
    from pmnav_bt.vlm.scripted_server import ChatServer, Script

    with ChatServer(Script([])) as s:  # answers nothing usable: the graph plans instead
        argv = ["plan", "hospital_2l", "--from", "start", "--to", "Laboratory", "--planner"]
        sets = ["--set", f"vlm.base_url={s.base_url}", "--set", "vlm.model=m"]
        code, out, err = run(capsys, *argv, "vlm", *sets, "--set", "vlm.retries=0")
    assert code == 0, err
    assert "ride: {lift1: take the lift to level L2}" in out and "vlm->graph" in out
