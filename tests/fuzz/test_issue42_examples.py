"""Every example of issue 42, as a test: the last tracebacks, exits 0 on bad input and a
results folder overwritten. Each refused input gets one line and a non-zero exit.

In-process (fuzzkit.pmnav_cli); the cases that run episodes or stop a process are in
test_results_overwrite.py, test_disk_full.py and test_worker_parent_death.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from fuzzkit import TRIED, one_line, pmnav_cli
from test_issue16_examples import building_file

pytestmark = pytest.mark.timeout(120)  # bounded time, whatever regresses

HUGE = "9" * 5000  # past int()'s 4300-digit limit


def refused(capsys, argv: list, *words: str) -> str:
    TRIED["issue 42 examples"] += 1
    code, _, err = pmnav_cli(capsys, *argv)
    assert code != 0, err
    return one_line(err, *words)


def pgm_map(folder: Path, width: int, height: int, origin=(0.0, 0.0), res=0.05) -> str:
    """A ROS map of free cells (map_server's 254), ``width`` x ``height``: its YAML's name."""
    cells = b"\xfe" * (width * height)
    (folder / "m.pgm").write_bytes(f"P5\n{width} {height}\n255\n".encode() + cells)
    (folder / "m.yaml").write_text(
        yaml.safe_dump({"image": "m.pgm", "resolution": res, "origin": [*origin, 0.0]})
    )
    return "m.yaml"


# -- tracebacks --------------------------------------------------------------------------


def test_validate_a_grid_smaller_than_its_building(capsys, tmp_path):
    f = building_file(tmp_path, floor_plan={"ros_map": pgm_map(tmp_path, 20, 20)})
    code, out, err = pmnav_cli(capsys, "validate", f)
    TRIED["issue 42 examples"] += 1
    assert code == 0 and "OK" in out and "Traceback" not in err
    assert "runs off the floor-plan grid (20x20 cells, 1 x 1 m)" in err


@pytest.mark.parametrize(
    "argv",
    [
        ["plan", "fig2_hospital", "--from", f"seg{HUGE}", "--to", "room17"],
        ["plan", "fig2_hospital", "--from", f"seg{HUGE}(a-b)", "--to", "room17"],
        ["sim", "run", "--goal", "room1", "--building", "straight_office", "--start", f"seg{HUGE}"],
    ],
    ids=["plan-from", "plan-from-named", "run-start"],
)
def test_segment_numbers_of_5000_digits(capsys, tmp_path, argv):
    line = refused(capsys, [*argv, *(["--out", tmp_path] if "run" in argv else [])], "segment")
    assert "seg9999" in line and len(line) < 300  # the number is cut short in the message


# -- exit 0 on bad input -----------------------------------------------------------------


def test_plan_refuses_the_floor_plan_validate_refuses(capsys, tmp_path):
    (tmp_path / "m.yaml").write_text("image: nope.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    f = building_file(tmp_path, floor_plan={"ros_map": "m.yaml"})
    for argv in (
        ["map", f],
        ["plan", f, "--from", "seg1", "--to", "room1"],
        ["sim", "episodes", f, "-n", "1"],
        ["sim", "run", "--building", f, "--goal", "room1", "--out", tmp_path / "o"],
    ):
        refused(capsys, argv, "b.yaml", "floor_plan.ros_map", "nope.pgm")
    code, _, err = pmnav_cli(capsys, "validate", f)
    assert code == 1 and "floor_plan.ros_map" in err and "nope.pgm" in err


@pytest.mark.parametrize("command", ["validate", "map", "plan"])
def test_a_building_path_with_a_trailing_slash(capsys, tmp_path, command):
    f = f"{building_file(tmp_path)}/"
    argv = [command, f] + (["--from", "seg1", "--to", "room1"] if command == "plan" else [])
    code, _, err = pmnav_cli(capsys, *argv)
    TRIED["issue 42 examples"] += 1
    assert code != 0 and "Traceback" not in err
    assert "b.yaml/" in err and "ending in '/'" in err


@pytest.mark.parametrize(
    "argv, option",
    [
        (["sim", "eval", "--variants", ","], "--variants"),
        (["sim", "eval", "--variants", " , ,"], "--variants"),
        (["sim", "eval", "--building", ","], "--building"),
        (["sim", "table3", "--building", ","], "--building"),
        (["report", "--variants", ","], "--variants"),
        (["sim", "eval", "--tier", ","], "--tier"),
    ],
)
def test_lists_that_name_nothing(capsys, tmp_path, argv, option):
    out = tmp_path / "o"
    refused(capsys, [*argv, "--out", out], option)
    assert not list(out.glob("**/results*"))


@pytest.mark.parametrize(
    "argv",
    [
        ["sim", "run", "--goal", "room1", "--out", ""],
        ["sim", "eval", "--out", ""],
        ["sim", "eval", "--out="],
        ["sim", "table3", "--out", ""],
        ["sim", "show", "straight_office", "--out", ""],
        ["map", "straight_office", "--image", ""],
        ["validate", ""],
    ],
)
def test_empty_paths(capsys, tmp_path, monkeypatch, argv):
    monkeypatch.chdir(tmp_path)
    refused(capsys, argv, "empty")
    assert list(tmp_path.iterdir()) == []  # nothing written into the current folder


@pytest.fixture
def episode_file(tmp_path):
    """One straight_office episode as `pmnav sim episodes` writes it; edit() changes it."""
    from pmnav_bt.sim.episodes import generate_episodes

    ep = generate_episodes("straight_office", "easy", 1, seed=0)[0].to_dict()

    def edit(**changes) -> Path:
        f = tmp_path / "e.json"
        f.write_text(json.dumps({"schema_version": 2, "episodes": [{**ep, **changes}]}))
        return f

    return edit


def test_an_episode_start_outside_the_building(capsys, tmp_path, episode_file):
    f = episode_file(start_x=500.0, start_y=500.0)
    refused(capsys, ["sim", "run", "--episodes", f, "--out", tmp_path / "o"], "start", "corridor")
    assert not (tmp_path / "o" / "results.jsonl").exists()


def test_an_episode_naming_another_building_than_its_file(capsys, tmp_path, episode_file):
    f = episode_file(building="fig2_hospital")
    line = refused(capsys, ["sim", "run", "--episodes", f, "--out", tmp_path / "o"])
    assert "'fig2_hospital'" in line and "'straight_office'" in line and "building_path" in line


# -- results overwritten -----------------------------------------------------------------

EARLIER = {
    "results.jsonl": '{"variant": "pmnav", "key": "pmnav/e0", "config_sha": "x"}\n',
    "results.json": '{"pmnav": []}',
    "results.md": "# PM-Nav evaluation\n\nan earlier run\n",
}


@pytest.mark.parametrize(
    "argv",
    [
        ["sim", "eval", "-n", "1", "--building", "straight_office"],
        ["sim", "table3", "-n", "1", "--building", "straight_office"],
    ],
    ids=["eval", "table3"],
)
def test_a_folder_of_earlier_results_is_refused(capsys, tmp_path, argv):
    out = tmp_path / "earlier"
    out.mkdir()
    for name, text in EARLIER.items():
        (out / name).write_text(text)
    refused(capsys, [*argv, "--out", out], str(out), "--resume", "--overwrite")
    assert {p.name: p.read_text() for p in out.iterdir()} == EARLIER
    refused(capsys, [*argv, "--out", out, "--resume", "--overwrite"], "choose one")
