"""Every example of issue 16, as a test: a hostile input gets one clear line, results survive.

The classes that used to segfault, hang or exhaust memory run ``pmnav`` in a child with
a timeout and an address-space limit (fuzzkit.pmnav_subprocess); the others run in this
process (fuzzkit.pmnav_cli). Each asserts: non-zero exit, exactly one line on stderr
naming the file, field or option, no traceback.
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import pytest
import yaml
from fuzzkit import TRIED, assert_clean_failure, one_line, pmnav_cli, pmnav_subprocess

from pmnav_bt.map.catalogue import BUILTIN_DIR

pytestmark = pytest.mark.timeout(120)  # bounded time, whatever regresses

OFFICE = yaml.safe_load((BUILTIN_DIR / "straight_office.yaml").read_text())


def building_file(tmp_path: Path, fname: str = "b.yaml", **changes) -> Path:
    data = {**OFFICE, **changes}
    f = tmp_path / fname
    f.write_text(yaml.safe_dump(data, sort_keys=False))
    return f


def cli_fails(capsys, argv: list, *words: str) -> str:
    TRIED["issue examples: in-process CLI"] += 1
    code, _, err = pmnav_cli(capsys, *argv)
    assert code != 0, err
    return one_line(err, *words)


# -- crashes -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def deep_yaml(tmp_path_factory) -> Path:
    f = tmp_path_factory.mktemp("deep") / "deep.yaml"
    f.write_text("schema_version: 1\nname: deep\nwaypoints: " + "[" * 50_000 + "]" * 50_000)
    return f


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", "{f}"],
        ["map", "{f}"],
        ["plan", "{f}", "--from", "seg1", "--to", "room1"],
        ["sim", "run", "--building", "{f}", "--goal", "room1", "--out", "{out}"],
    ],
    ids=["validate", "map", "plan", "sim-run"],
)
def test_deep_yaml_is_refused_not_a_segfault(deep_yaml, tmp_path, argv):
    TRIED["issue examples: child process"] += 1
    args = [a.format(f=deep_yaml, out=tmp_path / "o") for a in argv]
    res = pmnav_subprocess(*args)
    line = assert_clean_failure(res, "deep.yaml", "nested deeper than 32 levels")
    assert line


def test_huge_floor_plan_png_is_refused_from_its_header(tmp_path):
    from test_fuzz_loaders import _png

    TRIED["issue examples: child process"] += 1
    (tmp_path / "plan.png").write_bytes(_png(30_000, 30_000, b"\0" * 64))
    f = building_file(tmp_path, floor_plan={"image": "plan.png", "metres_per_pixel": 0.05})
    res = pmnav_subprocess("map", f, "--image", tmp_path / "out.png")
    assert_clean_failure(res, "floor_plan.image", "30000x30000 pixels")
    assert not (tmp_path / "out.png").exists()


# -- tracebacks with one cause each ------------------------------------------------------

ENCODINGS = {
    "binary": b"\x89PNG\r\n\x1a\n\x00\x00\xff\xfe",
    "utf16": "schema_version: 1\nname: x\n".encode("utf-16"),
    "latin1": "schema_version: 1\nname: caf\xe9\n".encode("latin-1"),
}


@pytest.mark.parametrize("enc", list(ENCODINGS))
@pytest.mark.parametrize("what", ["building", "config", "episodes", "ros_map"])
def test_non_utf8_files(capsys, tmp_path, enc, what):
    f = tmp_path / f"x.{'json' if what == 'episodes' else 'yaml'}"
    f.write_bytes(ENCODINGS[enc])
    argv = {
        "building": ["map", f],
        "config": ["sim", "run", "--goal", "room1", "--config", f],
        "episodes": ["sim", "run", "--episodes", f],
        "ros_map": ["validate", building_file(tmp_path, floor_plan={"ros_map": f.name})],
    }[what]
    if what == "ros_map":
        code, _, err = pmnav_cli(capsys, *argv)
        assert code == 1 and "not UTF-8" in err and "Traceback" not in err
        TRIED["issue examples: in-process CLI"] += 1
        return
    cli_fails(capsys, argv, f.name, "not UTF-8")


def test_integer_over_4300_digits(capsys, tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text(building_file(tmp_path).read_text() + "wall_height: " + "9" * 5000 + "\n")
    cli_fails(capsys, ["map", f], "b.yaml", "more than 4300 digits")


@pytest.mark.parametrize("where", ["building", "config", "episodes"])
def test_path_over_255_characters(capsys, where):
    long = "/tmp/" + "x" * 300 + ".yaml"
    argv = {
        "building": ["map", long],
        "config": ["sim", "run", "--goal", "room1", "--config", long],
        "episodes": ["sim", "run", "--episodes", long],
    }[where]
    cli_fails(capsys, argv, "path too long")


@pytest.mark.parametrize("value", ["[", "{a: 1", "'x", "1e-300", ".inf", "-.nan", "true", "'10'"])
def test_set_values_that_are_not_usable(capsys, value):
    cli_fails(
        capsys, ["sim", "run", "--goal", "room1", "--set", f"tree.tick_hz={value}"], "tree.tick_hz"
    )


@pytest.fixture
def a_file(tmp_path) -> Path:
    f = tmp_path / "file"
    f.write_text("x")
    return f


@pytest.mark.parametrize(
    "argv, words",
    [
        (["sim", "eval", "-n", "1", "--out", "{file}"], ["--out", "is a file"]),
        (["sim", "eval", "-n", "1", "--out", "{file}/sub"], ["--out", "is a file"]),
        (["sim", "eval", "-n", "1", "--out", "/tmp/" + "y" * 300], ["--out", "path too long"]),
        (["sim", "run", "--goal", "room1", "--out", "{file}"], ["--out", "is a file"]),
        (["sim", "show", "straight_office", "--out", "{file}/sub"], ["--out", "is a file"]),
        (["sim", "episodes", "straight_office", "--out", "{file}/e.json"], ["--out", "is a file"]),
        (["map", "straight_office", "--image", "{dir}/x.txt"], ["--image", ".png"]),
        (["map", "straight_office", "--image", "{file}/x.png"], ["--image", "is a file"]),
        (
            ["plan", "straight_office", "--from", "seg1", "--to", "room1", "--image", "{dir}"],
            ["--image"],
        ),
    ],
    ids=[
        "eval-file",
        "eval-under-file",
        "eval-long",
        "run-file",
        "show-under-file",
        "episodes-under-file",
        "map-image-txt",
        "map-image-under-file",
        "plan-image-folder",
    ],
)
def test_output_problems_before_any_work(capsys, a_file, argv, words):
    args = [a.format(file=a_file, dir=a_file.parent) for a in argv]
    cli_fails(capsys, args, *words)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_out(capsys, tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        cli_fails(capsys, ["sim", "eval", "-n", "1", "--out", ro / "x"], "--out", "cannot write")
    finally:
        ro.chmod(stat.S_IRWXU)


TREE_LINE = {"type": "tree", "nodes": [{"id": "1", "name": "r", "class": "S", "parent": None}]}


@pytest.mark.parametrize(
    "records, words",
    [
        ([{**TREE_LINE, "nodes": {"id": "1"}}], ["'nodes' must be a non-empty list"]),
        ([{"type": "tree", "nodes": [TREE_LINE["nodes"][0]] * 2}], ["duplicate node id '1'"]),
        (
            [{"type": "tree", "nodes": [{"id": "1", "name": "r", "class": "S", "parent": "1"}]}],
            ["not an earlier node's id"],
        ),
        (
            [
                TREE_LINE,
                {
                    "type": "tick",
                    "tick": "1",
                    "time": 0,
                    "status": {},
                    "feedback": {},
                    "blackboard": {},
                },
            ],
            ["'tick' must be an integer"],
        ),
        (
            [
                TREE_LINE,
                {
                    "type": "tick",
                    "tick": 1,
                    "time": 0,
                    "status": [],
                    "feedback": {},
                    "blackboard": {},
                },
            ],
            ["'status' must be an object"],
        ),
    ],
    ids=["nodes-not-list", "duplicate-ids", "self-parent", "tick-str", "status-list"],
)
def test_tree_log_records_are_type_checked(capsys, tmp_path, records, words):
    f = tmp_path / "t.jsonl"
    f.write_text("".join(json.dumps(r) + "\n" for r in records))
    cli_fails(capsys, ["tree", "replay", f], "t.jsonl", *words)


def test_deep_json(capsys, tmp_path):
    f = tmp_path / "e.json"
    f.write_text("[" * 100_000 + "]" * 100_000)
    cli_fails(capsys, ["sim", "run", "--episodes", f], "e.json", "nested")
    t = tmp_path / "t.jsonl"
    t.write_text(json.dumps(TREE_LINE) + "\n" + "[" * 100_000 + "]" * 100_000 + "\n")
    cli_fails(capsys, ["tree", "replay", t], "t.jsonl", "line 2", "nested")


@pytest.mark.parametrize(
    "argv, words",
    [
        (
            [
                "sim",
                "run",
                "--goal",
                "room1",
                "--building",
                "straight_office",
                "--start",
                "46,20," + "9" * 400,
            ],
            ["pose", "finite"],
        ),
        (["sim", "show", "straight_office", "--pose", "nan,nan,nan"], ["--pose", "finite"]),
        (["sim", "show", "straight_office", "--pose", "1e400,0,0"], ["--pose", "finite"]),
        (["sim", "show", "straight_office", "--pose", "5000,0,0"], ["--pose", "within"]),
        (["sim", "episodes", "straight_office", "--seed", "-5"], ["--seed", "-5"]),
        (["sim", "run", "--goal", "room1", "--seed", "-5"], ["--seed"]),
        (["sim", "eval", "--jobs", str(10**30)], ["--jobs", "CPUs"]),
        (["sim", "eval", "--jobs", "0"], ["--jobs"]),
        (["sim", "eval", "-n", str(10**30)], ["-n"]),
        (["sim", "episodes", "straight_office", "-n", str(10**30)], ["-n"]),
        (
            ["plan", "straight_office", "--from", "seg1", "--to", "room1", "--max-gap", "inf"],
            ["--max-gap", "finite"],
        ),
        (["sim", "show", "straight_office", "--width", "100000"], ["--width"]),
    ],
    ids=[
        "start-400-digits",
        "pose-nan",
        "pose-overflow",
        "pose-far",
        "episodes-seed-neg",
        "run-seed-neg",
        "jobs-huge",
        "jobs-zero",
        "eval-n-huge",
        "episodes-n-huge",
        "max-gap-inf",
        "show-width-huge",
    ],
)
def test_odd_numbers_on_the_command_line(capsys, argv, words):
    cli_fails(capsys, argv, *words)


# -- hangs and blow-ups ------------------------------------------------------------------


@pytest.mark.parametrize("what", ["building", "config"])
def test_fifo_is_refused_not_a_hang(tmp_path, what):
    TRIED["issue examples: child process"] += 1
    fifo = tmp_path / "f.yaml"
    os.mkfifo(fifo)
    argv = ["map", fifo] if what == "building" else ["sim", "run", "--goal", "r", "--config", fifo]
    res = pmnav_subprocess(*argv, timeout=30)
    assert_clean_failure(res, "f.yaml", "not a regular file")


@pytest.mark.parametrize("what", ["building", "config"])
def test_dev_zero_is_refused_not_read(what):
    TRIED["issue examples: child process"] += 1
    argv = (
        ["validate", "/dev/zero"]
        if what == "building"
        else ["sim", "run", "--goal", "r", "--config", "/dev/zero"]
    )
    res = pmnav_subprocess(*argv, timeout=30)
    assert res.returncode > 0 and "Traceback" not in res.stderr
    assert "/dev/zero" in res.stderr and "not a regular file" in res.stderr


@pytest.mark.parametrize(
    "setting, words",
    [
        ("tree.tick_hz=1e-300", ["tree.tick_hz", "greater than or equal to 0.5"]),
        ("tree.tick_hz=.inf", ["tree.tick_hz"]),
        ("sim.width=100000", ["sim.width", "less than or equal to 1920"]),
        ("tree.budget_actions=1e30", ["tree.budget_actions"]),
    ],
)
def test_config_values_that_would_hang_or_blow_up(capsys, setting, words):
    cli_fails(capsys, ["sim", "run", "--goal", "room1", "--set", setting], "--set", *words)


def test_wall_height_1e30_is_refused(capsys, tmp_path):
    f = building_file(tmp_path, wall_height=1e30)
    cli_fails(capsys, ["map", f], "b.yaml", "wall_height", "less than or equal to 20")


def test_alias_bomb_is_refused(capsys, tmp_path):
    big = "x" * (1 << 20)
    head = building_file(tmp_path).read_text()
    f = tmp_path / "bomb.yaml"
    f.write_text(head + f"description: &s {big}\nextra: [" + ", ".join(["*s"] * 20_000) + "]\n")
    assert f.stat().st_size > 1_100_000
    cli_fails(capsys, ["map", f], "bomb.yaml", "aliases")
    # Fewer aliases, each a 1 MB string: refused by the text limits, still cheap.
    g = tmp_path / "names.yaml"
    rooms = "".join(
        f"  - {{id: r{i}, name: {'&s ' + big if i == 0 else '*s'}, door: [{6.5 + i * 0.1}, 1.1]}}\n"
        for i in range(100)
    )
    g.write_text(head.split("rooms:")[0] + f"rooms:\n{rooms}")
    cli_fails(capsys, ["map", g], "names.yaml", "at most 200 characters")


# -- unsafe output names -----------------------------------------------------------------


@pytest.mark.parametrize("name", ["../../..", "a/b", "x" * 100_000])
def test_building_names_never_leave_out(capsys, tmp_path, name):
    f = building_file(tmp_path, name=name)
    out = tmp_path / "deep" / "out"
    code, _, err = pmnav_cli(
        capsys, "sim", "show", f, "--out", out, "--width", "64", "--height", "48"
    )
    TRIED["issue examples: in-process CLI"] += 1
    if len(name) > 200:
        assert code != 0
        one_line(err, "name", "at most 200 characters")
        return
    assert code == 0, err
    written = sorted(p.name for p in out.iterdir())
    assert len(written) == 4 and all("/" not in w and not w.startswith(".") for w in written)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b.yaml", "deep"]
    assert sorted(p.name for p in (tmp_path / "deep").iterdir()) == ["out"]


def test_episode_file_names_are_safe():
    from pmnav_bt.loading import safe_filename

    for text in ["../../..-room1", "a/b\\c", "..", "", "x" * 1000, "room\0 1"]:
        name = safe_filename(text)
        assert name and "/" not in name and "\\" not in name and not name.startswith(".")
        assert len(name) <= 100 and "\0" not in name


# -- lost results ------------------------------------------------------------------------


def test_results_written_atomically(tmp_path, monkeypatch):
    from pmnav_bt.experiments import evaluation
    from pmnav_bt.loading import atomic_write_text

    target = tmp_path / "results.json"
    atomic_write_text(target, '{"old": "valid"}')

    def disk_full(_fd):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", disk_full)
    with pytest.raises(OSError):
        evaluation.save_evaluation({}, tmp_path, "# header")
    assert json.loads(target.read_text()) == {"old": "valid"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["results.json"]  # no temp left


def test_cut_tree_log_replays_up_to_the_cut(capsys, tmp_path):
    tick = {
        "type": "tick",
        "tick": 0,
        "time": 0.0,
        "status": {"1": "RUNNING"},
        "feedback": {},
        "blackboard": {},
    }
    lines = [json.dumps(TREE_LINE)] + [json.dumps({**tick, "tick": i}) for i in range(3)]
    f = tmp_path / "t.jsonl"
    f.write_text("\n".join(lines)[:-10])  # killed mid-write of the last record
    code, out, err = pmnav_cli(capsys, "tree", "replay", f)
    TRIED["issue examples: in-process CLI"] += 1
    assert code == 0
    one_line(err, "t.jsonl", "line 4", "cut short", "2 complete tick records")
    assert "tick 0" in out and "tick 1" in out and "tick 2" not in out
    # A broken line in the middle is still an error.
    g = tmp_path / "g.jsonl"
    g.write_text("\n".join([lines[0], lines[1][:-5], lines[2]]) + "\n")
    cli_fails(capsys, ["tree", "replay", g], "g.jsonl", "line 2", "not valid JSON")


# -- smaller -----------------------------------------------------------------------------


def test_goal_name_whitespace_matches_the_node():
    from pmnav_bt.hardware.goal import parse_args, result_for

    args = parse_args(["room18 "])
    assert args.goal == "room18"  # the node strips it and names the stripped goal
    assert result_for(json.dumps({"goal": "room18", "success": True}), args.goal)
    assert result_for("not json", args.goal) is None
    assert result_for("[1]", args.goal) is None


@pytest.mark.parametrize(
    "change, words",
    [
        ({"schema_version": "1"}, ["schema_version", "valid integer"]),
        ({"wall_height": True}, ["wall_height", "valid number"]),
        ({"corridor_width": "2.4"}, ["corridor_width", "valid number"]),
    ],
)
def test_strings_and_booleans_are_not_numbers(capsys, tmp_path, change, words):
    cli_fails(capsys, ["map", building_file(tmp_path, **change)], "b.yaml", *words)


def test_duplicate_keys_are_refused(capsys, tmp_path):
    f = tmp_path / "b.yaml"
    f.write_text(building_file(tmp_path).read_text() + "name: again\n")
    cli_fails(capsys, ["map", f], "b.yaml", "duplicate key 'name'")


def test_validate_opens_the_floor_plan(capsys, tmp_path):
    (tmp_path / "plan.png").write_bytes(b"\x89PNG\r\n\x1a\n" + b"\0" * 40)  # a broken PNG
    f = building_file(tmp_path, floor_plan={"image": "plan.png", "metres_per_pixel": 0.05})
    code, _, err = pmnav_cli(capsys, "validate", f)
    TRIED["issue examples: in-process CLI"] += 1
    assert code == 1 and "floor_plan.image" in err and "Traceback" not in err


def test_doors_along_one_wall_never_chain():
    from pmnav_bt.map.building import building_from_data
    from pmnav_bt.map.priori_map import parse_building

    rooms = [{"id": f"room{i}", "door": [10 + 0.5 * i, 1.2]} for i in range(10)]  # 4.5 m
    rooms += [{"id": "facing", "door": [10.2, -1.2]}]
    b = building_from_data({**OFFICE, "rooms": rooms, "landmarks": []})
    pm = parse_building(b)
    node_of = {r: pm.places[r].node for r in [f"room{i}" for i in range(10)] + ["facing"]}
    assert len({node_of[f"room{i}"] for i in range(10)}) == 10  # one node per door
    assert node_of["facing"] == node_of["room0"]  # facing doors still share one
    for i in range(10):
        x, _ = pm.nodes[node_of[f"room{i}"]].pos
        assert abs(x - (10 + 0.5 * i)) < 0.15  # no plan off by metres


def test_run_files_stay_in_out_whatever_the_episode_id(tmp_path):
    """The tree log and plot of `sim run` are named after the episode id (building name and
    goal): `../../..` in it never reaches outside --out."""
    from dataclasses import replace

    from pmnav_bt.experiments.evaluation import custom_episode, run_episode
    from pmnav_bt.testing.oracle import oracle_config

    TRIED["issue examples: in-process CLI"] += 1
    ep = replace(custom_episode("straight_office", "room1"), id="../../../evil/x")
    out = tmp_path / "a" / "out"
    r = run_episode(ep, oracle_config(), out_dir=out)
    assert r.tree_log.parent == out and r.plot.parent == out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a"]
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["out"]


@pytest.mark.parametrize("value", ["maybe", "2"])
def test_the_door_switch_takes_only_a_boolean(capsys, value):
    cli_fails(
        capsys,
        ["sim", "run", "--goal", "room1", "--set", f"tree.localization_doors={value}"],
        "--set",
        "tree.localization_doors",
        "valid boolean",
    )
