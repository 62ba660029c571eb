"""The 'pmnav sim' workflows a user runs with their own building, from any directory."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from pmnav_bt.experiments.cli import main
from pmnav_bt.map.catalogue import BUILTIN_DIR, load_building
from pmnav_bt.map.floorplan import rasterize_building, save_ros_map
from pmnav_bt.testing.oracle import ORACLE_SET


def run(capsys, *argv) -> tuple[int, str, str]:
    with pytest.raises(SystemExit) as info:
        main(list(argv))
    out, err = capsys.readouterr()
    return info.value.code or 0, out, err


@pytest.fixture
def own_building(tmp_path, monkeypatch):
    """A copy of a built-in building in tmp_path/plans, with a ros_map floor plan in
    plans/maps/, and the working directory elsewhere."""
    plans = tmp_path / "plans"
    (plans / "maps").mkdir(parents=True)
    data = yaml.safe_load((BUILTIN_DIR / "straight_office.yaml").read_text())
    data["name"] = "my_office"
    save_ros_map(rasterize_building(load_building("straight_office")), plans / "maps" / "ros.yaml")
    data["floor_plan"] = {"ros_map": "maps/ros.yaml"}
    path = plans / "my_office.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    cwd = tmp_path / "elsewhere"
    cwd.mkdir()
    monkeypatch.chdir(cwd)
    return path


def test_episodes_print_json_on_stdout_and_write_nothing_here(capsys, own_building):
    code, out, err = run(capsys, "sim", "episodes", str(own_building), "--tier", "easy", "-n", "2")
    assert code == 0
    data = json.loads(out)  # stdout is the JSON and nothing else
    assert len(data["episodes"]) == 2 and "Episode tiers" in err
    ep = data["episodes"][0]
    assert ep["building"] == "my_office" and ep["building_path"] == str(own_building.resolve())
    assert len(ep["building_sha256"]) == 64
    assert list(own_building.parent.parent.joinpath("elsewhere").iterdir()) == []


def test_run_an_episode_file_needs_no_goal_and_plots_the_ros_map(capsys, own_building, tmp_path):
    eps = tmp_path / "eps.json"
    code, _, err = run(
        capsys, "sim", "episodes", str(own_building), "-n", "1", "--seed", "3", "--out", str(eps)
    )
    assert code == 0 and "wrote 1 episodes" in err
    code, _, err = run(capsys, "sim", "run", "--episodes", str(eps), "--goal", "room1")
    assert code == 2 and "drop --goal" in err
    # The floor plan (maps/ros.yaml, relative to the building file) is found for the plot.
    argv = ["sim", "run", "--episodes", str(eps), "--index", "0", "--out", "o", *ORACLE_SET]
    code, out, err = run(capsys, *argv)
    assert code == 0, out + err
    assert "SUCCESS" in out and "trajectory plot:" in out
    assert len(list((tmp_path / "elsewhere" / "o").glob("*.trajectory.png"))) == 1


def test_run_a_goal_in_an_own_building_by_relative_path(capsys, own_building):
    rel = "../plans/my_office.yaml"
    argv = ["sim", "run", "--building", rel, "--goal", "room1", "--out", "o", *ORACLE_SET]
    code, out, err = run(capsys, *argv)
    assert code == 0, out + err
    assert "PM-Nav [sim_gt (oracle)] in my_office" in out and "SUCCESS" in out
    assert " 0 collisions, 0 people contacts, " in out  # the clean world has nobody about


def test_eval_an_own_building_from_another_directory(capsys, own_building):
    argv = ["sim", "eval", "--building", str(own_building), "--tier", "easy", "-n", "1"]
    code, out, err = run(
        capsys, *argv, "--variants", "pmnav", "--jobs", "1", "--out", "o", *ORACLE_SET
    )
    assert code == 0, out + err
    # Every variant runs in the clean and the realistic world, side by side.
    head = out.splitlines()[0]
    assert head.index("PM-Nav, clean world SR") < head.index("PM-Nav, realistic world SR")
    assert "| easy | 1 | 100.0 |" in out
    # The oracle is labelled as such wherever results print.
    md = Path("o/results.md").read_text()
    assert "PM-Nav, realistic world: grounder sim_gt (oracle)" in md
    results = json.loads(Path("o/results.json").read_text())
    assert list(results) == ["pmnav@clean", "pmnav@realistic"]
    r = results["pmnav@clean"][0]
    assert r["error"] is None and r["building"] == "my_office"
    # Contacts with people are recorded per episode (the realistic world has people) and
    # totalled per variant.
    assert all(isinstance(rs[0]["people_contacts"], int) for rs in results.values())
    assert "per 100 episodes); people contacts: " in out


def test_eval_refuses_an_unknown_world_or_none(capsys):
    for worlds, says in (("foggy", "unknown world 'foggy'"), (",", "--worlds ',': names nothing")):
        code, out, err = run(capsys, "sim", "eval", "--worlds", worlds, "--out", "o")
        assert code == 2 and says in err, err


def test_eval_exits_non_zero_and_counts_errored_episodes(capsys, own_building, monkeypatch):
    def crash(*args, **kwargs):
        raise RuntimeError("the simulator fell over")

    monkeypatch.setattr("pmnav_bt.experiments.evaluation.run_episode", crash)
    argv = ["sim", "eval", "--building", str(own_building), "--tier", "easy", "-n", "2"]
    argv += ["--variants", "pmnav", "--worlds", "clean", "--jobs", "1", "--out", "o"]
    code, out, err = run(capsys, *argv)
    assert code == 1
    assert "episodes could not be run (pmnav@clean 2 of 2)" in err and "fell over" in err
    assert "PM-Nav, clean world errors" in out  # the table counts them apart from failures


def test_eval_all_means_every_builtin_building(monkeypatch):
    from pmnav_bt.experiments.options import building_names
    from pmnav_bt.map.catalogue import builtin_buildings

    assert building_names("all") == builtin_buildings()
    assert building_names("a.yaml, t_school") == ["a.yaml", "t_school"]


def test_a_changed_building_file_is_one_clear_line(capsys, own_building, tmp_path):
    eps = tmp_path / "eps.json"
    assert run(capsys, "sim", "episodes", str(own_building), "-n", "1", "--out", str(eps))[0] == 0
    own_building.write_text(own_building.read_text() + "\n# moved a door\n")
    code, out, err = run(capsys, "sim", "run", "--episodes", str(eps))
    assert code == 2 and "has changed since the episodes were made" in err
    assert len(err.strip().splitlines()) == 1
